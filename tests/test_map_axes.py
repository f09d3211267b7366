"""A map's axes ([map] x, y, x_range, y_range): validation, the starts each pixel gets, the ticks and labels the
frame shows, the energy barrier with rates on the axes, and a zoom too narrow for f32 running in f64 and
agreeing with DOP853."""
import json
import math
import shutil

import numpy as np
import pytest

from conftest import ocr_line, run_cli
from render.draw import axes
from render.errors import SceneError
from render.maps import fractal
from render.physics import grid, reference
from render.video import pipeline
from render.config.scene import load

SMALL = ["video.width=256", "video.height=144", "video.fps=30", "integrator.min_faithful=0"]
OMEGA = SMALL + ["video.duration=1", "map.x=omega1", "map.y=omega2", "map.x_range=[-6, 6]", "map.y_range=[-4, 8]",
                 "pendulums.theta1=1.0", "pendulums.theta2=0.5"]
# A 1e-3 rad window across the edge of a flip region: DOP853 flips its lower rows near 1.6 s and not its upper
# ones within the video (found by bisection along θ2 at θ1 = −1.9).
ZOOM = SMALL + ["video.duration=2.5", "map.x_range=[-1.9005, -1.8995]", "map.y_range=[2.2420, 2.2430]"]


def number(label: str) -> float:
    return float(label.replace("−", "-"))


def read_number(img: np.ndarray) -> float | None:
    """A tick label read back by tesseract from a crop of the frame (conftest.ocr_line, as tests/test_gif.py reads
    its clock); None if none reads a number."""
    return ocr_line(img, "0123456789.-", r"\s*(-?\d+(\.\d+)?)\s*")


