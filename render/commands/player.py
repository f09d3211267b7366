"""What `pendulum show`'s keys do and when the next frame is due, apart from any window: the Player, the
FrameSource it plays, and the PNG a saved frame becomes. Tested without a display (tests/test_show.py).
"""
from __future__ import annotations

import struct
import time
import zlib
from pathlib import Path
from typing import Callable, Protocol

import numpy as np

from ..config.options import check_out_folder
from ..errors import SceneError
from ..video.atomic import write_atomic

POLL_S = 1 / 60  # longest wait between looks at the keyboard (keys are read when the window is updated)

# Taichi's names for the keys (ti.GUI.SPACE, ti.GUI.RIGHT, ti.GUI.ESCAPE, ti.GUI.EXIT), checked in window.Window.
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

    def __init__(self, source: FrameSource, fps: float, folder: Callable[[], Path], clock=time.perf_counter):
        """folder(): where s saves a frame, asked at each save (saves_to())."""
        self.source, self.folder, self.clock = source, folder, clock
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
        try:
            folder = self.folder()
        except SceneError as e:
            return f"cannot save: {e}"
        path = folder / f"{self.source.name}_frame_{self.index:05d}.png"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            write_atomic(path, png_bytes(self.frame))
        except OSError as e:
            return f"cannot save {path}: {e.strerror or e}"
        return f"saved {path}"


def saves_to(scene, out: Path) -> Callable[[], Path]:
    """Where s saves `scene`'s frames: where `render` writes it (OUT/NAME/, OUT/NAME__<hash>/ with overrides, a
    comparison's OUT/compare/NAME/), checked as render checks it, again at each save: a symlink put there
    while the window was open could lead out of OUT."""
    def folder() -> Path:
        check_out_folder(scene, out, files=())
        return scene.out_dir(out)
    return folder


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
