"""The step limit: a bound on the fastest rate of the linearised dynamics over every state the run can reach,
and, for a method that gains energy on these coordinates, the step that keeps that gain within max_drift.

A conservative system keeps its energy (damping only lowers it), and the energy watchdog stops a run whose
energy drifts by more than integrator.max_drift, so every state of the run lies in the set
{E(q, v) ≤ E_max·(1 + max_drift)}, E_max the largest initial energy of the scene. For a chain of rigid links
this bound is the largest spectral radius of the Jacobian of (θ, ω) ↦ (ω, θ'') over that set, without
damping (the step limit adds the damping rate: integrators.timestep). It is found by sampling: angles
everywhere (random, plus every aligned and folded configuration), and velocities on the energy shell along
random directions and along M(θ)'s eigenvectors (the soft mode is the "whip" of a heavy lower bob). The
Jacobian is taken by central differences of render/physics/reference.py's independent model; the largest radius
found, times MARGIN for the gaps between samples, is the bound. A step h is stable for a method when h·bound
stays below the method's limit (integrators.Method.stability).

Stable is not enough where the method is not symplectic on (θ, ω) (integrators.Method.energy_gain: symplectic Euler
and RK2; the mass matrix depends on θ): energy then grows run-long, and near the stability limit chains
drifted by 2-400 % in 5 s or blew up, which voids the premise above. energy_limit measures that growth:
the method itself runs PILOT_STEPS steps of auto's step (a tenth of the stability limit) on the reference
model, from the scene's own starts and from the hardest states of the shell (the largest radii, and as many
at random). Per state it takes the largest relative excursion |E − E(0)|/scale seen and a secular rate (the
mean error of the pilot's second half less its first, over half its span); the run's drift is predicted as
the largest excursion plus the duration times the fastest rate. An order-p method's error scales like h^p,
which gives the step at which that prediction is DRIFT_MARGIN below max_drift; never a step longer than the
pilot's (no extrapolation upwards). It is conservative because the shell's worst states drift far faster
than a trajectory that only passes them: measured with a 0.5 s pilot on 8 random double and triple chains
(masses to 1:10, lengths to 1:5), the shell predicted 3-60x the drift of 5 s of the real trajectory for
symplectic Euler, 11-300x for RK2; a pilot from the starts alone was not enough (chaos reaches the whip
later: 0.002 drifted by 0.5 s, 0.5 by 5 s). On springs (Cartesian, constant masses) symplectic Euler is
symplectic, and RK2's gain follows from its stability function on the fastest mode (oscillator_limit).
"""
import dataclasses
import itertools
import math

import numpy as np

from . import integrators, reference
from .integrators import DEFAULT_MAX_DRIFT

MARGIN = 1.25  # over the largest sampled radius: covers what falls between the samples
SAMPLES = 1024  # random configurations
DIRECTIONS = 4  # random velocity directions per configuration, besides M(θ)'s eigenvectors
PILOT_STEPS = 400  # per pilot state: at auto's step, 80 radians of the fastest mode
PILOT_STATES = 32  # the hardest shell states, and as many random ones
PILOT_STARTS = 16  # the scene's own starts, evenly spaced over the fan
DRIFT_MARGIN = 2.0  # the pilot's predicted drift stays below max_drift / DRIFT_MARGIN

# A render plans its step several times (the quality pilots, the certificate's runs, the render itself):
# the last few answers are kept, keyed by everything they depend on.
_memo: dict = {}


def memo(key, compute):
    if key not in _memo:
        if len(_memo) >= 16:
            _memo.clear()
        _memo[key] = compute()
    return _memo[key]


def shell(scene, q0: np.ndarray, v0: np.ndarray):
    """The undamped parameters, the sampled states (q, v) of the energy shell and their spectral radii."""
    p = dataclasses.replace(reference.params(scene), damping=0.0)  # timestep adds the damping rate
    e_max = float(np.max(reference.energy(p, q0, v0))) * (1 + (scene.integrator.max_drift or DEFAULT_MAX_DRIFT))
    return memo(("shell", p, e_max), lambda: _sample(p, e_max))


def _sample(p, e_max: float):
    n = len(p.lengths)
    rng = np.random.default_rng(0)  # the same bound for the same scene, every run
    corners = np.array(list(itertools.product((0.0, math.pi), repeat=n)))
    th = np.concatenate([corners, rng.uniform(-math.pi, math.pi, (SAMPLES, n))])
    rest = np.zeros_like(th)
    room = e_max - reference.energy(p, th, rest)  # kinetic energy left at each configuration
    th = th[room >= 0]
    room = room[room >= 0]
    mass = reference.chain_mass(th, p)
    dirs = [np.linalg.eigh(mass)[1][:, :, k] for k in range(n)]  # the soft and the stiff modes
    dirs += [rng.normal(size=th.shape) for _ in range(DIRECTIONS)]
    states_q, states_v = [], []
    for u in dirs:  # undamped, the Jacobian at −v has the negated spectrum of that at v: one sign is enough
        kin = 0.5 * np.einsum("ni,nij,nj->n", u, mass, u)
        states_q.append(th)
        states_v.append(u * np.sqrt(room / kin)[:, None])
    q, v = np.concatenate(states_q), np.concatenate(states_v)
    return p, q, v, spectral_radii(p, q, v)


