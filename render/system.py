"""What every pendulum system shares: state fields, the integrators, the time step and the watchdog.

A subclass supplies the physics as Taichi functions (accel, energy, bobs) and its kernels; the integrator is
chosen at compile time with ti.static, so a run compiles only the method it uses.
"""

import math

import numpy as np
import taichi as ti

from . import runtime
from .scene import Scene, SceneError

# dt·ω_max must stay below this for the method to be stable on a linear oscillator (ω the fastest mode).
# implicit_midpoint's bound is where its fixed-point iteration stops contracting (h·L < 1), not stability.
STABILITY = {"symplectic_euler": 2.0, "verlet": 2.0, "rk4": 2.785, "yoshida4": 1.573, "implicit_midpoint": 1.0}
ORDER = {"symplectic_euler": 1, "verlet": 2, "rk4": 4, "yoshida4": 4, "implicit_midpoint": 2}
SAFETY = 0.1  # "auto" keeps dt·ω_max at a tenth of the limit: stable is not enough, it must be accurate
AUTO_DT = 1e-3  # longest step "auto" takes when no stiffness limits it
DEFAULT_MAX_DRIFT = 0.05

# Yoshida's 4th-order composition of three velocity-Verlet steps.
_CBRT2 = 2.0 ** (1.0 / 3.0)
YOSHIDA_W1 = 1.0 / (2.0 - _CBRT2)
YOSHIDA_W0 = -_CBRT2 / (2.0 - _CBRT2)


class SimulationError(RuntimeError):
    """A failure while running (exit 1), e.g. a numerical blow-up caught by the watchdog."""


def timestep(scene: Scene, omega_max: float) -> tuple[float, int]:
    """(step h, substeps per frame). h = frame time / substeps, never longer than the requested dt."""
    frame_dt = 1.0 / scene.video.fps
    method, dt = scene.integrator.method, scene.integrator.dt
    limit = STABILITY[method] / omega_max
    if dt == "auto":
        dt = min(AUTO_DT, SAFETY * limit)
    elif dt > limit and not scene.integrator.allow_unstable:
        raise SceneError(
            f"{scene.source}: integrator.dt: {dt:g} s is beyond the stability limit of {method} for this scene: "
            f"dt*omega_max must stay below {STABILITY[method]:g} (omega_max = {omega_max:.4g} rad/s, so "
            f"dt < {limit:.3g} s); use integrator.dt = \"auto\" or a smaller dt, "
            f"or set integrator.allow_unstable = true to proceed anyway")
    substeps = max(1, math.ceil(frame_dt / dt - 1e-9))
    return frame_dt / substeps, substeps


