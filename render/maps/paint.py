"""How a map is painted: its decorations once, then each frame the plot's pixels, each by what its points did
(the colourings and the trust mask of render/maps/fractal.py), and the legend's swatches in the same colours.

Painting is the map's half that draws: Map (fractal.py) and FtleMap (ftle.py) inherit it and set what it reads
(the scene and layout, the event and faithful-time fields, a divergence map's pair distances, the colour
scales). An event map (flip_time, divergence) keeps its plot between frames: a pixel whose points have all
settled, or cannot flip, keeps its colour, so only the pixels still pending, or settled since the last frame,
are painted again; at the end of a 20 s flip map, 7 % of them.
"""

import math

import numpy as np
import taichi as ti

from . import supersample
from .colours import PENDING_GREY, palette, sin8, untrusted
from .data import NEVER, PENDING
from ..draw import axes


@ti.data_oriented
class Painting:
    """The drawing side of a map (see the module's docstring)."""

    COLOUR = "fractal_colour"  # the kernel that paints the whole plot; a subclass's map names its own
    plot = None  # an event map's plot, kept between frames (Map.__init__); the others are painted whole each frame
    # The frame drawn into last (a render draws every frame into one): drawn into again, only the clock's rows
    # are put back, not the whole background (2.8 MB at 720p: 0.25 ms a frame, the best of timeit's rounds, so
    # 0.3 s of a 20 s map's 1200 frames)
    kept = None

    def new_frame(self) -> np.ndarray:
        return np.empty((self.lay.height, self.lay.width, 3), np.uint8)  # draw() writes every pixel

    def draw(self, out: np.ndarray | None = None, t: float | None = None) -> np.ndarray:
        """The map at the simulation's time (t, the canvas's clock argument, is the same and unused here)."""
        if out is None:
            out = self.new_frame()
        if out is not self.kept:
            np.copyto(out, self.background)
        elif self.font:  # drawn into last: outside the plot only the clock's rows differ from the background
            y = self.decor.clock[1]
            rows = slice(max(y, 0), max(y + self.font.text_height("t"), 0))
            out[rows] = self.background[rows]
        self.kept = out
        if self.plot is None:
            self.launch(self.COLOUR, out, self.sim.t)
        else:
            self.launch("fractal_repaint", self.plot, self.sim.t, self.painted)
            self.painted = self.sim.t
            y, x = self.lay.y0 + self.r0, self.lay.x0
            out[y:y + self.h, x:x + self.w] = self.plot
        if self.font:
            x, y = self.decor.clock
            self.font.draw(out, f"t = {self.sim.t:.2f} s", x, y, colour=axes.INK, ha="right")
        return out

    def decorate(self) -> np.ndarray:
        """The static parts of every frame: background, axes, labels, colour bar and legend."""
        sim, i = self.sim, self.scene.integrator
        self.decor = axes.decorate(self.scene, self.lay, (self.lo, self.hi),
                                   f"{i.method} dt={1e3 * sim.h:.3g} ms {i.precision}")
        bg = np.empty((self.lay.height, self.lay.width, 3), np.uint8)
        bg[:] = axes.BACKGROUND
        for x, y, w, h, rgb in self.decor.rects:
            bg[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = rgb
        for x, y, w, h, what in self.decor.swatches:
            self.launch("fractal_swatch", bg, x, y, w, h, SWATCHES.index(what))
        if self.font and self.decor.texts:
            self.font.draw_many(bg, [(s, x, y, {"colour": axes.INK, **kw}) for s, x, y, kw in self.decor.texts])
        return bg

    # ------------------------------------------------------------ kernels
    @ti.func
    def time_colour(self, t):
        """An event time on the log scale: early bright, late dark blue."""
        u = (ti.log(ti.max(t, self.lo)) - self.log_lo) / self.log_span
        return palette(1.0 - u)

    @ti.func
    def bar_colour(self, u):
        """The colour bar's colour at u in [0, 1] (bottom to top): time from lo to hi, log."""
        return self.time_colour(ti.exp(self.log_lo + u * self.log_span))

    @ti.func
    def together(self, d):
        """A pair's distance, ε to the threshold on a log scale, as a grey."""
        u = ti.log(ti.max(d, self.eps) / self.eps) / self.log_ratio
        g = 0.06 + 0.5 * ti.min(u, 1.0)
        return ti.Vector([g, g, g])

    @ti.kernel
    def fractal_colour(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), t: ti.f32):
        """Every pixel of the plot: its one sample's colour, or the mean of its samples' in linear light."""
        for r, c in ti.ndrange(self.h, self.w):
            col = self.pixel_colour(r * self.w + c, t, c, self.r0 + r)  # the whole plot's hatch, in any band
            put(out, self.lay.y0 + self.r0 + r, self.lay.x0 + c, col)

    @ti.kernel
    def fractal_repaint(self, plot: ti.types.ndarray(dtype=ti.u8, ndim=3), t: ti.f32, since: ti.f32):
        """An event map's plot (the band's h × w pixels) brought from its time `since` to t: the pixels with a
        point still pending, or whose event came at or after `since`, painted as fractal_colour paints them.
        The others are as they were: their claims (their event times, or 0 below the barrier) and so their
        colours and their hatch have not changed since they settled."""
        for r, c in ti.ndrange(self.h, self.w):
            p = r * self.w + c
            again = False
            for s in ti.static(range(self.samples)):
                ev = self.event[p * self.samples + s]
                again |= ev == PENDING or ev >= since
            if again:
                put(plot, r, c, self.pixel_colour(p, t, c, self.r0 + r))

    @ti.func
    def pixel_colour(self, p, t, c, r):
        """Pixel p's colour (column c, row r): its one point's, or the mean of its samples' in linear light."""
        col = ti.Vector([0.0, 0.0, 0.0])
        if ti.static(self.samples == 1):
            col = self.point_colour(p, p, t, c, r)
        else:
            for s in ti.static(range(self.samples)):
                col += supersample.linear(self.point_colour(p * self.samples + s, p, t, c, r))
            col = supersample.encode(col / self.samples)
        return col

    @ti.func
    def point_colour(self, j, p, t, c, r):
        """Point j's colour (of pixel p, at column c and row r): it claims its trajectory up to min(t, its
        event), trusted up to the pixel's faithful time."""
        ev = self.event[j]
        claim = t
        col = ti.Vector([0.0, 0.0, 0.0])
        if ti.static(self.kind == "angles"):
            q = self.sim.q[j]
            col = 0.5 + 0.5 * ti.Vector([sin8(q[0]), sin8(q[1]), sin8(q[0] + q[1] + 0.5 * math.pi)])
        else:
            if ev >= 0.0:
                col, claim = self.time_colour(ev), ev
            elif ev == NEVER:
                claim = 0.0  # settled by energy, not by the integration
            elif ti.static(self.twins):
                col = self.together(self.apart[j])  # the pair's distance, kept by the advance
            else:
                col = ti.Vector([PENDING_GREY] * 3)
        if claim > self.until[p]:
            col = untrusted(col, c, r)
        return col

    @ti.kernel
    def fractal_swatch(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), x0: ti.i32, y0: ti.i32, w: ti.i32,
                       h: ti.i32, what: ti.i32):
        """A legend's colour bar or swatch, drawn with the plot's own colours (SWATCHES names `what`)."""
        for r, c in ti.ndrange(h, w):
            u = 1.0 - (r + 0.5) / h  # 0 at the bottom, 1 at the top
            col = ti.Vector([0.0, 0.0, 0.0])
            if what == 0:  # the colour bar
                col = self.bar_colour(u)
            elif what == 1:  # distance while together: ε (bottom) to the threshold
                col = self.together(self.eps * ti.exp(u * self.log_ratio))
            elif what == 2:
                col = ti.Vector([PENDING_GREY] * 3)
            elif what == 3:  # untrusted: the mask over the time colours, left to right
                col = untrusted(palette(1.0 - (c + 0.5) / w), c, r)
            elif what == 4:  # angles: the colours of θ1 from −π to π with θ2 = 0
                th = math.pi * (2.0 * (c + 0.5) / w - 1.0)
                col = 0.5 + 0.5 * ti.Vector([sin8(th), 0.0, sin8(th + 0.5 * math.pi)])
            # what == 5: never, black
            y, x = y0 + r, x0 + c
            if 0 <= y < out.shape[0] and 0 <= x < out.shape[1]:
                put(out, y, x, col)


@ti.func
def put(out: ti.template(), y, x, col):
    """Colour col (linear 0..1 per channel, clipped at 1) as the bytes of pixel (y, x) of out."""
    for k in ti.static(range(3)):
        out[y, x, k] = ti.cast(ti.min(col[k], 1.0) * 255.0 + 0.5, ti.u8)


SWATCHES = ("time", "distance", "pending", "untrusted", "angles", "never")
