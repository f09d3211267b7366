"""The layout: the HUD, the panel labels and the caption own their bands and corners, and the pendulums' view
(their whole reach, render/draw/framing.py) is fitted into what is left, so no text ever lies where a
pendulum can draw. Every preset that draws a fan, at 1280x720 and at its GIF's size (drawn at that size).

Each case checks two things against the canvas's own framing (canvas.view): the pendulums, put in extreme
states (every chain stretched out straight, in many directions), draw only inside the reach disc; and the
HUD's pixels (drawn alone, at the first, a middle and the last frame, the chart's history filled) and the
labels' pixels lie outside it. And a frame drawn with the HUD is the one without it, maxed with the HUD alone,
so the HUD's pixels are what a render draws.
"""
import math

import numpy as np
import pytest

from render.config.scene import list_presets, load
from render.physics import registry, runtime
from render.physics.keys import DRAWN

FEWER = 8  # pendulums, where the reach does not depend on the fan (rigid chains: their length)


def fan_presets():
    out = []
    for path in list_presets():
        s = load(path.stem)
        # a fan: neighbours a little apart (not poincare_shell's shell of one energy, whose "spread" means nothing)
        if s.pendulums.layout == "fan" and s.pendulums.count > 1 and any(s.has(e) for e in DRAWN):
            out.append(path.stem)
    return out


FANS = fan_presets()
SIZES = ("720p", "gif")


def scene_at(name, size, *sets):
    s = load(name)
    v = s.video
    if size == "720p":
        w, h = 1280, 720
    else:  # as the GIF: gif_width wide (never upscaled), the frame's aspect, the height even
        w = min(v.gif_width, v.width)
        h = max(2, round(v.height * w / v.width / 2) * 2)
    fewer = [f"pendulums.count={FEWER}"] if s.system in ("rigid", "triple") else []
    return load(name, [f"video.width={w}", f"video.height={h}", *fewer, *sets])


def stretched(sim, k: int) -> np.ndarray:
    """States with every pendulum's chain straight out to its full reach, each in its own direction (offset
    by k): rigid chains with every angle equal; springs with both bobs on one ray, the outer one at the bound."""
    q = sim.q.to_numpy()
    phi = 2 * math.pi * (np.arange(sim.n) + k / 3) / sim.n
    if sim.ANGLES:
        q[:] = phi[:, None].astype(q.dtype)
    else:  # (x1, y1, x2, y2): the bound is the outer bob's; the inner one halfway
        r = sim.reach() * (1 - 1e-6)
        tip = np.stack([r * np.sin(phi), -r * np.cos(phi)], 1)
        q[:, 0:2], q[:, 2:4] = 0.5 * tip, tip  # (cast to the state's precision)
    return q


def ink(frame: np.ndarray) -> np.ndarray:
    return frame.max(2) > 0


def hud_pixels(h, shape) -> np.ndarray:
    """Every pixel the HUD draws, over a black frame, at its first, a middle and its last frame."""
    lit = np.zeros(shape[:2], bool)
    if h.fan:
        h.history.from_numpy(np.linspace(-9.0, 1.0, h.frames, dtype=np.float32))  # beyond the axis both ways
    for t in (0.0, 0.5 * h.duration, h.duration):
        out = np.zeros(shape, np.uint8)
        h.draw(out, t)
        lit |= ink(out)
    return lit


