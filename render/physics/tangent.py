"""The tangent map of one frame of a system's numerical flow, exact, in canonical coordinates.

    flow = TangentFlow(sim)          # sim: an allocated System (its q, v are the state at the frame's start)
    images = flow.frame(basis)       # basis (n, 2D, k) -> DΦ·basis, before the frame loop steps sim

What is differentiated: one frame of the scene's own integrator (steps.step, `substeps` steps of h)
over the system's own force, wrapped in canonical coordinates:
    (q, p) -> (q, v = velocities(q, p)) -> substeps of steps.step -> (q, momenta(q, v)).
Taichi's forward mode (ti.ad.FwdMode) carries a dual number for every tangent vector through that kernel,
so the result is the tangent map of the numerical flow to round-off, not a finite difference, and no
physics is written twice: the integrator, force(), momenta() and velocities() are the system's.

Why the discrete step and not variational equations integrated beside the state: the step's derivative is
one kernel that needs nothing from the system beyond what it declares (no second set of equations per
integrator), and its determinant is the numerical flow's volume change exactly (RK4 at dt 1e-3 on classic:
|ln det| about 1e-12 per frame, 1.7e-9 at the worst frame of 200 s; tests/test_lyapunov.py). Why canonical
(q, p): volume is conserved there (Liouville) and shrinks as e^{-D·c·t} under the damping −c·p; in (θ, ω) the
tangent vectors' volume would also carry ln det M(θ), a term of order ln(cond M)/T in a finite-time sum.
The elastic system's hooks take p = v, canonical up to the constant masses, which changes no volume ratio.

Each element of the kernel's loop is one tangent vector of one pendulum: its seed is that vector (set as
the input field's duals) and the primal restarts every frame from the system's state: 2D dual frames per
pendulum per frame, in one launch (cost measured in render/trust/lyapunov.py).

Taichi 1.7.4 limits, measured: its forward mode rejects the inline sin/cos of render/physics/sincos.py (integer
quadrant and select) and the matrix-typed locals unless the kernel is compiled with force_scalarize_matrix
(set only while this kernel compiles and runs); so the tangent kernel runs a twin of the system with
libm's sin/cos (derivative cos, exactly), which differs from the primal's inline ones by an ulp. The
implicit midpoint's data-dependent `break` is not differentiable there either: it is refused.
"""

import contextlib

import numpy as np
import taichi as ti

from . import integrators, registry, steps
from ..errors import SceneError


def check_method(scene):
    """Refuse (bad input) a scene whose integrator the tangent kernel cannot differentiate."""
    method = scene.integrator.method
    why = integrators.METHOD[method].no_tangent
    if why:
        others = [m for m in registry.get(scene.system).METHODS if not integrators.METHOD[m].no_tangent]
        raise SceneError(f"{scene.source}: integrator.method: {method}: no tangent map: {why}; "
                         f"use --set integrator.method=rk4 (or another of {', '.join(others)})")


def libm_twin(sim):
    """The system's parameters with libm's sin/cos, which forward mode differentiates (no fields)."""
    twin = sim.scene.replace(integrator={"trig": "libm"})
    return registry.kernels(twin.system)(twin, subset=sim.subset, allocate=False)


@contextlib.contextmanager
def scalarized():
    """Compile (and run) with matrices scalarised, which Taichi's forward mode needs for matrix locals."""
    cfg = ti.lang.impl.current_cfg()
    saved = cfg.force_scalarize_matrix
    cfg.force_scalarize_matrix = True
    try:
        yield
    finally:
        cfg.force_scalarize_matrix = saved


@ti.data_oriented
class TangentFlow:
    def __init__(self, sim):
        check_method(sim.scene)
        self.sim = sim
        self.twin = libm_twin(sim)
        self.D, self.k = sim.D, 2 * sim.D
        self.m = sim.n * self.k  # one kernel element per tangent vector of each pendulum
        # dx: the input's offset (dq, dp), 0, whose duals are the seeds; out: the frame's end (q, p)
        self.dx = ti.Vector.field(self.k, ti.f64, shape=self.m, needs_dual=True)
        self.out = ti.Vector.field(self.k, ti.f64, shape=self.m, needs_dual=True)
        self.loss = ti.field(ti.f64, shape=(), needs_dual=True)  # FwdMode's required (unused) loss and param:
        self.unit = ti.field(ti.f64, shape=(), needs_dual=True)  # the seeds are dx's duals, set per element

    @ti.kernel
    def map_frame(self, sys: ti.template(), substeps: ti.i32, h: ti.f64):
        """One frame from the system's state, in (q, p), offset by dx (0): the duals carry the tangent vectors."""
        D = ti.static(self.D)
        for e in range(self.m):
            i = e // self.k
            dx = self.dx[e]
            q0 = ti.Matrix.cols([self.sim.q[i]])
            p = sys.momenta(q0, ti.Matrix.cols([self.sim.v[i]])) + ti.Matrix.cols([dx[D:]])
            q = q0 + ti.Matrix.cols([dx[:D]])
            v = sys.velocities(q, p)
            for _ in range(substeps):
                q, v = steps.step(sys, q, v, h)
            p = sys.momenta(q, v)
            self.out[e] = ti.Vector([q[c, 0] for c in ti.static(range(D))] + [p[c, 0] for c in ti.static(range(D))])

    def frame(self, basis: np.ndarray) -> np.ndarray:
        """The images under one frame of the numerical flow of `basis` (n, 2D, k): k tangent vectors per
        pendulum in canonical (dq, dp) at the system's current state. Call before the system advances."""
        n, dim, k = basis.shape
        seeds = basis.transpose(0, 2, 1).reshape(n * k, dim)  # element e = pendulum e // k, vector e % k
        self.dx.dual.from_numpy(seeds)
        self.out.dual.fill(0)  # forward mode adds into the output's duals
        with scalarized(), ti.ad.FwdMode(loss=self.loss, param=self.unit, seed=[1.0], clear_gradients=False):
            self.map_frame(self.twin, self.sim.substeps, self.sim.h)
        return self.out.dual.to_numpy().reshape(n, k, dim).transpose(0, 2, 1)
