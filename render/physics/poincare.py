"""The `poincare` effect: the Poincaré section θ1 = 0 (mod 2π), ω1 > 0 of a double pendulum, found as the
(θ2, ω2) points where each pendulum crosses it; and the `shell` start. render/draw/section.py draws them.

- **Crossings** are found where the substeps happen (System.advance calls render/physics/crossings.py's
  detect() after every step; read() here takes them back): θ1 is unwrapped, so a step crosses the section
  upwards where it passes a multiple of 2π while increasing. The crossing is located within the step by
  cubic Hermite interpolation of the step itself, from the state and its derivative (the system's own force)
  at both ends: θ1(u) = 2πk is solved by Newton from the chord, then θ2 and ω2 are interpolated at that u.
  Its error is h⁴/384 times the fourth derivative, below the step's own: tests/test_poincare.py checks
  crossings against scipy's event location on the independent model within 1e-6 (on poincare_shell at
  dt ≈ 1 ms they agree within 1e-9 s, rad and rad/s over 6 s), so Hénon's extra step is not needed. An
  advance records at most SLOTS crossings per pendulum (θ1 would have to turn SLOTS times within one frame
  to lose one); losses are counted in metadata.
- **layout = "shell"** starts every pendulum with the energy of the preset's (theta, omega), on the section:
  θ1 = 0, (θ2, ω2) spread over the section's accessible region by a low-discrepancy (R2) sequence, and ω1 > 0
  solved from the energy. The energy is the reference model's (render/physics/reference.py): it is a quadratic in ω1,
  so three evaluations give its coefficients, and no formula is written twice.
"""
import math

import numpy as np

from . import reference
from ..errors import SceneError

SLOTS = 4  # crossings kept per pendulum and advance call
TAU = 2.0 * math.pi
PLASTIC = 1.324717957244746  # the R2 sequence's generator: frac(½ + k/p, ½ + k/p²) fills a square evenly


def read(sim, t0: float) -> tuple[np.ndarray, ...]:
    """The last advance's crossings (it started at time t0): pendulum, time, θ2 (unwrapped), ω2; and how many
    were lost beyond SLOTS."""
    count, rows = sim.crossed.to_numpy(), sim.crossings.to_numpy()
    i, k = np.nonzero(np.arange(SLOTS)[None, :] < count[:, None])
    c = rows[i, k].astype(np.float64)
    return i, t0 + c[:, 0], c[:, 1], c[:, 2], int(np.maximum(count - SLOTS, 0).sum())


# ------------------------------------------------------------------ the shell start and the ω2 range (host)
def quadratic(p, th2: np.ndarray, w2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """E(ω1) = A·ω1² + B·ω1 + C on the section θ1 = 0 at each (θ2, ω2), from the reference energy at
    ω1 = 0, ±1."""
    q = np.stack([np.zeros_like(th2), th2], 1)
    e = [reference.energy(p, q, np.stack([np.full_like(w2, w1), w2], 1)) for w1 in (0.0, 1.0, -1.0)]
    return 0.5 * (e[1] + e[2]) - e[0], 0.5 * (e[1] - e[2]), e[0]


def reach(p, energy: float) -> float:
    """The largest |θ2| on the section at this energy: where the potential (E at rest) reaches it, by bisection
    (it grows with |θ2| from the hanging rest)."""
    def rest(th2):
        return quadratic(p, np.array([th2]), np.zeros(1))[2][0]
    if rest(math.pi) < energy:
        return math.pi
    lo, hi = 0.0, math.pi
    for _ in range(60):
        lo, hi = ((lo + hi) / 2, hi) if rest((lo + hi) / 2) < energy else (lo, (lo + hi) / 2)
    return hi


def omega2_range(p, energy: float, th_max: float = math.pi) -> float:
    """The largest |ω2| on the section at this energy (|θ2| <= th_max): where its minimum over ω1,
    C − B²/4A, reaches it."""
    th2 = np.linspace(-th_max, th_max, 1025)
    a, b, c0 = quadratic(p, th2, np.zeros_like(th2))
    _, b1, c1 = quadratic(p, th2, np.ones_like(th2))  # B and C − V are linear and quadratic in ω2
    room = np.maximum(energy - c0, 0.0) / (c1 - c0 - b1 * b1 / (4.0 * a))
    return 1.01 * math.sqrt(room.max())  # a margin for the grid's step


def shell_start(scene, th: np.ndarray, w: np.ndarray):
    """layout = "shell" (see the module docstring): th, w (N, 2) rewritten in place. Points of the R2 sequence
    in the box the section's accessible region fits in, kept where a positive ω1 gives them the energy: the
    region fills a fair part of its box at any energy, so a few rounds find them all."""
    p = reference.params(scene)
    energy = float(reference.energy(p, th[:1], w[:1])[0])
    if not energy > 0.0:
        raise SceneError(f"{scene.source}: pendulums.layout: \"shell\" starts pendulums with the energy of "
                         f"theta1, theta2, omega1, omega2, which is {energy:g} J here (the hanging rest, where "
                         f"the section is a point); give a start with some energy")
    th_max = reach(p, energy)
    w_max = omega2_range(p, energy, th_max)
    n, found, k = len(th), [], 0
    while sum(len(f[0]) for f in found) < n:
        j = np.arange(k, k + 2 * n + 64, dtype=np.float64)
        th2 = th_max * (2.0 * ((0.5 + j / PLASTIC) % 1.0) - 1.0)
        w2 = w_max * (2.0 * ((0.5 + j / PLASTIC ** 2) % 1.0) - 1.0)
        a, b, c = quadratic(p, th2, w2)
        disc = b * b - 4.0 * a * (c - energy)
        root = (-b + np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
        keep = (disc >= 0.0) & (root > 0.0)
        found.append((th2[keep], w2[keep], root[keep]))
        k += len(j)
    th2, w2, w1 = (np.concatenate(f)[:n] for f in zip(*found))
    th[:] = np.stack([np.zeros(n), th2], 1)
    w[:] = np.stack([w1, w2], 1)
