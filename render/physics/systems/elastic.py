"""The elastic double pendulum: two springs (k = stiffness / rest length) and gravity, in Cartesian form: its
declaration, plan and framing (Newton's equations, in Taichi: render/physics/kernels/elastic.py)."""
import math

import numpy as np

from .. import stability
from ..keys import Real
from ..plan import Plan


class Elastic(Plan):
    SYSTEM = "elastic"
    NAME = "spring"
    DOC = "two springs of rest lengths `lengths`, k = stiffness / rest length (Newton in x, y)"
    D = 4  # q = (x1, y1, x2, y2) with the pivot at the origin, v likewise
    LINKS = ("spring", "spring")
    # Young's-modulus-like E, as in the seed. Within [1e-6, 1e12]: the spring constants k = E/l this gives
    # with lengths in [1e-6, 1e6] stay finite in f32; how fast a stiff spring makes the step is budget.py's.
    KEYS = {"stiffness": Real(2e3, 1e-6, 1e12)}
    METHODS = ("symplectic_euler", "rk2", "rk4", "verlet", "yoshida4")
    DEFAULT_EFFECTS = ("springs", "bobs", "trails", "energy")
    STATE = {"pos": ("q", (2, 2)), "vel": ("v", (2, 2))}
    REFERENCE = "springs"
    ERROR_UNIT = "max |Δx| of the bobs [m]"
    ACCURACY_CASE = ("elastic_fan", 1.0)
    ACCURACY_LADDER = (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)

    def __init__(self, scene, *args, **kwargs):
        p = scene.pendulums
        (self.m1, self.m2), (self.l1, self.l2) = p.masses, p.lengths
        self.k1, self.k2 = p.stiffness / p.lengths[0], p.stiffness / p.lengths[1]
        super().__init__(scene, *args, **kwargs)

    def omega_max(self, q0, v0) -> float:
        """Fastest linear mode of the two springs along the chain: sqrt of the top eigenvalue of M⁻¹K."""
        k1, k2, m1, m2 = self.k1, self.k2, self.m1, self.m2
        mk = np.array([[(k1 + k2) / m1, -k2 / m1], [-k2 / m2, k2 / m2]])
        return math.sqrt(max(np.linalg.eigvals(mk).real))

    def energy_limit(self, q0, v0, method) -> float:
        return stability.oscillator_limit(self.scene, self.omega_max(q0, v0), method)

    def deviation(self, qa, qb):
        """The farthest bob's distance apart, as a fraction of the total rest length."""
        gap = np.hypot(qa[..., 0::2] - qb[..., 0::2], qa[..., 1::2] - qb[..., 1::2])
        return gap.max(-1) / (self.l1 + self.l2)

    def initial_state(self):
        """Bobs at their rest lengths along the fan's angles, velocities from ω1, ω2."""
        th, w = self.initial_angles()
        (th1, th2), (w1, w2) = th.T, w.T
        l1, l2 = self.l1, self.l2
        x1, y1 = l1 * np.sin(th1), -l1 * np.cos(th1)
        vx1, vy1 = l1 * w1 * np.cos(th1), l1 * w1 * np.sin(th1)
        x2, y2 = x1 + l2 * np.sin(th2), y1 - l2 * np.cos(th2)
        vx2, vy2 = vx1 + l2 * w2 * np.cos(th2), vy1 + l2 * w2 * np.sin(th2)
        return np.stack([x1, y1, x2, y2], 1), np.stack([vx1, vy1, vx2, vy2], 1)

    def initial_energy(self) -> float:
        """The largest energy of any pendulum at t = 0 (as energy() computes it; damping only lowers it)."""
        q, v = self.initial_state()
        x1, y1, x2, y2 = q.T
        s1, s2 = np.hypot(x1, y1) - self.l1, np.hypot(x2 - x1, y2 - y1) - self.l2
        kin = 0.5 * self.m1 * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * self.m2 * (v[:, 2] ** 2 + v[:, 3] ** 2)
        grav = self.m1 * self.g * (y1 + self.l1) + self.m2 * self.g * (y2 + self.l1 + self.l2)
        return float(np.max(kin + 0.5 * self.k1 * s1 ** 2 + 0.5 * self.k2 * s2 ** 2 + grav))

    def reach(self) -> float:
        """How far from the pivot either bob can ever get, from the energy: nothing leaves the frame.

        With stretches s1, s2 the outer bob is at most l1 + s1 + l2 + s2 from the pivot, and each bob is at
        most that far below it, so the potential is at least
            f(s1, s2) = ½k1·s1² − (m1 + m2)·g·s1 + ½k2·s2² − m2·g·s2
        (gravity measured as energy() does, zero at the rest lengths hanging). Kinetic energy is never
        negative, so every state reached has f ≤ E, the largest initial energy. On that ellipse,
        ½k1(s1 − a/k1)² + ½k2(s2 − b/k2)² ≤ C with a = (m1 + m2)g, b = m2·g, C = E + a²/2k1 + b²/2k2,
        the largest s1 + s2 is a/k1 + b/k2 + √(2C(1/k1 + 1/k2)) (Cauchy-Schwarz). The inner bob's bound,
        l1 + a/k1 + √(2C/k1), is smaller, so this one frames both."""
        a, b = (self.m1 + self.m2) * self.g, self.m2 * self.g
        c = max(self.initial_energy(), 0.0) + a * a / (2 * self.k1) + b * b / (2 * self.k2)
        stretch = a / self.k1 + b / self.k2 + math.sqrt(2 * c * (1 / self.k1 + 1 / self.k2))
        return self.l1 + self.l2 + stretch


SYSTEM = Elastic