class System(runtime.Launcher):
    """Base of @ti.data_oriented systems. Subclasses set D (coordinates per pendulum) and NAME."""

    D = 0
    NAME = ""

    def __init__(self, scene: Scene):
        self.scene = scene
        p = scene.pendulums
        self.n = p.count
        self.method = scene.integrator.method
        self.damped = scene.has("damping")
        self.damping = p.damping
        self.g = p.gravity
        self.m1, self.m2 = p.masses
        self.l1, self.l2 = p.lengths
        self.h, self.substeps = timestep(scene, self.omega_max())
        self.tol = 1e-14 if scene.integrator.precision == "f64" else 1e-6  # implicit solves, in state units
        real = runtime.real()
        self.q = runtime.field("state.q", real, self.n, self.D)
        self.v = runtime.field("state.v", real, self.n, self.D)
        self.bad = runtime.field("watchdog.bad", ti.i32, ())
        self.t = 0.0
        q0, v0 = self.initial_state()
        self.q.from_numpy(q0.astype(np.float64 if real == ti.f64 else np.float32))
        self.v.from_numpy(v0.astype(np.float64 if real == ti.f64 else np.float32))
        self.bad[None] = self.n
        if scene.has("energy"):
            self.e = runtime.field("energy.e", real, self.n)
            self.e0 = runtime.field("energy.e0", real, self.n)
            self.escale = runtime.field("energy.scale", real, self.n)
            self.drift = runtime.field("energy.max_drift", real, ())

    # --------------------------------------------------------------- per-system parts
    def omega_max(self) -> float:
        """Fastest rate in rad/s that limits the step (the stiffest mode, or a speed bound)."""
        raise NotImplementedError

    def initial_angles(self) -> tuple[np.ndarray, np.ndarray]:
        """θ1, θ2 per pendulum: a fan θ2 − spread·i/count, or a θ1×θ2 grid over [−π, π]²."""
        p, n = self.scene.pendulums, self.n
        if p.layout == "grid":
            w, h = self.scene.video.width, self.scene.video.height
            th1 = np.tile(np.linspace(-np.pi, np.pi, w), h)
            th2 = np.repeat(np.linspace(np.pi, -np.pi, h), w)  # row 0 at the top of the frame
            return th1, th2
        i = np.arange(n, dtype=np.float64)
        return np.full(n, p.theta1), p.theta2 - p.spread * i / n

    # --------------------------------------------------------------- integrators
    @ti.func
    def step(self, q, v, h):
        if ti.static(self.method == "symplectic_euler"):
            q, v = self.symplectic_euler(q, v, h)
        elif ti.static(self.method == "verlet"):
            q, v = self.verlet(q, v, h)
        elif ti.static(self.method == "yoshida4"):
            q, v = self.verlet(q, v, YOSHIDA_W1 * h)
            q, v = self.verlet(q, v, YOSHIDA_W0 * h)
            q, v = self.verlet(q, v, YOSHIDA_W1 * h)
        elif ti.static(self.method == "rk4"):
            q, v = self.rk4(q, v, h)
        elif ti.static(self.method == "implicit_midpoint"):
            q, v = self.implicit_midpoint(q, v, h)
        return q, v

    @ti.func
    def force(self, q, v):
        a = self.accel(q, v)
        if ti.static(self.damped):
            a -= self.damping * v
        return a

    @ti.func
    def symplectic_euler(self, q, v, h):
        """The seed's v += a·h; x += v·h. Symplectic for the separable elastic system only: on the rigid
        system (θ, ω) are not canonical, so its energy error grows slowly (see README, Accuracy vs. time)."""
        v += h * self.force(q, v)
        return q + h * v, v

    @ti.func
    def verlet(self, q, v, h):
        v += 0.5 * h * self.force(q, v)
        q += h * v
        return q, v + 0.5 * h * self.force(q, v)

    @ti.func
    def rk4(self, q, v, h):
        a1 = self.force(q, v)
        q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
        a2 = self.force(q2, v2)
        q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
        a3 = self.force(q3, v3)
        q4, v4 = q + h * v3, v + h * a3
        a4 = self.force(q4, v4)
        return q + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4), v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)

    @ti.func
    def advance_one(self, i: ti.i32, substeps: ti.i32):
        q, v = self.q[i], self.v[i]
        for _ in range(substeps):
            q, v = self.step(q, v, self.h)
        self.q[i], self.v[i] = q, v
        if not (ti.abs(q).max() < 1e30 and ti.abs(v).max() < 1e30):  # also false for NaN
            ti.atomic_min(self.bad[None], i)

    @ti.func
    def energy_one(self, i: ti.i32, first: ti.i32):
        e = self.energy(self.q[i], self.v[i])
        self.e[i] = e
        if first:
            self.e0[i] = e
            self.escale[i] = ti.max(ti.abs(e), self.energy_floor())
        d = (e - self.e0[i]) / self.escale[i]
        if ti.static(self.damped):
            d = ti.max(d, 0.0)  # damping may only remove energy; a gain is the error
        ti.atomic_max(self.drift[None], ti.abs(d))
        if not ti.abs(d) < 1e30:
            ti.atomic_min(self.bad[None], i)

    @ti.func
    def energy_floor(self):
        """Energy scale for pendulums whose own energy is near zero."""
        return 1e-3 * (self.m1 + self.m2) * ti.max(self.g, 1.0) * (self.l1 + self.l2)

    # --------------------------------------------------------------- host side
    def advance_frame(self):
        self.launch(f"{self.NAME}_advance", self.substeps)
        self.t += self.substeps * self.h

    def measure_energy(self, first: bool = False):
        """Energies at this frame into self.e, and the max relative drift so far into self.drift."""
        if first:
            self.drift[None] = 0.0
        self.launch(f"{self.NAME}_energy", int(first))

    def check(self, frame: int, max_drift: float | None):
        """Watchdog, once per frame: NaN/inf anywhere, or energy drift beyond the tolerance."""
        bad = int(self.bad[None])
        hint = "try a smaller integrator.dt, --quality high, or a symplectic method"
        if bad < self.n:
            raise SimulationError(f"{self.scene.name}: frame {frame} (t={self.t:.4g} s): pendulum {bad} became "
                                  f"NaN/inf ({self.method}, dt={self.h:.3g} s); {hint}")
        if max_drift is not None and self.scene.has("energy"):
            drift = float(self.drift[None])
            if drift > max_drift:
                worst = int(np.argmax(np.abs(self.e.to_numpy() - self.e0.to_numpy()) / self.escale.to_numpy()))
                raise SimulationError(
                    f"{self.scene.name}: frame {frame} (t={self.t:.4g} s): pendulum {worst}: relative energy drift "
                    f"{drift:.3g} exceeds integrator.max_drift = {max_drift:g} ({self.method}, dt={self.h:.3g} s); "
                    f"{hint}")

    def state(self) -> dict[str, np.ndarray]:
        raise NotImplementedError
