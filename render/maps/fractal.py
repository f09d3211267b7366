"""Fractal maps: one pendulum per pixel of a plot of two start quantities (θ1 × θ2 unless [map] x and y say
otherwise: render/physics/grid.py), coloured by what it does.

The preset key `fractal` picks the colouring:
- **angles**: the pixel's current angles as a colour (R sin θ1, G sin θ2, B cos(θ1 + θ2));
- **flip_time**: the first time |θ1| or |θ2| (any link of the chain) passes π, on a log time scale;
- **divergence**: the first time the pixel and its twin, started map.epsilon further on the last link, are
  map.threshold apart in (θ1, θ2, ω1, ω2) (Euclidean, rad and rad/s); while they are still together,
  their distance on a log scale in grey.

Events are found at every substep (linearly interpolated within it), not at frame times, and a pixel whose
event has happened is no longer integrated: its colour is settled. Pixels are advanced by the system's own
integrator (steps.step on the system's force, lane matrices as in System.advance): no physics here.

**Which pixels cannot flip.** With angles from the hanging position, bob i at height −Σ_{j≤i} l_j cos θ_j and
μ_k = m_k + ... + m_n the mass at or below link k, the potential energy (zero hanging at rest) is

    V(θ) = g Σ_k μ_k l_k (1 − cos θ_k),

a sum of one term per link. On the set where link k points straight up (θ_k = ±π) it is least with every
other link hanging, where it is B_k = 2 g μ_k l_k. Energy never grows (damping only removes it) and kinetic
energy is not negative, so a pendulum with E < B_k can never bring link k over the top, and one with
E < B = min_k B_k flips no link at all: it is black from the first frame and never integrated. E is each
start's full energy (fractal_setup: kinetic too, so the claim holds with rates on the axes); from rest,
E = V(θ(0)); for two links of equal unit masses and lengths, B = 2g and the condition is 2 cos θ1 + cos θ2
> 1. The bound is tight: the state with link k up and the others hanging, at rest, has E = B_k exactly, so
no smaller barrier holds (tests/test_fractal.py: a DOP853 run flips no pixel inside it, and starts just
above B_k with link k just short of the top do flip).

**The trust mask.** A pixel shows a claim about its trajectory up to min(t, its event time). The
certificate (render/trust/certify.py) runs on a lattice of pixels (grid.trust_indices) instead of a fan's evenly spaced
pendulums, and each pixel's faithful time is the least of its lattice neighbours' (grid.faithful_map). A
pixel whose claim reaches past that time is drawn desaturated and hatched. Pixels that cannot flip are
trusted: energy, not the integration, settles them.

**Samples and data.** With map.samples = 4 or 9 a pixel is 4 or 9 sub-pixel starts (grid.sample_starts), the
map's *points*: each is its own pendulum (with its own twin), with its own event and its own claim against
the pixel's faithful time, and the pixel shows their colours' mean in linear light (render/maps/supersample.py).
With one sample, a point is its pixel. result() hands each point's value, claim and cannot-flip mask to the
map's NAME.npz (render/maps/data.py).
"""

import math

import numpy as np
import taichi as ti

from .data import NEVER, PENDING  # the event field's "not happened (yet)" and "cannot happen"
from .paint import Painting
from ..physics import grid, runtime, steps
from ..draw.font import Font


def barriers(masses, lengths, g: float) -> list[float]:
    """B_k = 2 g μ_k l_k: the least energy (zero hanging at rest) with which link k can point straight up."""
    return [2.0 * g * sum(masses[k:]) * lengths[k] for k in range(len(lengths))]


def time_scale(duration: float) -> tuple[float, float]:
    """The log colour scale's range in s: from 0.1 s (or a quarter of a short video) to the end."""
    return min(0.1, duration / 4), duration


