"""`pendulum show`: a live window playing a preset, frame for frame what `pendulum render` encodes.

Three parts, kept apart so each can change alone:

- a **frame source** (the `FrameSource` protocol below) produces the frames: `pipeline.Source`, the very
  object `pendulum render` draws its frames with;
- a **Player** decides what the keys do and when the next frame is due. It knows nothing of windows, so it is
  tested without a display;
- the **window** is Taichi's legacy `ti.GUI` (X11; GGUI would need Vulkan). Frames are copied straight into
  its pixel buffer, so the window shows the video's pixels exactly, unscaled.

Keys: space pauses and resumes (at the end it plays again from the start), → shows exactly one more frame
(and pauses), r restarts from t = 0, s saves the frame on screen as OUT/NAME/NAME_frame_<index>.png, q or Esc
(or closing the window) quits with exit 0. Playback is paced at the preset's fps, or as fast as frames come
when they come slower. At the end of the video the last frame stays up.

Without an X display (no DISPLAY, one that cannot be opened, or one that does not answer within
DISPLAY_TIMEOUT_S) the command exits 2 with one line that suggests `pendulum render`. This is checked with
libX11's XOpenDisplay before Taichi is asked for a window: Taichi itself would only fail after compiling the
scene, and it logs its own error line on stderr.
"""
from __future__ import annotations

import argparse
import ctypes
import os
import shlex
import struct
import sys
import threading
import time
import zlib
from pathlib import Path
from typing import Protocol

import numpy as np

from ..video import pipeline
from ..video.atomic import write_atomic
from ..errors import SceneError
from ..config.options import add_common, add_quality, thread_count
from ..config.scene import load

DISPLAY_TIMEOUT_S = 5.0  # a display that has not answered by then will not: a local one answers in ms
POLL_S = 1 / 60  # longest wait between looks at the keyboard (keys are read when the window is updated)

# Taichi's names for the keys (ti.GUI.SPACE, ti.GUI.RIGHT, ti.GUI.ESCAPE, ti.GUI.EXIT), checked in open_window.
ACTIONS = {" ": "pause", "Right": "step", "r": "restart", "R": "restart", "s": "save", "S": "save",
           "q": "quit", "Q": "quit", "Escape": "quit", "WMClose": "quit"}
KEYS_HELP = "space pause/play, → one frame, r restart, s save PNG, q/Esc quit"


class NoDisplay(SceneError):
    """No window can be opened here: bad input in the CLI's terms (exit 2, one line)."""


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


# ------------------------------------------------------------------ the window
class XConnection:
    """An open libX11 connection, held until the window is up: a bare X server (Xvfb) resets when its last
    client leaves, and a connection attempt during that reset fails (seen as ti.GUI failing now and then)."""

    def __init__(self, x11, conn):
        self.x11, self.conn = x11, conn

    def close(self):
        if self.conn:
            self.x11.XCloseDisplay(self.conn)
            self.conn = None


def check_display(suggest: str) -> XConnection:
    """Raise NoDisplay (one line, suggesting `suggest`) unless an X display can be opened; returns the
    connection, to be closed once the window is open.

    Probed with libX11's XOpenDisplay, which fails quietly and at once; Taichi already links libX11.
    """
    display, wayland = os.environ.get("DISPLAY"), os.environ.get("WAYLAND_DISPLAY")
    hint = f"to write the video instead: {suggest}"
    if not display:
        if wayland:
            raise NoDisplay(f"show: the window needs X11 and DISPLAY is not set (WAYLAND_DISPLAY={wayland}: "
                            f"start XWayland); {hint}")
        raise NoDisplay(f"show: no display (DISPLAY is not set); {hint}")
    try:
        x11 = ctypes.CDLL("libX11.so.6")
    except OSError:
        raise NoDisplay(f"show: libX11 is not installed (Debian: apt-get install libx11-6); {hint}") from None
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    conn = open_display(x11, display)
    if conn is None:
        raise NoDisplay(f"show: display {display!r} did not answer within {DISPLAY_TIMEOUT_S:g} s; {hint}")
    if not conn:
        raise NoDisplay(f"show: cannot open display {display!r}; {hint}")
    return XConnection(x11, conn)


