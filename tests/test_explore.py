"""`pendulum show MAP_PRESET`: the Explorer without a window (a click's inset, a box's zoom, back), and the real
window under Xvfb, driven by xdotool: a click opens an inset whose pendulum starts at the clicked pixel's
(θ1, θ2), a dragged box zooms to exactly the box's pixels, and b goes back.

Needs (Debian): apt-get install -y xvfb xdotool; skipped cleanly without them (the xvfb fixture of test_show).
Without a display at all, show of a map fails as show of any preset does: tests/test_show.py.
"""
import math
import queue
import re
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from conftest import ROOT
from render.commands.explore import Explorer
from render.config.options import output_name
from render.config.scene import load
from render.draw import axes
from render.physics import grid
from test_show import env_without_display, grab_window, xdotool, xvfb  # noqa: F401 - xvfb is a fixture

W, H = 256, 144
SETS = [f"video.width={W}", f"video.height={H}", "video.fps=10", "video.duration=3", 'video.formats=["mp4"]']
AXES = re.compile(r"axes: x (\w+) \[(\S+), (\S+)\], y (\w+) \[(\S+), (\S+)\], (f32|f64)")


class Lines:
    """show's stdout, line by line, read in a thread so that waiting for one never blocks the test."""

    def __init__(self, proc):
        self.proc, self.q, self.seen = proc, queue.Queue(), []
        threading.Thread(target=lambda: [self.q.put(line.rstrip("\n")) for line in proc.stdout], daemon=True).start()

    def wait(self, pattern, timeout=60.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self.q.get(timeout=0.2)
            except queue.Empty:
                if self.proc.poll() is not None:
                    pytest.fail(f"show exited ({self.proc.returncode}): {self.proc.stderr.read()} {self.seen}")
                continue
            self.seen.append(line)
            m = re.search(pattern, line)
            if m:
                return m
        pytest.fail(f"timed out waiting for {pattern!r}; saw {self.seen}")


def test_the_explorer_without_a_window(tmp_path):
    """On a 64x64 map (all plot, no decorations): hover, click, drag and b, as the window would pass them."""
    said = []
    scene = load("fractal_flip", ["video.width=64", "video.height=64", "video.fps=10", "video.duration=1"])
    ex = Explorer(scene, "cpu", None, tmp_path, log=said.append)
    assert (ex.lay.x0, ex.lay.y0, ex.lay.w, ex.lay.h) == (0, 0, 64, 64)
    ex.mouse("move", (10, 50))
    frame = ex.compose()
    assert frame.shape == (64, 64, 3) and (frame[:14].max(-1) > 150).any()  # the hover caption
    ex.mouse("press", (40, 8))
    ex.mouse("release", (41, 9))  # a click: under DRAG_MIN apart
    q, v = ex.inset.run.sim.q.to_numpy()[0], ex.inset.run.sim.v.to_numpy()[0]
    step = 2 * np.pi / 64
    assert np.allclose(q, [-np.pi + 41.5 * step, np.pi - 9.5 * step], rtol=2e-7) and not v.any()  # f32
    assert said[-1].startswith("inset: theta1=") and "pixel (41, 9)" in said[-1]
    size, at = ex.inset.frame.shape[0], 64 - 3 - ex.inset.frame.shape[0]  # bottom right, 3 px in
    out = ex.compose()
    assert (out[at - 1, at:at + size] == axes.FRAME).all() and (out[at:at + size, at - 1] == axes.FRAME).all()
    assert (out[at:at + size, at:at + size] != ex.player.frame[at:at + size, at:at + size]).any()
    ex.key("b")
    assert ex.inset is None and said[-1] == "inset closed"
    ex.mouse("press", (8, 40))
    ex.mouse("move", (23, 55))
    assert (ex.compose()[40, 8:24] == 255).all()  # the box being dragged
    ex.mouse("release", (23, 55))
    (xq, xlo, xhi), (yq, ylo, yhi) = grid.axes_of(ex.scene.map)
    assert np.allclose([xlo, xhi, ylo, yhi], [-np.pi + 8 * step, -np.pi + 24 * step, np.pi - 56 * step,
                                              np.pi - 40 * step], rtol=0, atol=1e-12)
    assert len(ex.stack) == 2 and ex.scene.integrator.precision == "f32"
    said_s = ex.player.key("s")  # a zoom is another scene: saved where `render` would write it, given its box
    box = [f"map.{k}=[{lo!r}, {hi!r}]" for k in ("x_range", "y_range") for lo, hi in [getattr(ex.stack[-1].map, k)]]
    zoomed = output_name(load("fractal_flip", ["video.width=64", "video.height=64", "video.fps=10",
                                               "video.duration=1", *box]), True)
    assert said_s.startswith(f"saved {tmp_path / zoomed.name / 'fractal_flip_frame_'}"), (said_s, zoomed.name)
    ex.key("b")
    assert ex.player.key("s").startswith(f"saved {tmp_path / 'fractal_flip' / 'fractal_flip_frame_'}")
    assert len(ex.stack) == 1 and grid.axes_of(ex.scene.map) == grid.axes_of(scene.map)
    ex.key("b")
    assert said[-1] == "at the preset's own axes"


def test_a_second_click_plays_its_pixel_in_the_same_inset_as_a_new_one_would(tmp_path):
    """A click on another pixel of the map moves the inset to that start: no new Run or Canvas (Taichi never
    frees their fields and kernels), and the same frames and start as an inset made for that pixel."""
    from render.commands.explore import Inset
    scene = load("fractal_flip", ["video.width=64", "video.height=64", "video.fps=10", "video.duration=1"])
    ex = Explorer(scene, "cpu", None, tmp_path, log=[].append)
    ex.click(41, 9)
    first = ex.inset
    for _ in range(3):
        first.advance(0.0)
    ex.click(12, 50)
    assert ex.inset is first
    fresh = Inset(ex.scene, ex.start_of(12, 50), first.size, "cpu", None)
    assert ex.inset.start == fresh.start and np.array_equal(ex.inset.frame, fresh.frame)
    for _ in range(3):
        ex.inset.advance(0.0)
        fresh.advance(0.0)
        assert np.array_equal(ex.inset.frame, fresh.frame)


def test_zooming_in_and_back_out_keeps_no_earlier_maps_kernels_or_fields(tmp_path):
    """Taichi frees a map's fields and compiled kernels only with its runtime: with one runtime for every map, each
    zoom and back left the last map's behind (the process grew to 490 MB in 60 of them, benchmarks/explore_zooms.py).
    Each map now has a runtime of its own, so after any number of zooms and backs Taichi holds what one map needs."""
    import gc

    from taichi.lang import impl

    def held():  # Taichi's compiled kernels and trees of fields
        gc.collect()
        rt = impl.get_runtime()
        return sum(len(k.compiled_kernels) for k in rt.kernels), rt.prog.get_snode_tree_size()

    scene = load("fractal_flip", ["video.width=64", "video.height=64", "video.fps=10", "video.duration=1"])
    ex = Explorer(scene, "cpu", None, tmp_path, log=[].append)
    ex.player.tick(1e9)  # a frame drawn: every kernel of a map has run
    one_map = held()
    for _ in range(3):
        ex.mouse("press", (8, 8))
        ex.mouse("release", (40, 40))
        ex.player.tick(1e9)
        ex.key("b")
        ex.player.tick(1e9)
    assert held() == one_map and min(one_map) > 0


def test_a_map_too_small_for_an_inset_says_so_on_a_click(tmp_path):
    said = []
    scene = load("fractal_flip", ["video.width=40", "video.height=16", "video.fps=10", "video.duration=1"])
    ex = Explorer(scene, "cpu", None, tmp_path, log=said.append)
    ex.mouse("press", (5, 5))
    ex.mouse("release", (5, 5))
    assert ex.inset is None and said[-1] == "inset: a 40x16 map has no room for one", said
    assert ex.compose().shape == (16, 40, 3)


def test_click_opens_the_pixels_pendulum_and_a_box_zooms(xvfb, tmp_path):  # noqa: F811 - the fixture
    lay = grid.layout(W, H)
    assert lay.font is not None
    cmd = [sys.executable, "-m", "render", "show", "fractal_flip", "--out", str(tmp_path)]
    for s in SETS:
        cmd += ["--set", s]
    proc = subprocess.Popen(cmd, cwd=ROOT, env={**env_without_display(), "DISPLAY": xvfb},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out = Lines(proc)
        first = out.wait(AXES.pattern)
        assert first.groups() == ("theta1", repr(-math.pi), repr(math.pi), "theta2", repr(-math.pi), repr(math.pi),
                                  "f32")
        wid = None
        while wid is None:
            r = xdotool(xvfb, "search", "--name", "^pendulum show: fractal_flip", check=False)
            wid = r.stdout.split()[0] if r.returncode == 0 and r.stdout.split() else time.sleep(0.1)

        # a click: the inset's pendulum starts at the pixel's centre (its state read back, in the map's f32)
        c, r = 40, 20
        xdotool(xvfb, "mousemove", "--window", wid, str(lay.x0 + c), str(lay.y0 + r), "click", "1")
        m = out.wait(r"inset: theta1=(\S+) theta2=(\S+) pixel \((\d+), (\d+)\): (.*)")
        assert (int(m[3]), int(m[4])) == (c, r)
        want = (-math.pi + (c + 0.5) * 2 * math.pi / lay.w, math.pi - (r + 0.5) * 2 * math.pi / lay.h)
        assert np.allclose([float(m[1]), float(m[2])], want, rtol=2e-7, atol=0), (m[0], want)
        assert re.fullmatch(r"flips at \d+\.\d+ s|not yet at \d+\.\d+ s|cannot flip \(energy\)", m[5]), m[5]

        # the inset is on screen: a bordered square in the bottom right with the pendulum's rods in it
        def inset_shown():
            px = grab_window(xvfb, int(wid), W, H)
            if px is None:
                return False
            size = max(16, min(H // 2, W // 3, 360)) // 2 * 2
            pad = max(lay.pad, 3)
            x, y = W - size - pad, H - size - pad
            border = (px[y - 1, x:x + size] == axes.FRAME).all()
            return border and (px[y:y + size, x:x + size].max(-1) > 100).sum() > 20
        deadline = time.monotonic() + 10
        while not inset_shown():
            assert time.monotonic() < deadline, "the inset never showed"
            time.sleep(0.1)

        # a box from plot pixel (10, 30) to (30, 50): the new axes are exactly those pixels' edges
        (c0, r0), (c1, r1) = (10, 30), (30, 50)
        xdotool(xvfb, "mousemove", "--window", wid, str(lay.x0 + c0), str(lay.y0 + r0))
        xdotool(xvfb, "mousedown", "1")
        time.sleep(0.1)
        xdotool(xvfb, "mousemove", "--window", wid, str(lay.x0 + c1), str(lay.y0 + r1))
        time.sleep(0.1)
        xdotool(xvfb, "mouseup", "1")
        m = out.wait(AXES.pattern)
        step = 2 * math.pi / lay.w
        want = (-math.pi + c0 * step, -math.pi + (c1 + 1) * step, math.pi - (r1 + 1) * step, math.pi - r0 * step)
        assert (m[1], m[4]) == ("theta1", "theta2")
        assert np.allclose([float(m[k]) for k in (2, 3, 5, 6)], want, rtol=0, atol=1e-12), (m[0], want)

        # b: back to the preset's axes (recomputed); q quits
        xdotool(xvfb, "key", "--window", wid, "b")
        assert out.wait(AXES.pattern).groups() == first.groups()
        xdotool(xvfb, "key", "--window", wid, "q")
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    stderr = proc.stderr.read()
    assert proc.returncode == 0, stderr
    assert "Traceback" not in stderr
