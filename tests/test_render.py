"""End to end: every shipped preset, shortened, rendered and decoded back; `simulate`; the CLI entry points."""
import json
import math

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import PICKS, SMALL_FPS, SMALL_H, SMALL_SECONDS, SMALL_W, out_folder, run_cli, small_scene
from render.config.scene import list_presets, load
from render.physics.integrators import DEFAULT_MAX_DRIFT


PRESETS = [p.stem for p in list_presets()]
W, H, FPS, SECONDS = SMALL_W, SMALL_H, SMALL_FPS, SMALL_SECONDS  # conftest's preset_renders
# dB, decoded frames vs the raw ones. The MP4's first (a key frame): H.264 crf 32 superfast (a finer quantiser
# beside the reach circle) with yuv420p chroma subsampling, which costs most on coloured text over black (the HUD,
# a comparison's labels): compare_methods measured 30.7 dB here (29.3 under veryfast). Its later frames, predicted
# from the earlier ones, lose more: 22.3 dB at the least (seed_rigid at 2.9 s, its fan spread over the frame).
# The GIF's: the same frames through a 256-colour palette, dithered, 27.0 dB at the least (seed_rigid at 2.9 s).
MIN_PSNR_MP4_FIRST, MIN_PSNR_MP4, MIN_PSNR_GIF = 28.0, 20.0, 24.0


def mse(a, b):
    return np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)


def psnr(a, b):
    err = mse(a, b)
    return 99.0 if err == 0 else 10 * np.log10(255.0 ** 2 / err)


def assert_shows(decoded, raw: dict, psnr_min: float, label: str):
    """Each decoded frame at conftest's PICKS is its own raw frame: within psnr_min dB of it, four times (6 dB)
    nearer to it than a black frame is (a fan's frame is mostly black, which a PSNR alone forgives: classic's
    first frame is 30 dB from black), and twice nearer to it than to any other pick's raw frame (a frozen or
    shuffled video shows the wrong one). Over every preset here the least margins were 9.6 (classic's MP4 at
    2.9 s) and 4.0 (fractal_flip's MP4 at 2.9 s)."""
    for pick, f in PICKS.items():
        got, want = decoded[f], raw[pick]
        err = mse(got, want)
        assert psnr(got, want) >= psnr_min, (label, pick, psnr(got, want))
        assert err < mse(np.zeros_like(want), want) / 4, (label, pick, err, mse(np.zeros_like(want), want))
        for other, frame in raw.items():
            if other != pick and mse(frame, want) > 0:
                assert 2 * err < mse(got, frame), (label, pick, other, err, mse(got, frame))


@pytest.fixture(scope="module")
def rendered(preset_renders):
    """Each preset rendered once (conftest): its folder, metadata and raw frames at PICKS."""
    return preset_renders


@pytest.mark.parametrize("name", PRESETS)
def test_mp4_decodes_to_every_frame(rendered, name):
    d, meta, raw = rendered[name]
    frames = iio.imread(d / f"{name}.mp4")
    info = iio.immeta(d / f"{name}.mp4")
    assert frames.shape == (round(FPS * SECONDS), H, W, 3)
    assert info["fps"] == FPS and info["codec"] == "h264" and info["pix_fmt"].startswith("yuv420p")
    assert psnr(frames[0], raw["first"]) >= MIN_PSNR_MP4_FIRST
    assert_shows(frames, raw, MIN_PSNR_MP4, name)
    assert meta["outputs"][f"{name}.mp4"] == (d / f"{name}.mp4").stat().st_size


@pytest.mark.parametrize("name", PRESETS)
def test_gif_decodes_at_its_own_size_and_rate(rendered, name):
    from PIL import Image

    d, meta, raw = rendered[name]
    scene = small_scene(name)
    gif = iio.imread(d / f"{name}.gif")
    gif_fps = min(scene.video.gif_fps, FPS)
    gw = min(scene.video.gif_width, W)  # never upscaled
    assert gif.shape[0] == math.ceil(gif_fps * round(FPS * SECONDS) / FPS - 1e-9)  # ffmpeg's fps filter
    assert gif.shape[1:3] == (round(H * gw / W / 2) * 2, gw)
    with Image.open(d / f"{name}.gif") as im:
        assert im.info["duration"] == 1000 // gif_fps and im.info.get("loop") == 0
    # at this size and rate the GIF's frames are the video's own (render/video/gif.py draws its own only where
    # they differ), through a 256-colour palette
    assert gif_fps == FPS and gw == W
    assert_shows(gif[..., :3], raw, MIN_PSNR_GIF, name)