def open_display(x11, display: str, timeout: float = DISPLAY_TIMEOUT_S):
    """XOpenDisplay's answer (0 when it fails), or None when none came within `timeout`.

    XOpenDisplay waits without end on a server that accepts the connection and never answers, and while it
    waits in C no Python signal handler runs: SIGTERM would be ignored. So it runs in a daemon thread while
    this one waits, interruptibly; one still waiting when the process exits is simply dropped with it.
    """
    result = []
    opener = threading.Thread(target=lambda: result.append(x11.XOpenDisplay(display.encode())),
                              name="XOpenDisplay", daemon=True)
    opener.start()
    opener.join(timeout)
    return (result[0] or 0) if result else None


class quiet_fds:
    """Send fds 1 and 2 to /dev/null for a block: Taichi's C++ logger writes there directly."""

    def __enter__(self):
        sys.stdout.flush()
        sys.stderr.flush()
        self.saved = [os.dup(1), os.dup(2)]
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        os.close(null)

    def __exit__(self, *exc):
        for fd, saved in zip((1, 2), self.saved):
            os.dup2(saved, fd)
            os.close(saved)


class Window:
    """A ti.GUI window of the video's size, in fast mode: its pixel buffer is one uint32 0x00RRGGBB per
    pixel, row 0 at the top (taichi 1.7.4, Linux; the project pins that version). A frame is copied into it
    channel by channel, about 1 ms at 720p, against some 20 ms for set_image's float conversion."""

    def __init__(self, title: str, width: int, height: int, suggest: str):
        import taichi as ti

        assert (ti.GUI.SPACE, ti.GUI.RIGHT, ti.GUI.ESCAPE, ti.GUI.EXIT) == (" ", "Right", "Escape", "WMClose")
        self.press, self.release, self.motion, self.lmb = ti.GUI.PRESS, ti.GUI.RELEASE, ti.GUI.MOTION, ti.GUI.LMB
        self.size = (width, height)
        try:
            with quiet_fds():
                self.gui = ti.GUI(title, res=(width, height), fast_gui=True)
        except RuntimeError:  # "Taichi fails to create a window"
            raise NoDisplay(f"show: cannot open a window on display {os.environ.get('DISPLAY')!r}; "
                            f"to write the video instead: {suggest}") from None
        buf = self.gui.img
        if not (buf.dtype == np.uint32 and buf.size == width * height and sys.byteorder == "little"):
            self.gui.close()
            raise RuntimeError("ti.GUI's fast buffer is not the expected uint32 per pixel (taichi 1.7.4)")
        self.gui.fps_limit = None  # the Player paces frames
        self.pixels = buf.view(np.uint8).reshape(height, width, 4)  # bytes B, G, R, 0 per pixel

    @property
    def open(self) -> bool:
        return self.gui is not None and self.gui.running

    def keys(self):
        return [e.key for e in self.gui.get_events(self.press)]

    def events(self):
        """Keys pressed and the left button's moves since the last update: ("key", name, at), or ("press" |
        "move" | "release", "LMB", at), at the frame pixel (x, y) under the cursor, row 0 at the top. Taichi
        gives (x / w, (h − 1 − y) / h) in f32 (taichi 1.7.4, X11; tests/test_explore.py clicks known pixels)."""
        w, h = self.size
        out = []
        for e in self.gui.get_events():
            at = (min(max(round(e.pos[0] * w), 0), w - 1), min(max(h - 1 - round(e.pos[1] * h), 0), h - 1))
            if e.key == self.lmb and e.type in (self.press, self.release):
                out.append(("press" if e.type == self.press else "release", e.key, at))
            elif e.type == self.motion:
                out.append(("move", e.key, at))
            elif e.type == self.press:
                out.append(("key", e.key, at))
        return out

    def blit(self, frame: np.ndarray):
        for c in range(3):
            self.pixels[..., 2 - c] = frame[..., c]

    def update(self):
        self.gui.show()  # puts the buffer on screen and collects the X events

    def close(self):
        if self.gui is not None:
            self.gui.close()
            self.gui = None


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