def labels_read_back(frame, lay, scene) -> list[tuple[float, float | None]]:
    """(value, what tesseract reads) for every labelled tick of both axes, each label cropped from the frame
    where decorate put it (x labels centred under their mark but clear of the legend, y labels right-aligned)."""
    cw, ch = lay.cell()
    out = []
    (xq, *xr), (yq, *yr) = grid.axes_of(scene.map)
    for t in axes.x_ticks(lay, xq, *xr):
        if t.label:
            half = len(t.label) * cw // 2
            x, y = axes.x_label_at(lay, t), lay.y0 + lay.h + 2 * lay.pad
            out.append((t.value, read_number(frame[y - 2:y + ch + 1, x - half - 1:x + half + 1])))
    for t in axes.y_ticks(lay, yq, *yr):
        if t.label:
            x, y = lay.x0 - 2 * lay.pad, lay.y0 + lay.h - 1 - t.at
            out.append((t.value, read_number(frame[y - ch // 2 - 2:y + ch // 2 + 2, x - len(t.label) * cw - 2:x + 1])))
    return out


def x_labels_apart(lay, scene):
    """The x axis's labels neither touch each other (a character's gap at least) nor reach the legend."""
    cw, _ = lay.cell()
    boxes = [(axes.x_label_at(lay, t) - len(t.label) * cw / 2, axes.x_label_at(lay, t) + len(t.label) * cw / 2)
             for t in axes.x_ticks(lay, *grid.axes_of(scene.map)[0]) if t.label]
    assert all(b[0] - a[1] >= cw for a, b in zip(boxes, boxes[1:])), boxes
    assert boxes[-1][1] <= lay.x0 + lay.w + 4 * lay.pad, boxes  # where the legend's column starts


def run_map(scene):
    src = pipeline.Source(scene)
    frames = [src.next_frame().copy() for _ in range(scene.frames)]
    return src, frames


# ---------------------------------------------------------------- the keys

@pytest.mark.parametrize("sets, key, words", [
    (["map.x=theta3"], "map.x", ["theta3", "omega2"]),
    (["map.y=mass_ratio"], "map.y", ["m2/m1", "per scene"]),
    (["map.x=length_ratio"], "map.x", ["l2/l1"]),
    (["map.x_range=[1, 1]"], "map.x_range", ["lo < hi"]),
    (["map.y_range=[2, -2]"], "map.y_range", ["lo < hi"]),
    (["map.x_range=[0]"], "map.x_range", ["two numbers"]),
    (["map.x_range=[1.0, 1.0000000000000002]"], "map.x_range", ["narrower"]),
    (["map.x=theta2"], "map.y", ["theta2", "two different"]),
])
def test_bad_axes_name_the_file_and_key(sets, key, words):
    with pytest.raises(SceneError) as e:
        load("fractal_flip", sets)
    msg = str(e.value)
    assert msg.startswith(f"presets/fractal_flip.toml: {key}:") and "\n" not in msg, msg
    assert all(w in msg for w in words), msg


def test_each_link_has_its_angle_and_rate_and_a_fan_has_no_axes():
    assert grid.quantities(2) == ("theta1", "theta2", "omega1", "omega2")
    assert grid.quantities(3) == ("theta1", "theta2", "theta3", "omega1", "omega2", "omega3")
    with pytest.raises(SceneError, match="classic.toml: map.x: only a fractal map"):
        load("classic", ["map.x=omega1"])


def test_bad_axis_on_the_command_line_exits_2_and_writes_nothing(tmp_path):
    r = run_cli("render", "fractal_flip", "--out", tmp_path, "--set", "map.x_range=[3, -3]")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "fractal_flip.toml: map.x_range:" in r.stderr and "Traceback" not in r.stderr
    assert not list(tmp_path.iterdir())


def test_default_axes_leave_scene_layout_and_hash_as_they_were():
    plain = load("fractal_flip")
    spelled = load("fractal_flip", ["map.x=\"theta1\"", "map.y=\"theta2\"", f"map.x_range=[{-math.pi!r}, {math.pi!r}]"])
    assert spelled.hash() == plain.hash() == "3062fd5c56fee5a2"  # the hash main had before axes existed
    assert grid.plot(plain) == grid.layout(1280, 720)
    assert plain.integrator.precision == "f32" and "f64" not in grid.axes_summary(plain)


# ---------------------------------------------------------------- ticks

def test_ticks_label_their_values_and_sit_where_the_values_fall():
    wide = lambda s: max(6, len(s) + 1) * 6  # noqa: E731 - as decorate spaces x labels in the 6x13 font
    # units of π only where the range is a simple multiple of π
    assert [t.label for t in axes.axis_ticks("theta1", 0.0, 2 * np.pi, 300, wide)] == ["0", "π/2", "π", "3π/2", "2π"]
    assert grid.pi_units(-np.pi, np.pi) and not grid.pi_units(0.0, np.pi / 2) and not grid.pi_units(-1.0, 1.0)
    assert [t.label for t in axes.axis_ticks("omega1", -np.pi, np.pi, 300, wide)][0] != "−π"  # rates: decimals
    for q, lo, hi, n in [("omega1", -6.0, 6.0, 300), ("theta2", 2.2420, 2.2430, 300), ("theta1", -1.9005, -1.8995, 60),
                         ("omega2", 0.5, 0.50001, 600), ("theta1", -1e-3, 1e-3, 300)]:
        ticks = axes.axis_ticks(q, lo, hi, n, wide)
        labelled = [t for t in ticks if t.label]
        assert len(ticks) >= 2 and len(labelled) >= 2, (q, lo, hi, ticks)
        step = ticks[1].value - ticks[0].value
        for t in ticks:
            assert lo - 1e-9 * step <= t.value <= hi + 1e-9 * step
            assert t.at == min(round(n * (t.value - lo) / (hi - lo)), n - 1)
        for t in labelled:  # enough digits: each label reads back as its value, to well under a step
            assert abs(number(t.label) - t.value) < 1e-6 * step, (t.label, t.value)
            assert len(t.label) <= grid.label_chars(q, lo, hi)  # the layout made room for it
        assert len({t.label for t in labelled}) == len(labelled)


def test_an_omega_map_starts_each_pixel_at_its_rates_and_draws_its_ticks():
    scene = load("fractal_flip", OMEGA)
    src, frames = run_map(scene)
    lay, sim = src.canvas.lay, src.sim
    assert lay == grid.plot(scene) and lay.font == "6x13"
    # every pixel starts at its centre's (ω1, ω2), row 0 at the top, the angles as [pendulums] states them
    q0, v0 = sim.initial_state()
    c, r = np.meshgrid(np.arange(lay.w), np.arange(lay.h))
    assert np.allclose(v0[:, 0], (-6 + (c.ravel() + 0.5) * 12 / lay.w), rtol=0, atol=1e-12)
    assert np.allclose(v0[:, 1], (8 - (r.ravel() + 0.5) * 12 / lay.h), rtol=0, atol=1e-12)
    assert (q0 == (1.0, 0.5)).all()
    # the barrier counts the kinetic energy: exactly the starts whose full energy is below it never flip
    e = reference.energy(scene, q0, v0)
    never = src.canvas.event.to_numpy() == fractal.NEVER
    b = min(fractal.barriers((1.0, 1.0), (1.0, 1.0), 9.8))
    assert never.any() and (~never).any()
    assert (never == (e < b))[np.abs(e - b) > 1e-4].all()
    # tick marks where decorate puts them, labels under them reading their values
    frame = frames[-1]
    d = src.canvas.decor
    label_at = {(x, y): s for s, x, y, _ in d.texts}
    for (q, lo, hi), horizontal in zip(grid.axes_of(scene.map), (True, False)):
        ticks = (axes.x_ticks if horizontal else axes.y_ticks)(lay, q, lo, hi)
        assert len([t for t in ticks if t.label]) >= 2
        assert [number(t.label) for t in ticks if t.label] == [t.value for t in ticks if t.label]
        for t in ticks:
            if horizontal:
                x = lay.x0 + t.at
                assert (frame[lay.y0 + lay.h + 1:lay.y0 + lay.h + 1 + lay.pad, x] == axes.FRAME).all()
                assert (frame[lay.y0 + lay.h + 2, x + 2] == axes.BACKGROUND).all()  # a mark, not a line
                if t.label:
                    assert label_at.get((axes.x_label_at(lay, t), lay.y0 + lay.h + 2 * lay.pad)) == t.label
            else:
                y = lay.y0 + lay.h - 1 - t.at
                assert (frame[y, lay.x0 - 1 - lay.pad:lay.x0 - 1] == axes.FRAME).all()
                if t.label:
                    assert label_at.get((lay.x0 - 2 * lay.pad, y)) == t.label
    x_labels_apart(lay, scene)
    texts = [s for s, *_ in d.texts]
    assert "ω₁ [rad/s]" in texts and "ω₂" in texts and "rad/s" in texts
    assert "−5" in texts and "5" in texts
    # the labels are drawn: glyph pixels (ink) under the x axis and left of the y axis
    below = frame[lay.y0 + lay.h + 2 * lay.pad:lay.y0 + lay.h + 2 * lay.pad + 13, lay.x0 - 10:lay.x0 + lay.w + 10]
    assert (below.max(-1) > 150).sum() > 30


# ---------------------------------------------------------------- zoom in f64

def test_a_1e_3_rad_zoom_runs_in_f64_and_its_trusted_pixels_agree_with_dop853(tmp_path):
    scene = load("fractal_flip", ZOOM)  # the preset says f32
    assert scene.integrator.precision == "f64"
    why = grid.axes_summary(scene)["f64"]
    assert "theta1" in why and "f32" in why
    src, _ = run_map(scene)
    lay, mp = src.canvas.lay, src.canvas
    # the starts: every pixel its own, one step apart (f32 would round 1.7e-5 rad steps to multiples of 2.4e-7)
    q0, _ = src.sim.initial_state()
    step = 1e-3 / lay.w
    xs = q0[:lay.w, 0]
    assert np.allclose(np.diff(xs), step, rtol=1e-9, atol=0) and abs(xs[0] - (-1.9005 + step / 2)) < 1e-15
    assert src.sim.q.to_numpy().dtype == np.float64
    # ticks: labels with the digits a 1e-3 window needs
    labels = [t.label for t in axes.y_ticks(lay, "theta2", 2.2420, 2.2430) if t.label]
    assert "2.2420" in labels and "2.2430" in labels
    x_labels_apart(lay, scene)  # and the frame's pixels say them: test_the_tick_labels_read_back_as_their_values
    # the map against DOP853 at 48 pixels, half of them flipped
    ev = mp.event.to_numpy().astype(np.float64)
    until = mp.until.to_numpy()
    t_end = (scene.frames - 1) / scene.video.fps
    trusted = np.where(ev >= 0, ev, t_end) <= until
    rng = np.random.default_rng(26)
    flipped, pending = np.flatnonzero(trusted & (ev >= 0)), np.flatnonzero(trusted & (ev == fractal.PENDING))
    assert len(flipped) > 100 and len(pending) > 100  # the window spans the edge
    pick = np.concatenate([rng.choice(flipped, 24, replace=False), rng.choice(pending, 24, replace=False)])
    th = np.stack([-1.9005 + (pick % lay.w + 0.5) * step, 2.2430 - (pick // lay.w + 0.5) * (1e-3 / lay.h)], axis=1)
    t = np.arange(0.0, t_end + 1e-12, 1e-4)
    q, _ = reference.solve(scene, (th, np.zeros_like(th)), t_end, t_eval=t, rtol=1e-12, atol=1e-12)
    over = np.abs(q).max(-1) > np.pi
    ref = np.where(over.any(0), t[over.argmax(0)], np.inf)
    assert np.isinf(ref[24:]).all()  # not flipped by the end: DOP853 neither
    assert np.abs(ref[:24] - ev[pick[:24]]).max() < 2e-3, (ref[:24], ev[pick[:24]])  # sampled every 0.1 ms
    # and the render says so in its metadata
    r = run_cli("render", "fractal_flip", "--out", tmp_path, "--name", "zoom", "--no-progress",
                *[a for s in ZOOM + ['video.formats=["png"]', "video.duration=0.2"] for a in ("--set", s)])
    assert r.returncode == 0, r.stderr
    assert "f64 (f64: the zoom is finer than f32 resolves)" in r.stdout, r.stdout
    meta = json.loads((tmp_path / "zoom" / "metadata.json").read_text())
    assert meta["integrator"]["precision"] == "f64" and "f64" in meta["map"]["axes"]
    assert meta["map"]["axes"]["y"] == {"quantity": "theta2", "unit": "rad", "range": [2.242, 2.243]}


@pytest.mark.skipif(shutil.which("tesseract") is None, reason="tesseract is not installed (Debian: tesseract-ocr)")
@pytest.mark.parametrize("sets", [ZOOM, OMEGA], ids=["zoom", "omega"])
def test_the_tick_labels_read_back_as_their_values(sets):
    """The frame's pixels say the labels: every one that tesseract reads, reads its tick's value (the zoom's
    2.2420 ... 2.2430, the rates' −5 ... 5), and most read."""
    scene = load("fractal_flip", [*sets, "video.duration=0.1"])  # the axes are drawn with the first frame
    src, frames = run_map(scene)
    read = labels_read_back(frames[-1], src.canvas.lay, scene)
    assert all(got is None or abs(got - want) < 1e-9 for want, got in read), read
    assert sum(got is not None for _, got in read) >= 0.75 * len(read) and len(read) >= 4, read
