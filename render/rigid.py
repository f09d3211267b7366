"""The rigid double pendulum: Lagrange's equations for θ1'', θ2'' (angles from the downward vertical)."""

import math

import numpy as np
import taichi as ti

from .system import System


@ti.data_oriented
class Rigid(System):
    D = 2  # q = (θ1, θ2), v = (ω1, ω2)
    NAME = "rigid"

    def omega_max(self) -> float:
        """A bound on the fastest local rate (rad/s), for choosing a stable step.

        Energy bounds the speed: T = ½ωᵀM(θ)ω ≤ E with λ_min(M) ≥ det/trace, so |ω| ≤ √(2E/λ_min). Near
        θ1 ≈ θ2 the ω² terms of θ1'' carry a factor up to ½√(m2/m1), so the local rate scales by √(1 + m2/m1):
        a heavy lower bob whips the light upper arm (m2/m1 = 1e3 blew up RK4 at dt = 1e-3 without this).
        """
        p = self.scene.pendulums
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        trace = (m1 + m2) * l1 ** 2 + m2 * l2 ** 2
        lam_min = m1 * m2 * l1 ** 2 * l2 ** 2 / trace
        energy = 2 * g * (m1 * l1 + m2 * (l1 + l2)) + 0.5 * trace * (p.omega1 ** 2 + p.omega2 ** 2)
        return math.sqrt(1 + m2 / m1) * math.sqrt(2 * energy / lam_min)

    def initial_state(self):
        p = self.scene.pendulums
        th1, th2 = self.initial_angles()
        w = np.empty((self.n, 2))
        w[:, 0], w[:, 1] = p.omega1, p.omega2
        return np.stack([th1, th2], axis=1), w

    @ti.func
    def accel(self, q, v):
        # Only sin/cos of θ1 and θ2 are evaluated: the rest follow by angle addition. Scalar libm trig is 93 %
        # of the kernel's time on a CPU (benchmarks/README.md), so 4 calls instead of 6 is a 1.5x speed-up.
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        s1, c1, s2, c2 = ti.sin(q[0]), ti.cos(q[0]), ti.sin(q[1]), ti.cos(q[1])
        sd, cd = s1 * c2 - c1 * s2, c1 * c2 + s1 * s2  # sin, cos of θ1 − θ2
        den = 2.0 * (m1 + m2 * sd * sd)  # 2m1 + m2 − m2·cos 2(θ1 − θ2), without the cancellation
        a1 = (-g * (2.0 * m1 + m2) * s1 - m2 * g * (sd * c2 - cd * s2)  # sin(θ1 − 2θ2) = sin(Δ − θ2)
              - 2.0 * sd * m2 * (v[1] * v[1] * l2 + v[0] * v[0] * l1 * cd)) / (l1 * den)
        a2 = (2.0 * sd * (v[0] * v[0] * l1 * (m1 + m2) + g * (m1 + m2) * c1
                          + v[1] * v[1] * l2 * m2 * cd)) / (l2 * den)
        return ti.Vector([a1, a2])

    @ti.func
    def energy(self, q, v):
        """Kinetic + gravitational, with the potential's zero at the hanging rest position."""
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        t = (0.5 * (m1 + m2) * l1 * l1 * v[0] * v[0] + 0.5 * m2 * l2 * l2 * v[1] * v[1]
             + m2 * l1 * l2 * v[0] * v[1] * ti.cos(q[0] - q[1]))
        y1 = -l1 * ti.cos(q[0])
        y2 = y1 - l2 * ti.cos(q[1])
        return t + m1 * g * (y1 + l1) + m2 * g * (y2 + l1 + l2)

    @ti.func
    def bobs(self, i: ti.i32):
        q = self.q[i]
        p1 = self.l1 * ti.Vector([ti.sin(q[0]), -ti.cos(q[0])])
        return p1, p1 + self.l2 * ti.Vector([ti.sin(q[1]), -ti.cos(q[1])])

    # The implicit midpoint rule is symplectic only in canonical coordinates (θ, p = M(θ)ω); applied to
    # (θ, ω) its symplecticity defect shrinks only like h³ and energy creeps.
    @ti.func
    def mass_matrix(self, q):
        c = ti.cos(q[0] - q[1])
        return (self.m1 + self.m2) * self.l1 * self.l1, self.m2 * self.l1 * self.l2 * c, self.m2 * self.l2 * self.l2

    @ti.func
    def momenta(self, q, v):
        a, b, d = self.mass_matrix(q)
        return ti.Vector([a * v[0] + b * v[1], b * v[0] + d * v[1]])

    @ti.func
    def velocities(self, q, p):
        a, b, d = self.mass_matrix(q)
        return ti.Vector([d * p[0] - b * p[1], a * p[1] - b * p[0]]) / (a * d - b * b)

    @ti.func
    def momentum_rate(self, q, v, p):
        """ṗ = ∂L/∂θ; viscous damping on θ'' is the generalised force −c·p."""
        s = self.m2 * self.l1 * self.l2 * v[0] * v[1] * ti.sin(q[0] - q[1])
        r = ti.Vector([-s - (self.m1 + self.m2) * self.g * self.l1 * ti.sin(q[0]),
                       s - self.m2 * self.g * self.l2 * ti.sin(q[1])])
        if ti.static(self.damped):
            r -= self.damping * p
        return r

    @ti.func
    def implicit_midpoint(self, q, v, h):
        """Midpoint rule in (θ, p), solved by fixed-point iteration to self.tol (at most 100 sweeps)."""
        p = self.momenta(q, v)
        q1, p1 = q + h * v, p + h * self.momentum_rate(q, v, p)
        pscale = h / ((self.m1 + self.m2) * self.l1 * self.l1 + self.m2 * self.l2 * self.l2)
        for _ in range(100):
            qm, pm = 0.5 * (q + q1), 0.5 * (p + p1)
            vm = self.velocities(qm, pm)
            qn, pn = q + h * vm, p + h * self.momentum_rate(qm, vm, pm)
            err = ti.max((qn - q1).norm_sqr(), (pn - p1).norm_sqr() * pscale * pscale)
            q1, p1 = qn, pn
            if err <= self.tol * self.tol:
                break
        return q1, self.velocities(q1, p1)

    @ti.kernel
    def rigid_advance(self, substeps: ti.i32):
        for i in range(self.n):
            self.advance_one(i, substeps)

    @ti.kernel
    def rigid_energy(self, first: ti.i32):
        for i in range(self.n):
            self.energy_one(i, first)

    def extent(self) -> float:
        return self.l1 + self.l2

    def state(self):
        return {"theta": self.q.to_numpy(), "omega": self.v.to_numpy()}
