"""`pendulum bench --quick` writes its report, its ratios from interleaved rounds with their spread; the fractal
preset renders (small) one pendulum per pixel."""
import json
import math
import statistics
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import run_cli
from render.commands import cli
from render.commands.bench import command, peers, report
from render.video import pipeline
from render.config.scene import load

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
import effects  # noqa: E402  (benchmarks/effects.py)

KEYS = ("end_to_end_over_encode_floor", "sim_speedup_vs_numpy_1e5", "fractal_peak_mem_mb",
        "rainbow_1000_draw_fps", "draw_fps", "encode_fps", "end_to_end_s", "encode_floor_s", "hud_ms_720p",
        "matplotlib_draw_ratio", "peak_gflops.f64", "peak_gflops.f32", "rigid_rk4_peak_fraction.f64",
        "rigid_rk4_peak_fraction.f32")
TARGETS = {"end_to_end_over_encode_floor", "sim_speedup_vs_numpy_1e5", "fractal_fps.flip_time", "fractal_peak_mem_mb",
           "fractal_fps.lyapunov",
           "rainbow_1000_draw_fps", "sim_speedup_vs_numba_1e5", "rigid_f64_steps_per_s_1e5",
           "rigid_f32_steps_per_s_1e5", "elastic_speedup_vs_numpy_1e5", "render_over_realtime",
           "matplotlib_peer_ratio", "hud_ms_720p", "matplotlib_draw_ratio", "fractal_fps.divergence",
           "rigid_rk4_peak_fraction.f64", "rigid_rk4_peak_fraction.f32"}
PEER_KEYS = ("sim_speedup_vs_numba_1e5", "elastic_speedup_vs_numba_1e5")  # null without numba
RATIOS = ("sim_speedup_vs_numpy_1e5", "elastic_speedup_vs_numpy_1e5", "matplotlib_peer_ratio", "matplotlib_draw_ratio",
          "rigid_rk4_peak_fraction.f64", "rigid_rk4_peak_fraction.f32")  # each with its spread over the rounds


def at(rep, key):
    for k in key.split("."):
        rep = rep[k]
    return rep


@pytest.mark.slow
def test_bench_quick_writes_report_json_and_md(tmp_path):
    out = tmp_path / "bench"
    r = run_cli("bench", "--quick", "--out", out, timeout=600)
    assert r.returncode == 0, r.stderr
    rep = json.loads((out / "report.json").read_text())
    for key in KEYS:
        val = at(rep, key)
        assert isinstance(val, (int, float)) and not isinstance(val, bool), (key, val)
        assert math.isfinite(val) and val > 0, (key, val)
    # docs/performance.md: fractal_fps per colouring, as a dict; each map rendered at 720p
    assert set(rep["fractal_fps"]) == {"angles", "flip_time", "divergence", "lyapunov"}
    assert all(math.isfinite(v) and v > 0 for v in rep["fractal_fps"].values()), rep["fractal_fps"]
    assert all(f["map"]["plot"]["width"] > 600 for f in rep["fractal"].values())
    assert rep["quick"] is True and rep["rounds"] == 2
    assert rep["machine"]["cpu_kind"] in ("avx2", "avx512") and len(rep["machine"]["load_avg_end"]) == 3
    for key in RATIOS:  # the value is the medians' ratio; the rounds' own ratios lie around it
        s = rep["spread"][key]
        assert s["rounds"] == 2 and s["min"] <= s["max"] and s["spread_pct"] >= 0, (key, s)
        assert s["value"] == pytest.approx(at(rep, key)), key
    hud = rep["spread"]["hud_ms_720p"]  # not a ratio: each round's median, and the median of those
    assert hud["rounds"] == len(rep["hud"]["rounds_ms"]) == 2 and hud["min"] <= rep["hud_ms_720p"] <= hud["max"]
    assert 0 < rep["rigid_rk4_peak_fraction"]["f64"] < 1.5  # of a peak measured on the same cores
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
        # every side's rate in every round, so that another summary than the median can be drawn from a report
        assert all(len(r) == 2 for r in s["rounds"].values()) and {"taichi", "numpy"} <= set(s["rounds"]), s
        assert s["taichi"] / s["numpy"] == pytest.approx(statistics.median(s["rounds"]["taichi"])
                                                         / statistics.median(s["rounds"]["numpy"]))
    md = (out / "report.md").read_text()
    assert "end_to_end_over_encode_floor" in md and "| rigid | f64 |" in md and "| flip_time | fractal_flip |" in md
    assert "## rainbow_1000" in md and "fraction of peak" in md and "range over 2 rounds" in md
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


