"""The `glow` effect: light adds up, then a tone map brings it into the screen's range.

Under glow the canvas composes its rods, coils, bobs and trails additively instead of with a max: where a
thousand thin pendulums overlap they add up to a bright core, and as chaos fans them out each keeps its own
faint colour (with video.palette = "rainbow" the coherent fan is white light and the spray a spectrum).
Lines are antialiased hairlines (segment()), as much light per unit of length at any slope; bobs are the
canvas's discs. The layers are stored tile by tile (runtime.field's block), where row-major order would miss
the cache at every pixel of a steep line.

Determinism: light is accumulated in fixed point (FIX per unit) with integer adds. Integer addition is
associative, so the sum per pixel, and the frame, is the same bytes whatever the order of the adds and the
number of threads (float adds in racing order would not be). Each contribution is rounded on its own, before
it is added, so it does not depend on the order either. On the CPU each thread draws its own band of rows
(render/draw/canvas.py), so the adds are plain; on CUDA they are atomic. An atomic add in a parallel loop
stays a locked instruction even with one thread: rainbow_1000's rods took 8.6 ms a frame with them, and
Taichi had turned them into plain adds only in the serial loop the bands replaced.

Tone map: byte = 255·(1 − exp(−light)), from a table indexed by light in steps of 1/512 (4096 entries, up
to a light of 8, where it is white). It is smooth near black, so a single faint pendulum stays visible, and
it saturates gracefully where hundreds overlap.

Trails fade in fixed point too: trail·decay with decay in 1/65536 steps, in integers. A trail value too faint
to reach the first step of the table is set to 0, so its tile can go dark (as the max canvas does; here it
can shift a sum with this frame's rods by less than 1/512 of light, the same at any thread count).
"""
import math

import numpy as np
import taichi as ti

from ..physics import runtime

FIX = 1 << 12  # fixed point: a light of 1.0 is 4096
SHIFT = 3  # the tone table is indexed by light >> SHIFT: steps of 8 / 4096 = 1/512
SIZE = 4096  # entries: up to a light of SIZE << SHIFT / FIX = 8 (255·(1 − e⁻⁸) rounds to 255)
DECAY_BITS = 16
TRAIL = 0.5  # a trail's light relative to its rod's (the max canvas draws it at 0.9 of the colour)
PEAK = 8.0  # see gain()


def gain(n: int) -> float:
    """Light of one pendulum's line: 1 alone, less in a crowd, so that a coherent fan of n is a white core
    (n·gain = PEAK·√n, well into the saturated end) while one pendulum on its own stays visible
    (1000 pendulums: 0.25, a byte of 57 on a line through pixel centres, split between two pixels else)."""
    return min(1.0, PEAK / math.sqrt(max(n, 1)))


def tone_table() -> np.ndarray:
    light = np.arange(SIZE) * (1 << SHIFT) / FIX
    return np.floor(255.0 * (1.0 - np.exp(-light)) + 0.5).astype(np.int32)


@ti.func
def add(cell: ti.template(), v, plain: ti.template()):
    """cell += v, plainly where no other thread writes the cell (`+=` on a field is an atomic add in Taichi)."""
    if ti.static(plain):
        cell = cell + v
    else:
        ti.atomic_add(cell, v)


