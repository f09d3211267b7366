"""The rigid double pendulum, θ1 and θ2 from the downward vertical: its declaration and plan (Lagrange's equations,
in Taichi: render/physics/kernels/rigid.py)."""
from .. import stability
from ..plan import Plan


class Rigid(Plan):
    SYSTEM = "rigid"
    NAME = "rigid"
    DOC = "two rigid massless rods (Lagrange's equations for the two angles)"
    D = 2  # q = (θ1, θ2), v = (ω1, ω2)
    LINKS = ("rod", "rod")
    ANGLES = True
    METHODS = ("symplectic_euler", "rk2", "rk4", "implicit_midpoint")
    DEFAULT_EFFECTS = ("rods", "bobs", "trails", "energy")
    STATE = {"theta": ("q", (2,)), "omega": ("v", (2,))}
    REFERENCE = "chain"
    ERROR_UNIT = "max |Δθ| [rad]"
    ACCURACY_CASE = ("classic", 2.0)
    ACCURACY_LADDER = (2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4)

    def __init__(self, scene, *args, **kwargs):
        (self.m1, self.m2), (self.l1, self.l2) = scene.pendulums.masses, scene.pendulums.lengths
        super().__init__(scene, *args, **kwargs)

    def omega_max(self, q0, v0) -> float:
        return stability.chain_rate(self.scene, q0, v0)

    def energy_limit(self, q0, v0, method) -> float:
        return stability.energy_limit(self.scene, q0, v0, method, self.energy_floor())

    def initial_state(self):
        return self.initial_angles()

    def reach(self) -> float:
        return self.l1 + self.l2


SYSTEM = Rigid
