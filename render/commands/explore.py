"""`pendulum show MAP_PRESET`: a map to explore, in the window `show` plays presets in (render/commands/show.py).

The map plays as `render` draws it (show's Player: space, →, r, s, q/Esc), and the mouse asks it questions:

- **hover**: the title row shows the start (x, y) of the pixel under the cursor and that pixel's value (its
  flip or divergence time so far, its FTLE);
- **click** a pixel: an inset over the legend's corner plays that pixel's pendulum from its start, drawn by the
  canvas `render` draws fans with (rods, bobs, trails), in the map's precision, looping; its start and value
  in its top left. Its start is read back from the inset's own state and printed:
  "inset: theta1=... theta2=... pixel (c, r): flips at 1.61 s";
- **drag** a box over the plot: zoom. The map is recomputed from t = 0 for the box's ranges (the preset with
  map.x_range and map.y_range overridden, validated as a preset is: in f64 where f32 cannot resolve the pixel
  steps, render/physics/grid.py), and "axes: x theta1 [lo, hi], y theta2 [lo, hi], f64" is printed;
- **b** or **BackSpace**: close the inset, else back to the axes before the last zoom (recomputed).

Taichi holds one runtime per process, which each map starts afresh (so that the last map's fields and kernels are
freed), so a map is never kept for later: going back recomputes it, and an inset is closed by any new map.
"""
from __future__ import annotations

import time

import numpy as np

from ..config.options import output_name
from ..config.scene import from_dict
from ..draw import axes
from ..draw.canvas import Canvas
from ..draw.font import Font
from ..errors import SceneError, SimulationError
from ..maps import fractal
from ..physics import grid, registry, runtime
from ..physics.stepper import Run
from ..video import pipeline
from .player import Player, saves_to, say
from .window import Window

BACK = ("b", "B", "BackSpace")
DRAG_MIN = 4  # pixels: a press and release further apart than this is a box to zoom into, not a click
KEYS_HELP = "click a pixel: its pendulum, drag a box: zoom, b/BackSpace: back"
INK = axes.INK
BOX = (255, 255, 255)


def pixel_scene(scene, start: dict, size: int):
    """One pixel's pendulum as a fan of one, drawn size × size: the map's scene without its map, its axes'
    quantities set to `start`."""
    d = scene.to_dict()
    for key in ("fractal", "map", "budget", "compare"):
        d.pop(key, None)
    d.update(name=f"{scene.name}_pixel", quality=None, effects=["rods", "bobs", "trails"])
    d["pendulums"].update(start, layout="fan", count=1, spread=0.0)
    d["video"].update(width=size, height=size, formats=["mp4"])
    return from_dict(d, f"{scene.source} (pixel)")


