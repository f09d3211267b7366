"""The FTLE map (`fractal = "lyapunov"`): each pixel's finite-time Lyapunov exponent, live as t grows,

    σ_t = (1/t) · ln s_max(DΦ(t)),

DΦ(t) the 4×4 Jacobian of the numerical flow from t = 0 in the pixel's state (θ1, θ2, ω1, ω2) (rad, rad/s:
the coordinates the divergence map measures distance in; a triple pendulum's map: 6×6), s_max its largest
singular value; σ in 1/s.

**The tangent map, exactly.** Every pixel carries four tangent vectors, the columns of M = DΦ(t)·e^{−L}
(M = I at t = 0). Each frame, one kernel runs the scene's own integrator over the system's own force through
the frame with the pixel's state as a forward-mode Dual (render/physics/dual.py) whose four tangents are M's
columns: its value is the pixel's new state, the very steps the plain advance takes (the same bits), and its
tangents are DΦ_frame·M to round-off (not a finite difference, and no physics written here). Then M is divided
by its largest entry m and L += ln m, which keeps it finite for any t; nothing else is done to it. No QR: the
columns are left to align with the stretching direction, which loses the smaller singular values to round-off
but not the largest, since s_max is well conditioned (|s_max(M + E) − s_max(M)| ≤ |E|), so ln s_max(DΦ(t)) = L +
ln s_max(M) is the finite-t value, not the asymptotic rate a renormalised basis would give.

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

**Cost.** The points go through the frame in the system's groups, in the loop System.advance_group vectorises,
with the scene's own sin and cos (inline, render/physics/sincos.py, unless it pins libm). At 720p (381,924
points, 17 RK4 substeps) a frame's simulation took 2.13 s when each tangent was a lane of Taichi's forward mode
through a libm twin of the system, and 0.18 s this way (`python benchmarks/map_frame.py fractal_lyapunov
--seconds 0.2`, 2-core Xeon, AVX-512, 2026-12-06). Its drawing, σ of every point (FtleMap.ftle_sigma) then the
colours, took 0.035 s.
"""

import numpy as np
import taichi as ti

