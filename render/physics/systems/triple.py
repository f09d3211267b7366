"""The rigid triple pendulum, a chain of any masses and lengths: its declaration and plan (Lagrange's equations for
the three angles, in Taichi: render/physics/kernels/triple.py)."""
from .. import stability
from ..plan import Plan


class Triple(Plan):
    SYSTEM = "triple"
    NAME = "triple"
    DOC = "three rigid massless rods (Lagrange's equations for the three angles)"
    D = 3  # q = (θ1, θ2, θ3), v = (ω1, ω2, ω3)
    LINKS = ("rod", "rod", "rod")
    ANGLES = True
    METHODS = ("symplectic_euler", "rk2", "rk4", "implicit_midpoint")
    DEFAULT_EFFECTS = ("rods", "bobs", "trails", "energy")
    STATE = {"theta": ("q", (3,)), "omega": ("v", (3,))}
    REFERENCE = "chain"
    ERROR_UNIT = "max |Δθ| [rad]"
    ACCURACY_CASE = ("triple_classic", 2.0)
    ACCURACY_LADDER = (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4)

    def __init__(self, scene, *args, **kwargs):
        m1, m2, m3 = scene.pendulums.masses
        self.l = scene.pendulums.lengths
        # μ_ij: mass at or below link max(i, j)
        self.mu = ((m1 + m2 + m3, m2 + m3, m3), (m2 + m3, m2 + m3, m3), (m3, m3, m3))
        self.tr = sum(self.mu[i][i] * self.l[i] ** 2 for i in range(3))  # trace of M, at any angles
        super().__init__(scene, *args, **kwargs)

    def omega_max(self, q0, v0) -> float:
        return stability.chain_rate(self.scene, q0, v0)

    def energy_limit(self, q0, v0, method) -> float:
        return stability.energy_limit(self.scene, q0, v0, method, self.energy_floor())

    def initial_state(self):
        return self.initial_angles()

    def reach(self) -> float:
        return sum(self.l)


SYSTEM = Triple
