"""`pendulum show`: a live window playing a preset, frame for frame what `pendulum render` encodes.

Three parts, kept apart so each can change alone:

- a **frame source** (the `FrameSource` protocol below) produces the frames: `pipeline.Source`, the very
  object `pendulum render` draws its frames with;
- a **Player** decides what the keys do and when the next frame is due. It knows nothing of windows, so it is
  tested without a display;
- the **window** (render/commands/window.py) is Taichi's legacy `ti.GUI` (X11; GGUI would need Vulkan). Frames
  are copied straight into its pixel buffer, so the window shows the video's pixels exactly, unscaled.

A map preset (one with `fractal`) is explored instead of only played: render/commands/explore.py.

Keys: space pauses and resumes (at the end it plays again from the start), → shows exactly one more frame
(and pauses), r restarts from t = 0, s saves the frame on screen as OUT/NAME/NAME_frame_<index>.png, q or Esc
(or closing the window) quits with exit 0. Playback is paced at the preset's fps, or as fast as frames come
when they come slower. At the end of the video the last frame stays up.

Without an X display the command exits 2 with one line that suggests `pendulum render`, before anything is
compiled (window.check_display).
"""
from __future__ import annotations

import argparse
import shlex
import struct
import time
import zlib
from pathlib import Path
from typing import Protocol

import numpy as np

from ..video import pipeline
from ..video.atomic import write_atomic
from ..config.options import add_common, add_quality, thread_count
from ..config.scene import load
from .window import DISPLAY_TIMEOUT_S, Window, check_display  # noqa: F401 - the display timeout is show's to tell

POLL_S = 1 / 60  # longest wait between looks at the keyboard (keys are read when the window is updated)

# Taichi's names for the keys (ti.GUI.SPACE, ti.GUI.RIGHT, ti.GUI.ESCAPE, ti.GUI.EXIT), checked in open_window.
ACTIONS = {" ": "pause", "Right": "step", "r": "restart", "R": "restart", "s": "save", "S": "save",
           "q": "quit", "Q": "quit", "Escape": "quit", "WMClose": "quit"}
KEYS_HELP = "space pause/play, → one frame, r restart, s save PNG, q/Esc quit"



class FrameSource(Protocol):
    """What the window plays. After reset(), next_frame() returns frame 0, then 1, ... up to frames - 1.

    - name: str, the scene's name (window title, file names);
    - frames: int, the number of frames in the video (frame 0 is t = 0);
    - index: int, the frame number of the frame next_frame() last returned (-1 right after reset());
    - reset(): back to t = 0 and the same initial state, so the frames repeat exactly;
    - next_frame() -> np.ndarray: the frame at index + 1 as H x W x 3 uint8 (row 0 at the top, RGB), the same
      pixels `pendulum render` encodes for that frame; then index is that frame's number. Never called when
      index == frames - 1. The array may be reused by the following call, so it is read before that.
    """

    name: str
    frames: int
    index: int

    def reset(self) -> None: ...

    def next_frame(self) -> np.ndarray: ...


# ------------------------------------------------------------------ the player: keys and pacing, no window
class Player:
    """Which frame is up, paused or playing, and when the next frame is due. Times come from `clock`."""

    def __init__(self, source: FrameSource, fps: float, save_dir: Path, clock=time.perf_counter):
        self.source, self.save_dir, self.clock = source, Path(save_dir), clock
        self.period = 1.0 / fps if fps > 0 else 0.0
        self.paused = False
        self.quit = False
        self.frame: np.ndarray | None = None
        self.changed = False  # a new frame since the window last copied one
        self.restart()

    @property
    def index(self) -> int:
        return self.source.index

    @property
    def at_end(self) -> bool:
        return self.source.index >= self.source.frames - 1

    def restart(self):
        self.source.reset()
        self._advance(self.clock())

    def _advance(self, now: float):
        self.frame = self.source.next_frame()
        self.changed = True
        self.due = now + self.period

    def key(self, key: str) -> str | None:
        """React to a key press (Taichi's key name); returns a line for the user, if any."""
        action = ACTIONS.get(key)
        if action == "quit":
            self.quit = True
        elif action == "pause":
            if self.at_end:  # the end holds the last frame; space plays the video again
                self.paused = False
                self.restart()
                return "playing from the start"
            self.paused = not self.paused
            if not self.paused:
                self.due = self.clock() + self.period
                return "playing"
            return f"paused at frame {self.index}/{self.source.frames - 1}"
        elif action == "step":
            self.paused = True
            if not self.at_end:
                self._advance(self.clock())
            return f"frame {self.index}/{self.source.frames - 1}"
        elif action == "restart":
            self.restart()
            return "restarted" + (" (paused)" if self.paused else "")
        elif action == "save":
            return self.save()
        return None

    def tick(self, now: float) -> bool:
        """Advance if playing and the next frame is due; returns whether it did."""
        if self.paused or self.at_end or now < self.due:
            return False
        late = now - self.due
        due = self.due + self.period if late < self.period else now + self.period  # behind: re-anchor
        self._advance(now)
        self.due = due
        return True

    def wait(self, now: float) -> float:
        """Seconds to sleep before the next look at keys and clock."""
        if self.paused or self.at_end:
            return POLL_S
        return min(POLL_S, max(0.0, self.due - now))

    def save(self) -> str:
        name = self.source.name
        path = self.save_dir / name / f"{name}_frame_{self.index:05d}.png"
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(path, png_bytes(self.frame))
        except OSError as e:
            return f"cannot save {path}: {e.strerror or e}"
        return f"saved {path}"