from . import colours, fractal, supersample
from ..physics import dual, grid, runtime, steps
from ..draw.font import Font
from ..physics.tangent import check_method

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
        self.k, real = 2 * sim.D, runtime.real()  # tangent vectors per point: the state's dimension (4 for rigid)
        self.tan = runtime.field("ftle.tangents", real, (self.points, self.k), self.k)  # M's columns
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
        self.launch("ftle_frame", substeps, h)

    def tangents(self) -> tuple[np.ndarray, np.ndarray]:
        """(M, L): per pixel the k×k matrix M (column k: the image of unit vector k) and L, DΦ(t) = M·e^L."""
        m = self.tan.to_numpy().astype(np.float64).reshape(self.pixels, self.k, -1).transpose(0, 2, 1)
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
        for p, k in self.tan:
            self.tan[p, k] = ti.Vector.unit(self.k, k, float)
        for p in range(self.points):
            self.log_scale[p], self.sigma[p] = 0.0, 0.0

    @ti.kernel
    def ftle_frame(self, substeps: ti.i32, h: float):
        """One frame of every point and its tangent vectors, in the system's groups (System.advance's loop)."""
        S = ti.static(runtime.SPREAD)
        for t in range(self.sim.groups * S):
            if t % S == 0:
                self.frame_group(t // S, substeps, h)

    @ti.func
    def frame_group(self, g, substeps, h):
        """Group g's points through one frame, each with its K tangent vectors as a Dual's tangents (see the
        module's docstring): the loop over lanes is System.advance_group's, which LLVM vectorises. Then each
        point's new state, and M = the images over their largest entry m, L += ln m."""
        sim = self.sim
        B, D, K = ti.static(sim.chunk, sim.D, self.k)
        Q, V = ti.Matrix.zero(float, D, B), ti.Matrix.zero(float, D, B)
        TQ, TV = ti.Matrix.zero(float, K * D, B), ti.Matrix.zero(float, K * D, B)  # row k·D + c: column k's
        for lane in range(B):
            p = ti.min(g * B + lane, sim.n - 1)
            Q[:, lane], V[:, lane] = sim.q[p], sim.v[p]
            for k in ti.static(range(K)):
                m = self.tan[p, k]
                for c in ti.static(range(D)):
                    TQ[k * D + c, lane], TV[k * D + c, lane] = m[c], m[D + c]
        for _ in range(substeps):
            for lane in range(B):  # the loop LLVM vectorises
                q = dual.Dual(ti.Matrix.cols([Q[:, lane]]), [ti.Matrix.cols([ti.Vector(
                    [TQ[k * D + c, lane] for c in ti.static(range(D))])]) for k in ti.static(range(K))])
                v = dual.Dual(ti.Matrix.cols([V[:, lane]]), [ti.Matrix.cols([ti.Vector(
                    [TV[k * D + c, lane] for c in ti.static(range(D))])]) for k in ti.static(range(K))])
                q, v = steps.step(sim, q, v, h)
                Q[:, lane], V[:, lane] = q.v[:, 0], v.v[:, 0]
                for k in ti.static(range(K)):
                    for c in ti.static(range(D)):
                        TQ[k * D + c, lane], TV[k * D + c, lane] = q.d[k][c, 0], v.d[k][c, 0]
        for lane in range(B):
            p = g * B + lane
            if p < sim.n:
                m = ti.max(ti.abs(TQ[:, lane]).max(), ti.abs(TV[:, lane]).max())
                ok = m > 0.0 and m < 1e30  # also NaN
                if ok:
                    for k in ti.static(range(K)):
                        self.tan[p, k] = ti.Vector([TQ[k * D + c, lane] for c in ti.static(range(D))]
                                                   + [TV[k * D + c, lane] for c in ti.static(range(D))]) / m
                    self.log_scale[p] += ti.log(m)
                sim.q[p], sim.v[p] = Q[:, lane], V[:, lane]
                state = ti.Vector([Q[c, lane] for c in ti.static(range(D))] + [V[c, lane] for c in ti.static(range(D))])
                sim.watch(p, state, ti.Vector([m, 1.0 / m]))  # a degenerate M (m = 0, 1/m = inf) too: σ is lost

    def draw(self, out=None, t=None):
        """σ_t of every point, then the map painted from it (paint.py)."""
        self.launch("ftle_sigma", self.sim.t)
        return super().draw(out, t)

    @ti.kernel
    def ftle_sigma(self, t: ti.f32):
        """σ_t of every point into sigma, before the colours are painted from it: in the system's groups, the
        lanes' MᵀM squared in loops LLVM vectorises (as System.advance_group's), their logarithm (a libm call)
        after them. The same bits as when each pixel's colour worked out its own σ, serially (fractal_lyapunov,
        its first 3 s at 640×360: σ, the last frame, the MP4 and the GIF compared), and a 720p frame's drawing
        91.4 → 34.9 ms (`python benchmarks/map_frame.py fractal_lyapunov --seconds 0.2`, 2-core Xeon, AVX-512)."""
        S = ti.static(runtime.SPREAD)
        for g in range(self.sim.groups * S):
            if g % S == 0:
                self.sigma_group(g // S, t)

    @ti.func
    def sigma_group(self, g, t):
        """σ_t of group g's points: each step a loop over the lanes with no call and no store to a field, the
        innermost loop, which LLVM vectorises. Unrolling the squarings in one lane loop drew a 720p frame in 22 ms
        instead of 34, but its first frame from an empty kernel cache took 6.4 s instead of 1.1 (a script not
        kept)."""
        B, n, K = ti.static(self.sim.chunk, self.sim.n, self.k)
        b, c = ti.Matrix.zero(float, K * K, B), ti.Matrix.zero(float, K * K, B)  # MᵀM and its powers, row-major
        for lane in range(B):
            m = ti.Matrix.cols([self.tan[ti.min(g * B + lane, n - 1), k] for k in ti.static(range(K))])
            mm = m.transpose() @ m
            b[:, lane] = ti.Vector([mm[i, j] for i, j in ti.static(ti.ndrange(K, K))])
            c[:, lane] = b[:, lane]
        for _ in range(SQUARINGS):
            for lane in range(B):
                x = ti.Matrix([[c[i * K + j, lane] for j in ti.static(range(K))] for i in ti.static(range(K))])
                x = x @ x
                x /= ti.abs(x).max()
                c[:, lane] = ti.Vector([x[i, j] for i, j in ti.static(ti.ndrange(K, K))])
        top = ti.Vector.zero(float, B)  # λ_max(MᵀM) of each lane
        for lane in range(B):
            top[lane] = self.rayleigh(b[:, lane], c[:, lane])
        for lane in range(B):
            j = g * B + lane
            if j < n:
                s = 0.0
                if t > 0.0:
                    s = (self.log_scale[j] + 0.5 * ti.log(top[lane])) / t  # ln s_max(M) = ½ ln λ_max(MᵀM)
                self.sigma[j] = s

    @ti.func
    def rayleigh(self, b, c):
        """λ_max(MᵀM) = s_max(M)² (see the module's docstring), from b = MᵀM and c = (MᵀM)^1024 normalised, both
        row-major: the Rayleigh quotient of c's column with the largest norm (the first such on a tie)."""
        K = ti.static(self.k)
        best, x = 0.0, ti.Vector.zero(float, K)
        for k in ti.static(range(K)):
            col = ti.Vector([c[i * K + k] for i in ti.static(range(K))])
            n = col.norm_sqr()
            better = n > best
            best, x = ti.select(better, n, best), ti.select(better, col, x)
        bm = ti.Matrix([[b[i * K + j] for j in ti.static(range(K))] for i in ti.static(range(K))])
        return x.dot(bm @ x) / x.norm_sqr()

    @ti.func
    def point_colour(self, j, p, t, c, r):
        """Point j's colour (of pixel p, at column c and row r), from its σ_t (ftle_sigma)."""
        s = self.sigma[j]
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
