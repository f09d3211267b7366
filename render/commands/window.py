"""The window `pendulum show` plays in: Taichi's legacy ti.GUI on X11 (GGUI would need Vulkan), opened only
after libX11 has shown that a display answers.

Without an X display (no DISPLAY, one that cannot be opened, or one that does not answer within
DISPLAY_TIMEOUT_S) opening fails with NoDisplay, one line that suggests `pendulum render`. The display is
probed with libX11's XOpenDisplay before Taichi is asked for a window: Taichi itself would only fail after
compiling the scene, and it logs its own error line on stderr.
"""
from __future__ import annotations

import ctypes
import os
import sys
import threading
import time

import numpy as np

from ..errors import SceneError

DISPLAY_TIMEOUT_S = 5.0  # a display that has not answered by then will not: a local one answers in ms
# A bare X server (Xvfb) resets when its last client leaves and refuses connections while it does (CI saw
# XOpenDisplay fail on a live Xvfb once); a refusal is retried this long before the display is called absent.
REFUSED_RETRY_S, REFUSED_PAUSE_S = 2.0, 0.05


class NoDisplay(SceneError):
    """No window can be opened here: bad input in the CLI's terms (exit 2, one line)."""


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
    deadline = time.monotonic() + REFUSED_RETRY_S
    conn = open_display(x11, display)
    while conn == 0 and time.monotonic() < deadline:
        time.sleep(REFUSED_PAUSE_S)
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