@pytest.mark.parametrize("name", PRESETS)
def test_metadata_has_the_contract_fields(rendered, name):
    d, meta, _ = rendered[name]
    on_disk = json.loads((d / "metadata.json").read_text())
    assert on_disk == meta
    for key in ("preset", "preset_hash", "versions", "arch", "frames", "fps", "width", "height", "duration",
                "integrator", "effects", "kernels", "energy", "timings_s", "outputs", "field_bytes"):
        assert key in meta, key
    assert set(meta["versions"]) >= {"package", "taichi", "numpy", "ffmpeg"}
    assert set(meta["integrator"]) >= {"method", "dt", "substeps", "precision"}
    assert set(meta["timings_s"]) >= {"simulate", "draw", "encode", "total"}
    assert meta["frames"] == round(FPS * SECONDS) and meta["arch"] == "cpu"
    assert meta["preset"]["name"] == name and meta["preset_hash"] == small_scene(name).hash()
    assert meta["integrator"]["substeps"] * meta["integrator"]["dt"] == pytest.approx(1 / FPS)
    if "energy" in meta["effects"]:  # the seed's scenes drift by design and say so (integrator.max_drift);
        # a comparison's drift is its worst variant's, a coarse method shown on purpose: the watchdog's bound
        floor = DEFAULT_MAX_DRIFT if "compare" in meta else 1e-3
        assert 0 <= meta["energy"]["max_rel_drift"] < max(floor, meta["preset"]["integrator"]["max_drift"] or 0)
    for key in ("faithfulness", "quality"):  # certified renders (docs/certified-renders.md)
        assert key in meta, key
    assert not list(d.glob(".*")), "temporary files left behind"


def test_simulate_writes_the_trajectory_format(tmp_path):
    out = tmp_path / "traj.npz"
    r = run_cli("simulate", "elastic_fan", "--out", out, "--set", "video.duration=0.5", "--set", "video.fps=20")
    assert r.returncode == 0, r.stderr
    z = np.load(out)
    assert set(z.files) == {"t", "pos", "vel", "energy"}
    assert z["t"].shape == (10,) and z["t"][0] == 0 and z["t"][-1] == pytest.approx(9 / 20)
    assert z["pos"].shape == (10, 10, 2, 2) and z["vel"].shape == (10, 10, 2, 2) and z["energy"].shape == (10, 10)
    # row 0 is the initial state: pendulum 0 at rest lengths along theta1, theta2
    p = load("elastic_fan").pendulums
    x1 = p.lengths[0] * np.array([np.sin(p.theta1), -np.cos(p.theta1)])
    np.testing.assert_allclose(z["pos"][0, 0, 0], x1, atol=1e-12)
    np.testing.assert_allclose(z["energy"], np.broadcast_to(z["energy"][0], (10, 10)), rtol=1e-4)


def test_simulate_rigid_and_python_dash_m(tmp_path):
    out = tmp_path / "sub" / "classic.npz"
    r = run_cli("simulate", "classic", "--out", out, "--set", "video.duration=0.2", "--set", "video.fps=10")
    assert r.returncode == 0, r.stderr
    z = np.load(out)
    assert set(z.files) == {"t", "theta", "omega", "energy"} and z["theta"].shape == (2, 1, 2)
    np.testing.assert_allclose(z["theta"][0, 0], [np.radians(120), np.radians(-10)])


def test_presets_lists_every_file_and_help_explains():
    r = run_cli("presets")
    assert r.returncode == 0
    assert [line.split()[0] for line in r.stdout.splitlines()] == PRESETS
    assert {"rigid_chaos", "elastic_fan", "classic"} <= set(PRESETS)
    h = run_cli("render", "--help")
    assert h.returncode == 0 and "--set" in h.stdout and "--quality" in h.stdout and "--arch" in h.stdout


def test_seed_presets_match_the_brief():
    rigid, elastic = load("rigid_chaos"), load("elastic_fan")
    assert (rigid.system, rigid.pendulums.count, rigid.pendulums.spread) == ("rigid", 100, 1e-4)
    assert (elastic.system, elastic.pendulums.count) == ("elastic", 10)
    assert elastic.pendulums.spread == pytest.approx(np.pi / 20)
    assert "trails" in rigid.effects and "springs" in elastic.effects


def test_cuda_request_falls_back_to_cpu_with_one_warning(tmp_path):
    r = run_cli("render", "classic", "--arch", "cuda", "--out", tmp_path, "--set", "video.duration=0.1",
                "--set", "video.width=64", "--set", "video.height=48")
    assert r.returncode == 0, r.stderr
    meta = json.loads((out_folder(tmp_path, "classic") / "metadata.json").read_text())
    if meta["arch"] == "cpu":  # no GPU here (CI): exactly one clear warning
        assert r.stderr.count("warning: --arch cuda") == 1
    else:  # a GPU: the render ran there, with nothing to warn of
        assert meta["arch"] == "cuda" and "warning" not in r.stderr, (meta["arch"], r.stderr)
