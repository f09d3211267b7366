"""The canvas's drawing primitives: a pendulum's colour; a pixel, an antialiased segment and a disc, each
written into one of its layers, marking the tiles it touched; and a spring's zig-zag, as the nodes its segments
join.

Apart from render/draw/canvas.py, which owns the layers, the view and the kernels that call these: how a shape
becomes pixels is one idea, what a frame draws and how it is composed another. Raster is a mixin of Taichi
functions the Canvas inherits; they read only its size (w, h, n, TILE), palette and compositing (rainbow,
glowing, gain, glow), bands of rows (banded, band_rows), coil amplitude (amp) and layer of bobs (rgb, drawn).
Coverage comes from the distance to each segment or circle; a primitive is composed with a max per channel,
which does not depend on drawing order, or under glow is added as light (render/draw/glow.py). Every
primitive is clipped to a band of rows [y0, y1): on the CPU each thread draws every primitive into its own
band (render/draw/canvas.py), so no two threads write one pixel and the max needs no atomic; on CUDA the band
is the frame and the max is atomic.
"""
import taichi as ti

COILS = 14  # zig-zag segments per spring
LEAD = 0.12  # straight fraction at each end of a spring
# The primitive kernels' loop on the CPU: a band of rows per thread, each band's work in the first of BAND_SLOTS
# iterations, since Taichi's CPU threads take a parallel loop in blocks of at least 512 (render/physics/runtime.py).
# A float atomic max is a compare-exchange loop, about 2/3 of the drawing time (rigid_chaos, 720p: rods+bobs
# 1.1 ms of CPU a frame serial, 2.9 ms on two threads with it), so bands, whose pixels no other thread writes,
# beat pendulums shared out with atomics.
BAND_SLOTS = 512


@ti.func
def to_byte(c):
    """One channel of a colour (f32) to a byte; monotone, so it commutes with the max."""
    return ti.cast(ti.min(c, 1.0) * 255.0 + 0.5, ti.u8)


@ti.func
def hue(h):
    """HSV (h, 1, 1) to RGB, h in [0, 1)."""
    k = ti.Vector([5.0, 3.0, 1.0])
    c = (k + h * 6.0) % 6.0
    return 1.0 - ti.max(0.0, ti.min(ti.min(c, 4.0 - c), 1.0))


