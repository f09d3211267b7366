"""Glow: light adds up and is tone-mapped, the rainbow palette sums to white, and rainbow_1000 is the same bytes
at any thread count (MP4 included)."""
import hashlib

import numpy as np
import pytest

from conftest import make_scene, run_cli
from render.draw import glow
from render.video import pipeline
from render.config.scene import load

VIDEO = {"width": 160, "height": 90, "fps": 10, "duration": 0.3}


def frames_of(scene, tmp_path, threads=None):
    out = []
    meta = pipeline.render(scene, tmp_path, threads=threads, frame_hook=lambda f, fr: out.append(fr.copy()))
    return meta, np.stack(out)


def test_the_tone_map_is_black_at_no_light_white_at_plenty_and_monotone():
    t = glow.tone_table()
    assert t[0] == 0 and t[-1] == 255 and (np.diff(t) >= 0).all()
    light = 1.0  # one pendulum's rod alone, through the middle of a pixel
    assert t[int(light * glow.FIX) >> glow.SHIFT] == round(255 * (1 - np.exp(-light)))


@pytest.mark.parametrize("effects", [["rods"], ["rods", "glow"]])
def test_coincident_pendulums_add_their_light_under_glow_only(tmp_path, effects):
    """Two and four identical pendulums in the rainbow palette: their colours add up to grey, and four give
    twice the light of two. Under a max the count makes no difference."""
    def scene(n):
        return make_scene("rigid", n, effects=effects, video={**VIDEO, "palette": "rainbow"},
                          pendulums={"theta1": 1.0, "theta2": 2.0, "spread": 0.0})
    _, two = frames_of(scene(2), tmp_path / "2")
    _, four = frames_of(scene(4), tmp_path / "4")
    lit = two.max(-1) > 0
    assert lit.any() and (four.max(-1) > 0)[lit].all()
    if "glow" in effects:
        assert (two[..., 0] == two[..., 1]).all() and (two[..., 1] == two[..., 2]).all()  # red + cyan: grey
        assert (four >= two).all() and (four[lit] > two[lit]).mean() > 0.9
        # twice the light: each byte back through the tone map, light = −ln(1 − byte/255), where a byte's
        # rounding moves it by under 2 % (two's bytes 40-180, four's below 240)
        light = lambda b: -np.log(1.0 - b.astype(np.float64) / 255.0)  # noqa: E731
        grey2, grey4 = two[..., 0], four[..., 0]
        fair = (grey2 >= 40) & (grey2 <= 180) & (grey4 < 240)
        ratio = light(grey4[fair]) / light(grey2[fair])
        assert fair.sum() > 50 and np.abs(ratio - 2.0).max() < 0.1, (fair.sum(), ratio.min(), ratio.max())
    else:
        np.testing.assert_array_equal(four, two)


def test_rainbow_1000_is_the_same_bytes_at_1_2_and_8_threads(tmp_path):
    """Short and small, but from t = 0 (all 1000 pendulums on top of each other: the most adds per pixel)
    to the spray of the last frame. Two threads still draw serially (SERIAL_MAX_THREADS); 8 take the
    parallel path, where the integer atomic adds race."""
    scene = load("rainbow_1000", ["video.width=320", "video.height=180", "video.fps=4", "video.duration=7",
                                  'video.formats=["mp4"]'])
    runs = {}
    for threads in (1, 2, 8):
        meta, frames = frames_of(scene, tmp_path / str(threads), threads)
        mp4 = (tmp_path / str(threads) / "rainbow_1000" / "rainbow_1000.mp4").read_bytes()
        runs[threads] = (hashlib.sha256(frames.tobytes()).hexdigest(), hashlib.sha256(mp4).hexdigest())
        assert "glow.tone" in meta["fields"]
    assert runs[1] == runs[2] == runs[8], runs
    assert frames[0].max() == 255 and frames[-1].max() > 0  # a white-hot start, still lit at the end


@pytest.mark.parametrize("sets, key", [(['effects=["fractal", "glow"]'], "effects"),
                                       (["video.palette=spectral"], "video.palette")])
def test_glow_and_palette_mistakes_exit_2_naming_the_key(sets, key, tmp_path):
    args = ["render", "fractal" if "fractal" in sets[0] else "rainbow_1000", "--out", tmp_path]
    for s in sets:
        args += ["--set", s]
    r = run_cli(*args)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert f"presets/{args[1]}.toml: {key}:" in r.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name, drawn", [("elastic_fan", ["springs", "bobs", "trails"]),
                                         ("triple_chaos", ["rods", "bobs", "trails"])])
def test_every_system_draws_under_glow_with_the_hud(name, drawn, tmp_path):
    effects = '","'.join(drawn + ["glow", "hud"])
    scene = load(name, ["video.width=160", "video.height=90", "video.fps=10", "video.duration=0.3",
                        'video.formats=["mp4"]', f'effects=["{effects}"]'])
    meta, frames = frames_of(scene, tmp_path)
    assert {"glow.tone", "hud.history"} <= set(meta["fields"])
    assert meta["fields"]["canvas.frame"] == 160 * 96 * 3 * 4  # fixed-point light, whole 8x8 tiles
    centre = frames[:, 20:70, 50:110]  # where the pendulums are (the HUD keeps to the corners)
    assert (centre.max(axis=(1, 2, 3)) > 100).all()
