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
with trails trail, lit, decay), compositing (glowing, glow) and HUD.
"""
import numpy as np
import taichi as ti

from ..physics import runtime
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
        self.shown = runtime.field("canvas.frame_shown", ti.i32, (self.ty, self.tx))  # may hold light
        self.shown.from_numpy(over)

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
    def compose(self, out: ti.template(), ty, tx):
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
                self.lit[ty, tx] = self.tile(out, ty, tx, True, True)
            elif lit:
                self.lit[ty, tx] = self.tile(out, ty, tx, False, True)
            elif drawn:
                self.tile(out, ty, tx, True, False)
        elif drawn:
            self.tile(out, ty, tx, True, False)
        if not (drawn or lit) and self.shown[ty, tx]:
            for y, x in ti.ndrange((ty * self.TILE, ti.min(ty * self.TILE + self.TILE, self.h)),
                                   (tx * self.TILE, ti.min(tx * self.TILE + self.TILE, self.w))):
                for k in ti.static(range(3)):
                    out[y, x, k] = ti.u8(0)
        self.shown[ty, tx] = drawn | lit | self.hud_tiles[ty, tx]
        self.drawn[ty, tx] = 0

    @ti.func
    def tile(self, out: ti.template(), ty, tx, layer: ti.template(), trail: ti.template()):
        lit = 0
        if ti.static(not self.glowing):
            lit = self.compose_tile(out, ty, tx, layer, trail)
        else:
            lit = self.glow.compose_tile(self, out, ty, tx, layer, trail)
        return lit

    @ti.func
    def compose_tile(self, out: ti.template(), ty, tx, layer: ti.template(), trail: ti.template()):
        """One tile; returns whether any trail in it is still visible after fading. The max of the layer's and
        the trail's bytes, which is the byte of their max."""
        lit = 0
        for y in range(ty * self.TILE, ti.min(ty * self.TILE + self.TILE, self.h)):
            for x in range(tx * self.TILE, ti.min(tx * self.TILE + self.TILE, self.w)):
                b = ti.Vector([0, 0, 0], ti.i32)
                if ti.static(layer):
                    c = self.rgb[y, x]
                    self.rgb[y, x] = ti.cast(ti.Vector([0, 0, 0]), self.rgb.dtype)
                    for k in ti.static(range(3)):
                        if ti.static(self.rgb.dtype == ti.u8):
                            b[k] = ti.cast(c[k], ti.i32)
                        else:
                            b[k] = ti.cast(to_byte(c[k]), ti.i32)
                if ti.static(trail):
                    t = self.trail[y, x]
                    if t.max() > 0.0:  # most pixels of a lit tile are off the trail: nothing to fade
                        faded = ti.cast(t * self.decay, ti.f32)
                        for k in ti.static(range(3)):
                            b[k] = ti.max(b[k], ti.cast(to_byte(t[k]), ti.i32))
                            if to_byte(faded[k]) == 0:
                                faded[k] = 0.0
                            else:
                                lit = 1
                        self.trail[y, x] = faded
                for k in ti.static(range(3)):
                    out[y, x, k] = ti.cast(b[k], ti.u8)
        return lit