class Inset:
    """A pixel's pendulum, played in a corner of the map at its fps, from the start again at the end."""

    def __init__(self, scene, start: dict, size: int, arch: str, threads):
        self.map, self.size = scene, size
        self.scene = pixel_scene(scene, start, size)
        self.run = Run(self.scene, arch, threads, precision=scene.integrator.precision, keep_log=True)
        self.canvas = Canvas(self.scene, self.run.sim)
        self.period = 1.0 / self.scene.video.fps
        self.begin(start, self.run.sim.q.to_numpy(), self.run.sim.v.to_numpy())

    def takes(self, scene, start: dict, size: int) -> bool:
        """Whether this inset can play another pixel of `scene`'s map: one whose axes are angles and rates only
        changes the start, which its kernels do not hold (a length or mass axis is compiled into them), where
        that start is stepped as this one is (dt "auto" and the energy limit follow the start). Taichi never
        frees a Run's fields and kernels: on fractal_flip at 320x180, 20 clicks took 3.0 s and 13 MB more
        resident memory a click with a new inset each, 6 ms and 0.03 MB reusing one (a script not kept)."""
        if scene is not self.map or size != self.size or any(k[:5] not in ("theta", "omega") for k in start):
            return False
        pixel = pixel_scene(self.map, start, self.size)
        self.plan = registry.get(pixel.system)(pixel)  # its plan: no Taichi field
        return (self.plan.h, self.plan.substeps) == (self.run.sim.h, self.run.sim.substeps)

    def move(self, start: dict):
        """Play the pendulum that starts at `start` instead, from its first frame (after takes() said yes)."""
        self.begin(start, *self.plan.initial_state())

    def begin(self, start: dict, q0, v0):
        self.state = (q0, v0)
        q, v = (a.astype(self.run.sim.q.to_numpy().dtype)[0] for a in (q0, v0))  # as it runs
        self.start = {k: float((q if k.startswith("theta") else v)[int(k[5:]) - 1]) for k in start}
        self.restart(time.perf_counter())

    def restart(self, now: float):
        self.run.sim.load(*self.state)
        self.canvas.restart()
        self.steps = self.run.frames()
        self.advance(now)

    def advance(self, now: float):
        index = next(self.steps, None)
        if index is None:  # the end: again from the start
            return self.restart(now)
        self.frame = self.canvas.draw(None, index / self.scene.video.fps)
        self.due = now + self.period

    def tick(self, now: float) -> bool:
        if now < self.due:
            return False
        self.advance(now)
        return True


def value_text(canvas, kind: str, p: int, t: float) -> str:
    """What the map says of pixel p at time t, in words (a supersampled pixel: of its first sample)."""
    p *= canvas.samples  # the pixel's first point (render/maps/fractal.py)
    if kind == "lyapunov":
        return f"σ = {float(canvas.sigma.to_numpy()[p]):.3g} 1/s"
    if kind == "angles":
        q = canvas.sim.q.to_numpy()[p]
        return "θ = (" + ", ".join(f"{x:.3f}" for x in q[:2]) + ")"
    ev = float(canvas.event.to_numpy()[p])
    verb = "parts" if kind == "divergence" else "flips"
    if ev >= 0:
        return f"{verb} at {ev:.3f} s"
    if ev == fractal.NEVER:
        return "cannot flip (energy)"
    return f"not yet at {t:.2f} s"


