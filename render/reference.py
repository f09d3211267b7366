"""Reference trajectories from scipy's DOP853 at rtol ~1e-13, for measuring the Taichi integrators' error.

Deliberately a different formulation from rigid.py/elastic.py, so a shared mistake cannot hide:
- rigid: Lagrange's equations in mass-matrix form M(θ)·θ'' = f(θ, ω), solved with np.linalg.solve;
- elastic: Newton's law with the spring forces written out in Cartesian components.
State layout everywhere: q, v of shape (N, D) as in the Taichi systems (rigid D=2: θ1, θ2; elastic D=4:
x1, y1, x2, y2 with the pivot at the origin).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.integrate import solve_ivp

RTOL = 1e-13  # DOP853 stays well-behaved down to ~100 ulps; tighter only adds round-off


@dataclasses.dataclass(frozen=True)
class Params:
    system: str
    lengths: tuple[float, float]
    masses: tuple[float, float]
    gravity: float
    stiffness: float = 0.0
    damping: float = 0.0  # viscous, on the accelerations, as in system.System.force


def params(src) -> Params:
    """Params from a Scene (or pass Params through)."""
    if isinstance(src, Params):
        return src
    p = src.pendulums
    damping = p.damping if src.has("damping") else 0.0
    return Params(src.system, tuple(p.lengths), tuple(p.masses), p.gravity, p.stiffness, damping)


def initial_state(scene) -> tuple[np.ndarray, np.ndarray]:
    """The fan's initial (q, v) in float64: pendulum i has θ2 − spread·i/count (DESIGN.md)."""
    p = scene.pendulums
    n = p.count
    th1 = np.full(n, p.theta1)
    th2 = p.theta2 - p.spread * np.arange(n) / n
    w1, w2 = np.full(n, p.omega1), np.full(n, p.omega2)
    if scene.system == "rigid":
        return np.stack([th1, th2], 1), np.stack([w1, w2], 1)
    (l1, l2) = p.lengths
    # Bob positions are sums of arm vectors; their time derivatives give the velocities.
    u1, u2 = np.stack([np.sin(th1), -np.cos(th1)], 1), np.stack([np.sin(th2), -np.cos(th2)], 1)
    du1, du2 = np.stack([np.cos(th1), np.sin(th1)], 1), np.stack([np.cos(th2), np.sin(th2)], 1)
    r1, r2 = l1 * u1, l1 * u1 + l2 * u2
    v1 = l1 * w1[:, None] * du1
    v2 = v1 + l2 * w2[:, None] * du2
    return np.concatenate([r1, r2], 1), np.concatenate([v1, v2], 1)