def check_canvas(canvas, where: str):
    """The pendulums draw inside the view's disc and the HUD outside it; returns the disc."""
    reach = canvas.view.reachable(canvas.h, canvas.w)
    hud, sim = canvas.hud, canvas.sim
    for k in range(3):
        canvas.hud = None
        canvas.restart()
        sim.q.from_numpy(stretched(sim, k))
        plain = canvas.draw()
        canvas.hud = hud
        plain[:, canvas.area:] = 0  # right of the pendulums' area: the Poincaré section, not theirs
        outside = ink(plain) & ~reach
        assert not outside.any(), f"{where}: a pendulum draws {outside.sum()} pixels outside its view"
    assert ink(plain).any()
    if hud is not None:
        lit = hud_pixels(hud, plain.shape)
        clash = lit & reach
        assert not clash.any(), f"{where}: the HUD draws {clash.sum()} pixels where a pendulum can reach " \
                                f"(first at row, col {np.argwhere(clash)[0]})"
        # the HUD over a frame is that frame maxed with the HUD alone: what a render draws
        canvas.restart()
        sim.q.from_numpy(stretched(sim, 0))
        with_hud = canvas.draw(t=0.0)
        alone = np.zeros_like(with_hud)
        hud.draw(alone, 0.0)
        canvas.hud = None
        canvas.restart()
        sim.q.from_numpy(stretched(sim, 0))
        without = canvas.draw()
        canvas.hud = hud
        np.testing.assert_array_equal(with_hud, np.maximum(without, alone))
    return reach


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", [n for n in FANS if not load(n).compare])
def test_no_hud_pixel_lies_where_a_pendulum_can_reach(name, size):
    from render.video import pipeline

    scene = scene_at(name, size)
    assert scene.has("hud"), f"{name}: a fan preset without the HUD"
    src = pipeline.Source(scene)
    check_canvas(src.canvas, f"{name} at {scene.video.width}x{scene.video.height}")


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", [n for n in FANS if load(n).compare])
def test_no_label_or_hud_pixel_lies_where_a_panel_pendulum_can_reach(name, size):
    from render.video import pipeline

    scene = scene_at(name, size, "video.duration=4")
    split = pipeline.open_source(scene)
    v = scene.video
    reach = np.zeros((v.height, v.width), bool)
    for panel, (x, y, w, h) in zip(split.panels, split.rects):
        reach[y:y + h, x:x + w] = check_canvas(panel.canvas, f"{name} panel at {w}x{h}")
    for f in (0, scene.frames // 2, scene.frames - 1):
        frame = np.zeros((v.height, v.width, 3), np.uint8)
        split.font.draw_many(frame, split.labels(f) + [split.clock(f)], blend="over")
        clash = ink(frame) & reach
        assert not clash.any(), f"{name}: a label draws {clash.sum()} pixels where a pendulum can reach (frame {f})"


@pytest.mark.parametrize("w, h", [(540, 540), (400, 720), (1920, 480)])
@pytest.mark.parametrize("name", ["rigid_chaos", "seed_elastic"])
def test_the_layout_holds_at_other_aspect_ratios(name, w, h):
    from render.video import pipeline

    scene = scene_at(name, "720p", f"video.width={w}", f"video.height={h}")
    check_canvas(pipeline.Source(scene).canvas, f"{name} at {w}x{h}")


def test_every_fan_preset_is_checked_and_has_a_hud():
    assert {"rigid_chaos", "triple_chaos", "rainbow_1000", "damped_heavy", "elastic_fan", "seed_rigid",
            "compare_methods", "compare_precision"} <= set(FANS)
    assert all(load(n).has("hud") for n in FANS)


def test_a_fitted_view_keeps_clear_of_a_band_and_the_nominal_one_is_kept_when_clear():
    from render.draw import framing

    free = framing.fit(1280, 720, 10.0)
    assert (free.cx, free.cy, free.radius) == (640.0, 360.0, 0.46 * 720)
    assert framing.fit(1280, 720, 10.0, [(0, 0, 100, 100)]) == free  # a corner clear of the disc changes nothing
    band = framing.fit(640, 660, 10.0, [(0, 0, 639, 119)])  # a label across the top
    assert band.cy - band.outer >= 119 + framing.GAP and band.cy + band.outer <= 660
    assert band.radius > 0.4 * (660 - 120)  # it fills what is left, not a sliver


def test_coinciding_ticks_stay_apart_and_the_time_axis_is_labelled():
    """elastic_fan's certificate ends 0.11 s apart (2.28 s, 2.39 s): two ticks, a dark column between."""
    from render.draw import hud, hud_text

    runtime.init("cpu", "f64")
    scene = load("elastic_fan")
    sim = registry.kernels(scene.system)(scene)
    info = hud.Info("caption", "verlet", 1e-3, "f64", faithful_until_s=2.28, median_until_s=2.39)
    h = hud.Hud(scene, sim, info, 1280, 720)
    a, r = h.ticks
    assert r - a >= 2 * h.th + 1
    out = np.zeros((720, 1280, 3), np.uint8)
    h.draw(out, 5.0)
    row = out[h.gy0 + 2]
    byte = lambda c: tuple(int(v * 255 + 0.5) for v in c)  # noqa: E731
    assert tuple(row[a]) == byte(hud_text.AMBER) and tuple(row[r]) == byte(hud_text.RED)
    assert row[a + h.th:r].max() == 0
    # the labels under the timeline: 0, both tick times and the end, none over another
    labels = h.time_labels()
    assert len(labels) == 4
    boxes = sorted(framing_box(rows) for rows in labels)
    assert all(b0[2] < b1[0] for b0, b1 in zip(boxes, boxes[1:]))
    assert boxes[0][0] == h.gx0 and boxes[-1][2] >= h.gx1 - 1


def framing_box(rows):
    from render.draw import framing
    return framing.box_of(rows)
