"""Reference trajectories from scipy's DOP853 at rtol ~1e-13, for measuring the Taichi integrators' error.

Deliberately a different formulation from the systems in render/physics/systems/, so a shared mistake cannot hide.
It knows two models, not the systems: a system names its model (System.REFERENCE), a scene tells it
(Scene.model), so this module imports nothing of the package.
- "chain": any number of rigid links, Lagrange's equations in mass-matrix form M(θ)·θ'' = f(θ, ω) with
  M_ij = μ_ij l_i l_j cos(θ_i − θ_j), μ_ij the mass at or below link max(i, j), solved by elimination;
- "springs": Newton's law with Hooke springs written out in Cartesian components.
State layout everywhere: q, v of shape (N, D) as in the Taichi systems (chain: the link angles; springs:
x1, y1, x2, y2 with the pivot at the origin).
"""
from __future__ import annotations

import dataclasses

import numpy as np

RTOL = 1e-13  # DOP853 stays well-behaved down to ~100 ulps; tighter only adds round-off


@dataclasses.dataclass(frozen=True)
class Params:
    model: str
    lengths: tuple[float, ...]
    masses: tuple[float, ...]
    gravity: float
    stiffness: float = 0.0
    damping: float = 0.0  # viscous, on the accelerations, as the systems apply it


def params(src) -> Params:
    """Params from a Scene (or pass Params through)."""
    if isinstance(src, Params):
        return src
    p = src.pendulums
    damping = p.damping if src.has("damping") else 0.0
    return Params(src.model, tuple(p.lengths), tuple(p.masses), p.gravity,
                  p.get("stiffness", 0.0), damping)


def initial_state(scene) -> tuple[np.ndarray, np.ndarray]:
    """The fan's initial (q, v) in float64: the last link of pendulum i has θ − spread·i/count (docs/presets.md)."""
    p = params(scene)
    pend, links = scene.pendulums, len(p.lengths)
    n = pend.count
    th = np.array([np.full(n, pend[f"theta{k + 1}"], dtype=np.float64) for k in range(links)]).T
    th[:, -1] = th[:, -1] - pend.spread * np.arange(n) / n
    w = np.array([np.full(n, pend[f"omega{k + 1}"], dtype=np.float64) for k in range(links)]).T
    if p.model == "chain":
        return th, w
    # Springs start at rest length: bob positions are sums of arm vectors, velocities their derivatives.
    pos, vel = _chain_points(th, w, p.lengths)
    return pos.reshape(n, -1), vel.reshape(n, -1)


def bob_positions(src, q: np.ndarray) -> np.ndarray:
    """Every bob's position (N, bobs, 2) from a state q (N, D), the pivot at the origin."""
    p = params(src)
    if p.model == "chain":
        return _chain_points(q, np.zeros_like(q), p.lengths)[0]
    return q.reshape(len(q), -1, 2)


def _chain_points(th, w, lengths):
    """Bob positions and velocities (N, links, 2) of a chain of rigid links at angles th, rates w."""
    arm = np.stack([np.sin(th), -np.cos(th)], -1) * np.asarray(lengths)[:, None]
    darm = np.stack([np.cos(th), np.sin(th)], -1) * np.asarray(lengths)[:, None] * w[..., None]
    return np.cumsum(arm, axis=1), np.cumsum(darm, axis=1)


def _below(masses) -> list[list[float]]:
    """μ_ij: the total mass at or below link max(i, j)."""
    n = len(masses)
    return [[float(sum(masses[max(i, j):])) for j in range(n)] for i in range(n)]


def chain_mass(th: np.ndarray, p: Params) -> np.ndarray:
    """The mass matrix M(θ) of a chain, (N, links, links), for angles th of shape (N, links)."""
    l = np.asarray(p.lengths)
    return np.asarray(_below(p.masses)) * np.outer(l, l) * np.cos(th[:, :, None] - th[:, None, :])


