"""The canvas's frame pass: its layers become the frame's bytes, tile by tile.

A 720p frame is 0.9 M pixels, but a few hundred pendulums touch only a small part of it. The canvas
(render/draw/canvas.py) composes TILE×TILE tiles that remember whether this frame's rods, coils and bobs or a
still-visible trail touched them; no layer is read for the others. The pass clears the layer it reads and
fades the trail in place, and writes the output array itself (a kernel argument), so there is no separate
clear, fade or field-to-numpy copy. Under a max the layer holds bytes (render/draw/raster.py's to_byte: the
byte of a max is the max of the bytes); under glow, light (render/draw/glow.py composes those tiles).

The frame drawn into last is kept: drawn into again, it is not cleared (a memset of a 720p frame was 0.7-1 ms
of rigid_chaos's 6 ms frame on a 2-core Xeon), but the pass zeroes every tile that may hold light from the last
frame and is not composed now: those composed then, and the HUD's boxes, which it draws over the finished
frame. Any other array is cleared first. tests/test_canvas.py holds both to the bytes of a new frame.

Compose is a mixin of the Canvas: it reads the canvas's size, tiles (TILE, ty, tx), layers (rgb, drawn, and
with trails trail, lit, decay), compositing (glowing, glow), HUD, and whether it writes words (word_rows).
"""
import numpy as np
import taichi as ti

from ..physics import runtime, vector_width
from .raster import to_byte


