"""The integration methods' facts in one table (METHOD), and the step size that keeps them stable.

What the program knows of a method besides its code (render/physics/steps.py): the step is planned, and a
scene refused, from these alone, so validation, the budget and `--quality`'s candidates import no Taichi.
"""
import dataclasses
import math

from ..errors import SceneError

DEFAULT_MAX_DRIFT = 0.05  # the energy watchdog's tolerance unless a scene sets integrator.max_drift


@dataclasses.dataclass(frozen=True)
class Method:
    """What the rest of the program knows of a method besides its code: one row of METHOD."""
    order: int  # of its global error: the certificate picks its shadow by it, a comparison its finest variant
    # dt·ω_max must stay below this for the method to be stable on a linear oscillator (ω the fastest mode).
    # implicit_midpoint's bound is where its fixed-point iteration stops contracting (h·L < 1), not stability.
    # rk2's 2 is its limit on the real axis (a decaying mode: |1 + z + z²/2| <= 1 for z in [-2, 0]). On the
    # imaginary axis no explicit two-stage method is stable at any step: an undamped oscillation grows by
    # |1 + iy - y²/2| = sqrt(1 + y⁴/4), about 1 + y⁴/8 per step for y = h·ω, i.e. 2e-4 per step at "auto"'s
    # y = 0.2 on the fastest mode the bound allows, 2e-7 on rigid_chaos at dt = 1e-3 (y = 0.034). The energy
    # watchdog stops a run where that growth shows.
    stability: float
    evals: int  # force evaluations per step: the cost --quality ranks candidates by, and the run-time estimate
    color: str  # its line in the charts of `pendulum accuracy` (a matplotlib colour)
    # Where it gains energy run-long, by the coordinates the system steps (its reference model): symplectic
    # Euler is symplectic on Cartesian springs (constant masses: v is a momentum up to them), not on a chain's
    # (θ, ω), whose mass matrix depends on θ; RK2 gains on every oscillation (|R(iy)|² = 1 + y⁴/4). There the
    # step must also keep the gain within max_drift over the run (render/physics/stability.py's energy_limit).
    # The others keep energy bounded (Verlet and Yoshida on springs, the implicit midpoint stepping canonical
    # (q, p) everywhere), or only lose it at a stable step (RK4: |R(iy)| < 1 for y < 2.83), which leaves the
    # stability bound's premise, E ≤ E_max·(1 + max_drift), intact; the watchdog still stops a loss beyond it.
    energy_gain: tuple[str, ...] = ()
    # On a linear oscillator a method that gains energy gains c·y^k of it per step (y = h·ω): (c, k). Springs
    # are linear in their stretch, so this bounds RK2's gain there from the fastest mode
    # (stability.oscillator_limit).
    oscillator_gain: tuple[float, int] | None = None
    no_tangent: str = ""  # why Taichi's forward mode cannot differentiate it (render/physics/tangent.py), if it cannot


METHOD = {
    "symplectic_euler": Method(order=1, stability=2.0, evals=1, color="tab:red", energy_gain=("chain",)),
    "verlet": Method(order=2, stability=2.0, evals=2, color="tab:orange"),
    "rk2": Method(order=2, stability=2.0, evals=2, color="tab:cyan", energy_gain=("chain", "springs"),
                  oscillator_gain=(0.25, 4)),
    "rk4": Method(order=4, stability=2.785, evals=4, color="tab:blue"),
    "yoshida4": Method(order=4, stability=1.573, evals=6, color="tab:green"),  # three Verlet steps of 2
    "implicit_midpoint": Method(order=2, stability=1.0, evals=8, color="tab:purple",
                                no_tangent="its fixed-point loop stops on a value (break), which Taichi's forward "
                                           "mode cannot differentiate"),
}

SAFETY = 0.1  # "auto" keeps dt·ω_max at a tenth of the limit: stable is not enough, it must be accurate
AUTO_DT = 1e-3  # longest step "auto" takes when no stiffness limits it


