"""The rigid double pendulum: Lagrange's equations for θ1'', θ2'' (angles from the downward vertical)."""
import math

import numpy as np
import taichi as ti

from ..system import System


@ti.data_oriented
class Rigid(System):
    SYSTEM = "rigid"
    NAME = "rigid"
    DOC = "two rigid massless rods (Lagrange's equations for the two angles)"
    D = 2  # q = (θ1, θ2), v = (ω1, ω2)
    LINKS = ("rod", "rod")
    ANGLES = True
    METHODS = ("symplectic_euler", "rk4", "implicit_midpoint")
    DEFAULT_EFFECTS = ("rods", "bobs", "trails", "energy")
    STATE = {"theta": ("q", (2,)), "omega": ("v", (2,))}
    REFERENCE = "chain"
    ERROR_UNIT = "max |Δθ| [rad]"
    ACCURACY_CASE = ("classic", 2.0)
    ACCURACY_LADDER = (2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4)
    # From `pendulum accuracy` on classic: RK4 beats implicit_midpoint at every cost (dt 1e-3: 1.8e-10 vs
    # 5.6e-6 rad for about the same ns/step), and its energy error over 1e5 steps stays ~1e-9.
    QUALITY = {
        "draft": {"method": "rk4", "dt": 1 / 60, "precision": "f32"},  # one step per 60 fps frame
        "standard": {"method": "rk4", "dt": 2e-3, "precision": "f64"},  # 2.8e-9 rad
        "high": {"method": "rk4", "dt": 1e-3, "precision": "f64"},  # 1.8e-10 rad
        "reference": {"method": "rk4", "dt": 2e-4, "precision": "f64"},  # 1.3e-13 rad, the reference's own
    }

    def __init__(self, scene):
        (self.m1, self.m2), (self.l1, self.l2) = scene.pendulums.masses, scene.pendulums.lengths
        super().__init__(scene)

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
        return self.initial_angles()

    def reach(self) -> float:
        return self.l1 + self.l2

    @ti.func
    def accel(self, q, v):
        # Only sin/cos of θ1 and θ2 are evaluated: the rest follow by angle addition. Scalar libm trig is 93 %
        # of the kernel's time on a CPU (benchmarks/README.md), so 4 calls instead of 6 is a 1.5x speed-up.
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        w1, w2 = v[0, :], v[1, :]
        s1, c1, s2, c2 = ti.sin(q[0, :]), ti.cos(q[0, :]), ti.sin(q[1, :]), ti.cos(q[1, :])
        sd, cd = s1 * c2 - c1 * s2, c1 * c2 + s1 * s2  # sin, cos of θ1 − θ2
        den = 2.0 * (m1 + m2 * sd * sd)  # 2m1 + m2 − m2·cos 2(θ1 − θ2), without the cancellation
        a1 = (-g * (2.0 * m1 + m2) * s1 - m2 * g * (sd * c2 - cd * s2)  # sin(θ1 − 2θ2) = sin(Δ − θ2)
              - 2.0 * sd * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * cd)) / (l1 * den)
        a2 = (2.0 * sd * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * c1
                          + w2 * w2 * l2 * m2 * cd)) / (l2 * den)
        return ti.Matrix.rows([a1, a2])

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


SYSTEM = Rigid