class Explorer:
    """The map on show, its zoom stack, the inset and the mouse; compose() makes the frame the window shows."""

    def __init__(self, scene, arch: str, threads, out, log=say, name: str | None = None):
        """out: the output root, where s saves a frame as `render` would write the map on show; name: the
        preset's own name, which a zoom's folder starts with (`scene`'s, if not given)."""
        self.arch, self.threads, self.out, self.log, self.name = arch, threads, out, log, name or scene.name
        self.stack = [scene]  # the scenes zoomed into, as given (before validation promotes a zoom to f64)
        self.cursor = self.press = None
        self.changed = True
        self.open(scene)

    @property
    def quit(self) -> bool:
        return self.player.quit

    def open(self, scene):
        self.inset = self.spare = None  # the inset on show, and the one kept for the next click on this map
        # Taichi frees fields and compiled kernels only with its runtime (a kernel of a new object is compiled
        # anew and the old one kept): each map starts a fresh one. `python benchmarks/explore_zooms.py` (60 zooms
        # in and back out, 640x360 fractal_flip, 2-core Xeon, AVX-512): the process grew steadily to 490 MB with
        # one runtime, and levels off at 271 MB after about 30 with a runtime a map. A zoom or a back took 0.3-0.6
        # s against 0.3-0.4 s (a fresh runtime's start, the kernels from the offline cache).
        runtime.forget()
        self.source = pipeline.Source(scene, arch=self.arch, threads=self.threads)
        self.scene, self.lay = self.source.scene, self.source.canvas.lay
        # a zoom is another scene: its frames go where `render` would write it, OUT/NAME__<its hash>/
        named = scene if scene is self.stack[0] else output_name(scene.replace(name=self.name), True)
        self.player = Player(self.source, scene.video.fps, saves_to(named, self.out))
        self.size = self.lay.font or "6x13"  # the decorations' font; a map too small for them: the smaller one
        self.font = self.source.canvas.font or Font(self.size)
        self.axes, self.starts = grid.axes_of(self.scene.map), grid.starts(self.scene)
        (xq, xlo, xhi), (yq, ylo, yhi) = self.axes
        self.log(f"axes: x {xq} [{xlo!r}, {xhi!r}], y {yq} [{ylo!r}, {yhi!r}], {self.scene.integrator.precision}")
        self.changed = True

    # ------------------------------------------------------------ where the mouse is
    def cell(self, at) -> tuple[int, int] | None:
        """The plot's (column, row) under frame pixel `at`, or None off the plot."""
        if at is None:
            return None
        c, r = at[0] - self.lay.x0, at[1] - self.lay.y0
        return (c, r) if 0 <= c < self.lay.w and 0 <= r < self.lay.h else None

    def start_of(self, c: int, r: int) -> dict:
        """The (x, y) start of plot pixel (c, r), to the bit as the map's (grid.starts: row 0 at the top)."""
        x, y = self.starts[r * self.lay.w + c]
        return {self.axes[0][0]: float(x), self.axes[1][0]: float(y)}

    # ------------------------------------------------------------ what the mouse and keys do
    def key(self, key: str):
        if key in BACK:
            return self.back()
        msg = self.player.key(key)
        if msg:
            self.log(msg)

    def mouse(self, kind: str, at: tuple[int, int]):
        """kind: "press", "move" or "release" of the left button (a move without it hovers)."""
        self.cursor, self.changed = at, True
        if kind == "press":
            self.press = at
        elif kind == "release" and self.press is not None:
            start, self.press = self.press, None
            if max(abs(at[0] - start[0]), abs(at[1] - start[1])) >= DRAG_MIN:
                self.zoom(start, at)
            elif self.cell(at):
                self.click(*self.cell(at))

    def click(self, c: int, r: int):
        start = self.start_of(c, r)
        room = min(self.lay.width, self.lay.height) - 2 * max(self.lay.pad, 3) - 2  # inside compose()'s margins
        size = min(max(16, min(self.lay.height // 2, self.lay.width // 3, 360)), room) // 2 * 2
        if size < 16:  # the smallest canvas a pendulum is drawn on
            return self.log(f"inset: a {self.lay.width}x{self.lay.height} map has no room for one")
        if self.spare is not None and self.spare.takes(self.scene, start, size):
            self.spare.move(start)
        else:
            self.spare = Inset(self.scene, start, size, self.arch, self.threads)
        self.inset = self.spare
        self.inset_value = value_text(self.source.canvas, self.scene.fractal, r * self.lay.w + c, self.source.sim.t)
        self.log("inset: " + " ".join(f"{k}={v!r}" for k, v in self.inset.start.items())
                 + f" pixel ({c}, {r}): {self.inset_value}")

    def zoom(self, a, b):
        """Into the box from frame pixel a to b, clipped to the plot, as whole pixels."""
        lay = self.lay
        c0, c1 = sorted(min(max(p[0] - lay.x0, 0), lay.w - 1) for p in (a, b))
        r0, r1 = sorted(min(max(p[1] - lay.y0, 0), lay.h - 1) for p in (a, b))
        (xq, xlo, xhi), (yq, ylo, yhi) = self.axes
        dx, dy = (xhi - xlo) / lay.w, (yhi - ylo) / lay.h
        box = {"x_range": [xlo + c0 * dx, xlo + (c1 + 1) * dx], "y_range": [yhi - (r1 + 1) * dy, yhi - r0 * dy]}
        try:
            scene = self.stack[-1].replace(map=box)
        except SceneError as e:  # e.g. narrower than f64 resolves: the map on show stays
            return self.log(f"zoom: {e}")
        self.log(f"zoom: computing the map for x {box['x_range']}, y {box['y_range']} ...")
        try:
            self.open(scene)
        except (SceneError, SimulationError) as e:  # refused by its certificate or --quality
            self.log(f"zoom: {e}")
            self.open(self.stack[-1])  # which may have restarted Taichi: the map before is recomputed
            return
        self.stack.append(scene)

    def back(self):
        if self.inset is not None:
            self.inset, self.changed = None, True
            self.log("inset closed")
        elif len(self.stack) > 1:
            self.stack.pop()
            self.open(self.stack[-1])
        else:
            self.log("at the preset's own axes")

    # ------------------------------------------------------------ time and the frame
    def tick(self, now: float):
        if self.player.tick(now) or self.player.changed:
            self.player.changed, self.changed = False, True
        if self.inset is not None and self.inset.tick(now):
            self.changed = True

    def wait(self, now: float) -> float:
        w = self.player.wait(now)
        return w if self.inset is None else min(w, max(0.0, self.inset.due - now))

    def compose(self) -> np.ndarray:
        out = self.player.frame.copy()
        lay, texts = self.lay, []
        cw, ch = grid.cell(self.size)
        pad = max(lay.pad, 3)
        if self.inset is not None:
            f = self.inset.frame
            s = f.shape[0]
            x, y = lay.width - s - pad, lay.height - s - pad
            out[y - 1:y + s + 1, x - 1:x + s + 1] = axes.FRAME
            out[y:y + s, x:x + s] = f
            start = " ".join(f"{axes.symbol(k)} {v:.5g}" for k, v in self.inset.start.items())
            texts += [(start, x + 2, y + 2, {}), (self.inset_value, x + 2, y + 2 + ch, {})]  # in its black top
        cell = self.cell(self.cursor)
        if cell:  # over the title row: the pixel under the cursor
            c, r = cell
            start = "  ".join(f"{axes.symbol(k)} {v:.6g}" for k, v in self.start_of(c, r).items())
            value = value_text(self.source.canvas, self.scene.fractal, r * lay.w + c, self.source.sim.t)
            out[:max(lay.y0 - 1, ch + 2), :lay.width - 13 * cw if lay.font else lay.width] = axes.BACKGROUND
            texts.append((f"{start}  {value}", pad, pad if lay.y0 else 1, {}))
        if self.press is not None and self.cursor is not None:
            (xa, ya), (xb, yb) = self.press, self.cursor
            x0, x1, y0, y1 = min(xa, xb), max(xa, xb), min(ya, yb), max(ya, yb)
            out[y0, x0:x1 + 1] = out[y1, x0:x1 + 1] = BOX
            out[y0:y1 + 1, x0] = out[y0:y1 + 1, x1] = BOX
        if texts:
            self.font.draw_many(out, [(s, x, y, {"colour": INK, "size": self.size, **kw}) for s, x, y, kw in texts])
        self.changed = False
        return out


def explore(scene, arch: str, threads, out, suggest: str, log=say, on_open=None, name: str | None = None) -> int:
    """Open the window on the map and run until q/Esc or the window closes; returns the exit code."""
    ex = Explorer(scene, arch, threads, out, log, name)
    win = Window(f"pendulum show: {scene.name}", ex.lay.width, ex.lay.height, suggest=suggest)
    if on_open:
        on_open()
    try:
        log(f"{scene.name}: a map of {ex.lay.w}x{ex.lay.h} pixels, {scene.frames} frames | {KEYS_HELP}")
        while win.open and not ex.quit:
            for kind, key, at in win.events():
                if kind == "key":
                    ex.key(key)
                else:
                    ex.mouse(kind, at)
                if ex.quit:
                    break
            ex.tick(time.perf_counter())
            if ex.changed:
                win.blit(ex.compose())
            win.update()
            time.sleep(ex.wait(time.perf_counter()))
    finally:
        win.close()
    return 0