class Raster:
    """The Canvas's primitives (see above); render/draw/section.py colours its crossings with colour()."""

    @ti.func
    def slot(self, s):
        """What iteration s of a primitive kernel's loop draws: pendulums lo <= i < hi, clipped to rows
        y0 <= y < y1, as (lo, hi, y0, y1). CPU: the first slot of each band draws every pendulum into that
        band; CUDA: slot s is pendulum s, the whole frame."""
        out = ti.Vector([s, s + 1, 0, self.h])
        if ti.static(self.banded):
            band = s // BAND_SLOTS
            y0 = band * self.band_rows
            out = ti.Vector([0, 0, y0, ti.min(self.h, y0 + self.band_rows)])
            if s % BAND_SLOTS == 0:
                out[1] = self.n
        return out

    @ti.func
    def colour(self, i):
        """video.palette: "fan", red to violet over the fan; "rainbow", the whole hue circle, so that a
        coherent fan adds up to white under glow (each channel averages 1/2 over the circle)."""
        h = 0.85 * i / ti.max(self.n - 1, 1) if self.n > 1 else 0.08
        if ti.static(self.rainbow):
            h = i / self.n
        return hue(h)

    @ti.func
    def ink(self, i, max_scale, max_lift):
        """Pendulum i's colour for a primitive: dimmed and lifted towards grey under max compositing, its
        share of the light under glow."""
        c = self.colour(i)
        if ti.static(not self.glowing):
            c = max_scale * c + max_lift
        else:
            c = self.gain * c
        return c

    @ti.func
    def plot(self, buf: ti.template(), tiles: ti.template(), y, x, c, y0, y1):
        if 0 <= x < self.w and y0 <= y < y1:
            if ti.static(self.glowing):
                self.glow.deposit(self, buf, y, x, c)
            for k in ti.static(range(3) if not self.glowing else ()):
                if ti.static(not self.banded):
                    ti.atomic_max(buf[y, x][k], c[k])
                elif ti.static(buf.dtype == ti.u8):  # a layer of bytes: the byte of the max
                    # c is f64 in an f64 runtime (Python floats are its default_fp): rounded to the f32 a
                    # layer of floats held, so that its byte is that layer's to the bit
                    old = ti.cast(buf[y, x][k], ti.i32)
                    buf[y, x][k] = ti.cast(ti.max(old, ti.cast(to_byte(ti.cast(c[k], ti.f32)), ti.i32)), ti.u8)
                else:
                    buf[y, x][k] = ti.max(buf[y, x][k], c[k])
            tiles[y // self.TILE, x // self.TILE] = 1  # every writer stores the same 1: the race is harmless

    @ti.func
    def segment(self, buf: ti.template(), tiles: ti.template(), a, b, r, c, y0, y1, flat: ti.template() = False):
        """A line from a to b (x, y in pixels), its rows y0 <= y < y1: under glow a hairline of light
        (render/draw/glow.py; `flat`: a trail's pieces, which must not overlap), else antialiased with
        half-width r. A band the line's pixels cannot reach is not walked."""
        if ti.min(a[1], b[1]) - r - 2.0 < y1 and ti.max(a[1], b[1]) + r + 2.0 >= y0:
            if ti.static(self.glowing):
                self.glow.segment(self, buf, tiles, a, b, c, flat, y0, y1)
            else:
                self.max_segment(buf, tiles, a, b, r, c, y0, y1)

    @ti.func
    def max_segment(self, buf: ti.template(), tiles: ti.template(), a, b, r, c, y0, y1):
        """Antialiased segment of half-width r, walked along its major axis, composed with a max; only the
        walk's rows in [y0, y1) are visited (the coverage of each pixel is the same as unclipped)."""
        swap = ti.abs(b[1] - a[1]) > ti.abs(b[0] - a[0])
        if swap:
            a, b = ti.Vector([a[1], a[0]]), ti.Vector([b[1], b[0]])
        if a[0] > b[0]:
            a, b = b, a
        d = b - a
        slope = d[1] / ti.max(d[0], 1e-6)
        reach = int(ti.ceil(1.42 * r + 1.5))
        # Pixels closer than r + 0.5 to the segment lie within this many pixels of its centre line along
        # the minor axis (end caps included); the old fixed band of ±reach is kept as an outer bound.
        band = (r + 0.5) * ti.sqrt(1.0 + slope * slope) + 0.01
        ll = ti.max(d.norm_sqr(), 1e-12)
        il = 1.0 / ti.sqrt(ll)  # 1 / |d|
        first, last = int(ti.floor(a[0] - r - 1.0)), int(ti.ceil(b[0] + r + 1.0))
        if swap:  # the major axis is y
            first, last = ti.max(first, y0), ti.min(last, y1 - 1)
        for u in range(first, last + 1):
            vl = a[1] + slope * (ti.min(ti.max(u, a[0]), b[0]) - a[0])
            vc = int(ti.round(vl))
            lo, hi = ti.max(vc - reach, int(ti.ceil(vl - band))), ti.min(vc + reach, int(ti.floor(vl + band)))
            if not swap:
                lo, hi = ti.max(lo, y0), ti.min(hi, y1 - 1)
            # Where every pixel of this column projects inside the segment (t in [0, 1] at both ends of the
            # column's run: t is linear in v), the distance to the segment is the distance to its line, |q × d|
            # / |d|, linear in v: no division and no square root a pixel. rigid_chaos at 720p, draw_frame with
            # rods alone 1.93 → 1.64 ms a frame (`python benchmarks/draw_kernels.py rigid_chaos --set
            # 'effects=["rods"]'`, 2 rounds each); its rounding differs from the projection's by one level in
            # a few pixels a video (the goldens hold). Columns at the end caps, and pieces under a pixel long (a
            # trail's), take the projection.
            # t times ll at the run's ends, tested against [0, ll] with no division: the same answer as t's
            # test, since both are f32 values and ll >= 1, so the quotient's rounding cannot cross 0 or 1 (it
            # moves by under 2^-53 of t where the f32 values next to ll are 2^-24 of it away). Two divisions a
            # column fewer: rods alone 1.46-1.49 -> 1.39-1.43 ms a frame (draw_kernels.py as above, 2 rounds).
            qx = ti.cast(u, ti.f32) - a[0]
            tlo = qx * d[0] + (ti.cast(lo, ti.f32) - a[1]) * d[1]
            thi = qx * d[0] + (ti.cast(hi, ti.f32) - a[1]) * d[1]
            inner = ll >= 1.0 and ti.min(tlo, thi) >= 0.0 and ti.max(tlo, thi) <= ll
            for v in range(lo, hi + 1):
                cov = 0.0
                if inner:
                    cross = qx * d[1] - (ti.cast(v, ti.f32) - a[1]) * d[0]
                    cov = ti.min(ti.max(r + 0.5 - ti.abs(cross) * il, 0.0), 1.0)
                else:
                    p = ti.Vector([ti.cast(u, ti.f32), ti.cast(v, ti.f32)])
                    t = ti.min(ti.max((p - a).dot(d) / ll, 0.0), 1.0)
                    cov = ti.min(ti.max(r + 0.5 - (p - a - t * d).norm(), 0.0), 1.0)
                if cov > 0.0:
                    if swap:
                        self.plot(buf, tiles, u, v, c * cov, y0, y1)
                    else:
                        self.plot(buf, tiles, v, u, c * cov, y0, y1)

    @ti.func
    def disc(self, centre, r, c, y0, y1):
        """A disc of radius r into the layer of bobs, its rows y0 <= y < y1."""
        reach = int(r) + 2
        cx, cy = int(ti.round(centre[0])), int(ti.round(centre[1]))
        rr = (r + 0.5) * (r + 0.5)
        # Pixels nearer the centre than r - 0.51 are covered whole: cov is 1 exactly, whatever the rounding of
        # their distance. Into a layer of bytes they go as the colour's bytes, made once, with no distance and no
        # conversion a pixel: the same bytes. rigid_chaos at 720p, draw_frame with bobs alone 0.83 → 0.52 ms a
        # frame, with rods and trails too 3.32-3.44 → 3.06-3.10 ms (`python benchmarks/draw_kernels.py
        # rigid_chaos [--set 'effects=["bobs"]']`, 2026-12-06).
        core = ti.max(r - 0.51, 0.0)
        core *= core  # the squared radius of that core
        full = ti.Vector([ti.cast(to_byte(ti.cast(c[k], ti.f32)), ti.i32) for k in ti.static(range(3))])
        for y in range(ti.max(cy - reach, y0), ti.min(cy + reach, y1 - 1) + 1):
            dy = ti.cast(y, ti.f32) - centre[1]
            if dy * dy < rr:  # only the columns a row of the disc covers (with a hair of margin)
                half = ti.sqrt(rr - dy * dy) + 0.01
                half_core = ti.sqrt(ti.max(core - dy * dy, 0.0))
                xi0, xi1 = int(ti.ceil(centre[0] - half_core)), int(ti.floor(centre[0] + half_core))
                if dy * dy >= core:  # the row misses the core
                    xi0, xi1 = 1, 0
                for x in range(ti.max(cx - reach, int(ti.ceil(centre[0] - half))),
                               ti.min(cx + reach, int(ti.floor(centre[0] + half))) + 1):
                    if ti.static(self.rgb.dtype == ti.u8):  # a layer of bytes (canvas.BYTE_LAYER)
                        if xi0 <= x <= xi1:
                            self.plot_bytes(y, x, full, y0, y1)
                        else:
                            self.disc_pixel(centre, r, c, y, x, y0, y1)
                    else:
                        self.disc_pixel(centre, r, c, y, x, y0, y1)

    @ti.func
    def disc_pixel(self, centre, r, c, y, x, y0, y1):
        """One pixel of disc(), its coverage from its distance to the centre."""
        dist = (ti.Vector([ti.cast(x, ti.f32), ti.cast(y, ti.f32)]) - centre).norm()
        cov = ti.min(ti.max(r + 0.5 - dist, 0.0), 1.0)
        if cov > 0.0:
            self.plot(self.rgb, self.drawn, y, x, c * cov, y0, y1)

    @ti.func
    def plot_bytes(self, y, x, byte, y0, y1):
        """plot() of a pixel covered whole into the layer of bytes: its colour's bytes, made once."""
        if 0 <= x < self.w and y0 <= y < y1:
            for k in ti.static(range(3)):
                self.rgb[y, x][k] = ti.cast(ti.max(ti.cast(self.rgb[y, x][k], ti.i32), byte[k]), ti.u8)
            self.drawn[y // self.TILE, x // self.TILE] = 1

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