@ti.data_oriented
class Map(Painting, runtime.Launcher):
    """The map of a grid scene: it advances the system (events per substep) and draws every frame (Painting)."""

    def __init__(self, scene, sim, cert, rows: range | None = None):
        v, self.scene, self.sim, self.kind = scene.video, scene, sim, scene.fractal
        self.place(rows)
        self.twins = self.kind == "divergence"
        self.lanes = 2 if self.twins else 1  # pendulums per point: a pixel's, or a pixel's and its twin
        self.per_group = sim.chunk // self.lanes  # points per group of fractal_advance (a pair is never split)
        self.barrier = min(barriers(sim.masses, sim.lengths, sim.g))
        self.eps, self.threshold = scene.map.epsilon, scene.map.threshold
        self.lo, self.hi = time_scale(v.duration)
        self.log_lo, self.log_span = math.log(self.lo), math.log(self.hi / self.lo)
        self.log_ratio = math.log(self.threshold / self.eps)
        self.event = runtime.field("fractal.event", ti.f32, self.points)
        self.cannot = runtime.field("fractal.cannot_flip", ti.u8, self.points)  # E < B, whatever the colouring
        self.pending = runtime.field("fractal.pending", ti.i32, self.points)  # the points with an event ahead
        self.n_pending = runtime.field("fractal.n_pending", ti.i32, ())
        # divergence: each pair's distance where the advance left it, for the paint's grey. Both states read again
        # there were 64 bytes a pixel, which beside x264 cost: `pendulum render fractal_divergence` drew in 11.1
        # and 10.4 s that way, 6.8 and 6.7 s this way (alternating, metadata.json's timings); alone, in
        # `python benchmarks/map_frame.py fractal_divergence --seconds 2`, no difference showed (6.1-6.6 ms a frame)
        self.apart = runtime.field("fractal.apart", runtime.real(), self.points if self.twins else 1)
        self.until = self.faithful(cert)
        self.font = Font(self.lay.font) if self.lay.font else None
        self.background = self.decorate()
        # A pixel whose events are all in, or that cannot flip, keeps its colour from then on: an event map's
        # plot is kept between frames and only the pixels still pending, or settled since, are painted again.
        self.plot = np.zeros((self.h, self.w, 3), np.uint8) if self.kind != "angles" else None
        self.restart()

    def place(self, rows: range | None):
        """The plot, and the band of its rows this map integrates and colours: all of them, or one tile's
        (render/maps/tiles.py: the system then holds only the band's pendulums)."""
        self.lay = grid.plot(self.scene)
        self.rows = range(self.lay.h) if rows is None else rows
        self.w, self.h, self.r0 = self.lay.w, len(self.rows), self.rows.start
        self.pixels = self.w * self.h
        self.samples = self.scene.map.samples  # sub-pixel starts per pixel (render/maps/supersample.py)
        self.points = self.pixels * self.samples  # the starts: pixel p's samples are points p·samples + s

    def faithful(self, cert):
        """The band's per-pixel faithful times (grid.faithful_map), as a field."""
        until = runtime.field("fractal.faithful_until", ti.f32, self.pixels)
        band = grid.faithful_map(self.scene, cert.until_s)[self.rows.start:self.rows.stop]
        until.from_numpy(band.ravel().astype(np.float32))
        return until

    def restart(self):
        """Every event pending again (or never, below the barrier), from the system's current (initial) state."""
        self.launch("fractal_setup")
        self.painted = -math.inf  # the time the plot was painted at: every pixel is painted at the next draw

    # ------------------------------------------------------------ host side
    def advance(self, substeps: int, h: float):
        """One frame on, for the frame loop (render/physics/stepper.py, which keeps the clock): the angles map is
        the plain advance; the others stop each pixel at its event."""
        sim = self.sim
        if self.kind == "angles":
            sim.launch(f"{sim.NAME}_advance", substeps, h)
        else:
            self.launch("fractal_advance", substeps, h, sim.t)

    def arrays(self) -> dict:
        """The band's fields on the host at the current frame: per point `event`, `cannot` (and the angles
        map's `q`), per pixel `until`; result() and summary() read them, a tile's are joined row-wise
        (render/maps/tiles.py)."""
        a = {"event": self.event.to_numpy(), "cannot": self.cannot.to_numpy(), "until": self.until.to_numpy()}
        if self.kind == "angles":
            a["q"] = self.sim.q.to_numpy()
        return a

    def result(self) -> dict:
        return self.result_of(self.scene, self.arrays(), self.sim.t)

    def summary(self) -> dict:
        return self.summarise(self.scene, self.arrays(), self.sim.t)

    @staticmethod
    def result_of(scene, a: dict, t: float) -> dict:
        """Per point (pixels · samples, in the map's order) at time t, from arrays(), for the map's data
        (render/maps/data.py): `value`, what the colouring measures (the event time in s, PENDING or NEVER; the
        angles map: the links' angles, (points, links)); `claim`, how far along its trajectory the colour
        speaks for (the trust mask compares it with the pixel's faithful time); `cannot_flip`, E < B; per pixel
        `until`, its faithful time; and `t`."""
        ev, t32 = a["event"], np.float32(t)
        if scene.fractal == "angles":
            value, claim = a["q"], np.full(len(ev), t32)
        else:
            value, claim = ev, np.where(ev >= 0, ev, np.where(ev == NEVER, np.float32(0), t32))
        return {"value": value, "claim": claim, "cannot_flip": a["cannot"].astype(bool), "until": a["until"],
                "t": t}

    @staticmethod
    def summarise(scene, a: dict, t: float) -> dict:
        """For metadata.json: the plot, the lattice, and how many points (pixels, or their samples) had their
        event, trusted or not, at time t, from arrays() (a map's own, or its tiles' joined)."""
        ev, samples = a["event"], scene.map.samples
        until = np.repeat(a["until"], samples)
        done, pending = ev >= 0, ev == PENDING
        claim = np.where(done, ev, np.float32(t))
        lay, stride = grid.plot(scene), scene.map.trust_stride
        return {"colouring": scene.fractal, "plot": {"x": lay.x0, "y": lay.y0, "width": lay.w, "height": lay.h},
                "axes": grid.axes_summary(scene),
                "pixels": len(a["until"]), "samples": samples, "time_scale_s": list(time_scale(scene.video.duration)),
                "lattice": {"stride": stride, "pixels": len(grid.lattice_axis(lay.w, stride))
                            * len(grid.lattice_axis(lay.h, stride))},
                "cannot_flip": int((ev == NEVER).sum()), "events": int(done.sum()),
                "events_trusted": int((done & (claim <= until)).sum()), "pending": int(pending.sum()),
                "pending_trusted": int((pending & (claim <= until)).sum())}

    # ------------------------------------------------------------ kernels
    @ti.kernel
    def fractal_setup(self):
        for j in range(self.points):
            i = j * self.lanes  # the point's own pendulum, not its twin
            below = self.sim.energy(self.sim.q[i], self.sim.v[i]) < self.barrier
            self.cannot[j] = ti.cast(below, ti.u8)
            self.event[j] = PENDING
            if ti.static(self.twins):
                self.apart[j] = ti.sqrt((self.sim.q[i] - self.sim.q[i + 1]).norm_sqr()
                                        + (self.sim.v[i] - self.sim.v[i + 1]).norm_sqr())
            if ti.static(self.kind == "flip_time"):
                if below:
                    self.event[j] = NEVER

    @ti.kernel
    def fractal_advance(self, substeps: ti.i32, h: float, t0: float):
        """Every point with an event ahead, `substeps` steps of h on, recording events as they happen.

        The points still pending are listed first, in order, and stepped in groups of `chunk` pendulums from
        that list: at the end of the 20 s flip map 7 % of the points are pending, but they are spread over a
        quarter of the map's fixed groups of neighbours, which stepped 3.5 times the pendulums that needed it.
        A group is stepped as System.advance steps it: its state in local D × chunk matrices, each substep a
        loop over their columns that LLVM vectorises, with the same instructions for every column, so that no
        pendulum's bits depend on the column or the group it is stepped in (frames stay byte-identical at any
        thread count). The events are found in a loop of their own, so that their branches leave the step's SIMD. A
        pendulum whose event is in is stepped on with its group but put back where its event left it, and the
        group stops as soon as all of its events are in. A pixel and its twin are neighbouring columns, and
        stop together when they part."""
        sim = self.sim
        B = ti.static(self.sim.chunk)
        L = ti.static(self.lanes)
        P = ti.static(self.per_group)
        S = ti.static(runtime.SPREAD)
        n = 0
        ti.loop_config(serialize=True)  # the list in point order: a cheap pass next to the stepping
        for j in range(self.points):
            if self.event[j] == PENDING:
                self.pending[n] = j
                n += 1
        self.n_pending[None] = n
        for t in range((self.n_pending[None] + P - 1) // P * S):  # see runtime.SPREAD
            if t % S == 0:
                g = t // S
                on = ti.Vector.zero(ti.i32, B)  # 1 while the column's event is ahead: it is stepped on
                Q, V = ti.Matrix.zero(float, sim.D, B), ti.Matrix.zero(float, sim.D, B)
                for k in range(P):  # a column past the list's end steps a copy of its last point, and is not kept
                    kk = g * P + k
                    j = self.pending[ti.min(kk, self.n_pending[None] - 1)]
                    for m in ti.static(range(L)):
                        Q[:, k * L + m], V[:, k * L + m] = sim.q[j * L + m], sim.v[j * L + m]
                    if kk < self.n_pending[None]:
                        for m in ti.static(range(L)):
                            on[k * L + m] = 1
                near = ti.Vector.zero(float, P)  # divergence: each pair's distance at the start of the substep
                if ti.static(self.twins):  # unrolled, as below
                    for k in ti.static(range(P)):
                        near[k] = self.distance(Q, V, k * L)
                for s in range(substeps):
                    Q0, V0 = Q, V
                    for lane in range(B):  # the loop LLVM vectorises
                        q, v = steps.step(sim, ti.Matrix.cols([Q[:, lane]]), ti.Matrix.cols([V[:, lane]]), h)
                        Q[:, lane], V[:, lane] = q[:, 0], v[:, 0]
                    far = near  # and at its end: once per substep (the next one starts from it), apart from the
                    # events' branches. The P pairs' loop unrolled took a 720p frame from 69 to 65 ms at
                    # vector_width's 16 lanes, 102 to 95 ms at LLVM's own width (AVX-512 Xeon; python
                    # benchmarks/map_frame.py fractal_divergence --seconds 1.5, interleaved pairs)
                    if ti.static(self.twins):
                        for k in ti.static(range(P)):
                            far[k] = self.distance(Q, V, k * L)
                    live = 0
                    for k in range(P):  # a point: a pixel, or a pixel and its twin (columns lane, lane + 1)
                        lane = k * L
                        if on[lane]:
                            live = 1
                            j = self.pending[g * P + k]
                            if self.events(j, Q0, Q, lane, near[k], far[k], t0 + s * h, h):
                                for m in ti.static(range(L)):
                                    on[lane + m] = 0
                        else:
                            for m in ti.static(range(L)):
                                Q[:, lane + m], V[:, lane + m] = Q0[:, lane + m], V0[:, lane + m]
                    near = far
                    if not live:
                        break
                for k in range(P):
                    kk = g * P + k
                    if kk < self.n_pending[None]:
                        j = self.pending[kk]
                        for m in ti.static(range(L)):
                            i = j * L + m
                            sim.q[i], sim.v[i] = Q[:, k * L + m], V[:, k * L + m]
                            sim.watch(i, Q[:, k * L + m], V[:, k * L + m])
                        if ti.static(self.twins):
                            self.apart[j] = near[k]

    @ti.func
    def events(self, j, q, q1, lane, d0, d1, t, h):
        """Point j's event (column `lane`) within the step from angles q at t to q1 at t + h (a divergence
        map's: its pair's distances d0 to d1), recorded at its interpolated time; whether it happened."""
        frac = 2.0
        if ti.static(self.twins):
            if d1 > self.threshold:
                frac = ti.max(0.0, (self.threshold - d0) / (d1 - d0))
        else:
            for k in ti.static(range(self.sim.D)):
                a, b = ti.abs(q[k, lane]), ti.abs(q1[k, lane])
                if b > math.pi and a <= math.pi:
                    frac = ti.min(frac, (math.pi - a) / (b - a))
        if frac <= 1.0:
            self.event[j] = t + frac * h
        return frac <= 1.0

    @ti.func
    def distance(self, q, v, lane):
        """|(θ, ω) of pendulum `lane` − those of its twin `lane` + 1|."""
        return ti.sqrt((q[:, lane] - q[:, lane + 1]).norm_sqr() + (v[:, lane] - v[:, lane + 1]).norm_sqr())