def gains_energy(method: str, model: str) -> bool:
    """Whether `method` gains energy run-long on a system of this reference model ("chain" | "springs")."""
    return model in METHOD[method].energy_gain


def step_limit(scene, omega_max: float, energy_limit: float = math.inf) -> float:
    """The longest step the scene's method is offered at: its stability limit over the rate, damping added,
    and no longer than `energy_limit` (the step that keeps its energy gain within max_drift: Plan.energy_limit).

    Viscous damping c adds a decaying mode of rate c, which limits explicit methods on the real axis as an
    oscillation of rate ω does on the imaginary one; adding the two is a simple, safe bound."""
    return min(stability_limit(scene, omega_max), energy_limit)


def stability_limit(scene, omega_max: float) -> float:
    damping = scene.pendulums.damping if scene.has("damping") else 0.0
    rate = omega_max + damping
    if not math.isfinite(rate):
        raise SceneError(f"{scene.source}: pendulums: the scene's fastest rate is not finite (omega_max = "
                         f"{omega_max}): its values are beyond what f64 arithmetic can step")
    return METHOD[scene.integrator.method].stability / rate if rate > 0 else math.inf  # at rest without gravity


SUBSTEP_LIMIT = 2 ** 31 - 1  # System.advance takes the substeps per frame as a Taichi i32


def check_substeps(scene, substeps: int, h: float) -> None:
    """Refuse substeps per frame beyond the kernel's i32 counter: beyond it the count wrapped to 0 and the video
    froze (render/config/budget.py refuses long runs by their time)."""
    if substeps > SUBSTEP_LIMIT:
        many = f"{substeps}" if substeps < 10 ** 15 else f"about {float(substeps):.3g}"  # not 300 digits
        raise SceneError(f"{scene.source}: integrator.dt: dt too small: {many} substeps per frame of {h:.3g} s "
                         f"exceed the step counter's limit of {SUBSTEP_LIMIT}; use a larger integrator.dt")


def timestep(scene, omega_max: float, energy_limit: float = math.inf) -> tuple[float, int]:
    """(step h, substeps per frame). h = frame time / substeps, never longer than the requested dt."""
    frame_dt = 1.0 / scene.video.fps
    method, dt = scene.integrator.method, scene.integrator.dt
    limit = stability_limit(scene, omega_max)
    if dt == "auto":
        dt = min(AUTO_DT, SAFETY * limit, energy_limit)  # the energy limit is itself an accuracy bound
    elif dt > energy_limit and dt <= limit and not scene.integrator.allow_unstable:
        drift = scene.integrator.max_drift or DEFAULT_MAX_DRIFT
        raise SceneError(
            f"{scene.source}: integrator.dt: {dt:g} s is beyond the energy limit of {method} for this scene: it is "
            f"not symplectic on these coordinates, and pilot steps from the scene's hardest states say its energy "
            f"could drift past integrator.max_drift = {drift:g} within the {scene.video.duration:g} s, "
            f"so dt < {energy_limit:.3g} s; use integrator.dt = \"auto\", a smaller dt or a symplectic method, "
            f"or set integrator.allow_unstable = true to proceed anyway")
    elif dt > limit and not scene.integrator.allow_unstable:
        damping = scene.pendulums.damping if scene.has("damping") else 0.0
        with_damping = f" + damping {damping:g} 1/s" if damping else ""
        raise SceneError(
            f"{scene.source}: integrator.dt: {dt:g} s is beyond the stability limit of {method} for this scene: "
            f"dt*omega_max must stay below {METHOD[method].stability:g} (omega_max = {omega_max:.4g} "
            f"rad/s{with_damping}, so dt < {limit:.3g} s); use integrator.dt = \"auto\" or a smaller dt, "
            f"or set integrator.allow_unstable = true to proceed anyway")
    substeps = max(1, math.ceil(frame_dt / dt - 1e-9))
    return frame_dt / substeps, substeps
