"""An offscreen canvas: Taichi kernels that draw each frame straight into a numpy uint8 array.

Its primitives (render/draw/raster.py) are composited with a max per channel, which does not depend on
drawing order, so frames are byte-identical across runs and thread counts. On the CPU each thread draws every
primitive into a band of rows of its own, so no pixel has two writers and the max needs no atomic, then
composes its rows (render/draw/compose.py). A frame is three kernels: the bobs' pixels, the trails' stamp
(with trails) and draw_frame, compiled with the primitives the scene calls for and no others. The pendulums'
view (render/draw/framing.py) holds everything they can ever reach, clear of the HUD's boxes and of what the
caller draws over the frame (keep_clear).
"""
import numpy as np
import taichi as ti

from ..physics import runtime
from . import framing
from .compose import Compose
from .raster import BAND_SLOTS, COILS, Raster

TRAIL_FLOOR = 0.03  # a trail fades to this brightness over video.trail_seconds
TILE = 8  # pixels per tile side for compositing: small enough to hug thin trails, cheap to track (14k at 720p)
# A band of rows per thread pays for its wake-up of the thread pool (runtime.SERIAL_WORK) in a heavy frame only:
# below this many primitives (pendulums x links) times rows, a frame draws on the launching thread. Whole
# frames, ms wall / CPU, in two bands and in one (`python benchmarks/draw_kernels.py PRESET`, 2-core Xeon,
# 2026-12-06): rigid_chaos (144k) 5.83 / 6.86 and 4.99 / 4.99; its GIF's 352x198 frame 2.69 / 2.57 and
# 1.84 / 1.84; triple_chaos (216k) 5.21 / 5.96 and 4.63 / 4.63; rainbow_1000 (1.44M) 8.08 / 9.73 and 10.38 /
# 10.27. And in a render on two cores the encoders hold the other one.
BANDED_WORK = 720_000
# Under a max the layer of rods, coils and bobs holds the bytes they print as (the byte of a max is the max of
# the bytes: raster.to_byte), a quarter of the memory the frame pass and the primitives read and write; False
# keeps floats, as CUDA's atomic max needs (32-bit values). tests/test_canvas.py holds both to the same frames.
BYTE_LAYER = True


