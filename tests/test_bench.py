"""`pendulum bench --quick` writes its report; the fractal preset renders (small) one pendulum per pixel."""
import json
import math

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import run_cli
from render.commands import peers
from render.video import pipeline
from render.config.scene import load

KEYS = ("end_to_end_over_encode_floor", "sim_speedup_vs_numpy_1e5", "fractal_peak_mem_mb",
        "rainbow_1000_draw_fps", "draw_fps", "encode_fps", "end_to_end_s", "encode_floor_s")
TARGETS = {"end_to_end_over_encode_floor", "sim_speedup_vs_numpy_1e5", "fractal_fps.flip_time", "fractal_peak_mem_mb",
           "rainbow_1000_draw_fps", "sim_speedup_vs_numba_1e5", "rigid_f64_steps_per_s_1e5",
           "rigid_f32_steps_per_s_1e5", "elastic_speedup_vs_numpy_1e5", "render_over_realtime",
           "matplotlib_peer_ratio"}
PEER_KEYS = ("sim_speedup_vs_numba_1e5", "elastic_speedup_vs_numba_1e5")  # null without numba


@pytest.mark.slow
def test_bench_quick_writes_report_json_and_md(tmp_path):
    out = tmp_path / "bench"
    r = run_cli("bench", "--quick", "--out", out, timeout=600)
    assert r.returncode == 0, r.stderr
    rep = json.loads((out / "report.json").read_text())
    for key in KEYS:
        val = rep[key]
        assert isinstance(val, (int, float)) and not isinstance(val, bool), (key, val)
        assert math.isfinite(val) and val > 0, (key, val)
    # DESIGN.md: fractal_fps per colouring, as a dict; each map rendered at 720p
    assert set(rep["fractal_fps"]) == {"angles", "flip_time", "divergence", "lyapunov"}
    assert all(math.isfinite(v) and v > 0 for v in rep["fractal_fps"].values()), rep["fractal_fps"]
    assert all(f["map"]["plot"]["width"] > 600 for f in rep["fractal"].values())
    assert rep["quick"] is True
    assert set(rep["targets"]) == TARGETS
    for key, t in rep["targets"].items():  # a peer that did not run (numba not installed) is null, not a miss
        assert isinstance(t["met"], bool) or (t["met"] is None and t["value"] is None and key in PEER_KEYS), (key, t)
    for key in ("rigid_f64_steps_per_s_1e5", "rigid_f32_steps_per_s_1e5", "elastic_speedup_vs_numpy_1e5",
                "render_over_realtime", "matplotlib_peer_ratio") + PEER_KEYS:  # issue 17
        assert key in rep and (rep[key] is None) == (key in PEER_KEYS and rep["peers"]["numba"] == peers.MISSING)
    cases = {(s["system"], s["precision"]) for s in rep["sim"] if s["n"] == 10**5}
    assert cases == {("rigid", "f32"), ("rigid", "f64"), ("elastic", "f32"), ("elastic", "f64")}
    # the numpy baseline integrates the same equations: f64 agrees to round-off, f32 to its own precision
    for s in rep["sim"]:
        assert s["agree"] < (1e-9 if s["precision"] == "f64" else 1e-3), s
    md = (out / "report.md").read_text()
    assert "end_to_end_over_encode_floor" in md and "| rigid | f64 |" in md and "| flip_time | fractal_flip |" in md
    assert "## rainbow_1000" in md
    assert not list(out.glob(".*")), "temporary files left behind"


def small_fractal(w=64, h=36, seconds=0.2):
    return load("fractal", [f"video.width={w}", f"video.height={h}", f"video.duration={seconds}",
                            "video.gif_width=32"])


def test_fractal_preset_is_a_720p_grid_without_trails_or_rods():
    from render.physics import grid
    s = load("fractal")
    lay = grid.layout(1280, 720)
    assert (s.video.width, s.video.height, s.pendulums.count) == (1280, 720, lay.pixels)
    assert lay.w == lay.h > 600  # a square plot of one pendulum per pixel, the axes and legend around it
    assert s.pendulums.layout == "grid" and s.effects == ("fractal",) and s.fractal == "angles"


def test_fractal_renders_one_pendulum_per_pixel(tmp_path):
    scene = small_fractal()
    frames = []
    meta = pipeline.render(scene, tmp_path, frame_hook=lambda f, fr: frames.append(fr.copy()))
    frames = np.stack(frames)
    assert frames.shape == (scene.frames, 36, 64, 3)
    assert sorted(meta["kernels"]) == ["fractal_colour", "fractal_setup", "rigid_advance"]
    assert not [f for f in meta["fields"] if "trail" in f or f == "canvas.frame"], meta["fields"]
    # frame 0 colours each pixel by its starting angles: theta1 = -pi..pi left to right, theta2 = pi..-pi down
    # (too small a frame for axes: the map fills it, one pendulum at the centre of each pixel)
    centres = (np.arange(64) + 0.5) / 64, (np.arange(36) + 0.5) / 36
    th1, th2 = np.meshgrid(np.pi * (2 * centres[0] - 1), np.pi * (1 - 2 * centres[1]))
    want = 0.5 + 0.5 * np.stack([np.sin(th1), np.sin(th2), np.cos(th1 + th2)], axis=-1)
    assert np.abs(frames[0].astype(int) - np.round(want * 255)).max() <= 1
    assert (frames[-1] != frames[0]).any()  # the pendulums move
    video = iio.imread(tmp_path / "fractal" / "fractal.mp4")
    assert video.shape == frames.shape


def test_fractal_frames_do_not_depend_on_thread_count(tmp_path):
    runs = []
    for threads in (1, 2):
        frames = []
        pipeline.render(small_fractal(seconds=0.1), tmp_path / str(threads), threads=threads,
                        frame_hook=lambda f, fr: frames.append(fr.tobytes()))
        runs.append(frames)
    assert runs[0] == runs[1]


def test_serial_and_parallel_drawing_give_the_same_bytes(tmp_path):
    """Few CPU threads draw serially with a plain max; more threads (and CUDA) use atomic max in parallel."""
    from render.draw.canvas import SERIAL_MAX_THREADS
    assert SERIAL_MAX_THREADS < 8
    scene = load("rigid_chaos", ["video.width=320", "video.height=180", "video.duration=1", 'video.formats=["mp4"]'])
    runs = []
    for threads in (1, 8):  # 8 > canvas.SERIAL_MAX_THREADS: the parallel, atomic path even on a 2-core CPU
        frames = []
        pipeline.render(scene, tmp_path / str(threads), threads=threads,
                        frame_hook=lambda f, fr: frames.append(fr.tobytes()))
        runs.append(frames)
    assert runs[0] == runs[1]
