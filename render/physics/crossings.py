"""The Poincaré section's crossings, found within each substep in Taichi (render/physics/poincare.py says how;
its read() takes them back, and its shell start needs no Taichi).
"""
import taichi as ti

from . import runtime
from .poincare import SLOTS, TAU


def allocate(sim):
    """The crossing fields of a system whose scene has the effect: this step's crossings per pendulum."""
    sim.crossings = runtime.field("poincare.crossings", runtime.real(), (sim.n, SLOTS), 3)  # (t in step, θ2, ω2)
    sim.crossed = runtime.field("poincare.count", ti.i32, sim.n)


@ti.func
def hermite(y0, y1, d0, d1, u):
    """The cubic through y0, y1 with slopes d0, d1 (per unit of u) at u = 0, 1."""
    return (y0 + u * (d0 + u * (3.0 * (y1 - y0) - 2.0 * d0 - d1 + u * (2.0 * (y0 - y1) + d0 + d1))))


@ti.func
def hermite_slope(y0, y1, d0, d1, u):
    return d0 + u * (6.0 * (y1 - y0) - 4.0 * d0 - 2.0 * d1 + 3.0 * u * (2.0 * (y0 - y1) + d0 + d1))


@ti.func
def detect(sys: ti.template(), i, s, q0, v0, q1, v1, h):
    """Record pendulum i's crossing of the section in substep s (from q0, v0 to q1, v1; D × 1), if any."""
    k0, k1 = ti.floor(q0[0, 0] / TAU), ti.floor(q1[0, 0] / TAU)
    if k1 > k0 and i < sys.n:
        a0, a1 = sys.force(q0, v0), sys.force(q1, v1)
        y0, y1 = q0[0, 0] - k1 * TAU, q1[0, 0] - k1 * TAU  # below and at or above the section
        d0, d1 = h * v0[0, 0], h * v1[0, 0]
        u = y0 / (y0 - y1)
        for _ in range(4):  # Newton from the chord: its error is O(h²), squared each time
            u = ti.min(ti.max(u - hermite(y0, y1, d0, d1, u) / hermite_slope(y0, y1, d0, d1, u), 0.0), 1.0)
        th2 = hermite(q0[1, 0], q1[1, 0], h * v0[1, 0], h * v1[1, 0], u)
        w2 = hermite(v0[1, 0], v1[1, 0], h * a0[1, 0], h * a1[1, 0], u)
        k = sys.crossed[i]
        if k < SLOTS:
            sys.crossings[i, k] = ti.Vector([(s + u) * h, th2, w2])
        sys.crossed[i] = k + 1
