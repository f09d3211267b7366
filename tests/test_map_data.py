"""A map's per-pixel data (NAME.npz, render.load_map) and supersampling (map.samples): the npz's flip times
against the PNG's colours and against DOP853, a supersampled pixel as its samples' colours averaged in linear
light, sub-pixel starts, determinism at 1 and 2 threads, the budget, and bad input."""
import imageio.v3 as iio
import numpy as np
import pytest

import render
from conftest import run_cli
from render.config import budget, estimate
from render.config.scene import load
from render.errors import EncodeError, SceneError
from render.maps import colours, data, fractal, supersample
from render.physics import grid, reference, registry
from render.video import pipeline


def small(name="fractal_flip", n=32, seconds=4.0, *sets):
    """A preset on an n×n frame (too small for axes: the map fills it), at 30 fps."""
    return load(name, [f"video.width={n}", f"video.height={n}", f"video.duration={seconds}", "video.fps=30",
                       "integrator.min_faithful=0", *sets])


def rendered(scene, out):
    """Render `scene` into `out`; its metadata, its map data and its PNG (the last frame, lossless)."""
    meta = pipeline.render(scene, out)
    d = scene.out_dir(out)
    return meta, render.load_map(d), iio.imread(d / f"{scene.name}.png")


# ---------------------------------------------------------------- the colours an npz's values call for

def palette(u):
    """colours.PALETTE at u in [0, 1], piecewise linear, as numpy: (..., 3)."""
    stops = np.asarray(colours.PALETTE)
    x = np.clip(u, 0.0, 1.0) * (len(stops) - 1)
    k = np.minimum(np.floor(x).astype(int), len(stops) - 2)
    f = (x - k)[..., None]
    return (1 - f) * stops[k] + f * stops[k + 1]


def sample_colours(d, time_scale):
    """Each sample's colour (H, W, S, 3) from the npz alone: its flip time on the log scale (early bright),
    black where it cannot flip, grey while pending; where it is not trusted, most of the colour drained and a
    diagonal hatch every colours.HATCH pixels."""
    lo, hi = time_scale
    v = d.value.astype(np.float64)
    u = (np.log(np.maximum(v, lo)) - np.log(lo)) / np.log(hi / lo)
    col = np.where((v >= 0)[..., None], palette(1 - u), 0.0)
    col[v == d.pending] = colours.PENDING_GREY
    col[v == d.never] = 0.0
    lum = (col * [0.3, 0.59, 0.11]).sum(-1, keepdims=True)
    drained = 0.75 * (lum + 0.3 * (col - lum))
    r, c = np.indices(v.shape[:2])
    hatch = ((r + c) % colours.HATCH == 0)[..., None, None]
    drained = np.where(hatch, np.where(lum > 0.45, 0.1, 0.5), drained)
    return np.where(d.trusted[..., None], col, drained)


def to_bytes(col):
    return np.floor(np.minimum(col, 1.0) * 255.0 + 0.5).astype(int)


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.maximum(c, 0) ** (1 / 2.4) - 0.055)


def first_crossing(t, x, level):
    """Per column of x (len(t), N): the first time x passes `level`, linearly interpolated; inf if never."""
    out = np.full(x.shape[1], np.inf)
    for j in np.flatnonzero((x > level).any(0)):
        i = int((x[:, j] > level).argmax())
        out[j] = t[0] if i == 0 else t[i - 1] + (level - x[i - 1, j]) / (x[i, j] - x[i - 1, j]) * (t[i] - t[i - 1])
    return out


# ---------------------------------------------------------------- the npz of a flip map