@ti.data_oriented
class Glow:
    def __init__(self, decay: float):
        self.tone = runtime.field("glow.tone", ti.i32, SIZE)
        self.tone.from_numpy(tone_table())
        self.decay = int(round(decay * (1 << DECAY_BITS)))

    @ti.func
    def deposit(self, cv: ti.template(), buf: ti.template(), y, x, c):
        """Add light c (f32, in units of 1) at a pixel of canvas cv's layer, rounded to fixed point first."""
        for k in ti.static(range(3)):
            add(buf[y, x][k], ti.cast(c[k] * FIX + 0.5, ti.i32), cv.banded)

    @ti.func
    def segment(self, cv: ti.template(), buf: ti.template(), tiles: ti.template(), a, b, c, flat: ti.template(),
                y0, y1):
        """A hairline from a to b (pixels) into canvas cv's layer `buf`: Xiaolin Wu's antialiased line, two
        pixels per column of its major axis, split by where the line crosses the column, and as much light
        per unit of length whatever its slope. Under glow lines are thin by design (the max canvas's
        half-width does not apply): 1000 pendulums draw 2000 rods of up to 160 px a frame, and this is 3.5x
        cheaper than the max canvas's coverage from the distance to the segment (14 -> 4 ms a frame).
        `flat`: the columns of [a, b), half-open, so consecutive segments of a trail share none. Only rows
        y0 <= y < y1 are lit (a thread's band: render/draw/raster.py)."""
        swap = ti.abs(b[1] - a[1]) > ti.abs(b[0] - a[0])
        if swap:
            a, b = ti.Vector([a[1], a[0]]), ti.Vector([b[1], b[0]])
        flipped = a[0] > b[0]
        if flipped:
            a, b = b, a
        d = b - a
        slope = d[1] / ti.max(d[0], 1e-6)
        light = c * ti.cast(FIX, ti.f32) * ti.sqrt(1.0 + slope * slope)
        first, last = int(ti.ceil(a[0])), int(ti.floor(b[0]))
        if ti.static(flat):  # leave out the column of the segment's own end (b, or a when flipped)
            if flipped and first == a[0]:
                first += 1
            elif not flipped and last == b[0]:
                last -= 1
        if swap:  # the major axis is y
            first, last = ti.max(first, y0), ti.min(last, y1 - 1)
        for u in range(first, last + 1):
            y = a[1] + slope * (u - a[0])
            v = int(ti.floor(y))
            f = y - v
            self.hair(cv, buf, tiles, u, v, swap, light * (1.0 - f), y0, y1)
            self.hair(cv, buf, tiles, u, v + 1, swap, light * f, y0, y1)

    @ti.func
    def hair(self, cv: ti.template(), buf: ti.template(), tiles: ti.template(), u, v, swap, light, y0, y1):
        """Fixed-point light at (u, v) of the major axis walk (swapped back to x, y), if y0 <= y < y1."""
        y, x = v, u
        if swap:
            y, x = u, v
        if 0 <= x < cv.w and y0 <= y < y1:
            for k in ti.static(range(3)):
                add(buf[y, x][k], ti.cast(light[k] + 0.5, ti.i32), cv.banded)
            tiles[y // cv.TILE, x // cv.TILE] = 1

    @ti.func
    def compose_tile(self, cv: ti.template(), out: ti.template(), ty, tx, layer: ti.template(),
                     trail: ti.template()):
        """One tile of canvas cv: (layer + trail) tone-mapped to bytes; clears the layer, fades the trail.
        Returns whether any trail in it is still visible."""
        lit = 0
        zero = ti.Vector([0, 0, 0], ti.i32)
        for y in range(ty * cv.TILE, ti.min(ty * cv.TILE + cv.TILE, cv.h)):
            for x in range(tx * cv.TILE, ti.min(tx * cv.TILE + cv.TILE, cv.w)):
                s = zero
                if ti.static(layer):
                    s = cv.rgb[y, x]
                    cv.rgb[y, x] = zero
                if ti.static(trail):
                    t = cv.trail[y, x]
                    if t.max() > 0:  # most pixels of a lit tile are off the trail: nothing to fade
                        s += t
                        faded = zero
                        for k in ti.static(range(3)):
                            f = ti.cast((ti.cast(t[k], ti.i64) * self.decay) >> DECAY_BITS, ti.i32)
                            if f >= (1 << SHIFT):
                                faded[k] = f
                                lit = 1
                        cv.trail[y, x] = faded
                for k in ti.static(range(3)):  # as unsigned: a sum that overflowed shows white, not garbage
                    i = ti.min(ti.cast(s[k], ti.u32) >> ti.u32(SHIFT), ti.u32(SIZE - 1))
                    out[y, x, k] = ti.cast(self.tone[ti.cast(i, ti.i32)], ti.u8)
        return lit