def chain_rows(th, w, p: Params) -> list:
    """θ'' of every link from M(θ)·θ'' = f, on rows (one array of all pendulums per link), by Gaussian
    elimination over the links (M is symmetric positive definite). Rows keep each array contiguous and in
    its own precision, so this doubles as the bench's numpy peer."""
    n, l, g, mu = len(th), p.lengths, p.gravity, _below(p.masses)
    mass = [[mu[i][i] * l[i] * l[i] if i == j else None for j in range(n)] for i in range(n)]
    f = [-g * mu[i][i] * l[i] * np.sin(th[i]) for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            d = th[i] - th[j]
            mass[i][j] = mass[j][i] = mu[i][j] * l[i] * l[j] * np.cos(d)
            pull = mu[i][j] * l[i] * l[j] * np.sin(d)  # ∂M_ij/∂θ_j, the ω² coupling of links i and j
            f[i] = f[i] - pull * w[j] * w[j]
            f[j] = f[j] + pull * w[i] * w[i]
    for k in range(n):  # forward elimination
        for i in range(k + 1, n):
            r = mass[i][k] / mass[k][k]
            for j in range(k + 1, n):
                mass[i][j] = mass[i][j] - r * mass[k][j]
            f[i] = f[i] - r * f[k]
    acc = [None] * n
    for i in range(n - 1, -1, -1):  # back substitution
        acc[i] = (f[i] - sum(mass[i][j] * acc[j] for j in range(i + 1, n))) / mass[i][i]
    return [a - p.damping * wi for a, wi in zip(acc, w)]


def springs_rows(q, v, p: Params) -> list:
    """Bob accelerations from Hooke springs (k = stiffness / rest length) and gravity, on rows x1, y1, x2, y2."""
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    k1, k2 = p.stiffness / l1, p.stiffness / l2
    x1, y1, x2, y2 = q
    r1 = np.hypot(x1, y1)
    dx, dy = x2 - x1, y2 - y1
    r2 = np.hypot(dx, dy)
    t1, t2 = k1 * (r1 - l1) / r1, k2 * (r2 - l2) / r2  # tension per unit length of each spring
    acc = [(-t1 * x1 + t2 * dx) / m1, (-t1 * y1 + t2 * dy) / m1 - g, -t2 * dx / m2, -t2 * dy / m2 - g]
    return [a - p.damping * vi for a, vi in zip(acc, v)]


def _per_pendulum(rows):
    """An accel on rows as one on (N, D) arrays."""
    def accel(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
        return np.stack(rows(list(q.T), list(v.T), p), 1)
    return accel


chain_accel = _per_pendulum(chain_rows)
springs_accel = _per_pendulum(springs_rows)


def chain_energy(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    """Kinetic + potential from the bob positions, zero at the hanging rest position (as the systems)."""
    pos, vel = _chain_points(q, v, p.lengths)
    m = np.asarray(p.masses)
    rest = -np.cumsum(p.lengths)  # each bob's height hanging at rest
    return (0.5 * m * (vel ** 2).sum(-1)).sum(1) + (m * p.gravity * (pos[..., 1] - rest)).sum(1)


def springs_energy(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    k1, k2 = p.stiffness / l1, p.stiffness / l2
    s1 = np.hypot(q[:, 0], q[:, 1]) - l1
    s2 = np.hypot(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]) - l2
    kin = 0.5 * m1 * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * m2 * (v[:, 2] ** 2 + v[:, 3] ** 2)
    return kin + 0.5 * (k1 * s1 ** 2 + k2 * s2 ** 2) + m1 * g * (q[:, 1] + l1) + m2 * g * (q[:, 3] + l1 + l2)


MODEL_ROWS = {"chain": chain_rows, "springs": springs_rows}
MODEL_ACCEL = {"chain": chain_accel, "springs": springs_accel}
MODEL_ENERGY = {"chain": chain_energy, "springs": springs_energy}


def accel(src, q, v) -> np.ndarray:
    p = params(src)
    return MODEL_ACCEL[p.model](np.atleast_2d(q), np.atleast_2d(v), p)


def energy(src, q, v) -> np.ndarray:
    p = params(src)
    return MODEL_ENERGY[p.model](np.atleast_2d(q), np.atleast_2d(v), p)


def rk4_step(src, q: np.ndarray, v: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """One classical RK4 step of the reference model on (D, N) arrays (a row per coordinate, contiguous):
    the numpy peer of `pendulum bench`."""
    p = params(src)
    rows = MODEL_ROWS[p.model]

    def f(q, v):
        return np.stack(rows(list(q), list(v), p))
    a1 = f(q, v)
    q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
    a2 = f(q2, v2)
    q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
    a3 = f(q3, v3)
    q4, v4 = q + h * v3, v + h * a3
    a4 = f(q4, v4)
    return q + h / 6 * (v + 2 * v2 + 2 * v3 + v4), v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)


def long_double(src, indices, h: float, frames: int) -> np.ndarray:
    """The angles or positions (frames, len(indices), D) of those pendulums at the first `frames` frame times, by
    rk4_step in numpy's long double (x87's 64-bit mantissa, 11 bits past f64) at step h (rounded to a whole
    number per frame): a truth for f64 runs where DOP853 in f64 shares their round-off (an exact equilibrium,
    late chaos). The certificate's test and benchmarks/certificate_truth.py use it."""
    q0, v0 = initial_state(src)
    q, v = q0[indices].T.astype(np.longdouble), v0[indices].T.astype(np.longdouble)
    per_frame = round(1 / (src.video.fps * h))
    step = np.longdouble(1) / (src.video.fps * per_frame)
    out = [q.T.astype(np.float64)]
    for _ in range(1, frames):
        for _ in range(per_frame):
            q, v = rk4_step(src, q, v, step)
        out.append(q.T.astype(np.float64))
    return np.array(out)


def solve(src, y0, t_end: float, t_eval=None, rtol: float = RTOL, atol: float = RTOL):
    """Integrate y0 = (q0, v0), each (N, D), to t_end with DOP853.

    Returns (q, v) at t_end, each (N, D); with t_eval, arrays of shape (len(t_eval), N, D).
    """
    p = params(src)
    q0, v0 = (np.atleast_2d(np.asarray(a, dtype=np.float64)) for a in y0)
    n, d = q0.shape
    f = MODEL_ACCEL[p.model]

    def rhs(t, y):
        q, v = y[:n * d].reshape(n, d), y[n * d:].reshape(n, d)
        return np.concatenate([v.ravel(), f(q, v, p).ravel()])

    from scipy.integrate import solve_ivp  # not at the top: loading any scene loads this module (stability.py
    # bounds the step with its models), and scipy takes about a second to import

    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([q0.ravel(), v0.ravel()]), method="DOP853",
                    rtol=rtol, atol=atol, t_eval=[t_end] if t_eval is None else t_eval)
    if not sol.success:
        raise RuntimeError(f"reference solve failed: {sol.message}")
    y = sol.y.T.reshape(-1, 2, n, d)
    if t_eval is None:
        return y[-1, 0], y[-1, 1]
    return y[:, 0], y[:, 1]