@pytest.mark.slow
def test_the_npz_flip_times_agree_with_the_png_and_with_dop853_on_100_trusted_pixels(tmp_path):
    scene = small("fractal_flip", 32, 4.0, "map.trust_stride=4")
    meta, d, png = rendered(scene, tmp_path)
    name = scene.name
    assert meta["outputs"][f"{name}.npz"] == (tmp_path / name / f"{name}.npz").stat().st_size
    assert render.load_map(tmp_path / name / f"{name}.npz").value.tobytes() == d.value.tobytes()  # file or folder
    assert (d.colouring, d.unit, d.samples) == ("flip_time", "s", 1)
    assert (d.x_quantity, d.y_quantity, d.x_unit, d.y_unit) == ("theta1", "theta2", "rad", "rad")
    assert d.value.shape == d.cannot_flip.shape == d.trusted.shape == (32, 32, 1) and d.trusted_until.shape == (32, 32)
    assert d.t == pytest.approx((scene.frames - 1) / scene.video.fps)
    # the axes: pixel centres from -π to π, θ2 downwards; every sample starts at its pixel's centre
    assert np.allclose(d.x, -np.pi + (np.arange(32) + 0.5) * 2 * np.pi / 32) and np.allclose(d.y, -d.x)
    assert np.allclose(d.starts[..., 0, 0], d.x[None, :]) and np.allclose(d.starts[..., 0, 1], d.y[:, None])
    # what the metadata counts, the npz holds
    m, v = meta["map"], d.value
    assert m["cannot_flip"] == (v == d.never).sum() == d.cannot_flip.sum() > 100
    assert m["events"] == (v >= 0).sum() > 200 and m["events_trusted"] == ((v >= 0) & d.trusted).sum()
    assert m["pending"] == (v == d.pending).sum() and ((v >= 0) | (v == d.pending) | d.cannot_flip).all()
    # the PNG's colours are the ones its stored times, masks and trust call for, at every pixel
    want = to_bytes(sample_colours(d, m["time_scale_s"])[:, :, 0])
    assert np.abs(want - png.astype(int)).max() <= 1
    # DOP853 (render/physics/reference.py's chain model) from 100 trusted pixels' starts: 70 that flipped,
    # 30 that had not by t
    rng = np.random.default_rng(26)
    flipped = np.flatnonzero((v[..., 0] >= 0).ravel() & d.trusted[..., 0].ravel())
    pending = np.flatnonzero((v[..., 0] == d.pending).ravel() & d.trusted[..., 0].ravel())
    pick = np.concatenate([rng.choice(flipped, 70, replace=False), rng.choice(pending, 30, replace=False)])
    q0 = d.starts.reshape(-1, 2)[pick]
    t = np.arange(0.0, d.t + 1e-12, 1e-3)
    q, _ = reference.solve(scene, (q0, np.zeros_like(q0)), d.t, t_eval=t, rtol=1e-11, atol=1e-11)
    ref = first_crossing(t, np.abs(q).max(-1), np.pi)
    ev = v.ravel()[pick].astype(np.float64)
    assert np.abs(ev[:70] - ref[:70]).max() < 5e-3, np.abs(ev[:70] - ref[:70]).max()
    assert (ref[70:] > d.t - 1e-3).all(), ref[70:]  # not flipped by the last frame either


def test_load_map_refuses_what_is_not_a_map(tmp_path):
    with pytest.raises(FileNotFoundError, match="no map data"):
        render.load_map(tmp_path)
    np.savez(tmp_path / "x.npz", t=np.arange(3))
    with pytest.raises(ValueError, match="x.npz: not a map's data"):
        render.load_map(tmp_path / "x.npz")
    (tmp_path / "y.npz").write_text("hello")
    with pytest.raises(ValueError, match="y.npz: not a map's data"):
        render.load_map(tmp_path / "y.npz")
    h, w = 2, 3  # a map's fields, the shapes render/maps/data.py gives; then each one damaged
    good = {"colouring": "flip_time", "unit": "s", "x_quantity": "theta1", "y_quantity": "theta2", "x_unit": "rad",
            "y_unit": "rad", "x": np.zeros(w), "y": np.zeros(h), "starts": np.zeros((h, w, 1, 2)),
            "value": np.zeros((h, w, 1), np.float32), "t": 1.0, "cannot_flip": np.zeros((h, w, 1), bool),
            "trusted_until": np.zeros((h, w), np.float32), "trusted": np.ones((h, w, 1), bool), "pending": -1.0,
            "never": -2.0}
    np.savez(tmp_path / "good.npz", **good)
    assert render.load_map(tmp_path / "good.npz").value.shape == (h, w, 1)
    for name, bad, says in (("t", np.arange(3.0), "t is"), ("x", np.zeros(4), "plot's 2 x 4 pixels"),
                            ("unit", np.zeros(2), "unit is"), ("trusted", np.ones((w, h)), "trusted is")):
        np.savez(tmp_path / "bad.npz", **{**good, name: bad})
        with pytest.raises(ValueError, match=f"bad.npz: not a map's data \\(.*{says}"):
            render.load_map(tmp_path / "bad.npz")
    raw = bytearray((tmp_path / "good.npz").read_bytes())
    at = raw.index(b"starts.npy") + 200  # inside that member's bytes: its CRC no longer matches
    raw[at] ^= 0xFF
    (tmp_path / "crc.npz").write_bytes(bytes(raw))
    with pytest.raises(ValueError, match="crc.npz: not a map's data"):
        render.load_map(tmp_path / "crc.npz")


def test_a_render_that_fails_as_it_finishes_leaves_no_npz(tmp_path, monkeypatch):
    from render.video import encode

    def failing(self, audio=None, publish=True):
        self.abort()
        raise EncodeError("ffmpeg failed (a test)")

    monkeypatch.setattr(encode.Encoder, "close", failing)
    with pytest.raises(EncodeError):
        pipeline.render(small("fractal_flip", 32, 0.2), tmp_path)
    assert not list(tmp_path.rglob("*"))  # no NAME.npz, no temporary, and the folder made for them is gone