def test_interleaved_rounds_take_each_side_in_turn():
    calls = []

    def side(name, rates):
        it = iter(rates)
        return lambda: (calls.append(name), next(it))[1]
    runs = peers.interleave({"ours": side("ours", [10, 12, 20]), "peer": side("peer", [5, 4, 5])}, 3)
    assert calls == ["ours", "peer"] * 3
    assert runs == {"ours": [10, 12, 20], "peer": [5, 4, 5]}
    r = peers.ratio(runs["ours"], runs["peer"])  # medians 12 / 5; the rounds' ratios 2, 3, 4
    assert r == {"value": pytest.approx(2.4), "min": 2.0, "max": 4.0, "spread_pct": pytest.approx(100 * 2 / 2.4),
                 "rounds": 3}
    assert peers.ratio([1.0], None) is None  # a peer that did not run
    assert report.spread_text(r) == "2..4 (83 %)" and report.with_spread(r) == "**2.40** (2.00..4.00 (83 %))"


def fake_results(numba=True):
    """What the phases return, small and made up, for the report alone (no phase runs)."""
    rows = []
    for system in ("rigid", "elastic"):
        for prec in ("f32", "f64"):
            for n in (100, 10**5):
                runs = {"taichi": [4e7, 5e7, 6e7], "numpy": [2e6, 2.5e6, 2e6], "numba": [1e7, 1e7, 1.2e7]}
                rows.append({"system": system, "precision": prec, "n": n, "taichi": 5e7, "numpy": 2e6,
                             "numba": 1e7 if numba and n == 10**5 else None, "speedup": 25.0, "agree": 1e-12,
                             "vs": {"numpy": peers.ratio(runs["taichi"], runs["numpy"]),
                                    "numba": peers.ratio(runs["taichi"], runs["numba"] if numba else None)}})
    frac = peers.ratio([2e10, 3e10], [8e10, 1e11])
    pk = {p: {"peak_gflops": 90.0, "rigid_rk4_gflops": 25.0, "flops_per_step": 600, "fraction": frac}
          for p in ("f32", "f64")}
    mpl = {"frames": 60, "ours_s": 2.0, "matplotlib_s": 7.0, "ours_draw_fps": 300.0, "matplotlib_draw_fps": 20.0,
           "vs": {"render": peers.ratio([0.5, 0.5], [1 / 7, 1 / 7]), "draw": peers.ratio([300.0, 280.0], [20.0, 21.0])}}
    fractal = {"wall_s": 2.0, "frames": 12, "duration_s": 0.2, "fps": 6.0,
               "timings": {"certify": 0.1, "simulate": 1.0, "draw": 0.5, "encode": 0.2},
               "integrator": {"method": "rk4", "dt": 2e-3, "substeps": 9, "precision": "f64"},
               "map": {"plot": {"width": 640}, "events": 3, "events_trusted": 3}}
    res = {"sim": {"rows": rows, "peak": pk},
           "e2e": {"wall_s": 1.2, "rounds_s": [1.3, 1.1], "frames": 120,
                   "timings": {"simulate": 0.1, "draw": 0.6, "encode": 0.4}, "fixed_s": 0.3,
                   "draw_fps": 200.0, "sim_draw_fps": 180.0, "floor_s": 1.0, "floor_rounds_s": [0.9, 1.1],
                   "encode_fps": 120.0},
           "hud": {"frames": 118, "ms": 0.8, "rounds_ms": [0.9, 0.8], "spread": peers.spread([0.9, 0.8], 0.8),
                   "size": "1280x720"}, "matplotlib": mpl,
           "rainbow": {"frames": 178, "draw_fps": 40.0, "sim_fps": 300.0, "size": "1280x720", "effects": ["rods"]},
           **{f"fractal_{c}": {**fractal, "preset": p} for c, p in command.FRACTALS.items()}}
    for r in res.values():
        r["peak_mem_mb"] = 100.0
    return res


