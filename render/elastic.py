"""The elastic double pendulum: two springs (k = stiffness / rest length) and gravity, in Cartesian form."""

import math

import numpy as np
import taichi as ti

from .system import System


def spring_constants(p) -> tuple[float, float]:
    return p.stiffness / p.lengths[0], p.stiffness / p.lengths[1]


def omega_max(p) -> float:
    """Fastest linear mode of the two springs along the chain: sqrt of the top eigenvalue of M⁻¹K."""
    k1, k2 = spring_constants(p)
    m1, m2 = p.masses
    mk = np.array([[(k1 + k2) / m1, -k2 / m1], [-k2 / m2, k2 / m2]])
    return math.sqrt(max(np.linalg.eigvals(mk).real))


@ti.data_oriented
class Elastic(System):
    D = 4  # q = (x1, y1, x2, y2) with the pivot at the origin, v likewise
    NAME = "spring"

    def __init__(self, scene):
        self.k1, self.k2 = spring_constants(scene.pendulums)
        super().__init__(scene)

    def omega_max(self) -> float:
        return omega_max(self.scene.pendulums)

    def initial_state(self):
        """Bobs at their rest lengths along the fan's angles, velocities from ω1, ω2."""
        p = self.scene.pendulums
        th1, th2 = self.initial_angles()
        l1, l2 = p.lengths
        x1, y1 = l1 * np.sin(th1), -l1 * np.cos(th1)
        vx1, vy1 = l1 * p.omega1 * np.cos(th1), l1 * p.omega1 * np.sin(th1)
        x2, y2 = x1 + l2 * np.sin(th2), y1 - l2 * np.cos(th2)
        vx2, vy2 = vx1 + l2 * p.omega2 * np.cos(th2), vy1 + l2 * p.omega2 * np.sin(th2)
        return np.stack([x1, y1, x2, y2], 1), np.stack([vx1, vy1, vx2, vy2], 1)

    @ti.func
    def spring_pull(self, d, k, rest):
        """Force on the far end of a spring along d (guarded so a spring of zero length gives no NaN)."""
        r = d.norm()
        return -k * (r - rest) * d / ti.max(r, 1e-12)

    @ti.func
    def accel(self, q, v):
        p1, p2 = ti.Vector([q[0], q[1]]), ti.Vector([q[2], q[3]])
        f1 = self.spring_pull(p1, self.k1, self.l1)
        f2 = self.spring_pull(p2 - p1, self.k2, self.l2)
        a1 = (f1 - f2) / self.m1
        a2 = f2 / self.m2
        return ti.Vector([a1[0], a1[1] - self.g, a2[0], a2[1] - self.g])

    @ti.func
    def energy(self, q, v):
        p1, p2 = ti.Vector([q[0], q[1]]), ti.Vector([q[2], q[3]])
        s1, s2 = p1.norm() - self.l1, (p2 - p1).norm() - self.l2
        kin = 0.5 * self.m1 * (v[0] * v[0] + v[1] * v[1]) + 0.5 * self.m2 * (v[2] * v[2] + v[3] * v[3])
        springs = 0.5 * self.k1 * s1 * s1 + 0.5 * self.k2 * s2 * s2
        grav = self.m1 * self.g * (q[1] + self.l1) + self.m2 * self.g * (q[3] + self.l1 + self.l2)
        return kin + springs + grav

    @ti.func
    def bobs(self, i: ti.i32):
        q = self.q[i]
        return ti.Vector([q[0], q[1]]), ti.Vector([q[2], q[3]])

    @ti.kernel
    def spring_advance(self, substeps: ti.i32):
        for i in range(self.n):
            self.advance_one(i, substeps)

    @ti.kernel
    def spring_energy(self, first: ti.i32):
        for i in range(self.n):
            self.energy_one(i, first)

    def extent(self) -> float:
        """Reach of the outer bob: rest lengths plus the largest stretch energy allows (bounded)."""
        p = self.scene.pendulums
        return (p.lengths[0] + p.lengths[1]) * 1.15

    def state(self):
        return {"pos": self.q.to_numpy().reshape(self.n, 2, 2), "vel": self.v.to_numpy().reshape(self.n, 2, 2)}
