"""The rigid double pendulum in Taichi: Lagrange's equations for θ1'', θ2'' (angles from the downward vertical)."""
import taichi as ti

from .. import dual
from ..system import System
from ..systems.rigid import Rigid


@ti.data_oriented
class RigidKernels(Rigid, System):
    @ti.func
    def accel(self, q, v):
        # Only sin/cos of θ1 and θ2 are evaluated, inline (render/physics/sincos.py: no libm call, so the advance loop
        # vectorises) unless the scene pins libm; the rest follow by angle addition.
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        w1, w2 = v[0, :], v[1, :]
        s1, c1 = self.sincos(q[0, :])
        s2, c2 = self.sincos(q[1, :])
        sd, cd = s1 * c2 - c1 * s2, c1 * c2 + s1 * s2  # sin, cos of θ1 − θ2
        den = 2.0 * (m1 + m2 * sd * sd)  # 2m1 + m2 − m2·cos 2(θ1 − θ2), without the cancellation
        a1 = (-g * (2.0 * m1 + m2) * s1 - m2 * g * (sd * c2 - cd * s2)  # sin(θ1 − 2θ2) = sin(Δ − θ2)
              - 2.0 * sd * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * cd)) / (l1 * den)
        a2 = (2.0 * sd * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * c1
                          + w2 * w2 * l2 * m2 * cd)) / (l2 * den)
        return dual.rows([a1, a2])  # of Duals too: the FTLE map carries tangents through (render/physics/dual.py)

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
    def points(self, q):
        p1 = self.l1 * ti.Vector([ti.sin(q[0]), -ti.cos(q[0])])
        return ti.Matrix.rows([p1, p1 + self.l2 * ti.Vector([ti.sin(q[1]), -ti.cos(q[1])])])

    # The implicit midpoint steps in canonical coordinates (θ, p = M(θ)ω), where it is symplectic.
    @ti.func
    def mass_matrix(self, q):
        c = ti.cos(q[0, :] - q[1, :])
        return (self.m1 + self.m2) * self.l1 * self.l1, self.m2 * self.l1 * self.l2 * c, self.m2 * self.l2 * self.l2

    @ti.func
    def momenta(self, q, v):
        a, b, d = self.mass_matrix(q)
        return ti.Matrix.rows([a * v[0, :] + b * v[1, :], b * v[0, :] + d * v[1, :]])

    @ti.func
    def velocities(self, q, p):
        a, b, d = self.mass_matrix(q)
        det = a * d - b * b
        return ti.Matrix.rows([(d * p[0, :] - b * p[1, :]) / det, (a * p[1, :] - b * p[0, :]) / det])

    @ti.func
    def momentum_rate(self, q, v, p):
        """ṗ = ∂L/∂θ; viscous damping on θ'' is the generalised force −c·p."""
        s = self.m2 * self.l1 * self.l2 * v[0, :] * v[1, :] * ti.sin(q[0, :] - q[1, :])
        r = ti.Matrix.rows([-s - (self.m1 + self.m2) * self.g * self.l1 * ti.sin(q[0, :]),
                            s - self.m2 * self.g * self.l2 * ti.sin(q[1, :])])
        if ti.static(self.damped):
            r -= self.damping * p
        return r

    @ti.func
    def p_scale(self, h):
        return h / ((self.m1 + self.m2) * self.l1 * self.l1 + self.m2 * self.l2 * self.l2)


KERNELS = RigidKernels