def chain_rate(scene, q0: np.ndarray, v0: np.ndarray) -> float:
    """Bound (rad/s) on |eigenvalues| of the linearised chain over every state with E ≤ max E(q0, v0)."""
    return MARGIN * float(shell(scene, q0, v0)[3].max())


def spectral_radii(p, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Per state, the largest |eigenvalue| of d(q, v)/dt's Jacobian over the states (N, D), by central
    differences."""
    n, d = q.shape
    jac = np.zeros((n, 2 * d, 2 * d))
    jac[:, :d, d:] = np.eye(d)
    for k in range(d):
        step = np.zeros(d)
        step[k] = 1e-6
        jac[:, d:, k] = (reference.accel(p, q + step, v) - reference.accel(p, q - step, v)) / 2e-6
        scale = 1e-6 * max(1.0, float(np.abs(v).max()))
        step[k] = scale
        jac[:, d:, d + k] = (reference.accel(p, q, v + step) - reference.accel(p, q, v - step)) / (2 * scale)
    return np.abs(np.linalg.eigvals(jac)).max(-1)


# The pilot's steps: integrators.py's symplectic Euler and RK2 (explicit midpoint), on the reference model.
def _symplectic_euler(p, q, v, h):
    v = v + h * reference.accel(p, q, v)
    return q + h * v, v


def _rk2(p, q, v, h):
    vm = v + 0.5 * h * reference.accel(p, q, v)
    return q + h * vm, v + h * reference.accel(p, q + 0.5 * h * v, vm)


PILOT = {"symplectic_euler": _symplectic_euler, "rk2": _rk2}


def energy_limit(scene, q0: np.ndarray, v0: np.ndarray, method: str, floor: float) -> float:
    """The longest step (s) at which `method` keeps the run's energy drift within max_drift over the whole
    video, measured by the pilot (module docstring); inf where the method does not gain energy on a chain.
    `floor` is the watchdog's energy scale for pendulums near rest (System.energy_floor)."""
    if not integrators.gains_energy(method, "chain"):
        return math.inf
    key = ("energy", reference.params(scene), method, floor, scene.video.duration, scene.integrator.max_drift,
           q0.tobytes(), v0.tobytes())
    return memo(key, lambda: _energy_limit(scene, q0, v0, method, floor))


def _energy_limit(scene, q0, v0, method, floor) -> float:
    p, q, v, radii = shell(scene, q0, v0)
    damping = scene.pendulums.damping if scene.has("damping") else 0.0
    rate = MARGIN * float(radii.max()) + damping
    if rate <= 0:
        return math.inf  # at rest without gravity: nothing moves
    h = integrators.SAFETY * integrators.METHOD[method].stability / rate  # auto's step
    rng = np.random.default_rng(1)
    pick = np.concatenate([np.argsort(radii)[-PILOT_STATES:], rng.choice(len(radii), PILOT_STATES)])
    starts = np.unique(np.round(np.linspace(0, len(q0) - 1, min(len(q0), PILOT_STARTS))).astype(np.int64))
    q, v = np.concatenate([q[pick], q0[starts]]), np.concatenate([v[pick], v0[starts]])
    allowed = (scene.integrator.max_drift or DEFAULT_MAX_DRIFT) / DRIFT_MARGIN
    scale = np.maximum(np.abs(reference.energy(p, q, v)), floor)  # as the watchdog scales a pendulum's drift
    predicted = pilot(p, q, v, scale, h, method, scene.video.duration)
    while not math.isfinite(predicted):  # blew up even at a tenth of the stability limit: pilot finer
        h /= 4
        predicted = pilot(p, q, v, scale, h, method, scene.video.duration)
    return h * min(1.0, allowed / predicted) ** (1.0 / integrators.METHOD[method].order) if predicted > 0 else h


def pilot(p, q: np.ndarray, v: np.ndarray, scale: np.ndarray, h: float, method: str, duration: float) -> float:
    """The drift over `duration` that PILOT_STEPS steps of h from the states (N, D) predict (inf on a blow-up):
    the largest excursion |E − E(0)| / scale seen, plus the duration times the fastest secular rate, a state's
    mean error over the second half of the pilot less that over the first, over half the pilot's span."""
    e0 = reference.energy(p, q, v)
    err = np.empty((PILOT_STEPS, len(q)))
    with np.errstate(all="ignore"):
        for k in range(PILOT_STEPS):
            q, v = PILOT[method](p, q, v, h)
            err[k] = (reference.energy(p, q, v) - e0) / scale
    if not np.isfinite(err).all():
        return math.inf
    half = PILOT_STEPS // 2
    rate = np.abs(err[half:].mean(0) - err[:half].mean(0)) / (half * h)
    return float(np.abs(err).max() + rate.max() * duration)


def oscillator_limit(scene, omega_max: float, method: str) -> float:
    """The energy limit on linear springs, where a method gains c·y^k of a mode's energy per step
    (integrators.Method.oscillator_gain), most on the fastest mode: all the energy there, the T/h steps of the run
    gain T·c·h^(k−1)·ω^k, at most max_drift / DRIFT_MARGIN; inf where the method does not gain on springs."""
    if not integrators.gains_energy(method, "springs") or omega_max <= 0:
        return math.inf
    c, k = integrators.METHOD[method].oscillator_gain
    allowed = (scene.integrator.max_drift or DEFAULT_MAX_DRIFT) / DRIFT_MARGIN
    return (allowed / (c * scene.video.duration * omega_max ** k)) ** (1.0 / (k - 1))
