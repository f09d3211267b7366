"""The Taichi side every pendulum system shares: state fields, the advance and energy kernels, the drawing
contract's points and the watchdog, on top of the system's Plan (render/physics/plan.py: its declaration,
step and initial state).

A system's Taichi class (render/physics/kernels/) subclasses its Plan (render/physics/systems/) and System,
and writes its physics once as Taichi functions:
- accel(q, v) on lane matrices (row k = coordinate k, column l = pendulum l of a group), so the same code
  runs one pendulum or several packed side by side; trig through self.sincos, not ti.sin;
- energy(q, v) and points(q) for one pendulum's vectors.
The steps (render/physics/steps.py) call force(); the canvas reads only points() and the Python-side
contract (LINKS, bob_sizes(), reach(), lengths). Only stepper.Run builds one with fields.
"""

import numpy as np
import taichi as ti

from . import crossings, dual, launch, runtime, steps, vector_width
from .plan import Plan
from .recording import Recording
from .sincos import sincos
from ..errors import SimulationError

BLOWN = 100.0  # a relative energy drift this large is a blow-up, not a drift


class System(Plan, Recording, runtime.Launcher):
    """Base of the systems' @ti.data_oriented classes."""

    def __init__(self, scene, subset=None, allocate: bool = True, compensated: bool = False):
        """The plan (Plan.start), and its state in Taichi fields. Without `allocate` only the plan and the
        Taichi functions, no field: a twin whose functions another kernel calls (tangent.libm_twin).
        compensated: RK4 whose steps are added to the state by compensated sums (steps.add_compensated), with
        the carries in fields of their own: the certificate's shadow (render/trust/certify.py)."""
        q0, v0 = self.start(scene, subset)
        self.compensated = compensated
        if compensated and (self.method != "rk4" or scene.integrator.trig == "libm"):
            raise ValueError(f"compensated sums are for RK4 with inline sin/cos, not {self.method}")
        self.libm = scene.integrator.trig == "libm"
        self.damped = scene.has("damping")
        self.damping = scene.pendulums.damping
        self.poincare = scene.has("poincare")  # crossings of the section recorded per substep (crossings.py)
        if not allocate:
            return
        self.tol = 1e-14 if scene.integrator.precision == "f64" else 1e-6  # implicit solves, in state units
        real = runtime.real()
        # 4 AVX2 registers of lanes either way, or as many as a forced width takes (vector_width.lanes)
        self.chunk = vector_width.lanes(self.CHUNK * (2 if real == ti.f32 else 1))
        self.groups = -(-self.n // self.chunk)
        self.q = runtime.field("state.q", real, self.n, self.D)
        self.v = runtime.field("state.v", real, self.n, self.D)
        self.bad = runtime.field("watchdog.bad", ti.i32, ())
        if compensated:
            self.cq = runtime.field("state.q_carry", real, self.n, self.D)
            self.cv = runtime.field("state.v_carry", real, self.n, self.D)
        if self.poincare:
            crossings.allocate(self)
        self.load(q0, v0)
        if scene.has("energy"):
            self.floor = self.energy_floor()
            self.e = runtime.field("energy.e", real, self.n)
            self.e0 = runtime.field("energy.e0", real, self.n)
            self.escale = runtime.field("energy.scale", real, self.n)
            self.drift = runtime.field("energy.max_drift", real, ())

    def load(self, q0: np.ndarray, v0: np.ndarray):
        """Set the state (and the clock and the watchdog) to t = 0."""
        dtype = np.float64 if runtime.real() == ti.f64 else np.float32
        self.q.from_numpy(q0.astype(dtype))
        self.v.from_numpy(v0.astype(dtype))
        self.bad[None] = self.n
        if self.compensated:
            self.cq.fill(0)
            self.cv.fill(0)
        if self.poincare:
            self.crossed.fill(0)
        self.t = 0.0

    def restart(self):
        """Back to the initial state, as first built: the same frames follow again."""
        q0, v0 = self.initial_state()
        if self.subset is not None:
            q0, v0 = q0[self.subset], v0[self.subset]
        self.load(q0, v0)

    def kernel(self, name: str):
        """Kernels are logged under the system's prefix ("rigid_advance") and shared by every system."""
        return {"advance": self.advance_by, "energy": self.energies}[name.removeprefix(f"{self.NAME}_")]

    def advance_by(self, substeps: int, h: float | None = None):
        """`substeps` steps of h (default: the scene's step), on the launching thread where that is little work
        (runtime.serial)."""
        launch.call(self, "advance_libm" if self.libm else "advance", substeps, self.h if h is None else h,
                    runtime.serial(self.n * substeps))

    # --------------------------------------------------------------- per-system parts
    @ti.func
    def accel(self, q, v):
        """Accelerations for lane matrices q, v (D × pendulums)."""
        raise NotImplementedError

    @ti.func
    def energy(self, q, v):
        """Total energy of one pendulum, zero at the hanging rest position."""
        raise NotImplementedError

    @ti.func
    def points(self, q):
        """The bobs of one pendulum as a (links × 2) matrix of positions in m, the pivot at the origin."""
        raise NotImplementedError

    # Canonical hooks for the implicit midpoint: a separable system with constant masses may take p = v.
    @ti.func
    def momenta(self, q, v):
        return v

    @ti.func
    def velocities(self, q, p):
        return p

    @ti.func
    def momentum_rate(self, q, v, p):
        return self.force(q, v)

    @ti.func
    def p_scale(self, h):
        """Converts a change of momentum into a change of position over a step, for the solver's tolerance."""
        return h

    # --------------------------------------------------------------- shared Taichi parts
    @ti.func
    def sincos(self, x):
        """(sin x, cos x) for accel: inline (render/physics/sincos.py) unless the scene asks for libm's exact bits;
        of a Dual (render/physics/dual.py), the same values and their derivatives."""
        if ti.static(dual.is_dual(x)):
            return dual.sincos(x, self.trig)
        else:
            return self.trig(x)

    @ti.func
    def trig(self, x):
        if ti.static(self.libm):
            return ti.sin(x), ti.cos(x)
        else:
            return sincos(x)

    @ti.func
    def lane_force(self, q, v):
        a = self.accel(q, v)
        if ti.static(self.damped):
            a -= self.damping * v
        return a

    @ti.func
    def force(self, q, v):
        """Accelerations with damping, for lane matrices or for one pendulum's vectors."""
        if ti.static(len(q.get_shape()) == 1):
            return self.lane_force(ti.Matrix.cols([q]), ti.Matrix.cols([v]))[:, 0]
        else:
            return self.lane_force(q, v)

    @ti.kernel
    def advance(self, substeps: ti.i32, h: float, serial: ti.template()):
        """All pendulums `substeps` steps of h on, in groups of `chunk` (advance_group); advance_libm's one at a
        time where the scene pins libm's sin/cos."""
        S = ti.static(runtime.SPREAD)
        ti.loop_config(serialize=serial)
        for t in range(self.groups * S):  # blocks of 4 groups for the threads, not 512 (runtime.SPREAD)
            if t % S == 0:
                self.advance_group(t // S, substeps, h)

    @ti.kernel
    def advance_libm(self, substeps: ti.i32, h: float, serial: ti.template()):
        ti.loop_config(serialize=serial)
        for i in range(self.n):
            self.advance_one(i, substeps, h)

    @ti.func
    def advance_group(self, g, substeps, h):
        """Group g's pendulums `substeps` steps of h on: the state stays in registers and on the stack for the
        whole frame, and is read and written once.

        The group is copied into local D × chunk matrices Q, V, indexed by a runtime column (so they stay one
        stack array rather than chunk·D scalars), and each substep is a loop over those columns that steps one
        pendulum (a D × 1 lane matrix) at a time. With no call and no branch on values in the step, LLVM's
        loop vectoriser runs 4 (f64) or 8 (f32) columns per AVX2 instruction (16 or 32 a time in AVX-512 registers
        where render/physics/vector_width.py sets the width): that loop is the SIMD. Every
        pendulum goes through the same instructions whatever its group or thread, so frames are byte-identical
        at any thread count. The last group repeats its last pendulum as padding; only real ones are written."""
        B = ti.static(self.chunk)
        Q, V = ti.Matrix.zero(float, self.D, B), ti.Matrix.zero(float, self.D, B)
        CQ, CV = Q, V  # compensated sums' carries (unused without: optimised out)
        for lane in range(B):
            i = ti.min(g * B + lane, self.n - 1)
            Q[:, lane], V[:, lane] = self.q[i], self.v[i]
            if ti.static(self.compensated):
                CQ[:, lane], CV[:, lane] = self.cq[i], self.cv[i]
        Q0, V0 = Q, V  # each step's start, for the section's crossings (unused without: optimised out)
        if ti.static(self.poincare):
            for lane in range(B):
                if g * B + lane < self.n:
                    self.crossed[g * B + lane] = 0
        for s in range(substeps):
            if ti.static(self.poincare):
                Q0, V0 = Q, V
            for lane in range(B):  # the loop LLVM vectorises
                if ti.static(self.compensated):
                    dq, dv = steps.rk4_increment(self, ti.Matrix.cols([Q[:, lane]]), ti.Matrix.cols([V[:, lane]]), h)
                    Q[:, lane], CQ[:, lane] = steps.add_compensated(Q[:, lane], dq[:, 0], CQ[:, lane])
                    V[:, lane], CV[:, lane] = steps.add_compensated(V[:, lane], dv[:, 0], CV[:, lane])
                else:
                    q, v = steps.step(self, ti.Matrix.cols([Q[:, lane]]), ti.Matrix.cols([V[:, lane]]), h)
                    Q[:, lane], V[:, lane] = q[:, 0], v[:, 0]
            if ti.static(self.poincare):  # a loop of its own: its branch leaves the step's SIMD
                for lane in range(B):
                    crossings.detect(self, g * B + lane, s, ti.Matrix.cols([Q0[:, lane]]),
                                     ti.Matrix.cols([V0[:, lane]]), ti.Matrix.cols([Q[:, lane]]),
                                     ti.Matrix.cols([V[:, lane]]), h)
        for lane in range(B):
            i = g * B + lane
            if i < self.n:
                self.q[i], self.v[i] = Q[:, lane], V[:, lane]
                if ti.static(self.compensated):
                    self.cq[i], self.cv[i] = CQ[:, lane], CV[:, lane]
                self.watch(i, Q[:, lane], V[:, lane])

    @ti.func
    def advance_one(self, i, substeps, h):
        """Pendulum i alone, as before the chunks, for scenes that pin libm's sin/cos (libm calls do not
        vectorise), so its results are the earlier releases' to the bit (LLVM merges sin and cos differently in
        the chunked loop, and in f32 from upright those bits decide the chaos)."""
        q, v = ti.Matrix.cols([self.q[i]]), ti.Matrix.cols([self.v[i]])
        if ti.static(self.poincare):
            self.crossed[i] = 0
        for s in range(substeps):
            q0, v0 = q, v
            q, v = steps.step(self, q, v, h)
            if ti.static(self.poincare):
                crossings.detect(self, i, s, q0, v0, q, v, h)
        self.q[i], self.v[i] = q[:, 0], v[:, 0]
        self.watch(i, q, v)

    @ti.func
    def watch(self, i, q, v):
        """The watchdog's kernel side, after every advance: pendulum i's new state is NaN/inf (or beyond 1e30),
        flagged by the least such index (the host side: check)."""
        if not (ti.abs(q).max() < 1e30 and ti.abs(v).max() < 1e30):  # also NaN
            ti.atomic_min(self.bad[None], i)

    @ti.kernel
    def energies(self, first: ti.i32, serial: ti.template()):
        ti.loop_config(serialize=serial)
        for i in range(self.n):
            self.energy_one(i, first)

    @ti.func
    def energy_one(self, i: ti.i32, first: ti.i32):
        e = self.energy(self.q[i], self.v[i])
        self.e[i] = e
        if first:
            self.e0[i] = e
            self.escale[i] = ti.max(ti.abs(e), self.floor)
        d = (e - self.e0[i]) / self.escale[i]
        if ti.static(self.damped):
            d = ti.max(d, 0.0)  # damping may only remove energy; a gain is the error
        ti.atomic_max(self.drift[None], ti.abs(d))
        if not ti.abs(d) < 1e30:
            ti.atomic_min(self.bad[None], i)

    # --------------------------------------------------------------- host side (for render/physics/stepper.py)
    def measure_energy(self, first: bool = False):
        """Energies at this frame into self.e, and the max relative drift so far into self.drift."""
        if first:
            self.drift[None] = 0.0
        self.launch(f"{self.NAME}_energy", int(first), runtime.serial(2 * self.n))  # an energy: about 2 steps

    def check(self, frame: int, max_drift: float | None):
        """Watchdog, once per frame: NaN/inf anywhere, or energy drift beyond the tolerance. A blown-up pendulum
        is named by its index in the scene (a subset's too: the certificate's run)."""
        bad = int(self.bad[None])
        if bad < self.n:
            raise self.blew_up(frame, self.t, self.index(bad), "NaN/inf")
        if max_drift is not None and self.scene.has("energy"):
            drift = float(self.drift[None])
            if drift > max_drift:
                d = (self.e.to_numpy() - self.e0.to_numpy()) / self.escale.to_numpy()
                worst = int(np.argmax(d if self.damped else np.abs(d)))  # damped: only a gain is the error
                if d[worst] >= BLOWN:
                    raise self.blew_up(frame, self.t, worst, f"energy up {d[worst]:.3g}x its start's")
                raise SimulationError(
                    f"{self.scene.name}: frame {frame} (t={self.t:.4g} s): pendulum {worst}: relative energy drift "
                    f"{100 * d[worst]:+.3g} % ({'gained' if d[worst] > 0 else 'lost'}) exceeds integrator.max_drift "
                    f"= {max_drift:g} ({self.method}, dt={self.h:.3g} s); try a smaller integrator.dt, "
                    f"--quality high, or a symplectic method")

    def index(self, i: int) -> int:
        """The scene's index of this system's pendulum i."""
        return i if self.subset is None else int(self.subset[i])

    def blew_up(self, frame: int, t: float, pendulum: int, what: str) -> SimulationError:
        """The error of a run that blew up (the watchdog's, or the certificate's run: render/trust/certify.py)."""
        return SimulationError(f"{self.scene.name}: frame {frame} (t={t:.4g} s): blew up at t={t:.4g} s "
                               f"(pendulum {pendulum}: {what}; {self.method}, dt={self.h:.3g} s); use a smaller "
                               f"integrator.dt (\"auto\" keeps to the step limit)")

    def state(self) -> dict[str, np.ndarray]:
        """The arrays `simulate` writes for this frame, as STATE declares them."""
        return {name: getattr(self, src).to_numpy().reshape(self.n, *shape)
                for name, (src, shape) in self.STATE.items()}