# ---------------------------------------------------------------- supersampling

@pytest.mark.parametrize("samples, axes", [(4, []), (9, []),
                                           (4, ['map.x="omega1"', "map.x_range=[-2.0, 3.0]", "map.y_range=[0.5, 0.501]"])])
def test_sub_pixel_starts_split_each_pixel_into_a_regular_grid(samples, axes):
    scene = small("fractal_flip", 32, 1.0, f"map.samples={samples}", *axes)
    k = int(round(samples ** 0.5))
    xy = grid.sample_starts(scene).reshape(32, 32, samples, 2)
    centres = grid.starts(scene).reshape(32, 32, 2)
    assert np.allclose(xy.mean(2), centres, atol=1e-12, rtol=0)  # the samples sit around their pixel's centre
    fine = np.stack([supersample.fine_grid(xy[..., i].ravel(), 32, 32, samples) for i in (0, 1)], -1)
    # on the samples' own grid they are the pixel centres of a map k times as fine, whatever the axes span
    (_, xlo, xhi), (_, ylo, yhi) = grid.axes_of(scene.map)
    assert np.allclose(fine[0, :, 0], xlo + (np.arange(32 * k) + 0.5) * (xhi - xlo) / (32 * k), atol=1e-12, rtol=0)
    assert np.allclose(fine[:, 0, 1], yhi - (np.arange(32 * k) + 0.5) * (yhi - ylo) / (32 * k), atol=1e-12, rtol=0)
    assert np.allclose(fine[..., 0], fine[:1, :, 0]) and np.allclose(fine[..., 1], fine[:, :1, 1])
    assert (supersample.coarse(supersample.fine_grid(np.arange(32 * 32 * samples), 32, 32, samples), 32, 32, samples)
            == np.arange(32 * 32 * samples)).all()
    assert scene.pendulums.count == 32 * 32 * samples


def test_a_2x2_supersampled_map_integrates_the_samples_a_map_twice_as_fine_has_as_pixels():
    """Every sample is a pendulum of its own with its own event: a 16×16 map of 4 samples holds, sample for
    sample, the flip times of the 32×32 map whose pixel centres its samples are."""
    events = []
    for scene in (small("fractal_flip", 32, 3.0), small("fractal_flip", 16, 3.0, "map.samples=4")):
        src = pipeline.Source(scene)  # one at a time: each starts Taichi afresh
        for _ in range(src.frames):
            src.next_frame()
        events.append(src.canvas.event.to_numpy())
    ev = events[0].reshape(32, 32)
    mine = supersample.fine_grid(events[1], 16, 16, 4)
    assert (ev >= 0).sum() > 100 and (ev == fractal.NEVER).sum() > 100
    assert np.array_equal(mine == fractal.NEVER, ev == fractal.NEVER)
    assert (mine == ev).mean() > 0.999  # the same f32 starts and arithmetic: the same times, to the bit (here all)


@pytest.mark.slow
def test_an_ftle_map_of_4_samples_holds_each_samples_sigma_and_draws_the_barrier_on_their_grid():
    """As for the flip map: a 16×16 FTLE map of 4 samples is, sample for sample, the 32×32 map (σ_t, the
    barrier's curve, the cannot-flip mask), and its data hold σ_t per sample in 1/s."""
    got = []
    for scene in (small("fractal_lyapunov", 32, 0.3), small("fractal_lyapunov", 16, 0.3, "map.samples=4")):
        src = pipeline.Source(scene)
        for _ in range(src.frames):
            src.next_frame()
        got.append((data.arrays(scene, src.canvas), src.canvas.edge.to_numpy()))
    (fine, fine_edge), (four, edge) = got
    assert (str(four["colouring"]), str(four["unit"]), four["value"].shape) == ("lyapunov", "1/s", (16, 16, 4))
    sigma = fine["value"].reshape(32, 32)
    assert np.abs(supersample.fine_grid(four["value"].ravel(), 16, 16, 4) - sigma).max() < 1e-9 and sigma.max() > 0.5
    inside = fine["cannot_flip"].reshape(32, 32)
    assert np.array_equal(supersample.fine_grid(four["cannot_flip"].ravel(), 16, 16, 4), inside) and inside.any()
    assert np.array_equal(supersample.fine_grid(edge, 16, 16, 4), fine_edge.reshape(32, 32)) and edge.sum() > 20
    assert np.array_equal(four["trusted"], np.repeat((four["trusted_until"] >= np.float32(four["t"]))[..., None], 4, -1))