@ti.data_oriented
class Canvas(Raster, Compose, runtime.Launcher):
    TILE = TILE  # for its primitives (render/draw/raster.py), its frame pass (compose.py) and glow.py

    def __init__(self, scene, sim, info=None, keep_clear=()):
        """info: what the `hud` effect says beyond the drawing contract (render/draw/hud.py's Info; from the scene
        alone if not given). keep_clear: boxes (x0, y0, x1, y1) of this frame that something else draws over
        (a split-screen panel's label): the pendulums' view keeps clear of them, as of the HUD's."""
        v, self.scene, self.sim = scene.video, scene, sim
        self.w, self.h, self.n = v.width, v.height, sim.n
        self.rods, self.springs, self.bobs_on = scene.has("rods"), scene.has("springs"), scene.has("bobs")
        self.trails = scene.has("trails")
        self.decay = TRAIL_FLOOR ** (1.0 / (v.fps * v.trail_seconds))
        self.rainbow, self.glowing = v.palette == "rainbow", scene.has("glow")
        # The layers (colour, or under glow fixed-point light: render/draw/glow.py) are stored tile by tile: the
        # frame pass reads them a tile at a time, and a steep line walks down a column. Row by row, each of a tile's
        # rows was another page (15 kB apart at 720p): rigid_chaos's frame pass took 1.25x, its rods 1.3x as long.
        self.glow, self.trail_light, light = None, 1.0, ti.f32
        if self.glowing:
            from . import glow
            self.glow, self.gain, self.trail_light = glow.Glow(self.decay), glow.gain(self.n), glow.TRAIL
            light = ti.i32
        self.ty, self.tx = -(-self.h // TILE), -(-self.w // TILE)
        cfg = ti.lang.impl.current_cfg()
        self.banded = cfg.arch != ti.cuda  # else (CUDA) one pendulum per loop iteration, the max atomic
        heavy = self.n * len(sim.LINKS) * self.h >= BANDED_WORK
        self.bands = max(1, cfg.cpu_max_num_threads) if self.banded and heavy else 1
        self.one_band = self.banded and self.bands == 1  # its loops on the launching thread
        self.band_rows = -(-self.ty // self.bands) * TILE  # whole tiles: no tile's mark has two writers
        self.slots = self.bands * BAND_SLOTS if self.banded else self.n
        # the frame pass writes a tile's row as words where the width is whole tiles (compose.py's put_row); not on
        # CUDA, where Taichi copies each array argument back from the device, so two views of one frame would clash
        self.word_rows = self.banded and not self.glowing and self.w % TILE == 0
        self.no_words = np.zeros((1, 1), np.uint32)  # draw_frame's `words` where it writes bytes
        self.few = runtime.serial(self.n * len(sim.LINKS))  # a loop over the points runs serially (SERIAL_WORK)
        # this frame's rods, coils and bobs; zero outside the tiles marked in `drawn` (BYTE_LAYER)
        self.rgb = runtime.field("canvas.frame", ti.u8 if BYTE_LAYER and self.banded and not self.glowing else light,
                                 (self.h, self.w), 3, TILE)
        self.drawn = runtime.field("canvas.frame_tiles", ti.i32, (self.ty, self.tx))
        self.section, area = None, self.w  # the pendulums' width of the frame: all of it, or left of the section
        if scene.has("poincare"):
            from .section import Section
            from ..physics.keys import DRAWN
            area = self.w // 2 if any(scene.has(e) for e in DRAWN) else 0
            self.section = Section(self, scene, sim, area, self.w - area)
        self.area = area or self.w
        self.lw = max(0.6, 0.0011 * self.h)  # half-width of rods, coils and trails in pixels
        self.radii = tuple(max(2.0, 0.013 * self.h * size) for size in sim.bob_sizes())
        # how far a drawing spills past the chain's points: a bob's disc, a line's width (under glow a hairline
        # two pixels wide), a coil's zig-zag (at most the nominal amplitude: a fitted view is never larger)
        nominal = framing.SHARE * min(self.area, self.h) / sim.reach()  # px per metre
        spill = max(self.radii) + 0.5 if self.bobs_on else 0.0  # a disc covers pixels closer than r + 0.5
        pad = max(spill, self.lw + 0.5, 2.0) + 0.5
        pad += 0.035 * nominal * min(sim.lengths) if self.springs else 0.0
        self.hud = None
        if scene.has("hud"):  # imported only when called for: no HUD, no font field, no HUD kernel
            from .hud import Hud, Info
            self.hud = Hud(scene, sim, info or Info.of(scene), self.area, self.h,
                           framing.fit(self.area, self.h, pad))
        # the pendulums' view: their whole reach, clear of the HUD's text and anything else drawn over them
        boxes = list(keep_clear) + (self.hud.boxes if self.hud is not None else [])
        self.view = framing.fit(self.area, self.h, pad, boxes)
        self.cx, self.cy = self.view.cx, self.view.cy
        self.scale = self.view.radius / sim.reach()  # pixels per metre
        self.amp = 0.035 * self.scale * min(sim.lengths)  # coil amplitude
        self.links = sim.LINKS  # the drawing contract: what joins each pair of points of the chain
        self.tip = len(self.links) - 1
        # draw_frame is compiled with the primitives the scene calls for: the kernel log says which
        self.frame_kernel = "draw_frame[" + ",".join(
            e for e, on in (("rods", self.rods), ("springs", self.springs), ("bobs", self.bobs_on)) if on) + "]"
        self.pos = runtime.field("canvas.bobs_px", ti.f32, (self.n, len(self.links)), 2)
        if self.trails:
            self.trail = runtime.field("canvas.trail", light, (self.h, self.w), 3, TILE)
            self.lit = runtime.field("canvas.trail_tiles", ti.i32, (self.ty, self.tx))  # tiles with a visible trail
            self.last = runtime.field("canvas.trail_last_px", ti.f32, self.n, 2)
        self.path, self.follows, self.skipped = None, False, 0  # see follow()
        self.keep_frames()  # the frame drawn last is drawn over without a clear (compose.py)
        self.fps = v.fps
        self.frame_no = 0

    def follow(self, gap: int):
        """For a canvas that draws only some of the frames (the GIF's, render/video/gif.py): skip() on each frame
        it leaves out (at most `gap` in a row) keeps where the last bob is, and the next draw() stamps the path
        through those points into the trails in the same launch, so a trail is the curve the bob drew, not
        chords between drawn frames. Call before the first frame."""
        if self.trails and gap:
            self.path = runtime.field("canvas.trail_path_px", ti.f32, (gap, self.n), 2)
            self.follows = True

    def kernel(self, name: str):
        return self.draw_frame if name == self.frame_kernel else super().kernel(name)

    @property
    def tracing(self) -> bool:
        """Whether skip() keeps anything now: a trail, follow()ed, after the first frame (no path before it)."""
        return self.follows and self.frame_no > 0

    def skip(self):
        """A frame this canvas does not draw (see follow())."""
        if self.tracing:
            if self.skipped == self.path.shape[0]:
                raise ValueError(f"more than {self.skipped} frames skipped in a row: follow() was told fewer")
            self.launch("trail_path_pixels", self.skipped)
            self.skipped += 1

    def restart(self):
        """Back to the first frame: no trail yet."""
        self.frame_no, self.kept = 0, None
        if self.section is not None:
            self.section.restart()
        if self.trails:
            self.trail.fill(0)
            self.lit.fill(0)
        self.skipped = 0

    def new_frame(self) -> np.ndarray:
        """A frame for draw(), which it fills whole."""
        return np.zeros((self.h, self.w, 3), np.uint8)

    def draw(self, out: np.ndarray | None = None, t: float | None = None) -> np.ndarray:
        """The current state of the simulation as an H×W×3 uint8 frame, written into `out` if given.

        t is the simulated time, for the HUD's clock (default: one frame per draw since the start)."""
        out = self.frame_for(out)
        self.launch("bob_pixels")
        if self.trails:
            self.launch("stamp_trails", int(self.frame_no == 0), self.skipped)
            self.skipped = 0
        self.launch(self.frame_kernel, out, self.words(out), self.shown)
        if self.section is not None:
            self.section.draw(out, self.frame_no == 0)
        if self.hud is not None:
            self.hud.draw(out, self.frame_no / self.fps if t is None else t)
        self.frame_no += 1
        return out

    def words(self, out: np.ndarray) -> np.ndarray:
        """`out`'s rows as uint32, the same memory, for draw_frame (word_rows); else a stand-in it never reads."""
        if not self.word_rows:
            return self.no_words
        # a reshape would copy, and the frame would never see the words; a view of other rows would misplace them
        if not out.flags.c_contiguous or out.shape != (self.h, self.w, 3) or out.dtype != np.uint8:
            raise ValueError(f"Canvas.draw: out must be a C-contiguous {self.h}x{self.w}x3 uint8 array")
        return out.reshape(self.h, -1).view(np.uint32)

    # ------------------------------------------------------------ kernels
    @ti.func
    def joint(self, i, j: ti.template()):
        """Where link j of pendulum i starts: the pivot, or the previous bob."""
        a = ti.Vector([self.cx, self.cy], ti.f32)
        if ti.static(j > 0):
            a = self.pos[i, j - 1]
        return a

    @ti.func
    def pixel(self, pts, j: ti.template()):
        """Point j of a chain (pts, world metres) in pixels, y down."""
        return ti.Vector([self.cx + self.scale * pts[j, 0], self.cy - self.scale * pts[j, 1]], ti.f32)

    @ti.kernel
    def bob_pixels(self):
        """The system's chain points in pixels, at frame times only; serial for a few thousand points, less
        work than waking the thread pool."""
        ti.loop_config(serialize=self.few)
        for i in range(self.n):
            pts = self.sim.points(self.sim.q[i])
            for j in ti.static(range(len(self.links))):
                self.pos[i, j] = self.pixel(pts, j)

    @ti.kernel
    def trail_path_pixels(self, slot: ti.i32):
        """Where the last bob is at a skipped frame (follow()), in pixels."""
        ti.loop_config(serialize=self.few)
        for i in range(self.n):
            self.path[slot, i] = self.pixel(self.sim.points(self.sim.q[i]), self.tip)

    @ti.kernel
    def stamp_trails(self, first: ti.i32, skipped: ti.i32):
        """The outer bob's path since the last frame into the trail layer (the frame pass fades it): through
        the points of the `skipped` frames before this one (follow()), then to where it is now."""
        ti.loop_config(serialize=self.one_band)
        for s in range(self.slots):
            w = self.slot(s)
            for i in range(w[0], w[1]):
                p = self.pos[i, self.tip]  # the last bob leaves the trail
                a = p if first else self.last[i]
                c = self.ink(i, 0.9, 0.0) * self.trail_light
                for k in range(skipped + 1):  # one call of segment(), which is inlined: half the code to compile
                    b = p
                    if ti.static(self.follows):
                        if k < skipped:
                            b = self.path[k, i]
                    self.segment(self.trail, self.lit, a, b, self.lw, c, w[2], w[3], True)
                    a = b
        ti.loop_config(serialize=self.few)
        for i in range(self.n):  # after every band has read where the bob was
            self.last[i] = self.pos[i, self.tip]

    @ti.kernel
    def draw_frame(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), words: ti.types.ndarray(dtype=ti.u32, ndim=2),
                   shown: ti.types.ndarray(dtype=ti.i32, ndim=2)):
        """This frame's rods, coils and bobs, as the scene calls for them, composed with the trails into `out`
        (render/draw/compose.py). On the CPU it is one parallel loop: each band's thread draws every primitive
        into its rows, then composes its rows. A parallel loop is a wake-up of the thread pool, about 0.29 ms
        each in rigid_chaos's frame (2-core Xeon; runtime.SERIAL_WORK), which was paid by a kernel per primitive
        and one to compose. On CUDA: a loop over the pendulums (atomic max or adds), then one over the tiles."""
        ti.loop_config(serialize=self.one_band)
        for s in range(self.slots):
            w = self.slot(s)
            for i in range(w[0], w[1]):
                self.primitives(i, w[2], w[3])
            if ti.static(self.banded):
                if s % BAND_SLOTS == 0:  # the band's own slot: its rows are all drawn now
                    self.pivot(w[2], w[3])
                    for ty in range(w[2] // TILE, ti.min(-(-w[3] // TILE), self.ty)):
                        for tx in range(self.tx):
                            self.compose(out, words, shown, ty, tx)
        if ti.static(not self.banded):
            self.pivot(0, self.h)
            for ty, tx in ti.ndrange(self.ty, self.tx):
                self.compose(out, words, shown, ty, tx)

    @ti.func
    def primitives(self, i, y0, y1):
        """Pendulum i's rods, coils and bobs in rows y0 <= y < y1, those the scene calls for."""
        for j in ti.static(range(len(self.links))):
            if ti.static(self.rods and self.links[j] == "rod"):
                self.segment(self.rgb, self.drawn, self.joint(i, j), self.pos[i, j], self.lw,
                             self.ink(i, 0.55, 0.15), y0, y1)
            if ti.static(self.springs and self.links[j] == "spring"):
                a, b = self.joint(i, j), self.pos[i, j]
                for k in range(COILS + 2):
                    self.segment(self.rgb, self.drawn, self.coil_node(a, b, k), self.coil_node(a, b, k + 1),
                                 self.lw, self.ink(i, 0.55, 0.15), y0, y1)
        if ti.static(self.bobs_on):
            for j in ti.static(range(len(self.links))):
                self.disc(self.pos[i, j], self.radii[j], self.ink(i, 1.0, 0.0), y0, y1)

    @ti.func
    def pivot(self, y0, y1):
        if ti.static(self.bobs_on):
            self.disc(ti.Vector([self.cx, self.cy], ti.f32), 3.0, ti.Vector([0.8, 0.8, 0.8]), y0, y1)