class Compose:
    def keep_frames(self):
        """The kept frame's state: call once the HUD is made (its boxes count as lit at every frame)."""
        self.kept = None
        over = np.zeros((self.ty, self.tx), np.int32)
        t, h, w = self.TILE, self.h, self.w
        for x0, y0, x1, y1 in self.hud.boxes if self.hud is not None else ():
            over[max(y0, 0) // t:min(y1, h - 1) // t + 1, max(x0, 0) // t:min(x1, w - 1) // t + 1] = 1
        self.hud_tiles = runtime.field("canvas.hud_tiles", ti.i32, (self.ty, self.tx))
        self.hud_tiles.from_numpy(over)
        # the tiles that may hold light: draw_frame's argument, which the frame pass rewrites, and what the MP4's
        # conversion reads to skip the dark ones (lit_tiles(), render/video/yuv.py)
        self.shown = over

    def lit_tiles(self) -> tuple[np.ndarray, int] | None:
        """(tiles, side): which side×side tiles (row-major) of the frame drawn last may hold anything but black;
        the rest are black to the byte. None where something draws into the frame after the frame pass besides
        the HUD (whose boxes count as lit): a Poincaré section's half."""
        return None if self.section is not None else (self.shown, self.TILE)

    def frame_for(self, out: np.ndarray | None) -> np.ndarray:
        """The array a draw composes into: `out`, cleared unless it is the frame drawn last; a new zeroed one
        for None."""
        if out is None:
            out = self.new_frame()
        elif out is not self.kept:
            out.fill(0)
        self.kept = out
        return out

    @ti.func
    def compose(self, out: ti.template(), words: ti.template(), shown: ti.template(), ty, tx):
        """max(layer, trail) to bytes in a tile something touched; zero in a tile that held light in the kept
        frame and is dark now; the rest as it is.

        It clears the layer and fades the trail as it reads them. Fading after reading equals the old
        fade-before-stamp order bit for bit. A faded trail value that would print as 0 is set to exactly 0:
        it could never show again (the byte of a max is the max of the bytes), and the tile can go dark.
        """
        drawn, lit = self.drawn[ty, tx], 0
        if ti.static(self.trails):
            lit = self.lit[ty, tx]
            if drawn and lit:  # one branch per tile, so each pixel loop is straight-line code
                self.lit[ty, tx] = self.tile(out, words, ty, tx, True, True)
            elif lit:
                self.lit[ty, tx] = self.tile(out, words, ty, tx, False, True)
            elif drawn:
                self.tile(out, words, ty, tx, True, False)
        elif drawn:
            self.tile(out, words, ty, tx, True, False)
        if not (drawn or lit) and shown[ty, tx]:
            black = ti.Vector.zero(ti.i32, 3 * self.TILE)
            for r in range(self.TILE):
                self.put_row(out, words, ty, tx, r, black, 0)
        shown[ty, tx] = drawn | lit | self.hud_tiles[ty, tx]
        self.drawn[ty, tx] = 0

    @ti.func
    def tile(self, out: ti.template(), words: ti.template(), ty, tx, layer: ti.template(), trail: ti.template()):
        lit = 0
        if ti.static(not self.glowing):
            lit = self.compose_tile(out, words, ty, tx, layer, trail)
        else:
            lit = self.glow.compose_tile(self, out, ty, tx, layer, trail)
        return lit

    @ti.func
    def compose_tile(self, out: ti.template(), words: ti.template(), ty, tx, layer: ti.template(),
                     trail: ti.template()):
        """One tile; returns whether any trail in it is still visible after fading. The max of the layer's and
        the trail's bytes, which is the byte of their max."""
        lit = 0
        if ti.static(trail):
            lit = self.fade_tile(out, words, ty, tx, layer)
        else:  # the layer's bytes as they are: a copy, row by row
            for r in range(self.TILE):
                b = ti.Vector.zero(ti.i32, 3 * self.TILE)
                for p in range(self.TILE):
                    y, x = self.in_tile(ty, tx, self.TILE * r + p)  # inside the fields: whole tiles
                    c = self.rgb[y, x]
                    self.rgb[y, x] = ti.cast(ti.Vector([0, 0, 0]), self.rgb.dtype)
                    for k in ti.static(range(3)):
                        if ti.static(self.rgb.dtype == ti.u8):
                            b[3 * p + k] = ti.cast(c[k], ti.i32)
                        else:
                            b[3 * p + k] = ti.cast(to_byte(c[k]), ti.i32)
                self.put_row(out, words, ty, tx, r, b, 0)
        return lit

    @ti.func
    def put_row(self, out: ti.template(), words: ti.template(), ty, tx, r, b, at: ti.template()):
        """Row r of tile (ty, tx) into the frame, where it is inside it: its bytes b[at:at + 3 TILE] (pixel by
        pixel, three channels each). Where the frame's width is whole tiles (word_rows) a tile's row is 3 TILE
        bytes at a multiple of 4, so it goes as 6 words (`words`: the frame's rows as uint32; little-endian, as on
        every CPU Taichi targets: byte 0 is a word's lowest) and not 24 bytes, each a store with its own address.
        rigid_chaos's draw_frame 2.82-2.83 → 2.34-2.44 ms a frame, its trails alone on one thread 1.24-1.27 →
        0.93-0.94 ms; the same bytes (`python benchmarks/draw_kernels.py rigid_chaos --seconds 20 [--threads 1
        --set 'effects=["trails"]']`, alternating with the code before, 2-core Xeon, AVX-512, 2026-12-07)."""
        y = (ty << ti.static(self.TILE.bit_length() - 1)) | r
        if y < self.h:
            if ti.static(self.word_rows):
                for j in ti.static(range(3 * self.TILE // 4)):
                    k = ti.static(at + 4 * j)
                    words[y, 3 * self.TILE // 4 * tx + j] = ti.cast(b[k], ti.u32) | (ti.cast(b[k + 1], ti.u32) << 8) | \
                        (ti.cast(b[k + 2], ti.u32) << 16) | (ti.cast(b[k + 3], ti.u32) << 24)
            else:
                for p in range(self.TILE):
                    x = (tx << ti.static(self.TILE.bit_length() - 1)) | p
                    if x < self.w:
                        for k in ti.static(range(3)):
                            out[y, x, k] = ti.cast(b[at + 3 * p + k], ti.u8)

    @ti.func
    def in_tile(self, ty, tx, k):
        """Pixel k (row-major, mod TILE²) of tile (ty, tx), as bits: so LLVM sees that every pixel is in the same
        tile and works out the tile's address once, not per pixel from y // TILE and x // TILE."""
        ti.static_assert(self.TILE & (self.TILE - 1) == 0, "in_tile needs a TILE that is a power of two")
        b = ti.static(self.TILE.bit_length() - 1)
        return (ty << b) | ((k >> b) & (self.TILE - 1)), (tx << b) | (k & (self.TILE - 1))

    @ti.func
    def fade_tile(self, out: ti.template(), words: ti.template(), ty, tx, layer: ti.template()):
        """A tile with a trail, two of its rows (16 pixels) at a time (P): the trail (and the layer) are read into
        arrays on the stack in the fields' own order (pixel by pixel, three channels each), the bytes and the
        faded trail are worked out there, channel by channel, then written back. Only that middle loop touches no
        field or array argument, so it is the one LLVM vectorises (a store through a pointer it cannot tell apart
        from the others keeps a loop over fields scalar); the loops around it have their addresses from
        in_tile(), in bits, so the tile's address is worked out once. rigid_chaos's trails alone, 20 s on one
        thread: 1.35-1.41 ms a frame, against 1.50-1.53 with in_tile() alone and 1.61-1.66 before both (channels
        by row, pixels found from y // TILE and x // TILE), and 2.34 pixel by pixel; the same bytes (`python
        benchmarks/draw_kernels.py rigid_chaos --seconds 20 --threads 1 --set 'effects=["trails"]'`, 2-core Xeon,
        AVX-512, 2026-12-07). The whole tile at once was as quick but slow to compile: a render from an empty
        kernel cache (`TI_OFFLINE_CACHE_FILE_PATH=$(mktemp -d) pendulum render rigid_chaos`) took 23.0 s, two
        rows at a time 20.3 s (15.7-16.4 s on 2026-12-07, before this order and after it alike). A pixel off the
        trail (0) fades to 0: no branch, and dark pixels stay dark."""
        # pixels at a time: two rows, or four where LLVM takes 32 lanes a loop, so that their 96 channels are 3
        # passes; 48 left 16 to the scalar remainder (rigid_chaos's draw_frame at 32 lanes: 1.59-1.61 ms with 48,
        # 1.34-1.38 with 96, 1.38-1.44 at 16 lanes; benchmarks/draw_kernels.py, 2-core AMD EPYC)
        P = ti.static(min(vector_width.lanes(2 * self.TILE), self.TILE * self.TILE))
        N = ti.static(3 * P)  # their channels, in the fields' order (pixel-major): 48 lanes at 16
        any_lit = 0
        for part in range(self.TILE * self.TILE // P):
            c = ti.Vector.zero(self.rgb.dtype, N)
            t = ti.Vector.zero(ti.f32, N)
            if ti.static(layer):
                for p in range(P):
                    y, x = self.in_tile(ty, tx, P * part + p)  # inside the fields: whole tiles
                    v = self.rgb[y, x]
                    for k in ti.static(range(3)):
                        c[3 * p + k] = v[k]
                for p in range(P):
                    y, x = self.in_tile(ty, tx, P * part + p)
                    self.rgb[y, x] = ti.cast(ti.Vector([0, 0, 0]), self.rgb.dtype)
            for p in range(P):
                y, x = self.in_tile(ty, tx, P * part + p)
                v = self.trail[y, x]
                for k in ti.static(range(3)):
                    t[3 * p + k] = v[k]
            b = ti.Vector.zero(ti.i32, N)
            lit = 0
            for j in range(N):  # the loop LLVM vectorises
                if ti.static(layer):
                    if ti.static(self.rgb.dtype == ti.u8):
                        b[j] = ti.cast(c[j], ti.i32)
                    else:
                        b[j] = ti.cast(to_byte(c[j]), ti.i32)
                faded = ti.cast(t[j] * self.decay, ti.f32)
                b[j] = ti.max(b[j], ti.cast(to_byte(t[j]), ti.i32))
                dark = to_byte(faded) == 0
                lit |= ti.cast(not dark, ti.i32)
                t[j] = ti.select(dark, 0.0, faded)
            for p in range(P):
                y, x = self.in_tile(ty, tx, P * part + p)
                self.trail[y, x] = ti.Vector([t[3 * p + k] for k in ti.static(range(3))])
            for r in ti.static(range(P // self.TILE)):
                self.put_row(out, words, ty, tx, P // self.TILE * part + r, b, 3 * self.TILE * r)
            any_lit |= lit
        return any_lit
