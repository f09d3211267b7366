"""The rigid triple pendulum in Taichi: Lagrange's equations for the three angles of a chain of any masses and lengths.

With μ_ij the mass at or below link max(i, j), M_ij = μ_ij l_i l_j cos(θ_i − θ_j) and
    Σ_j M_ij θ_j'' = −Σ_j μ_ij l_i l_j sin(θ_i − θ_j) ω_j² − g μ_ii l_i sin θ_i,
solved for θ'' by the explicit inverse of the symmetric 3×3 M (cofactors), lane by lane.
"""
import taichi as ti

from .. import dual
from ..system import System
from ..systems.triple import Triple


@ti.data_oriented
class TripleKernels(Triple, System):
    @ti.func
    def geometry(self, q):
        """Lane vectors: sin θ_i, and sin, cos of θ_i − θ_j for the pairs (1,2), (1,3), (2,3), by angle
        addition from the three sines and cosines (3 inline sincos, render/physics/sincos.py, instead of 12 libm calls)."""
        s1, c1 = self.sincos(q[0, :])
        s2, c2 = self.sincos(q[1, :])
        s3, c3 = self.sincos(q[2, :])
        return (s1, s2, s3, s1 * c2 - c1 * s2, c1 * c2 + s1 * s2, s1 * c3 - c1 * s3, c1 * c3 + s1 * s3,
                s2 * c3 - c2 * s3, c2 * c3 + s2 * s3)

    @ti.func
    def mass_matrix(self, c12, c13, c23):
        """The six distinct entries of M: (M11, M12, M13, M22, M23, M33)."""
        mu, l = self.mu, self.l
        return (mu[0][0] * l[0] * l[0], mu[0][1] * l[0] * l[1] * c12, mu[0][2] * l[0] * l[2] * c13,
                mu[1][1] * l[1] * l[1], mu[1][2] * l[1] * l[2] * c23, mu[2][2] * l[2] * l[2])

    @ti.func
    def solve(self, m, f0, f1, f2):
        """M⁻¹·f by cofactors of the symmetric M = [[a, b, c], [b, d, e], [c, e, k]], lane by lane."""
        a, b, c, d, e, k = m
        i00, i01, i02 = d * k - e * e, c * e - b * k, b * e - c * d
        i11, i12, i22 = a * k - c * c, b * c - a * e, a * d - b * b
        det = a * i00 + b * i01 + c * i02
        return dual.rows([(i00 * f0 + i01 * f1 + i02 * f2) / det, (i01 * f0 + i11 * f1 + i12 * f2) / det,
                          (i02 * f0 + i12 * f1 + i22 * f2) / det])

    @ti.func
    def accel(self, q, v):
        mu, l, g = self.mu, self.l, self.g
        s1, s2, s3, s12, c12, s13, c13, s23, c23 = self.geometry(q)
        w1, w2, w3 = v[0, :] * v[0, :], v[1, :] * v[1, :], v[2, :] * v[2, :]  # ω²
        f0 = -mu[0][1] * l[0] * l[1] * s12 * w2 - mu[0][2] * l[0] * l[2] * s13 * w3 - g * mu[0][0] * l[0] * s1
        f1 = mu[0][1] * l[0] * l[1] * s12 * w1 - mu[1][2] * l[1] * l[2] * s23 * w3 - g * mu[1][1] * l[1] * s2
        f2 = mu[0][2] * l[0] * l[2] * s13 * w1 + mu[1][2] * l[1] * l[2] * s23 * w2 - g * mu[2][2] * l[2] * s3
        return self.solve(self.mass_matrix(c12, c13, c23), f0, f1, f2)

    @ti.func
    def energy(self, q, v):
        """½ωᵀMω + g Σ μ_ii l_i (1 − cos θ_i): zero at the hanging rest position."""
        mu, l = self.mu, self.l
        e = 0.0
        for i in ti.static(range(3)):
            e += self.g * mu[i][i] * l[i] * (1.0 - ti.cos(q[i]))
            for j in ti.static(range(3)):
                e += 0.5 * mu[i][j] * l[i] * l[j] * ti.cos(q[i] - q[j]) * v[i] * v[j]
        return e

    @ti.func
    def points(self, q):
        p1 = self.l[0] * ti.Vector([ti.sin(q[0]), -ti.cos(q[0])])
        p2 = p1 + self.l[1] * ti.Vector([ti.sin(q[1]), -ti.cos(q[1])])
        return ti.Matrix.rows([p1, p2, p2 + self.l[2] * ti.Vector([ti.sin(q[2]), -ti.cos(q[2])])])

    # Canonical hooks: the implicit midpoint steps (θ, p = M(θ)ω), where it is symplectic.
    @ti.func
    def momenta(self, q, v):
        s1, s2, s3, s12, c12, s13, c13, s23, c23 = self.geometry(q)
        a, b, c, d, e, k = self.mass_matrix(c12, c13, c23)
        return ti.Matrix.rows([a * v[0, :] + b * v[1, :] + c * v[2, :], b * v[0, :] + d * v[1, :] + e * v[2, :],
                               c * v[0, :] + e * v[1, :] + k * v[2, :]])

    @ti.func
    def velocities(self, q, p):
        s1, s2, s3, s12, c12, s13, c13, s23, c23 = self.geometry(q)
        return self.solve(self.mass_matrix(c12, c13, c23), p[0, :], p[1, :], p[2, :])

    @ti.func
    def momentum_rate(self, q, v, p):
        """ṗ_i = ∂L/∂θ_i = −Σ_j μ_ij l_i l_j sin(θ_i − θ_j) ω_i ω_j − g μ_ii l_i sin θ_i; damping is −c·p."""
        mu, l, g = self.mu, self.l, self.g
        s1, s2, s3, s12, c12, s13, c13, s23, c23 = self.geometry(q)
        t12 = mu[0][1] * l[0] * l[1] * s12 * v[0, :] * v[1, :]
        t13 = mu[0][2] * l[0] * l[2] * s13 * v[0, :] * v[2, :]
        t23 = mu[1][2] * l[1] * l[2] * s23 * v[1, :] * v[2, :]
        r = ti.Matrix.rows([-t12 - t13 - g * mu[0][0] * l[0] * s1, t12 - t23 - g * mu[1][1] * l[1] * s2,
                            t13 + t23 - g * mu[2][2] * l[2] * s3])
        if ti.static(self.damped):
            r -= self.damping * p
        return r

    @ti.func
    def p_scale(self, h):
        return h / self.tr


KERNELS = TripleKernels