@pytest.mark.parametrize("kind", ["avx2", "avx512"])
def test_report_carries_each_ratio_with_its_spread_and_targets_by_cpu_kind(monkeypatch, kind):
    monkeypatch.setattr(report, "cpu_kind", lambda: kind)
    rep = report.summarise(fake_results(), True, 1.0, command.QUICK["chaos_s"], [0.5] * 3)
    assert rep["machine"]["cpu_kind"] == kind and rep["rounds"] == 2
    assert rep["hud_ms_720p"] == rep["hud_ms_per_frame"] == 0.8
    assert rep["peak_gflops"] == {"f32": 90.0, "f64": 90.0} and rep["peak_flops_f64"] == 90e9
    assert rep["rigid_rk4_peak_fraction"]["f64"] == pytest.approx(2.5 / 9)  # medians 2.5e10 / 9e10
    assert rep["rigid_rk4_fraction_of_peak_f32"] == rep["rigid_rk4_peak_fraction"]["f32"]
    assert rep["matplotlib_draw_ratio"] == pytest.approx(290 / 20.5) and rep["matplotlib_peer_ratio"] == 3.5
    assert rep["spread"]["matplotlib_draw_ratio"]["min"] == pytest.approx(280 / 21)
    assert rep["spread"]["sim_speedup_vs_numba_1e5"]["max"] == pytest.approx(6.0 / 1.2)
    t = rep["targets"]
    assert set(t) == TARGETS and t["matplotlib_draw_ratio"]["spread"] == rep["spread"]["matplotlib_draw_ratio"]
    hud = {"value": 0.8, "min": 0.8, "max": 0.9, "spread_pct": pytest.approx(12.5), "rounds": 2}
    assert t["hud_ms_720p"] == {"value": 0.8, "goal": "<= 1", "met": True, "value_over_goal": 0.8, "spread": hud}
    # the render and the floor, once a round: the medians' ratio, and round by round 1.3 / 0.9 and 1.1 / 1.1
    e2e, rt = t["end_to_end_over_encode_floor"], t["render_over_realtime"]
    assert e2e["value"] == pytest.approx(1.2) and e2e["spread"]["value"] == pytest.approx(1.2)
    assert (e2e["spread"]["min"], e2e["spread"]["max"]) == (pytest.approx(1.0), pytest.approx(1.3 / 0.9))
    chaos_s = command.QUICK["chaos_s"]
    assert rt["value"] == pytest.approx(1.2 / chaos_s) and rt["spread"]["max"] == pytest.approx(1.3 / chaos_s)
    goal, met, speedup = {"avx2": ("3.5e+07", True, "15"), "avx512": ("5.5e+07", False, "8")}[kind]
    f64 = t["rigid_f64_steps_per_s_1e5"]  # 5e7 steps/s: past AVX2's 3.5e7, short of AVX-512's 5.5e7
    assert f64["goal"] == f">= {goal}" and f64["met"] is met
    assert t["sim_speedup_vs_numpy_1e5"]["goal"] == f">= {speedup}" and t["sim_speedup_vs_numpy_1e5"]["met"]
    md = report.markdown(rep)
    assert "| matplotlib_draw_ratio | 14.1 | 13.3..15 (12 %) |" in md and "**0.278** (0.250..0.300 (18 %))" in md
    assert f"{kind} targets" in md and "load average" in md
    assert "| end-to-end render | 1.20 s (rounds 1.30, 1.10 s) |" in md
    assert "| hud_ms_720p | 0.8 | 0.8..0.9 (12 %) |" in md and "its 2 rounds' medians 0.8..0.9 (12 %)" in md


