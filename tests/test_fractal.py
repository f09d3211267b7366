"""Fractal maps: the energy barrier, flip and divergence times against DOP853 wherever the trust mask trusts
them, the mask against a shadow at every pixel, stills, determinism and bad input."""
import json

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import run_cli
from render.draw import axes
from render.trust import certify
from render.maps import fractal
from render.physics import grid, reference
from render.physics.stepper import Run
from render.video import pipeline
from render.config.scene import load

G = 9.8


def run_map(scene, threads=None):
    """Render `scene`'s frames through pipeline.Source (no encoding); the map, its system and the frames."""
    src = pipeline.Source(scene, threads=threads)
    frames = [src.next_frame().copy() for _ in range(scene.frames)]
    return src.canvas, src.sim, frames


def small(name, n=32, seconds=8.0, **sets):
    """A preset on an n×n frame (too small for axes: the map fills it), at 30 fps."""
    extra = [f"{k}={v}" for k, v in sets.items()]
    return load(name, [f"video.width={n}", f"video.height={n}", f"video.duration={seconds}", "video.fps=30",
                       "integrator.min_faithful=0", *extra])


def first_crossing(t, x, level):
    """Per column of x (len(t), N): the first time x passes `level`, linearly interpolated; inf if never."""
    over = x > level
    k = over.argmax(0)
    out = np.full(x.shape[1], np.inf)
    for j in np.flatnonzero(over.any(0)):
        i = k[j]
        out[j] = t[0] if i == 0 else t[i - 1] + (level - x[i - 1, j]) / (x[i, j] - x[i - 1, j]) * (t[i] - t[i - 1])
    return out


def reference_runs(scene, q0, v0, t_end, measure, chunk=128):
    """DOP853 (the independent chain model) from each start, sampled every ms; measure(q, v) per sample."""
    t = np.arange(0.0, t_end + 1e-12, 1e-3)
    out = []
    for a in range(0, len(q0), chunk):
        q, v = reference.solve(scene, (q0[a:a + chunk], v0[a:a + chunk]), t_end, t_eval=t, rtol=1e-12, atol=1e-12)
        out.append(measure(q, v))
    return t, np.concatenate(out, axis=1)


# ---------------------------------------------------------------- the energy barrier

def test_the_barrier_for_unit_masses_and_lengths_is_2cos_theta1_plus_cos_theta2_above_1():
    assert fractal.barriers((1.0, 1.0), (1.0, 1.0), G) == [4 * G, 2 * G]
    scene = load("fractal_flip")
    th = np.random.default_rng(1).uniform(-np.pi, np.pi, (20000, 2))
    e = reference.energy(scene, th, np.zeros_like(th))  # at rest: the potential alone
    inside = e < min(fractal.barriers((1.0, 1.0), (1.0, 1.0), G))
    assert (inside == (2 * np.cos(th[:, 0]) + np.cos(th[:, 1]) > 1)).all()


UNEVEN = {"pendulums.masses": "[1.0,3.0]", "pendulums.lengths": "[1.0,0.5]"}  # B = (8g, 3g): link 2 first


def test_no_pixel_inside_the_barrier_ever_flips_and_the_map_never_integrates_them():
    scene = small("fractal_flip", n=24, seconds=10.0, **UNEVEN)
    p = scene.pendulums
    b = min(fractal.barriers(p.masses, p.lengths, p.gravity))
    assert b == pytest.approx(3 * G)
    mp, sim, _ = run_map(scene.replace(video={"duration": 0.1}))
    q0, v0 = sim.initial_state()
    inside = reference.energy(scene, q0, v0) < b
    assert 0.2 < inside.mean() < 0.8
    ev = mp.event.to_numpy()
    assert ((ev == fractal.NEVER) == inside).all()  # black from the first frame, never integrated
    # DOP853 from every start inside: no link ever reaches the top, over 10 s (10^4 samples)
    _, peak = reference_runs(scene, q0[inside], v0[inside], 10.0, lambda q, v: np.abs(q).max(-1).max(0)[None])
    assert peak.max() < np.pi, peak.max()