def png_bytes(frame: np.ndarray) -> bytes:
    """An H x W x 3 uint8 frame as an 8-bit RGB PNG (zlib only; no imaging library at run time)."""
    h, w, _ = frame.shape
    rows = np.empty((h, 1 + 3 * w), np.uint8)
    rows[:, 0] = 1  # filter "Sub" on every row: mostly-black frames with smooth edges compress well
    flat = frame.reshape(h, 3 * w)
    rows[:, 1:4] = flat[:, :3]
    np.subtract(flat[:, 3:], flat[:, :-3], out=rows[:, 4:])  # uint8 wraps mod 256, as the PNG spec wants

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) + chunk(b"IEND", b""))


def say(line: str):
    print(line, flush=True)  # as it happens, also when stdout is a pipe


def play(source: FrameSource, fps: float, save_dir: Path, suggest: str, log=say, on_open=None) -> int:
    """Open the window and run until q/Esc or the window closes; returns the exit code."""
    player = Player(source, fps, save_dir)
    win = Window(f"pendulum show: {source.name}", *player.frame.shape[1::-1], suggest=suggest)
    if on_open:
        on_open()
    try:
        log(f"{source.name}: {source.frames} frames at {fps:g} fps | {KEYS_HELP}")
        while win.open and not player.quit:
            for key in win.keys():
                msg = player.key(key)
                if msg:
                    log(msg)
                if player.quit:
                    break
            player.tick(player.clock())
            if player.changed:
                win.blit(player.frame)
                player.changed = False
            win.update()
            time.sleep(player.wait(player.clock()))
    finally:
        win.close()
    return 0


# ------------------------------------------------------------------ CLI
def add_parser(sub):
    s = sub.add_parser(
        "show", help="play a preset live in a window (space, →, r, s, q)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Play PRESET in a window, frame for frame what `pendulum render` writes, drawn by the\n"
                    "same canvas and paced at the preset's fps. Needs an X display (DISPLAY); without one it\n"
                    "exits 2 and suggests the `pendulum render` command instead.",
        epilog="keys:\n"
               "  space     pause / play (at the end: play again from the start)\n"
               "  →         one frame more, and pause\n"
               "  r         restart from t = 0\n"
               "  s         save the frame on screen to OUT/NAME/NAME_frame_<index>.png\n"
               "  q, Esc    quit (so does closing the window)\n"
               "At the end of the video the last frame stays up.\n"
               "A map (a preset with `fractal`) is explored with the mouse:\n"
               "  hover     the title row shows the pixel's start and value\n"
               "  click     an inset plays that pixel's pendulum\n"
               "  drag      zoom into the box (the map is recomputed; in f64 where f32 cannot resolve it)\n"
               "  b, BackSpace  close the inset, else back to the axes before the last zoom")
    s.add_argument("preset", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    add_common(s)
    s.add_argument("--out", type=Path, default=Path("out"), help="where s saves frames (default: out)")
    add_quality(s)
    s.add_argument("--threads", type=thread_count, default=None, help="CPU threads for Taichi (default: all cores)")
    s.set_defaults(func=run)


def render_command(args) -> str:
    """The `pendulum render` line that writes what this `show` would have played."""
    parts = ["pendulum", "render", args.preset]
    for o in args.overrides:
        parts += ["--set", o]
    if args.quality:
        parts += ["--quality", args.quality]
    return shlex.join(parts)


def run(args) -> int:
    scene = load(args.preset, args.overrides, args.quality)
    suggest = render_command(args)
    probe = check_display(suggest)  # before any compiling: a missing display fails at once
    try:
        if scene.fractal:  # a map to explore: click, zoom, back (render/commands/explore.py)
            from .explore import explore
            return explore(scene, args.arch, args.threads, args.out, suggest, on_open=probe.close)
        source = pipeline.open_source(scene, arch=args.arch, threads=args.threads)  # a comparison: split screen
        return play(source, scene.video.fps, args.out, suggest, on_open=probe.close)
    finally:
        probe.close()