def test_report_without_numba_has_null_peer_ratios_and_spreads(monkeypatch):
    rep = report.summarise(fake_results(numba=False), True, 1.0, command.QUICK["chaos_s"], [0.5] * 3)
    for key in PEER_KEYS:
        assert rep[key] is None and rep["spread"][key] is None
    assert rep["targets"]["sim_speedup_vs_numba_1e5"]["met"] is None
    assert "null" in report.markdown(rep)


def test_the_e2e_phase_alternates_the_floor_and_the_render(monkeypatch, tmp_path):
    """Round i's floor, then round i's render (the first after a one-frame warm-up), in one process: the ratio's
    rounds pair times taken seconds apart, and its median is the medians' ratio (render/commands/bench/e2e.py)."""
    from render.commands.bench import e2e
    calls, walls = [], iter([7.0, 7.5, 6.9, 0.8])  # three rounds' renders, then the one-frame render
    floors = iter([6.2, 6.0, 6.4])
    raw = tmp_path / "frames.raw", tmp_path / "gif.raw"
    for path in raw:
        path.write_bytes(b"")
    monkeypatch.setattr(e2e, "record_frames", lambda cfg, arch, tmp: {"draw_fps": 300.0, "sim_draw_fps": 280.0,
                                                                       "files": raw})

    def floor(rec, tmp):
        calls.append("floor")
        return next(floors)

    def render(scene, arch, tmp, warm=None):
        calls.append(f"render {scene.frames}" + (f" after {warm.frames}" if warm is not None else ""))
        return next(walls), {"frames": scene.frames, "timings_s": {"draw": 1.0}}
    monkeypatch.setattr(e2e, "encode_floor", floor)
    monkeypatch.setattr(e2e, "timed_render", render)
    out = e2e.phase_e2e({**command.QUICK, "chaos_s": 2.0, "rounds": 3}, "cpu", tmp_path)
    assert calls == ["floor", "render 120 after 1", "floor", "render 120", "floor", "render 120", "render 1"]
    assert out["rounds_s"] == [7.0, 7.5, 6.9] and out["floor_rounds_s"] == [6.2, 6.0, 6.4]
    assert (out["wall_s"], out["floor_s"], out["fixed_s"]) == (7.0, 6.2, 0.8)
    assert out["encode_fps"] == pytest.approx(120 / 6.2) and not any(path.exists() for path in raw)
    spread = peers.ratio(out["rounds_s"], out["floor_rounds_s"])
    assert spread["value"] == pytest.approx(7.0 / 6.2) and spread["max"] == pytest.approx(7.5 / 6.0)