@pytest.mark.parametrize("link", [0, 1])
def test_the_barrier_is_tight_link_by_link(link):
    """Link k near the top, the others hanging, moving up: with E = B_k·(1 + 1e-4) it flips, so no barrier
    above B_k holds; with E = B_k·(1 − 1e-2) it cannot (from further down, where that energy is possible)."""
    scene = small("fractal_flip", **UNEVEN)
    p = scene.pendulums
    b = fractal.barriers(p.masses, p.lengths, p.gravity)[link]
    q = np.zeros((2, 2))
    q[:, link] = np.pi - np.array([1e-3, 0.25])
    rest = reference.energy(scene, q, np.zeros_like(q))
    inertia = sum(p.masses[link:]) * p.lengths[link] ** 2  # M_kk: the kinetic energy is ½ M_kk ω_k² alone
    v = np.zeros_like(q)
    e = b * np.array([1 + 1e-4, 1 - 1e-2])
    v[:, link] = np.sqrt(2 * (e - rest) / inertia)
    assert reference.energy(scene, q, v) == pytest.approx(e, rel=1e-12)
    _, peak = reference_runs(scene, q, v, 2.0, lambda q, v: np.abs(q[:, :, link]).max(0)[None])
    assert peak[0, 0] > np.pi and peak[0, 1] < np.pi, peak


@pytest.mark.parametrize("name, sets", [("fractal_flip", []), ("fractal_divergence", [
    'integrator.method="implicit_midpoint"', "map.epsilon=1e-3"])])  # pairs that part within the 3 s
def test_a_map_steps_each_pendulum_as_the_systems_advance_until_its_event_and_then_stops(name, sets):
    """The map's kernel steps its pixels in lanes, as System.advance does, and finds events between the
    substeps: a pendulum whose event is still ahead stands, to the bit, where the system's own advance puts
    the same start (the implicit midpoint too, whose solver iterates each pendulum, not each pair, to its
    tolerance), and one whose event is in has stopped there."""
    scene = load(name, ["video.width=48", "video.height=48", "video.duration=3", "video.fps=10",
                        "integrator.min_faithful=0", *sets])
    mp, sim, _ = run_map(scene)
    per_point = 2 if scene.fractal == "divergence" else 1
    pending = np.repeat(mp.event.to_numpy() == fractal.PENDING, per_point)
    done = np.repeat(mp.event.to_numpy() >= 0, per_point)
    assert pending.sum() > 100 and done.sum() > 100, (pending.sum(), done.sum())
    plain = Run(scene)  # a system of its own (the map's is still held), stepped by its advance kernel
    for _ in plain.frames():
        pass
    q_map, q_plain = sim.q.to_numpy(), plain.sim.q.to_numpy()
    assert q_map[pending].tobytes() == q_plain[pending].tobytes()
    assert (sim.v.to_numpy()[pending] == plain.sim.v.to_numpy()[pending]).all()
    assert (q_map[done] != q_plain[done]).any(-1).mean() > 0.9  # stopped at its event, while the plain run went on


@pytest.mark.parametrize("name, sets", [("fractal_flip", ["map.samples=4"]), ("fractal_divergence", [
    "map.epsilon=1e-3"])])
def test_an_event_map_repaints_only_what_changed_and_its_frames_are_those_painted_whole(name, sets):
    """An event map keeps its plot between frames and repaints only the pixels still pending or settled since
    the last paint: every frame, one after two advances included, is byte for byte the frame painted whole.
    (A divergence map's pending pairs change their grey every frame; a flip map's settle for good: late in
    it well under half of the plot still changes from frame to frame.)"""
    import math
    scene = load(name, ["video.width=96", "video.height=64", "video.duration=3", "video.fps=10",
                        "integrator.min_faithful=0", *sets])
    src = pipeline.Source(scene)
    canvas, last, changed = src.canvas, None, []
    for f in range(scene.frames):
        if f == 12:
            next(src._steps)  # a frame advanced but never drawn: what settled in it must still be repainted
        frame = src.next_frame()
        canvas.painted = -math.inf
        assert canvas.draw().tobytes() == frame.tobytes(), f
        if last is not None:
            changed.append((frame != last).any(-1).mean())
        last = frame
        if src.index == scene.frames - 1:
            break
    assert max(changed) > 0 and (scene.fractal == "divergence" or max(changed[-5:]) < 0.5), changed