def test_a_supersampled_pixel_is_its_samples_colours_averaged_in_linear_light(tmp_path):
    scene = small("fractal_flip", 32, 3.0, "map.samples=4", "map.trust_stride=4", 'video.formats=["mp4", "png"]')
    meta, d, png = rendered(scene, tmp_path)
    assert d.value.shape == (32, 32, 4) and meta["map"]["samples"] == 4
    col = sample_colours(d, meta["map"]["time_scale_s"])
    want = to_bytes(linear_to_srgb(srgb_to_linear(col).mean(2)))
    assert np.abs(want - png.astype(int)).max() <= 1
    # pixels whose samples differ: the mean of their sRGB values would be visibly darker
    naive = to_bytes(col.mean(2))
    mixed = np.ptp(col, axis=2).max(-1) > 0.3
    assert mixed.sum() > 50 and (np.abs(naive - png.astype(int)).max(-1)[mixed] > 3).mean() > 0.5


def test_four_samples_render_byte_identical_at_1_and_2_threads(tmp_path):
    scene = load("fractal_flip", ["video.width=256", "video.height=144", "video.duration=1", "video.fps=20",
                                  "map.samples=4"])
    runs = []
    for threads in (1, 2):
        frames = []
        pipeline.render(scene, tmp_path / str(threads), threads=threads,
                        frame_hook=lambda f, fr: frames.append(fr.copy()))
        runs.append(frames)
    a, b = runs
    assert len(a) == scene.frames == 20 and all(x.tobytes() == y.tobytes() for x, y in zip(a, b))
    one, two = (tmp_path / str(k) / scene.name / f"{scene.name}.npz" for k in (1, 2))
    assert one.read_bytes() == two.read_bytes()
    lay = grid.layout(256, 144)
    assert render.load_map(one.parent).value.shape == (lay.h, lay.w, 4)
    assert not list(one.parent.glob(".*")), "temporary files left behind"


def test_the_budget_counts_every_sample_as_a_pendulum(tmp_path):
    one = load("fractal_flip", ["video.width=640", "video.height=360", "video.duration=10"])
    nine = load("fractal_flip", ["video.width=640", "video.height=360", "video.duration=10", "map.samples=9"])
    assert nine.pendulums.count == 9 * one.pendulums.count == 9 * grid.layout(640, 360).pixels
    rates, _ = estimate.load_rates(None)
    e1, e9 = (estimate.estimate(s, rates) for s in (one, nine))
    assert e9.steps == 9 * e1.steps and e9.parts["simulate"] > 8 * e1.parts["simulate"]
    # every sample of the lattice's pixels is certified: 9 times the steps, beside the two runs' cost per frame
    assert len(grid.trust_indices(nine)) == 9 * len(grid.trust_indices(one))
    per_frame = 2 * one.frames * rates["frame_s"]
    assert e9.parts["certificate"] - per_frame == pytest.approx(9 * (e1.parts["certificate"] - per_frame))
    limit = (e1.total * e9.total) ** 0.5  # between the two: one fits, nine samples do not
    system = registry.get("rigid")
    budget.check(one.replace(budget=limit), system, tmp_path)
    with pytest.raises(SceneError, match="fractal_flip.toml: .*over the run-time budget"):
        budget.check(nine.replace(budget=limit), system, tmp_path)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("value, words", [("2", ["must be 1, 4 or 9", "got 2"]), ("4.0", ["got 4.0"]),
                                          ('"4"', ["got '4'"]), ("true", ["got True"])])
def test_bad_samples_are_refused_naming_the_key(value, words):
    with pytest.raises(SceneError) as e:
        load("fractal_flip", [f"map.samples={value}"])
    msg = str(e.value)
    assert "fractal_flip.toml" in msg and "map.samples" in msg and all(w in msg for w in words), msg
    assert len(msg.splitlines()) == 1


def test_samples_on_a_fan_or_too_many_are_refused_from_the_cli(tmp_path):
    for args, words in ((["classic", "--set", "map.samples=4"], ["map.samples", "only a fractal map"]),
                        (["fractal_flip", "--set", "map.samples=16"], ["map.samples", "must be 1, 4 or 9"]),
                        (["fractal_flip", "--set", "video.width=3840", "--set", "video.height=2160", "--set",
                          "map.samples=9"], ["map.samples", "more than 4000000"])):
        r = run_cli("render", *args, "--out", tmp_path)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert ".toml" in r.stderr and all(w in r.stderr for w in words), r.stderr
    assert not list(tmp_path.iterdir())


def test_samples_are_part_of_the_scene_and_one_sample_is_the_scene_as_before():
    scene = load("fractal_flip")
    assert scene.map.samples == 1 and load("fractal_flip", ["map.samples=1"]).hash() == scene.hash()
    assert load("fractal_flip", ["map.samples=4"]).hash() != scene.hash()
