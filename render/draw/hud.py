"""The `hud` effect: what a viewer needs to read the video, drawn over each frame from the bundled font.

    top left      the simulated time, big; its colour turns amber once the first certified pendulum is no
                  longer faithful and red once half of them are not; under it the method, precision and dt
    top right     the certificate: until when all, and half, of the pendulums are faithful
    bottom left   the live spread of the fan: the largest distance between neighbouring pendulums' last bobs,
                  on a log scale over the whole video's time axis, drawn up to now; under it the timeline,
                  with ticks where the render stops being faithful (the same times as the top right; two
                  that would coincide are drawn a dark column apart), and under that its times: 0, each
                  tick's, the end
    bottom right  the caption: the preset's description, right-aligned, wrapped around the pendulums' view
                  (up to hud_text.MAX_LINES lines, then cut with an ellipsis)

In a split-screen panel (render/draw/split.py) the panel's label says the method, step, cost and error at the top,
so the HUD keeps the spread and the timeline and puts the clock where the caption was. Under glow (rainbow_1000,
where the picture is the point) it is minimal: the clock and the spread chart, no method, certificate or caption.

Where it draws is known before the first frame: every text at its widest (the font is monospaced) and the
chart are boxes (self.boxes), and the canvas fits the pendulums' view, everything they can ever reach, clear of
them (render/draw/framing.py). So the HUD never covers a pendulum, at any size or aspect ratio. Sizes follow the
frame's height (hud_text.faces()); at small sizes (under 360 px) the certificate's words and the axis labels are left
out and its ticks and the clock's colour carry it. Everything is clipped to the frame.

It draws into the finished uint8 frame, after the canvas composed it, so it is the same under max or glow
compositing. The text that never changes (the method, the step, the certificate, the caption, the axis labels)
is drawn once, when the HUD is made, into a cached layer of lit pixels. Per frame: one small kernel for the
spread (a max, order independent) and its history, and one that draws into the frame, every write a max:
the cached layer pixel by pixel, the clock and the spread's value glyph by glyph (a line's cells do not
overlap), the graph and the timeline column by column. Each pixel has one writer in each loop, so frames are
byte-identical at any thread count, whether the loops run in parallel or (at few threads) serially.

What it says beyond the drawing contract (the caption, the integrator, the certificate) comes in an Info,
from pipeline.Source; the clock comes with each draw(). How each block of text reads and where it goes is
render/draw/hud_text.py's (HudText, which the Hud inherits); here are the geometry, the layer and the kernels.
"""
import dataclasses
import math

import numpy as np
import taichi as ti

from ..physics import runtime
from . import framing
from .font import Font
from .hud_text import AMBER, CURVE, DIM, FAINT, LOG_HI, LOG_LO, RED, WHITE, HudText, faces, step

# Up to this many threads the HUD's loops run on the launching thread: they write a few thousand pixels, less
# work than waking the thread pool for each of them (rigid_chaos, 720p, 2 threads, a busy 2-core machine: 0.8 ms
# a frame so, 1.4 ms with the pool). Either way each pixel has one writer, so the bytes are the same.
SERIAL_MAX_THREADS = 4


@dataclasses.dataclass(frozen=True)
class Info:
    """What the HUD says that is not in the drawing contract."""
    caption: str
    method: str
    dt: float | str  # the step used (or "auto" when not known)
    precision: str
    faithful_until_s: float | None = None  # the certificate (render/trust/certify.py), if there is one
    median_until_s: float | None = None
    panel: bool = False  # a split-screen panel (render/draw/split.py): its label already says method, step and error
    one_line: bool = False  # under 360 px, still say the certificate, in one line (the GIF's HUD: render/video/gif.py)

    @classmethod
    def of(cls, scene, dt=None, cert=None, panel=False):
        i = scene.integrator
        return cls(scene.description, i.method, i.dt if dt is None else dt, i.precision,
                   None if cert is None else cert.faithful_until_s, None if cert is None else cert.median_until_s,
                   panel)