# ---------------------------------------------------------------- flip times and the trust mask

@pytest.mark.slow
def test_flip_times_match_dop853_wherever_the_mask_trusts_them():
    """A 32×32 flip map (f32, RK4 at the preset's step, 8 s) against DOP853 from every pixel's start, and its
    lattice mask (stride 4) against the certificate run at every pixel."""
    scene = small("fractal_flip", n=32, seconds=8.0, **{"map.trust_stride": 4})
    mp, sim, _ = run_map(scene)
    ev = mp.event.to_numpy().astype(np.float64)
    t_end = (scene.frames - 1) / scene.video.fps  # the last frame: where the map stopped
    q0, v0 = sim.initial_state()
    t, ref = reference_runs(scene, q0, v0, t_end, lambda q, v: np.abs(q).max(-1))
    ref = first_crossing(t, ref, np.pi)
    e = reference.energy(scene, q0, v0)
    b = min(fractal.barriers((1.0, 1.0), (1.0, 1.0), G))
    assert not np.isfinite(ref[e < b]).any()  # nothing inside the barrier flips
    can = ev != fractal.NEVER
    claim = np.where(ev >= 0, ev, t_end)  # what a pixel shows reaches this far along its trajectory
    trusted = can & (claim <= mp.until.to_numpy())
    flipped = ev >= 0
    agree = (flipped == np.isfinite(ref)) & (~flipped | (np.abs(ev - ref) < 1e-2))
    assert agree[trusted].all(), np.flatnonzero(trusted & ~agree)
    assert np.abs(ev - ref)[trusted & flipped].max() < 5e-3  # tol 1e-3 rad at ω of order 1 rad/s
    assert trusted[flipped].mean() > 0.6 and flipped.sum() > 300  # the mask is not trivially all-distrust
    # the mask (least of four lattice samples) against a certificate at every pixel: it errs towards distrust
    fine = certify.certify(scene, indices=np.arange(scene.pendulums.count)).until_s
    fine_trusted = can & (claim <= fine)
    false_trust = (trusted & ~fine_trusted).sum() / can.sum()
    false_distrust = (~trusted & fine_trusted).sum() / can.sum()
    assert false_trust < 0.03 and false_distrust < 0.25, (false_trust, false_distrust)


@pytest.mark.slow
def test_divergence_times_match_dop853_wherever_the_mask_trusts_them():
    scene = small("fractal_divergence", n=16, seconds=8.0, **{"map.trust_stride": 3, "map.threshold": 0.01})
    mp, sim, _ = run_map(scene)
    ev = mp.event.to_numpy().astype(np.float64)
    t_end = (scene.frames - 1) / scene.video.fps
    q0, v0 = sim.initial_state()
    assert np.allclose(q0[1::2, 1] - q0[0::2, 1], scene.map.epsilon) and (q0[1::2, 0] == q0[0::2, 0]).all()

    def distance(q, v):
        return np.sqrt(((q[:, 0::2] - q[:, 1::2]) ** 2 + (v[:, 0::2] - v[:, 1::2]) ** 2).sum(-1))
    t, d = reference_runs(scene, q0, v0, t_end, distance)
    ref = first_crossing(t, d, scene.map.threshold)
    parted = ev >= 0
    trusted = np.where(parted, ev, t_end) <= mp.until.to_numpy()
    agree = (parted == np.isfinite(ref)) & (~parted | (np.abs(ev - ref) < 2e-2))
    assert agree[trusted].all(), np.flatnonzero(trusted & ~agree)
    assert parted.sum() > 40 and trusted[parted].mean() > 0.6


def test_the_lattice_gives_each_pixel_the_least_of_its_neighbours():
    scene = load("fractal_flip", ["video.width=32", "video.height=32", "map.trust_stride=8"])
    assert list(grid.lattice_axis(32, 8)) == [4, 12, 20, 28]
    idx = grid.trust_indices(scene)
    assert list(idx[:4]) == [4 * 32 + 4, 4 * 32 + 12, 4 * 32 + 20, 4 * 32 + 28]
    until = np.arange(16, dtype=float)  # sample (r, c) holds 4r + c
    m = grid.faithful_map(scene, until)
    assert m[4, 4] == 0 and m[12, 12] == 5 and m[4, 12] == 1  # on a sample: its own
    assert m[8, 8] == 0 and m[13, 25] == 6 and m[30, 30] == 15 and m[0, 0] == 0  # between: the least
    twins = load("fractal_divergence", ["video.width=32", "video.height=32", "map.trust_stride=8"])
    assert (grid.trust_indices(twins)[:2] == [2 * idx[0], 2 * idx[0] + 1]).all()
    assert grid.faithful_map(twins, np.repeat(until, 2) - np.tile([0, 0.5], 16))[12, 12] == 4.5  # the lesser


