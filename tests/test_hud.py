"""The HUD: the clock says the simulated time and changes colour past the certificate's marks, the spread is
the largest distance between neighbours' last bobs, it works for every system, and it stays in its corners."""
import subprocess
import sys

import numpy as np
import pytest

from render.draw import hud, hud_text
from render.physics.stepper import Run
from render.config.scene import load

W, H, FPS = 256, 144, 10


def run(name, info=None, upto=None, sets=(), size=(W, H)):
    """Draw a preset's frames with the HUD on (small, short); returns the canvas, the frames and the system."""
    scene = load(name, [f"video.width={size[0]}", f"video.height={size[1]}", f"video.fps={FPS}", "video.duration=0.5",
                        'effects=["bobs", "hud"]', *sets])
    from render.draw.canvas import Canvas

    run = Run(scene)
    sim = run.sim
    canvas = Canvas(scene, sim, info)
    frames = []
    for f in run.frames():
        frames.append(canvas.draw(t=f / FPS).copy())
        if f == upto:
            break
    return canvas, np.stack(frames), sim


def expected_text(canvas, text, colour, x, y, size, scale):
    img = np.zeros((H, W, 3), np.uint8)
    canvas.hud.font.draw(img, text, x, y, colour, scale, size=size)
    return img


def tip_positions(name, q):
    """The last bob of every pendulum, from the state, computed here (not with the system's own points())."""
    p = load(name).pendulums
    if q.shape[1] == 4:  # springs: q holds the bobs' positions
        return q[:, 2:4]
    return np.stack([sum(l * np.sin(q[:, k]) for k, l in enumerate(p.lengths)),
                     sum(-l * np.cos(q[:, k]) for k, l in enumerate(p.lengths))], 1)


@pytest.mark.parametrize("name", ["rigid_chaos", "elastic_fan", "triple_chaos"])
def test_every_system_gets_a_clock_and_its_fans_spread(name):
    canvas, frames, sim = run(name)
    h = canvas.hud
    small, big, _ = hud_text.faces(H)
    box = np.s_[h.m:h.m + 13, h.m:h.m + 6 * 11]  # the clock's cells at 256x144 (6x13)
    want = expected_text(canvas, "t =  0.40 s", hud_text.WHITE, h.m, h.m, *big)
    np.testing.assert_array_equal(frames[-1][box], want[box])
    tips = tip_positions(name, sim.q.to_numpy())
    spread = np.hypot(*np.diff(tips, axis=0).T).max()
    assert float(h.spread[None]) == pytest.approx(spread, rel=1e-6)
    assert h.history.to_numpy()[4] == pytest.approx(np.log10(spread / sim.reach()), abs=1e-5)


def test_the_clock_turns_amber_then_red_past_the_certificates_marks_and_the_timeline_has_ticks():
    info = hud.Info("a caption", "rk4", 1e-3, "f64", faithful_until_s=0.15, median_until_s=0.25)
    canvas, frames, _ = run("rigid_chaos", info)
    h = canvas.hud
    box = np.s_[h.m:h.m + 13, h.m:h.m + 6 * 11]
    byte = lambda c: tuple(int(np.floor(v * 255 + 0.5)) for v in c)  # noqa: E731
    for f, colour in ((0, hud_text.WHITE), (1, hud_text.WHITE), (2, hud_text.AMBER), (3, hud_text.RED),
                      (4, hud_text.RED)):  # t = 0 ... 0.4
        lit = frames[f][box].reshape(-1, 3)
        lit = {tuple(p) for p in lit[lit.max(1) > 0]}
        assert lit == {byte(colour)}, (f, lit)
    below_axis = frames[-1][h.gy1 + 3 * h.th]
    assert tuple(below_axis[h.x_of(0.15)]) == byte(hud_text.AMBER)
    assert tuple(below_axis[h.x_of(0.25)]) == byte(hud_text.RED)
    assert below_axis[h.x_of(0.15) + 1:h.x_of(0.25)].max() == 0


