"""An offscreen canvas: a framebuffer field and Taichi kernels that draw into it.

Antialiased coverage comes from the distance to each segment or circle. Primitives are composited with an
atomic max per channel, which does not depend on drawing order, so frames are byte-identical across runs and
thread counts. Each effect has its own kernel, launched (and compiled) only when the scene calls for it.
"""
import math

import numpy as np
import taichi as ti

from . import runtime

COILS = 14  # zig-zag segments per spring
LEAD = 0.12  # straight fraction at each end of a spring
TRAIL_FLOOR = 0.03  # a trail fades to this brightness over video.trail_seconds


@ti.func
def hue(h):
    """HSV (h, 1, 1) to RGB, h in [0, 1)."""
    k = ti.Vector([5.0, 3.0, 1.0])
    c = (k + h * 6.0) % 6.0
    return 1.0 - ti.max(0.0, ti.min(ti.min(c, 4.0 - c), 1.0))


@ti.data_oriented
class Canvas(runtime.Launcher):
    def __init__(self, scene, sim):
        v, self.scene, self.sim = scene.video, scene, sim
        self.w, self.h, self.n = v.width, v.height, sim.n
        self.rods, self.springs, self.bobs_on = scene.has("rods"), scene.has("springs"), scene.has("bobs")
        self.trails, self.fractal = scene.has("trails"), scene.has("fractal")
        self.img = runtime.field("canvas.image", ti.u8, (self.h, self.w, 3))
        if not self.fractal:
            self.rgb = runtime.field("canvas.frame", ti.f32, (self.h, self.w), 3)
            # pixels per metre, the pivot at the centre: the full reach fits with a margin
            self.scale = 0.46 * min(self.w, self.h) / sim.extent()
            self.lw = max(0.6, 0.0011 * self.h)  # half-width of rods, coils and trails in pixels
            self.amp = 0.035 * self.scale * min(sim.l1, sim.l2)  # coil amplitude
            m = max(sim.m1, sim.m2)
            self.r1 = max(2.0, 0.013 * self.h * (sim.m1 / m) ** (1 / 3))
            self.r2 = max(2.0, 0.013 * self.h * (sim.m2 / m) ** (1 / 3))
            self.pos = runtime.field("canvas.bobs_px", ti.f32, (self.n, 2), 2)
        if self.trails:
            self.trail = runtime.field("canvas.trail", ti.f32, (self.h, self.w), 3)
            self.last = runtime.field("canvas.trail_last_px", ti.f32, self.n, 2)
            self.decay = TRAIL_FLOOR ** (1.0 / (v.fps * v.trail_seconds))
        self.frame_no = 0

    def draw(self) -> np.ndarray:
        """The current state of the simulation as an H×W×3 uint8 frame."""
        if self.fractal:
            self.launch("fractal_colour")
            return self.img.to_numpy()
        self.launch("bob_pixels")
        self.launch("clear_frame")
        if self.trails:
            self.launch("fade_stamp_trails", int(self.frame_no == 0))
        if self.rods:
            self.launch("draw_rods")
        if self.springs:
            self.launch("draw_spring_coils")
        if self.bobs_on:
            self.launch("draw_bobs")
        self.launch("compose_frame")
        self.frame_no += 1
        return self.img.to_numpy()

    # ------------------------------------------------------------ primitives
    @ti.func
    def colour(self, i):
        return hue(0.85 * i / ti.max(self.n - 1, 1) if self.n > 1 else 0.08)

    @ti.func
    def plot(self, buf: ti.template(), y, x, c):
        if 0 <= x < self.w and 0 <= y < self.h:
            for k in ti.static(range(3)):
                ti.atomic_max(buf[y, x][k], c[k])

    @ti.func
    def segment(self, buf: ti.template(), a, b, r, c):
        """Antialiased segment of half-width r, walked along its major axis (x, y in pixels)."""
        swap = ti.abs(b[1] - a[1]) > ti.abs(b[0] - a[0])
        if swap:
            a, b = ti.Vector([a[1], a[0]]), ti.Vector([b[1], b[0]])
        if a[0] > b[0]:
            a, b = b, a
        d = b - a
        slope = d[1] / ti.max(d[0], 1e-6)
        reach = int(ti.ceil(1.42 * r + 1.5))
        ll = ti.max(d.norm_sqr(), 1e-12)
        for u in range(int(ti.floor(a[0] - r - 1.0)), int(ti.ceil(b[0] + r + 1.0)) + 1):
            vc = int(ti.round(a[1] + slope * (ti.min(ti.max(u, a[0]), b[0]) - a[0])))
            for v in range(vc - reach, vc + reach + 1):
                p = ti.Vector([ti.cast(u, ti.f32), ti.cast(v, ti.f32)])
                t = ti.min(ti.max((p - a).dot(d) / ll, 0.0), 1.0)
                cov = ti.min(ti.max(r + 0.5 - (p - a - t * d).norm(), 0.0), 1.0)
                if cov > 0.0:
                    if swap:
                        self.plot(buf, u, v, c * cov)
                    else:
                        self.plot(buf, v, u, c * cov)

    @ti.func
    def disc(self, buf: ti.template(), centre, r, c):
        reach = int(r) + 2
        cx, cy = int(ti.round(centre[0])), int(ti.round(centre[1]))
        for y in range(cy - reach, cy + reach + 1):
            for x in range(cx - reach, cx + reach + 1):
                dist = (ti.Vector([ti.cast(x, ti.f32), ti.cast(y, ti.f32)]) - centre).norm()
                cov = ti.min(ti.max(r + 0.5 - dist, 0.0), 1.0)
                if cov > 0.0:
                    self.plot(buf, y, x, c * cov)

    # ------------------------------------------------------------ kernels, one per effect
    @ti.kernel
    def bob_pixels(self):
        """World metres to pixels (y down), at frame times only."""
        cx, cy = 0.5 * self.w, 0.5 * self.h
        for i in range(self.n):
            p1, p2 = self.sim.bobs(i)
            self.pos[i, 0] = ti.Vector([cx + self.scale * p1[0], cy - self.scale * p1[1]], ti.f32)
            self.pos[i, 1] = ti.Vector([cx + self.scale * p2[0], cy - self.scale * p2[1]], ti.f32)

    @ti.kernel
    def clear_frame(self):
        for y, x in self.rgb:
            self.rgb[y, x] = ti.Vector([0.0, 0.0, 0.0], ti.f32)

    @ti.kernel
    def fade_stamp_trails(self, first: ti.i32):
        for y, x in self.trail:
            self.trail[y, x] *= self.decay
        for i in range(self.n):
            p = self.pos[i, 1]
            a = p if first else self.last[i]
            self.segment(self.trail, a, p, self.lw, 0.9 * self.colour(i))
            self.last[i] = p

    @ti.kernel
    def draw_rods(self):
        centre = ti.Vector([0.5 * self.w, 0.5 * self.h], ti.f32)
        for i, j in ti.ndrange(self.n, 2):
            a = centre if j == 0 else self.pos[i, 0]
            self.segment(self.rgb, a, self.pos[i, j], self.lw, 0.55 * self.colour(i) + 0.15)

    @ti.kernel
    def draw_spring_coils(self):
        centre = ti.Vector([0.5 * self.w, 0.5 * self.h], ti.f32)
        for i, j, k in ti.ndrange(self.n, 2, COILS + 2):
            a = centre if j == 0 else self.pos[i, 0]
            self.segment(self.rgb, self.coil_node(a, self.pos[i, j], k), self.coil_node(a, self.pos[i, j], k + 1),
                         self.lw, 0.55 * self.colour(i) + 0.15)

    @ti.func
    def coil_node(self, a, b, k):
        """Node k of the zig-zag from a to b: straight leads, then COILS alternating offsets."""
        t = 0.0
        side = 0.0
        if k == 0:
            t = 0.0
        elif k == COILS + 2:
            t = 1.0
        else:
            t = LEAD + (1.0 - 2.0 * LEAD) * (k - 1) / COILS
            if 1 < k < COILS + 1:
                side = 1.0 if k % 2 == 0 else -1.0
        d = b - a
        nrm = ti.Vector([-d[1], d[0]]) / ti.max(d.norm(), 1e-6)
        return a + t * d + side * self.amp * nrm

    @ti.kernel
    def draw_bobs(self):
        for i, j in ti.ndrange(self.n, 2):
            self.disc(self.rgb, self.pos[i, j], self.r1 if j == 0 else self.r2, self.colour(i))
        self.disc(self.rgb, ti.Vector([0.5 * self.w, 0.5 * self.h], ti.f32), 3.0, ti.Vector([0.8, 0.8, 0.8]))

    @ti.kernel
    def compose_frame(self):
        for y, x in self.rgb:
            c = self.rgb[y, x]
            if ti.static(self.trails):
                c = ti.max(c, self.trail[y, x])
            for k in ti.static(range(3)):
                self.img[y, x, k] = ti.cast(ti.min(c[k], 1.0) * 255.0 + 0.5, ti.u8)

    @ti.kernel
    def fractal_colour(self):
        """One pendulum per pixel: the two angles mapped to colour."""
        for y, x in ti.ndrange(self.h, self.w):
            q = self.sim.q[y * self.w + x]
            c = 0.5 + 0.5 * ti.Vector([ti.sin(q[0]), ti.sin(q[1]), ti.cos(q[0] + q[1])])
            for k in ti.static(range(3)):
                self.img[y, x, k] = ti.cast(c[k] * 255.0 + 0.5, ti.u8)