# ---------------------------------------------------------------- renders: stills, determinism, axes

@pytest.mark.parametrize("name", ["fractal_flip", "fractal_divergence"])
def test_maps_render_mp4_gif_and_png_byte_identical_at_1_and_2_threads(tmp_path, name):
    scene = load(name, ["video.width=256", "video.height=144", "video.duration=1", "video.fps=20"])
    assert scene.video.formats == ("mp4", "gif", "png")
    runs = []
    for threads in (1, 2):
        frames = []
        meta = pipeline.render(scene, tmp_path / str(threads), threads=threads,
                               frame_hook=lambda f, fr: frames.append(fr.copy()))
        runs.append((frames, meta))
    (a, meta), (b, _) = runs
    assert all(x.tobytes() == y.tobytes() for x, y in zip(a, b)) and len(a) == scene.frames == 20
    d = tmp_path / "1" / name
    assert iio.imread(d / f"{name}.png").tobytes() == a[-1].tobytes()  # the still is the last frame, lossless
    assert (d / f"{name}.png").read_bytes() == (tmp_path / "2" / name / f"{name}.png").read_bytes()
    assert iio.imread(d / f"{name}.mp4").shape == (20, 144, 256, 3)
    assert set(meta["outputs"]) == {f"{name}.{x}" for x in ("mp4", "gif", "png", "npz")}
    assert not list(d.glob(".*")), "temporary files left behind"
    m = json.loads((d / "metadata.json").read_text())["map"]
    assert m["colouring"] == scene.fractal and m["pixels"] == m["plot"]["width"] * m["plot"]["height"]
    assert m["events_trusted"] <= m["events"] and {"text_bytes", "fractal_swatch"} <= set(meta["kernels"])
    # decorations: the plot's border around it, and the legend drawn right of it
    lay = grid.layout(256, 144)
    frame = a[-1]
    assert (frame[lay.y0 - 1, lay.x0:lay.x0 + lay.w] == axes.FRAME).all()
    assert (frame[lay.y0:lay.y0 + lay.h, lay.x0 + lay.w + 1:] != axes.BACKGROUND).any(-1).sum() > 500


def test_axes_label_theta_in_units_of_pi_and_time_on_a_log_scale():
    assert [axes.pi_label(k * np.pi / 4) for k in range(-4, 5)] == \
        ["−π", "−3π/4", "−π/2", "−π/4", "0", "π/4", "π/2", "3π/4", "π"]
    assert axes.time_ticks(0.1, 20.0, 20) == [0.1, 0.2, 0.5, 1, 2, 5, 10, 20]
    assert axes.time_ticks(0.1, 20.0, 4) == [0.1, 1, 10]
    assert axes.power(1e-6) == "10⁻⁶"
    lay = grid.layout(1280, 720)
    assert lay.w == lay.h and lay.x0 + lay.w < 1280 - 200 and lay.font == "10x20"
    assert grid.layout(64, 36).w == 64 and grid.layout(64, 36).font is None  # too small: all map


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("sets, words", [
    (["system=\"elastic\""], ["fractal", "angles"]),
    (["map.threshold=1e-7"], ["map.threshold", "epsilon"]),
    (["pendulums.count=100"], ["pendulums.count", "leave it out"]),
    (["effects=[\"rods\"]"], ["fractal", "effects"]),
])
def test_bad_map_input_exits_2_naming_the_key(tmp_path, sets, words):
    args = ["render", "fractal_divergence", "--out", tmp_path]
    for s in sets:
        args += ["--set", s]
    r = run_cli(*args)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "fractal_divergence.toml" in r.stderr and all(w in r.stderr for w in words), r.stderr
    assert not list(tmp_path.iterdir())