def rigid_accel(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    """θ'' from M(θ)·θ'' = f, for q, v of shape (N, 2)."""
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    d = q[:, 0] - q[:, 1]
    c, s = np.cos(d), np.sin(d)
    mass = np.empty((len(q), 2, 2))
    mass[:, 0, 0] = (m1 + m2) * l1 * l1
    mass[:, 0, 1] = mass[:, 1, 0] = m2 * l1 * l2 * c
    mass[:, 1, 1] = m2 * l2 * l2
    f = np.stack([-m2 * l1 * l2 * v[:, 1] ** 2 * s - (m1 + m2) * g * l1 * np.sin(q[:, 0]),
                  m2 * l1 * l2 * v[:, 0] ** 2 * s - m2 * g * l2 * np.sin(q[:, 1])], 1)
    return np.linalg.solve(mass, f[:, :, None])[:, :, 0] - p.damping * v


def elastic_accel(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    """Bob accelerations from Hooke springs (k = stiffness / rest length) and gravity, q of shape (N, 4)."""
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    k1, k2 = p.stiffness / l1, p.stiffness / l2
    x1, y1, x2, y2 = q.T
    r1 = np.hypot(x1, y1)
    dx, dy = x2 - x1, y2 - y1
    r2 = np.hypot(dx, dy)
    t1, t2 = k1 * (r1 - l1) / r1, k2 * (r2 - l2) / r2  # tension per unit length of each spring
    ax1 = (-t1 * x1 + t2 * dx) / m1
    ay1 = (-t1 * y1 + t2 * dy) / m1 - g
    ax2 = -t2 * dx / m2
    ay2 = -t2 * dy / m2 - g
    return np.stack([ax1, ay1, ax2, ay2], 1) - p.damping * v


def rigid_energy(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    """Kinetic + potential from the bob positions, zero at the hanging rest position (as rigid.py)."""
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    vx1, vy1 = l1 * v[:, 0] * np.cos(q[:, 0]), l1 * v[:, 0] * np.sin(q[:, 0])
    vx2, vy2 = vx1 + l2 * v[:, 1] * np.cos(q[:, 1]), vy1 + l2 * v[:, 1] * np.sin(q[:, 1])
    y1 = -l1 * np.cos(q[:, 0])
    y2 = y1 - l2 * np.cos(q[:, 1])
    kin = 0.5 * m1 * (vx1 ** 2 + vy1 ** 2) + 0.5 * m2 * (vx2 ** 2 + vy2 ** 2)
    return kin + m1 * g * (y1 + l1) + m2 * g * (y2 + l1 + l2)


def elastic_energy(q: np.ndarray, v: np.ndarray, p: Params) -> np.ndarray:
    (l1, l2), (m1, m2), g = p.lengths, p.masses, p.gravity
    k1, k2 = p.stiffness / l1, p.stiffness / l2
    s1 = np.hypot(q[:, 0], q[:, 1]) - l1
    s2 = np.hypot(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]) - l2
    kin = 0.5 * m1 * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * m2 * (v[:, 2] ** 2 + v[:, 3] ** 2)
    return kin + 0.5 * (k1 * s1 ** 2 + k2 * s2 ** 2) + m1 * g * (q[:, 1] + l1) + m2 * g * (q[:, 3] + l1 + l2)


ACCEL = {"rigid": rigid_accel, "elastic": elastic_accel}
ENERGY = {"rigid": rigid_energy, "elastic": elastic_energy}


def energy(src, q, v) -> np.ndarray:
    p = params(src)
    return ENERGY[p.system](np.atleast_2d(q), np.atleast_2d(v), p)


def _rhs(p: Params, n: int, d: int):
    accel = ACCEL[p.system]

    def rhs(t, y):
        q, v = y[:n * d].reshape(n, d), y[n * d:].reshape(n, d)
        return np.concatenate([v.ravel(), accel(q, v, p).ravel()])
    return rhs


def rigid_rhs(t, y, p: Params):
    """dy/dt for y = (θ1, θ2, ω1, ω2) of one pendulum, or N of them flattened q-then-v."""
    return _rhs(p, len(y) // 4, 2)(t, y)


def elastic_rhs(t, y, p: Params):
    """dy/dt for y = (x1, y1, x2, y2, vx1, vy1, vx2, vy2) of one pendulum, or N of them flattened q-then-v."""
    return _rhs(p, len(y) // 8, 4)(t, y)


def solve(src, y0, t_end: float, t_eval=None, rtol: float = RTOL, atol: float = RTOL):
    """Integrate y0 = (q0, v0), each (N, D), to t_end with DOP853.

    Returns (q, v) at t_end, each (N, D); with t_eval, arrays of shape (len(t_eval), N, D).
    """
    p = params(src)
    q0, v0 = (np.atleast_2d(np.asarray(a, dtype=np.float64)) for a in y0)
    n, d = q0.shape
    sol = solve_ivp(_rhs(p, n, d), (0.0, t_end), np.concatenate([q0.ravel(), v0.ravel()]), method="DOP853",
                    rtol=rtol, atol=atol, t_eval=[t_end] if t_eval is None else t_eval)
    if not sol.success:
        raise RuntimeError(f"reference solve failed: {sol.message}")
    y = sol.y.T.reshape(-1, 2, n, d)
    if t_eval is None:
        return y[-1, 0], y[-1, 1]
    return y[:, 0], y[:, 1]
