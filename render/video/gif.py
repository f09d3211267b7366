"""The GIF's own frames: drawn by the render's canvas at the GIF's size and rate, not shrunk from the video's.

A 720p frame area-averaged down to 352 px turns its 6x13 and 10x20 text into grey mush and its one-pixel rods
into faint smears. So, where the GIF's size or rate is not the video's, a second canvas of the GIF's size
draws the same simulation (the same System, the same states: nothing is simulated twice) for the frames the
GIF keeps, with a HUD laid out for that height (render/draw/hud_text.py picks its font by the frame's height) and
trails that fade per GIF frame at the preset's trail_seconds. The frames the GIF skips still leave their
stretch of the path in its trails, so a trail is the curve the bob drew, not chords between GIF frames: the
canvas keeps where the last bob was at each (Canvas.follow) and stamps them with the next frame it draws.

A comparison's GIF is a second split screen at the GIF's size drawn from the first one's recorded runs.
A map's pixels are its pendulums, so a second map would be a second simulation: a map's GIF frame is the
video's frame area-averaged (render/video/downscale.py). So is a frame with a Poincaré section (its crossings
are read once per video frame) and any frame a caller hands the Encoder without a GIF frame of its own.

Which video frames the GIF keeps is ffmpeg's fps filter's choice, made here (repeats) so the pipe carries only
those.
"""
from __future__ import annotations

import dataclasses
import math
import time
from fractions import Fraction

import numpy as np


def rate(video) -> int:
    return min(video.gif_fps, video.fps)


def size(video) -> tuple[int, int]:
    """(width, height) of the GIF: gif_width (never upscaled), the height by the frame's aspect, even."""
    w = min(video.gif_width, video.width)
    return w, max(2, round(video.height * w / video.width / 2) * 2)


def _near(x: Fraction) -> int:
    return math.floor(x + Fraction(1, 2))  # ffmpeg's AV_ROUND_NEAR_INF, for x >= 0


def repeats(video, frames: int) -> list[int]:
    """How many GIF frames each video frame becomes (mostly 0 or 1): the GIF's frames are picked here and only
    those are piped, instead of every frame for ffmpeg's fps filter to drop (2/3 of the pipe at 60 -> 20 fps).
    The picks are that filter's (eof_action=pass): GIF frame k shows the last video frame whose time, rounded
    to the GIF's clock, is at most k, for k < ceil(frames·gif/fps) (checked against ffmpeg for 90 rate and
    length pairs: tests/test_encode.py)."""
    r = Fraction(rate(video), video.fps)
    slots = math.ceil(frames * r)
    starts = [_near(i * r) for i in range(frames)] + [slots]  # the last frame fills the slots up to the end
    return [max(0, min(starts[i + 1], slots) - starts[i]) for i in range(frames)]


def gap(repeats: list[int]) -> int:
    """The most video frames in a row that the GIF skips."""
    run = most = 0
    for n in repeats:
        run = 0 if n else run + 1
        most = max(most, run)
    return most


class _Canvas:
    """A fan's GIF: a second Canvas of the GIF's size over the render's own System."""

    def __init__(self, src, w: int, h: int, fps: int, skips: int):
        from ..draw.canvas import Canvas
        from ..draw.hud import Info

        v = src.scene.video
        small = dataclasses.replace(src.scene, video=dataclasses.replace(v, width=w, height=h, fps=fps))
        self.fps = v.fps
        info = dataclasses.replace(Info.of(src.scene, src.sim.h, src.cert), one_line=True)
        self.canvas = Canvas(small, src.sim, info)
        self.canvas.follow(skips)

    def skip(self, f: int):
        self.canvas.skip()

    def draw(self, f: int) -> np.ndarray:
        return self.canvas.draw(None, f / self.fps)


def _split(src, w: int, h: int, fps: int, skips: int):
    """A comparison's GIF: a SplitScreen of the GIF's size sharing the video's recorded runs (pass 1 is not run
    again), its panels drawn at the GIF's rate with the video's clock."""
    from ..draw.split import Replay, SplitScreen, layout
    from ..draw.split_text import LARGE, label_band

    class Panel(Replay):
        def next_frame(self, out=None):
            self.index += 1
            self.sim.q.from_numpy(self.q[self.index])
            return self.canvas.draw(out, self.index / src.scene.video.fps)

        def skip(self, f: int):
            if self.canvas.tracing:  # else there is nothing to keep (and from_numpy is a launch too)
                self.sim.q.from_numpy(self.q[f])
                self.canvas.skip()

    class Split(SplitScreen):
        def __init__(self):  # the video's split screen did SplitScreen.__init__'s work: share it
            vars(self).update(vars(src))
            self.scene = dataclasses.replace(src.scene, video=dataclasses.replace(src.scene.video, width=w, height=h))
            self.rects = layout(w, h, len(self.runs))
            # in the video's runtime (the same arch and threads: nothing restarts), adding to its kernel log
            self.panels = [Panel(sized(run["scene"], pw, ph), run["q"], run["cert"], src.arch, src.threads,
                                 keep_log=True, keep_clear=[(0, 0, pw - 1, label_band(self.scene, ph) - 1)])
                           for run, (_, _, pw, ph) in zip(self.runs, self.rects)]
            for p in self.panels:
                p.canvas.follow(skips)
            self.buffers = [p.canvas.new_frame() for p in self.panels]
            self.size = "10x20" if self.rects[0][3] >= LARGE else "6x13"
            self.timings = {"draw": 0.0}

        def skip(self, f: int):
            for p in self.panels:
                p.skip(f)

        def draw(self, f: int) -> np.ndarray:
            self.index = f - 1
            for p in self.panels:
                p.index = f - 1
            return self.next_frame()

    def sized(scene, pw, ph):
        return dataclasses.replace(scene, video=dataclasses.replace(scene.video, width=pw, height=ph, fps=fps))

    return Split()


class Frames:
    """The GIF's frames of a frame source (pipeline.Source or a SplitScreen): frame(f, video_frame) gives the
    GIF's frame for video frame f, or None where the GIF skips f. Its drawing time goes to timings["draw"]."""

    def __init__(self, src, video, timings: dict):
        self.repeats, self.timings = repeats(video, src.frames), timings
        self.w, self.h = size(video)
        self.own = None  # None: the video's frames, area-averaged
        scene, fps = src.scene, rate(video)
        if ((self.w, self.h), fps) != ((video.width, video.height), video.fps) and not scene.fractal \
                and not scene.has("poincare"):
            own = _split if scene.compare else _Canvas
            self.own = own(src, self.w, self.h, fps, gap(self.repeats))
        # A fan's GIF canvas reads only the System's state: a render of the GIF alone need not draw the video's
        # frames at all (a comparison's GIF panels replay what the video's split screen records as it draws).
        self.alone = isinstance(self.own, _Canvas)

    def frame(self, f: int, video_frame: np.ndarray | None) -> np.ndarray | None:
        t = time.perf_counter()
        out = None
        if self.own is None:
            if self.repeats[f]:
                from .downscale import shrink  # Taichi: not for a plan (it imports this module)
                out = shrink(video_frame, self.w, self.h)
        elif self.repeats[f]:
            out = self.own.draw(f)
        else:
            self.own.skip(f)
        self.timings["draw"] += time.perf_counter() - t
        return out