@ti.data_oriented
class Hud(HudText, runtime.Launcher):
    def __init__(self, scene, sim, info: Info, w: int, h: int, view=None):
        """view: the pendulums' nominal view (render/draw/framing.py's View), which the caption wraps around;
        the canvas then fits the view clear of every box in self.boxes."""
        self.sim, self.info, self.w, self.h = sim, info, w, h
        v = scene.video
        self.fps, self.duration, self.frames = v.fps, v.duration, scene.frames
        self.n, self.tip, self.reach = sim.n, len(sim.LINKS) - 1, sim.reach()
        self.fan = self.n > 1  # a spread needs neighbours
        self.minimal = scene.has("glow")  # where the look is the point: the clock and the chart, no prose
        (self.small, ss), (self.big, bs), (self.lab, ls) = faces(h)
        self.ss, self.bs, self.ls = ss, bs, ls
        self.words = h >= 360  # room for the certificate's words and the axis labels
        self.font = Font(self.small)
        self.serial = ti.lang.impl.current_cfg().cpu_max_num_threads <= SERIAL_MAX_THREADS
        m = self.m = max(3, round(0.016 * h))
        sh, bh, lh = self.cell(self.small, ss)[1], self.cell(self.big, bs)[1], self.cell(self.lab, ls)[1]
        self.th = max(1, h // 360)  # line thickness
        # the panel: the spread graph over the video's time axis, the timeline under it, its times under that
        self.gx0, self.gw = m, max(16, round(0.38 * h))
        self.gx1 = self.gx0 + self.gw
        self.gy1 = h - m - 1 - 3 * self.th - (lh + self.th if self.words else 0)
        self.gy0 = self.gy1 - (max(8, round(0.12 * h)) if self.fan else 0)
        self.value_at = (self.gx0, self.gy0 - max(2, m // 3) - sh)
        self.until = [(t, c) for t, c in ((info.faithful_until_s, AMBER), (info.median_until_s, RED))
                      if t is not None and t < self.duration]
        xs = [self.x_of(t) for t, _ in self.until]
        if len(xs) == 2 and xs[1] < xs[0] + 2 * self.th + 1:  # ticks that coincide: the later one just right of
            xs[1] = xs[0] + 2 * self.th + 1  # the other, with a dark column between (their labels say the times)
        self.ticks = tuple(xs) + (-1,) * (2 - len(xs))
        self.tick_colours = tuple(c for _, c in self.until) + (WHITE,) * (2 - len(self.until))
        self.tick_times = tuple(float(t) for t, _ in self.until) + (math.inf,) * (2 - len(self.until))
        chart = self.axis_labels() + self.time_labels()
        corners = [] if info.panel or self.minimal else [  # a panel's label says these; glow shows the picture
            self.text(f"{info.method} · {info.precision}", m, m + bh + m // 2),
            self.text(f"dt = {step(info.dt)} s", m, m + bh + m // 2 + sh)] + self.certificate()
        # what changes per frame, at its widest (the font is monospaced): the clock, the spread's value, the chart
        clock = [self.clock_rows(f"t = {max(self.duration, 10.0):5.2f} s", WHITE)]
        value = [self.value_rows(8.88e-3)] if self.fan else []
        graph = (self.gx0, self.gy0 - self.th, max([self.gx1] + [x + self.th - 1 for x in xs]), self.gy1 + 3 * self.th)
        caption = []
        if not (info.panel or self.minimal):  # the video's caption, not a panel's
            below = [framing.box_of(r) for r in chart + value] + [graph]
            above = [framing.box_of(r) for r in corners[2:]]  # the certificate, over the caption's column
            left = max(b[2] for b in below if b is not None) + 2 * m
            top = max([b[3] for b in above if b is not None] + [0]) + m
            caption = self.caption(" ".join(info.caption.split()), view, left, top)
        boxes = [framing.box_of(r) for r in chart + corners + clock + value + caption] + [graph]
        self.boxes = [b for b in boxes if b is not None]  # where the HUD draws: the view keeps clear of them
        rows = chart + corners + caption
        self.layer, self.lit = self.bake(rows)
        if self.fan:
            self.spread = runtime.field("hud.spread", runtime.real(), ())
            self.history = runtime.field("hud.history", ti.f32, max(self.frames, 1))

    # ------------------------------------------------------------ host-side: the baked text, the chart's scales
    def bake(self, rows: list):
        """The text that never changes, drawn once (by the font's kernel, in order) into a blank frame, as its
        lit pixels: y, x, r, g, b, for hud_draw to max into every frame. Returns the field and how many."""
        img = np.zeros((self.h, self.w, 3), np.uint8)
        if rows:
            self.font.draw_glyphs(img, np.concatenate(rows))
        y, x = np.nonzero(img.any(2))
        pixels = np.column_stack([y, x, img[y, x]]).astype(np.int32)
        layer = runtime.field("hud.layer", ti.i32, (max(len(y), 1), 5))  # a field has at least one row
        layer.from_numpy(pixels if len(y) else np.zeros((1, 5), np.int32))
        return layer, len(y)

    def x_of(self, t: float) -> int:
        return self.gx0 + int(round(min(max(t / self.duration, 0.0), 1.0) * self.gw))

    def y_of(self, log_value: float) -> int:
        f = (min(max(log_value, LOG_LO), LOG_HI) - LOG_LO) / (LOG_HI - LOG_LO)
        return self.gy1 - int(round(f * (self.gy1 - self.gy0)))

    def clock_colour(self, t: float):
        colour = WHITE
        for until, c in self.until:
            if t > until + 1e-9:
                colour = c
        return colour

    # ------------------------------------------------------------ per frame
    def draw(self, out: np.ndarray, t: float):
        """The HUD at simulated time t into the finished frame `out` (H×W×3 uint8)."""
        frame = min(max(int(round(t * self.fps)), 0), self.frames - 1)
        spread = self.launch("hud_spread", frame) if self.fan else 0.0  # returned: no field read to launch
        lines = [self.clock_rows(f"t = {t:5.2f} s", self.clock_colour(t))]
        if self.fan:
            lines.append(self.value_rows(spread))
        self.launch("hud_draw", out, frame, self.x_of(t), np.concatenate(lines), len(lines[0]))

    @ti.kernel
    def hud_spread(self, frame: ti.i32) -> float:
        """The spread now (returned) and its history: a max, the same in any order."""
        self.spread[None] = 0.0
        ti.loop_config(serialize=True)  # a few thousand pendulums at most: waking threads costs more
        for i in range(self.n - 1):
            a, b = self.sim.points(self.sim.q[i]), self.sim.points(self.sim.q[i + 1])
            d = ti.Vector([b[self.tip, 0] - a[self.tip, 0], b[self.tip, 1] - a[self.tip, 1]]).norm()
            ti.atomic_max(self.spread[None], d)
        rel = ti.max(ti.cast(self.spread[None] / self.reach, ti.f32), 1e-30)
        self.history[frame] = ti.log(rel) / ti.log(10.0)
        return self.spread[None]

    @ti.kernel
    def hud_draw(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), frame: ti.i32, now: ti.i32,
                 glyphs: ti.types.ndarray(dtype=ti.i32, ndim=2), clock: ti.i32):
        """The static text, the clock (glyphs[:clock]), the spread's value (the other glyphs), the graph and
        the timeline, into `out`: every write a max, as before.

        Four loops, one after the other, each giving every pixel it writes to one thread: the static text
        pixel by pixel, each line of text glyph by glyph (a line's cells do not overlap), the graph column
        by column. So the bytes are the same at any thread count, serial or not."""
        ti.loop_config(serialize=self.serial)
        for i in range(self.lit):  # inside the frame: it was drawn there
            y, x = self.layer[i, 0], self.layer[i, 1]
            for k in ti.static(range(3)):
                out[y, x, k] = ti.cast(ti.max(ti.cast(out[y, x, k], ti.i32), self.layer[i, 2 + k]), ti.u8)
        ti.loop_config(serialize=self.serial)
        for i in range(clock):
            self.font.glyph_max(out, glyphs, i)
        ti.loop_config(serialize=self.serial)
        for i in range(clock, glyphs.shape[0]):
            self.font.glyph_max(out, glyphs, i)
        ti.loop_config(serialize=self.serial)
        for x in range(self.gx0, self.gx1 + 1):  # column x writes only column x
            axis = ti.Vector(DIM) if x <= now else ti.Vector(FAINT)
            for j in range(self.th):
                self.put(out, self.gy1 + 1 + j, x, axis)
            for k in ti.static(range(2)):
                if ti.static(self.ticks[k] >= 0):
                    if self.ticks[k] <= x < self.ticks[k] + self.th:
                        self.column(out, x, self.gy0, self.gy1 + 3 * self.th, ti.Vector(self.tick_colours[k]))
            if ti.static(self.fan):
                if x <= now:
                    f = (x - self.gx0) * ti.max(self.frames - 1, 1) // self.gw
                    f = ti.min(f, frame)
                    fp = ti.min(ti.max(x - 1 - self.gx0, 0) * ti.max(self.frames - 1, 1) // self.gw, frame)
                    y, yp = self.y_px(self.history[f]), self.y_px(self.history[fp])
                    c = self.spread_colour(f)
                    for j in range(self.th):
                        self.column(out, x, yp - j, y - j, c)

    @ti.func
    def put(self, out: ti.template(), y, x, c):
        if 0 <= x < self.w and 0 <= y < self.h:
            for k in ti.static(range(3)):
                old = ti.cast(out[y, x, k], ti.i32)  # (LLVM has no max of u8)
                out[y, x, k] = ti.cast(ti.max(old, ti.cast(c[k] * 255.0 + 0.5, ti.i32)), ti.u8)

    @ti.func
    def column(self, out: ti.template(), x, y0, y1, c):
        for y in range(ti.min(y0, y1), ti.max(y0, y1) + 1):
            self.put(out, y, x, c)

    @ti.func
    def spread_colour(self, f):
        """The curve's colour at frame f: as the clock's was then."""
        t = f / self.fps
        c = ti.Vector(CURVE)
        for k in ti.static(range(2)):
            if ti.static(self.ticks[k] >= 0):
                if t > self.tick_times[k] + 1e-9:
                    c = ti.Vector(self.tick_colours[k])
        return c

    @ti.func
    def y_px(self, v):
        f = (ti.min(ti.max(v, LOG_LO), LOG_HI) - LOG_LO) / (LOG_HI - LOG_LO)
        return self.gy1 - ti.cast(ti.round(f * (self.gy1 - self.gy0)), ti.i32)
