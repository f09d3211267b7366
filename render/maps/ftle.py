"""The FTLE map (`fractal = "lyapunov"`): each pixel's finite-time Lyapunov exponent, live as t grows,

    σ_t = (1/t) · ln s_max(DΦ(t)),

DΦ(t) the 4×4 Jacobian of the numerical flow from t = 0 in the pixel's state (θ1, θ2, ω1, ω2) (rad, rad/s:
the coordinates the divergence map measures distance in; a triple pendulum's map: 6×6), s_max its largest
singular value; σ in 1/s.

**The tangent map, exactly.** Every pixel carries four tangent vectors, the columns of M = DΦ(t)·e^{−L}
(M = I at t = 0). Each frame, one forward-mode kernel (ti.ad.FwdMode, as in render/physics/tangent.py) runs the
scene's own integrator over the system's own force through the frame, once per column: the four columns
are four lanes of the same loop, each the pixel's state with that column as its dual, so the duals that come
out are DΦ_frame·M to round-off (not a finite difference, and no physics written here). Lane 0's primal
is the pixel's new state. Then M is divided by its largest entry m and L += ln m, which keeps it finite for
any t; nothing else is done to it. No QR: the columns are left to align with the stretching direction, which
loses the smaller singular values to round-off but not the largest, since s_max is well conditioned
(|s_max(M + E) − s_max(M)| ≤ |E|), so ln s_max(DΦ(t)) = L + ln s_max(M) is the finite-t value, not the
asymptotic rate a renormalised basis would give.

**s_max per pixel.** s_max(M)² = λ_max(MᵀM): MᵀM is squared ten times (normalised each time), so that a
column of it points along the top eigenvector but for a part (λ2/λ1)^1024, and that column's Rayleigh
quotient is λ_max to a relative 2e-4 at worst (near-equal eigenvalues, whose mixing then hardly matters):
far inside a colour step, and tests/test_ftle.py checks it against numpy's SVD.

**What is drawn.** σ on a linear scale, 0 (dark blue) to SIGMA_MAX 1/s (yellow), negative σ (damping) as 0;
the colour bar is in 1/s. The energy barrier (render/maps/fractal.py: a pendulum with E < B cannot flip any link)
is the black curve E(θ1, θ2) = B: the pixels inside it next to one outside. Inside, the motion is bounded
away from the top, and σ is still measured there, not blacked out (it is mostly small: regular motion).
The trust mask is the other maps': every pixel claims its trajectory up to t, and is desaturated and
hatched past the faithful time of its lattice neighbours. With map.samples = 4 or 9 each sample (point) carries
its own tangent vectors and σ, the barrier's curve is found on the samples' own finer grid (a sample on it is
black), and a pixel shows its samples' colours averaged as render/maps/paint.py paints every map.

**Trig.** Taichi's forward mode cannot differentiate render/physics/sincos.py's inline sin/cos, so the tangent
kernel steps a libm twin of the system (tangent.libm_twin) and its primal is the map's state. The preset
runs in f64, where libm's sin/cos and the inline ones the certificate checks differ by about an ulp (far
below its tolerance), and where libm's last bits, which differ between CPUs, do not grow into a different
picture within the video as they would in a chaotic f32 map (docs/numerics.md). libm calls do not
vectorise, and each lane carries a dual beside its primal: a frame costs 10 to 20 times the plain
vectorised advance of the same pixels (measured on the shared 2-core machine, indicative only: 3 to 5 s a
frame at 720p, 17 substeps), far from video speed; a forward mode through a differentiable inline sin/cos
in the vectorised loop is the way to close that gap.
"""

import numpy as np
import taichi as ti

from . import colours, fractal, supersample
from ..physics import grid, runtime, steps
from ..draw.font import Font
from ..physics.tangent import check_method, libm_twin, scalarized

SIGMA_MAX = 2.0  # 1/s: the top of the colour scale
SQUARINGS = 10  # of MᵀM, for its top eigenvector


