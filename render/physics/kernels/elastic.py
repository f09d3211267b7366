"""The elastic double pendulum in Taichi: Newton's equations for the two bobs in x, y."""
import taichi as ti

from ..system import System
from ..systems.elastic import Elastic


@ti.data_oriented
class ElasticKernels(Elastic, System):
    @ti.func
    def spring_pull(self, dx, dy, k, rest):
        """Force on the far end of a spring along (dx, dy) (guarded so a spring of zero length gives no NaN)."""
        r = ti.sqrt(dx * dx + dy * dy)
        pull = -k * (r - rest)
        return pull * dx / ti.max(r, 1e-12), pull * dy / ti.max(r, 1e-12)

    @ti.func
    def accel(self, q, v):
        x1, y1, x2, y2 = q[0, :], q[1, :], q[2, :], q[3, :]
        f1x, f1y = self.spring_pull(x1, y1, self.k1, self.l1)
        f2x, f2y = self.spring_pull(x2 - x1, y2 - y1, self.k2, self.l2)
        return ti.Matrix.rows([(f1x - f2x) / self.m1, (f1y - f2y) / self.m1 - self.g,
                               f2x / self.m2, f2y / self.m2 - self.g])

    @ti.func
    def energy(self, q, v):
        p1, p2 = ti.Vector([q[0], q[1]]), ti.Vector([q[2], q[3]])
        s1, s2 = p1.norm() - self.l1, (p2 - p1).norm() - self.l2
        kin = 0.5 * self.m1 * (v[0] * v[0] + v[1] * v[1]) + 0.5 * self.m2 * (v[2] * v[2] + v[3] * v[3])
        springs = 0.5 * self.k1 * s1 * s1 + 0.5 * self.k2 * s2 * s2
        grav = self.m1 * self.g * (q[1] + self.l1) + self.m2 * self.g * (q[3] + self.l1 + self.l2)
        return kin + springs + grav

    @ti.func
    def points(self, q):
        return ti.Matrix([[q[0], q[1]], [q[2], q[3]]])


KERNELS = ElasticKernels