def test_a_long_caption_wraps_in_its_corner_around_the_view_and_is_cut_there():
    w, h_px = 640, 360
    long = "word " * 300
    canvas, frames, _ = run("rigid_chaos", hud.Info(long, "rk4", 1e-3, "f64"), upto=0, size=(w, h_px))
    _, plain, _ = run("rigid_chaos", upto=0, sets=['effects=["bobs"]'], size=(w, h_px))
    added = (frames[0] != plain[0]).any(2)
    h = canvas.hud
    rows, cols = np.nonzero(added)
    assert cols.max() <= w - h.m - 1 and rows.max() <= h_px - h.m
    view = canvas.view
    right = added[:, int(view.cx):]  # right of the pivot: the certificate (none here) and the caption
    lines = np.nonzero(right.any(1))[0]
    assert len(lines) and lines.min() > view.cy  # the caption only, below the pivot
    assert not (added & view.reachable(h_px, w)).any()
    caption = [r for r in h.boxes if r[0] > view.cx]
    assert len(caption) == hud_text.MAX_LINES  # wrapped to its most lines, the last one cut with an ellipsis
    assert all(r[2] == w - h.m - 1 for r in caption)  # right-aligned
    assert added.mean() < 0.1  # the HUD is a frame around the picture, not over it


def test_a_single_pendulum_has_a_clock_and_a_timeline_but_no_spread():
    canvas, frames, _ = run("classic")
    h = canvas.hud
    assert not h.fan and not hasattr(h, "spread")
    box = np.s_[h.m:h.m + 13, h.m:h.m + 6 * 11]
    want = expected_text(canvas, "t =  0.40 s", hud_text.WHITE, h.m, h.m, *hud_text.faces(H)[1])
    np.testing.assert_array_equal(frames[-1][box], want[box])
    assert frames[-1][h.gy1 + 1, h.gx0:h.x_of(0.4)].min() > 0  # the timeline, lit up to now


SCRIPT = """
import hashlib, sys
import numpy as np
from render.draw import hud
from render.physics.stepper import Run
from render.config.scene import load
threads = int(sys.argv[1])
for w, h, panel in ((1280, 720, False), (640, 360, True)):
    scene = load("rigid_chaos", [f"video.width={w}", f"video.height={h}", "video.fps=60", "video.duration=0.5"])
    run = Run(scene, "cpu", threads)
    sim = run.sim
    info = hud.Info(scene.description, "rk4", 1e-3, "f64", faithful_until_s=0.15, median_until_s=0.3, panel=panel)
    h_ = hud.Hud(scene, sim, info, w, h)
    digest, lit = hashlib.sha256(), set()
    for f in run.frames():
        out = np.zeros((h, w, 3), np.uint8)
        out[::7, ::5] = 40  # something under the HUD for its max
        h_.draw(out, f / 60)
        digest.update(out.tobytes())
        lit.add(int((out.max(2) > 40).sum()))
    print(h_.serial, len(lit) > 1, digest.hexdigest())
"""


def test_the_hud_is_the_same_bytes_at_1_2_and_8_threads():
    """Drawn alone at 720p and as a 360p panel, every frame of half a second: on the launching thread at 1 and 2
    threads and by the thread pool at 8 (its loops give each pixel one writer), the same bytes."""
    runs = {}
    for threads in (1, 2, 8):
        r = subprocess.run([sys.executable, "-c", SCRIPT, str(threads)], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        out = r.stdout.split()
        runs[threads] = [out[k:k + 3] for k in (0, 3)]  # (serial, changes, digest) per size
    for threads, sizes in runs.items():
        assert [s[0] for s in sizes] == [str(threads <= hud.SERIAL_MAX_THREADS)] * 2, (threads, sizes)
        assert [s[1] for s in sizes] == ["True"] * 2  # the picture changes from frame to frame
    assert [s[2] for s in runs[1]] == [s[2] for s in runs[2]] == [s[2] for s in runs[8]], runs