def test_a_phase_that_compiled_runs_again_and_the_report_says_so(monkeypatch, tmp_path):
    """A phase whose process added a kernel to the offline cache timed its compiles: it runs once more and
    that run is kept (render/commands/bench/process.py); a phase that found every kernel runs once, and so does
    every phase of a quick run, whose report says which were timed with compiles."""
    from types import SimpleNamespace

    from render.commands.bench import process
    from render.physics import vector_width
    cache, ftle, runs = tmp_path / "cache", tmp_path / "cache-ftle", []  # the FTLE map's width may be another's
    cache.mkdir()
    ftle.mkdir()
    monkeypatch.setattr(vector_width, "cache_folder", lambda arch, tangents=False: str(ftle if tangents else cache))

    def phase(name, args, tmp):  # the first run of each phase compiles two kernels, written at its exit
        runs.append(name)
        if runs.count(name) == 1:
            for k in range(2):
                (ftle if name == "fractal_lyapunov" else cache).joinpath(f"T{name}{k}.tic").write_bytes(b"")
        return {"wall_s": 20.0 - len(runs)}
    monkeypatch.setattr(process, "_run_phase", phase)
    full, quick = SimpleNamespace(quick=False, arch="cpu"), SimpleNamespace(quick=True, arch="cpu")
    assert process.run_phase("e2e", full, tmp_path) == {"wall_s": 18.0, "compiled": 2, "rerun": True}
    assert process.run_phase("e2e", full, tmp_path) == {"wall_s": 17.0, "compiled": 0, "rerun": False}
    assert process.run_phase("hud", quick, tmp_path) == {"wall_s": 16.0, "compiled": 2, "rerun": False}
    assert process.run_phase("fractal_lyapunov", full, tmp_path) == {"wall_s": 14.0, "compiled": 2, "rerun": True}
    assert runs == ["e2e", "e2e", "e2e", "hud", "fractal_lyapunov", "fractal_lyapunov"]
    res = fake_results()
    assert "compile" not in report.markdown(report.summarise(res, True, 1.0, 2.0, [0.5] * 3))
    res["e2e"].update(compiled=2, rerun=True)
    res["hud"].update(compiled=8, rerun=False)
    rep = report.summarise(res, True, 1.0, 2.0, [0.5] * 3)
    assert rep["compiled"] == {"e2e": 2, "hud": 8} and rep["rerun"] == ["e2e"]
    md = report.markdown(rep)
    assert "compiled kernels (how many): e2e (2)." in md and "does not run a phase again): hud (8)." in md


def test_repeat_must_be_a_positive_count(capsys, tmp_path):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "--repeat", "0", "--out", str(tmp_path / "b")])
    err = capsys.readouterr().err
    assert e.value.code == 2 and "--repeat" in err and "positive integer" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name", command.FILES)
def test_a_folder_where_a_report_file_goes_is_refused_before_the_bench_runs(capsys, tmp_path, name):
    """Found only when the report is written, it cost a whole bench (6 minutes or more) and left the files
    written before it: refused at once now, and the files are written together (atomic.together)."""
    (tmp_path / "b" / name).mkdir(parents=True)
    assert cli.main(["bench", "--quick", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path / "b" / name) in err[0] and "is a folder" in err[0]
    assert [p.name for p in (tmp_path / "b").iterdir()] == [name]


def test_effects_table_shows_a_difference_within_the_noise_as_plus_minus():
    def run(effects, sim, draw):
        return {"preset": "rigid_chaos", "effects": effects, "sim": sim, "draw": draw, "fields": 0, "kernels": 2}
    bobs = effects.best([run(["bobs"], 1.0, 2.0), run(["bobs"], 1.0, 2.4)])  # 3.0 .. 3.4: noise 0.4
    assert bobs["draw"] == 2.0 and bobs["noise"] == pytest.approx(0.4)
    rods = effects.best([run(["bobs", "rods"], 1.0, 2.3), run(["bobs", "rods"], 1.0, 2.3)])  # +0.3: within it
    trails = effects.best([run(["bobs", "rods", "trails"], 1.0, 4.0)] * 2)  # +1.7: beyond
    text = effects.table([bobs, rods, trails]).splitlines()
    assert [line.split(" | ")[5] for line in text[2:]] == ["", "±", "+1.70"]


def test_the_effects_benchmark_measures_a_preset():
    """benchmarks/effects.py's own measurement (what `make figures` runs), on a few frames."""
    row = effects.measure("rigid_chaos", ["bobs", "rods"], 4, cpu=True)
    assert row["sim"] > 0 and row["draw"] > 0 and row["fields"] > 0 and row["kernels"] >= 2, row