@ti.data_oriented
class FtleMap(fractal.Map):
    """The FTLE map of a grid scene: it carries each pixel's tangent vectors through every frame and draws σ_t."""

    COLOUR = "ftle_colour"

    def __init__(self, scene, sim, cert, rows: range | None = None):
        check_method(scene)
        self.scene, self.sim, self.kind = scene, sim, scene.fractal
        self.place(rows)  # one pendulum per point: pixel p's samples are p·samples + s
        self.lo, self.hi = 0.0, SIGMA_MAX  # the colour scale, in 1/s
        self.eps, self.log_ratio = scene.map.epsilon, 1.0  # Map.fractal_swatch compiles its distance branch too
        self.twin = libm_twin(sim)
        self.k = 2 * sim.D  # tangent vectors per pixel: the state's dimension (4 for the double pendulum)
        real, n, D = runtime.real(), self.k * self.points, self.k  # one kernel element per tangent vector
        # dx: a zero offset to the state, whose duals are the columns of M; out: the frame's end and its duals
        self.dx = ti.Vector.field(D, real, shape=n, needs_dual=True)
        self.out = ti.Vector.field(D, real, shape=n, needs_dual=True)
        runtime.allocated["ftle.tangents"] = 4 * n * D * (8 if real == ti.f64 else 4)  # the two and their duals
        self.loss = ti.field(real, shape=(), needs_dual=True)  # FwdMode's required (unused) loss and param:
        self.unit = ti.field(real, shape=(), needs_dual=True)  # the seeds are dx's duals, set per element
        self.log_scale = runtime.field("ftle.log_scale", real, self.points)  # L
        self.sigma = runtime.field("ftle.sigma", real, self.points)  # σ_t as last drawn
        self.edge = runtime.field("ftle.barrier", ti.u8, self.points)
        self.until = self.faithful(cert)
        self.barrier = min(fractal.barriers(sim.masses, sim.lengths, sim.g))
        self.edge.from_numpy(self.barrier_curve())
        self.font = Font(self.lay.font) if self.lay.font else None
        self.background = self.decorate()
        self.restart()

    def barrier_curve(self) -> np.ndarray:
        """Per point, 1 where E < B and a 4-neighbour has E ≥ B: the barrier's curve, on its inner side, on the
        samples' own grid (render/maps/supersample.py), so that supersampling draws it finer, not wider."""
        self.launch("ftle_energy")
        self.inside = self.sigma.to_numpy() < self.barrier  # the cannot-flip mask, for the map's data
        inside = supersample.fine_grid(self.inside, self.h, self.w, self.samples)
        out = np.zeros_like(inside)
        out[1:] |= ~inside[:-1]
        out[:-1] |= ~inside[1:]
        out[:, 1:] |= ~inside[:, :-1]
        out[:, :-1] |= ~inside[:, 1:]
        return supersample.coarse(inside & out, self.h, self.w, self.samples).astype(np.uint8)

    def restart(self):
        """M = I and L = 0 at every pixel, from the system's current (initial) state."""
        self.launch("ftle_setup")

    def advance(self, substeps: int, h: float):
        """One frame on, for the frame loop (render/physics/stepper.py, which keeps the clock)."""
        self.out.dual.fill(0)  # forward mode adds into the output's duals
        with scalarized(), ti.ad.FwdMode(loss=self.loss, param=self.unit, seed=[1.0], clear_gradients=False):
            self.launch("ftle_frame", self.twin, substeps, h)
        self.launch("ftle_renormalise")

    def tangents(self) -> tuple[np.ndarray, np.ndarray]:
        """(M, L): per pixel the k×k matrix M (column k: the image of unit vector k) and L, DΦ(t) = M·e^L."""
        m = self.dx.dual.to_numpy().astype(np.float64).reshape(self.pixels, self.k, -1).transpose(0, 2, 1)
        return m, self.log_scale.to_numpy().astype(np.float64)

    def arrays(self) -> dict:
        """The band's fields on the host (fractal.Map.arrays): per point `sigma`, `inside` (E < B) and `edge`,
        per pixel `until`."""
        return {"sigma": self.sigma.to_numpy(), "inside": self.inside.copy(), "edge": self.edge.to_numpy(),
                "until": self.until.to_numpy()}

    @staticmethod
    def result_of(scene, a: dict, t: float) -> dict:
        """Per point at time t, as fractal.Map.result_of(): σ_t in 1/s as last drawn; every point claims its
        trajectory up to t."""
        return {"value": a["sigma"], "claim": np.full(len(a["sigma"]), np.float32(t)), "cannot_flip": a["inside"],
                "until": a["until"], "t": t}

    @staticmethod
    def summarise(scene, a: dict, t: float) -> dict:
        """For metadata.json: the plot, the lattice, σ's spread (over points) and how many pixels are trusted at
        time t, from arrays() (fractal.Map.summarise)."""
        sig, until = a["sigma"], a["until"]
        trusted = np.float32(t) <= until
        lay, stride = grid.plot(scene), scene.map.trust_stride
        q = np.percentile(sig, [5, 50, 95]).tolist() if t > 0 else [0.0] * 3
        return {"colouring": scene.fractal, "plot": {"x": lay.x0, "y": lay.y0, "width": lay.w, "height": lay.h},
                "axes": grid.axes_summary(scene),
                "pixels": len(until), "samples": scene.map.samples, "sigma_scale_per_s": [0.0, SIGMA_MAX],
                "lattice": {"stride": stride, "pixels": len(grid.lattice_axis(lay.w, stride))
                            * len(grid.lattice_axis(lay.h, stride))},
                "t_s": t, "sigma_percentiles_5_50_95_per_s": q, "trusted": int(trusted.sum()),
                "barrier_pixels": int(a["edge"].sum())}

    # ------------------------------------------------------------ kernels
    @ti.kernel
    def ftle_energy(self):
        """Each pixel's energy, into sigma for now (barrier_curve reads it once)."""
        for j in range(self.points):
            self.sigma[j] = self.sim.energy(self.sim.q[j], self.sim.v[j])

    @ti.kernel
    def ftle_setup(self):
        for e in range(self.k * self.points):
            self.dx[e] = ti.Vector.zero(float, self.k)
            self.dx.dual[e] = ti.Vector.unit(self.k, e % self.k, float)
        for j in range(self.points):
            self.log_scale[j], self.sigma[j] = 0.0, 0.0

    @ti.kernel
    def ftle_frame(self, sys: ti.template(), substeps: ti.i32, h: float):
        """One frame of every point, four times: lane e % k with column e % k of its M as the state's dual."""
        D = ti.static(self.sim.D)
        for e in range(self.k * self.points):
            p, d = e // self.k, self.dx[e]
            q = ti.Matrix.cols([self.sim.q[p] + ti.Vector([d[c] for c in ti.static(range(D))])])
            v = ti.Matrix.cols([self.sim.v[p] + ti.Vector([d[D + c] for c in ti.static(range(D))])])
            for _ in range(substeps):
                q, v = steps.step(sys, q, v, h)
            self.out[e] = ti.Vector([q[c, 0] for c in ti.static(range(D))] + [v[c, 0] for c in ti.static(range(D))])

    @ti.kernel
    def ftle_renormalise(self):
        """The new state (lane 0's primal), M = the frame's images over their largest entry m, L += ln m."""
        D, K = ti.static(self.sim.D, self.k)
        for p in range(self.points):
            m = 0.0
            for k in ti.static(range(K)):
                m = ti.max(m, ti.abs(self.out.dual[K * p + k]).max())
            ok = m > 0.0 and m < 1e30  # also NaN
            if ok:
                for k in ti.static(range(K)):
                    self.dx.dual[K * p + k] = self.out.dual[K * p + k] / m
                self.log_scale[p] += ti.log(m)
            x = self.out[K * p]
            self.sim.q[p] = ti.Vector([x[c] for c in ti.static(range(D))])
            self.sim.v[p] = ti.Vector([x[D + c] for c in ti.static(range(D))])
            self.sim.watch(p, x, ti.Vector([m, 1.0 / m]))  # a degenerate M (m = 0, 1/m = inf) too: σ is lost

    @ti.func
    def log_smax(self, p):
        """ln s_max(M) of point p: half the log of MᵀM's top eigenvalue (see the module's docstring)."""
        K = ti.static(self.k)
        m = ti.Matrix.cols([self.dx.dual[K * p + k] for k in ti.static(range(K))])
        b = m.transpose() @ m
        c = b
        for _ in range(SQUARINGS):
            c = c @ c
            c /= ti.abs(c).max()
        best, x = 0.0, ti.Vector.zero(float, K)
        for k in ti.static(range(K)):
            n = c[:, k].norm_sqr()
            if n > best:
                best, x = n, c[:, k]
        return 0.5 * ti.log(x.dot(b @ x) / x.norm_sqr())

    @ti.func
    def point_colour(self, j, p, t, c, r):
        """Point j's colour (of pixel p, at column c and row r), σ_t kept in sigma."""
        s = 0.0
        if t > 0.0:
            s = (self.log_scale[j] + self.log_smax(j)) / t
        self.sigma[j] = s
        col = colours.palette(s / SIGMA_MAX)
        if self.edge[j]:
            col = ti.Vector([0.0, 0.0, 0.0])
        if t > self.until[p]:
            col = colours.untrusted(col, c, r)
        return col

    @ti.func
    def bar_colour(self, u):
        """The colour bar's colour at u in [0, 1] (bottom to top): σ = u·SIGMA_MAX."""
        return colours.palette(u)

    @ti.kernel
    def ftle_colour(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), t: ti.f32):
        """σ_t of every pixel, on the linear scale (of each sample, their colours averaged in linear light); the
        barrier's curve black; past the faithful time, masked."""
        for r, c in ti.ndrange(self.h, self.w):
            col = self.pixel_colour(r * self.w + c, t, c, self.r0 + r)  # the whole plot's hatch, in any band
            for k in ti.static(range(3)):
                out[self.lay.y0 + self.r0 + r, self.lay.x0 + c, k] = ti.cast(ti.min(col[k], 1.0) * 255.0 + 0.5, ti.u8)
