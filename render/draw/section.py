"""The `poincare` effect's panel: the crossings render/physics/poincare.py finds, accumulated over the video.

θ2 wrapped to [−π, π) across, ω2 up, over the range energy allows on the section (the kinetic energy's
minimum over ω1 at each θ2), with axes as render/draw/axes.py draws a map's; each crossing a small disc in its pendulum's colour (the canvas's palette), composed with an atomic max into a layer that
persists over the video, so frames are the same bytes at any thread count. Beside the pendulums (when
effects also draw them) it takes the right half of the frame; alone it takes the whole frame.
"""
import math

import numpy as np
import taichi as ti

from . import axes
from .font import Font
from ..physics import reference, runtime
from ..physics.poincare import SLOTS, TAU, omega2_range, read

TITLE = ("Poincaré section θ₁ = 0, ω₁ > 0", "section θ₁ = 0")


def ticks(top: float, room: int = 3) -> list[float]:
    """Round values within ±top, 0 included: steps of 1, 2 or 5 times a power of ten, at most `room` each side."""
    for e in range(math.floor(math.log10(top)) - 1, math.ceil(math.log10(top)) + 2):
        for m in (1, 2, 5):
            step = m * 10.0 ** e
            if top // step <= room:
                return [k * step for k in range(-int(top // step), int(top // step) + 1)]
    return [0.0]


@ti.data_oriented
class Section(runtime.Launcher):
    """The panel of canvas `cv` in columns [x0, x0 + width) of its frame."""

    def __init__(self, cv, scene, sim, x0: int, width: int):
        self.cv, self.sim, self.n, self.fps = cv, sim, sim.n, scene.video.fps
        self.x0, self.width, self.height = x0, width, cv.h
        h = cv.h
        self.font_size = "10x20" if h >= 480 else "6x13"
        f = Font(self.font_size)
        cw, ch = f.text_width("0"), f.text_height("0")
        pad = max(3, ch // 3)
        top, bottom, left = ch + 2 * pad, 4 * pad + 2 * ch, 3 * pad + 7 * cw  # title; ticks + label; label + ticks
        self.side = max(8, min(h - top - bottom, width - left - 2 * pad))
        self.px = x0 + left + max(0, (width - left - pad - self.side) // 2)  # the plot, in frame pixels
        self.py = top + max(0, (h - top - bottom - self.side) // 2)
        q0, v0 = sim.initial_state()
        p = reference.params(scene)
        self.top = omega2_range(p, float(reference.energy(p, q0, v0).max()))  # energy only falls (damping)
        self.radius = max(0.7, 0.0016 * h)
        self.layer = runtime.field("poincare.points", ti.f32, (self.side, self.side), 3)
        self.background = self.decorate(f, scene, pad, cw, ch)
        self.restart()

    def restart(self):
        self.layer.fill(0)
        self.total, self.lost = 0, 0

    def decorate(self, f, scene, pad, cw, ch) -> np.ndarray:
        """The panel's static part: background, the plot's border, ticks and labels (as render/draw/axes.py)."""
        bg = np.empty((self.height, self.width, 3), np.uint8)
        bg[:] = axes.BACKGROUND
        x0, y0, s = self.px - self.x0, self.py, self.side
        for x, y, w, h in ((x0 - 1, y0 - 1, s + 2, 1), (x0 - 1, y0 + s, s + 2, 1), (x0 - 1, y0 - 1, 1, s + 2),
                           (x0 + s, y0 - 1, 1, s + 2)):
            bg[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = axes.FRAME
        small = {"size": self.font_size, "colour": axes.INK}
        title = next((t for t in TITLE if len(t) * cw <= self.width - 2 * pad), "")
        texts = [(title, self.width // 2, pad, {**small, "ha": "center"}),
                 ("θ₂", x0 + s // 2, y0 + s + 3 * pad + ch, {**small, "ha": "center"}),
                 ("ω₂", max(x0 - 3 * pad - 4 * cw, 2 * cw), y0 + s // 2, {**small, "ha": "right", "va": "middle"})]
        for k in range(5):  # θ2: −π, −π/2, 0, π/2, π
            x = x0 + min(round(s * k / 4), s - 1)
            bg[y0 + s + 1:y0 + s + 1 + pad, x] = axes.FRAME
            if k % 2 == 0 or s // 4 >= 6 * cw:
                texts.append((axes.pi_label(-math.pi + k * math.pi / 2), x, y0 + s + 2 * pad,
                              {**small, "ha": "center"}))
        for v in ticks(self.top, max(1, min(3, s // (4 * ch)))):  # ω2 in rad/s, labels two lines apart
            y = y0 + min(round((self.top - v) / (2 * self.top) * s), s - 1)
            bg[y, max(x0 - 1 - pad, 0):x0 - 1] = axes.FRAME
            texts.append((axes.number(v), x0 - 2 * pad, y, {**small, "ha": "right", "va": "middle"}))
        f.draw_many(bg, [t for t in texts if t[0]])
        return bg

    def draw(self, out: np.ndarray, first: bool):
        """This frame's new crossings (none in the first frame) into the layer, then the panel into `out`."""
        out[:, self.x0:self.x0 + self.width] = self.background
        if not first:
            self.launch("poincare_plot")
            i, _, _, _, lost = read(self.sim, 0.0)
            self.total, self.lost = self.total + len(i), self.lost + lost
        self.launch("poincare_compose", out)

    def summary(self) -> dict:
        """For metadata.json."""
        return {"section": "theta1 = 0 mod 2 pi, omega1 > 0", "points": "(theta2, omega2)", "crossings": self.total,
                "lost": self.lost, "omega2_range": [-round(self.top, 6), round(self.top, 6)]}

    @ti.kernel
    def poincare_plot(self):
        s, r = ti.cast(self.side, ti.f32), self.radius
        for i in range(self.n):
            for k in range(ti.min(self.sim.crossed[i], SLOTS)):
                c = self.sim.crossings[i, k]
                th2 = c[1] - TAU * ti.floor((c[1] + math.pi) / TAU)  # wrapped to [−π, π)
                x = ti.cast((th2 + math.pi) / TAU, ti.f32) * s - 0.5
                y = ti.cast((self.top - c[2]) / (2.0 * self.top), ti.f32) * s - 0.5
                colour = self.cv.colour(i)
                for dy, dx in ti.ndrange((-2, 3), (-2, 3)):  # a disc of radius r (< 1.5 px), antialiased
                    py, px = int(ti.round(y)) + dy, int(ti.round(x)) + dx
                    d = ti.Vector([px - x, py - y]).norm()
                    cov = ti.min(ti.max(r + 0.5 - d, 0.0), 1.0)
                    if cov > 0.0 and 0 <= px < self.side and 0 <= py < self.side:
                        for ch in ti.static(range(3)):
                            ti.atomic_max(self.layer[py, px][ch], cov * colour[ch])

    @ti.kernel
    def poincare_compose(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3)):
        for y, x in ti.ndrange(self.side, self.side):
            c = self.layer[y, x]
            if c.max() > 0.0:
                for ch in ti.static(range(3)):  # the canvas's byte over the background, a max (in i32: no u8 max)
                    b = ti.max(ti.cast(out[self.py + y, self.px + x, ch], ti.i32),
                               ti.cast(ti.min(c[ch], 1.0) * 255.0 + 0.5, ti.i32))
                    out[self.py + y, self.px + x, ch] = ti.cast(b, ti.u8)
