"""The up-front budget (render/config/budget.py, render/config/estimate.py): each estimate, its limit, and what the refusal
says. The run-time refusals run as a user runs them (cli.main in this process) and must come within 5 s
with nothing simulated, no kernel compiled and nothing written."""
import contextlib
import io
import json
import math
import re
import resource
import shutil
import time
from pathlib import Path

import pytest

from conftest import make_scene, run_cli
from render.commands import api, cli
from render.config import budget, estimate
from render.physics import keys, registry, runtime
from render.video import pipeline
from render.trust import certify
from render.errors import SceneError

SMALL = {"width": 64, "height": 48, "fps": 10, "duration": 1.0}
RATES = estimate.RATES


def check(scene, out=Path("."), simulate=False):
    return budget.check(scene, registry.get(scene.system), out, simulate)


def refusal(scene, **kw) -> str:
    with pytest.raises(SceneError) as e:
        check(scene, **kw)
    return str(e.value)


def run_main(argv) -> tuple[int, list[str], float]:
    """cli.main(argv) here: exit code, stderr lines, and the CPU seconds this process spent (not the wall time,
    which on a loaded machine is the machine's, not the check's)."""
    err = io.StringIO()
    t = time.process_time()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = cli.main([str(a) for a in argv])
        except SystemExit as e:
            code = e.code
    return code, err.getvalue().strip().splitlines(), time.process_time() - t


def refused_fast(argv, out: Path, *needles) -> str:
    """The command is refused (exit 2) in one line holding the estimate and the way to raise the budget, in
    under 5 s of CPU, before any Taichi field or kernel and with nothing written."""
    fields, kernels = dict(runtime.allocated), list(runtime.launched)
    code, lines, cpu = run_main([*argv, "--out", out, "--no-progress"])
    assert code == 2 and len(lines) == 1, lines
    line = lines[0]
    for needle in ("estimated", "over the run-time budget of 1 h", "--budget", "budget = ", *needles):
        assert needle in line, f"{needle!r} not in {line!r}"
    assert cpu < 5.0, f"refused in {cpu:.1f} s of CPU"
    assert runtime.allocated == fields and runtime.launched == kernels
    assert not out.exists()
    return line


class Started(Exception):
    """Raised by the stand-in for pipeline.render: the run got past every check."""


@pytest.fixture
def no_render(monkeypatch):
    """pipeline.render replaced by a stand-in that records what stderr held when the work would start."""
    seen = []

    def start(*args, **kw):
        seen.append(cli.sys.stderr.getvalue())
        raise Started()
    monkeypatch.setattr(pipeline, "render", start)
    return seen


def test_a_small_scene_passes():
    check(make_scene(video=SMALL))
    check(make_scene(video=SMALL), simulate=True)


# ------------------------------------------------------------------ the four classes the audit found


def test_the_certificates_shadow_counts(tmp_path):
    """triple_chaos at dt 1e-7: 2e10 steps of the render, and as many again for the certified pendulums (all
    100 of its 100) at the render's settings, and eight times as many for their shadow (RK4 at an eighth of the
    step)."""
    line = refused_fast(["render", "triple_chaos", "--set", "integrator.dt=1e-7"], tmp_path / "out",
                        "triple_chaos.toml: integrator.dt: dt too small", "2e10 steps", "certificate")
    assert "1200 frames x 166667 substeps of 1e-07 s x 100 pendulums" in line
    scene = api.load("triple_chaos", "integrator.dt=1e-7")
    est = estimate.estimate(scene, RATES)
    steps, rate = 1200 * 166667 * 100, RATES["steps_per_s"]["triple_f64"]
    assert est.steps == steps
    assert est.parts["simulate"] == pytest.approx(steps / rate + 1200 * RATES["frame_s"])
    assert est.parts["certificate"] == pytest.approx((steps + certify.FINER * steps) / rate
                                                     + 2 * 1200 * RATES["frame_s"])
    assert est.parts["simulate"] < budget.DEFAULT_LIMIT_S < est.total  # the render alone would have passed


def test_drawing_and_encoding_count(tmp_path):
    """4K for an hour at 30 fps: hardly any simulation, hours of drawing and x264 at 8.3 Mpixel a frame."""
    refused_fast(["render", "rigid_chaos", "--set", "video.width=3840", "--set", "video.height=2160", "--set",
                  "video.fps=30", "--set", "video.duration=3600", "--set", 'video.formats=["mp4"]'], tmp_path / "out",
                 "rigid_chaos.toml: video.width, video.height, video.duration:", "draw+encode")
    small = api.load("rigid_chaos", "video.width=640", "video.height=360")
    big = api.load("rigid_chaos", "video.width=3840", "video.height=2160")
    draw = {k: estimate.estimate(s, RATES).parts["draw+encode"] for k, s in (("small", small), ("big", big))}
    assert 8 < draw["big"] / draw["small"] < 36  # 36 times the pixels, the fixed costs a frame aside


def test_an_ftle_maps_sigma_counts_as_drawing():
    """fractal_lyapunov's colours are σ of each point's MᵀM, every frame (render/maps/ftle.py): its draw+encode is
    the same map's coloured by angle plus FTLE_SIGMA_STEPS plain RK4 steps per point and frame, and a triple
    pendulum's 6×6 matrix (3.375 times the multiplications of a 4×4) that many of its own, slower steps."""
    size = ["video.width=320", "video.height=180", "video.duration=2"]
    ftle = api.load("fractal_lyapunov", *size)
    angles = ftle.replace(fractal="angles")
    draw = {k: estimate.estimate(s, RATES).parts["draw+encode"] for k, s in (("ftle", ftle), ("angles", angles))}
    sigma = ftle.frames * ftle.pendulums.count * estimate.FTLE_SIGMA_STEPS / RATES["steps_per_s"]["rigid_f64"]
    assert draw["ftle"] - draw["angles"] == pytest.approx(sigma, rel=0.05) and sigma > 0.2 * draw["angles"]
    triple = api.load("fractal_lyapunov", *size, 'system="triple"', "pendulums.lengths=[1.0, 1.0, 1.0]",
                      "pendulums.masses=[1.0, 1.0, 1.0]")
    slower = RATES["steps_per_s"]["rigid_f64"] / RATES["steps_per_s"]["triple_f64"]
    assert estimate.sigma_s(triple, RATES) == pytest.approx(3.375 * slower * estimate.sigma_s(ftle, RATES))


def test_a_comparison_counts_the_sum_of_its_panels(tmp_path):
    """Four panels of 1e5 pendulums for 10 s: each panel alone, drawn at its size, is within the hour; all four
    are not."""
    argv = ["compare", "rigid_chaos", "--vary", "integrator.dt=1e-3,5e-4,2.5e-4,2e-3", "--set",
            "pendulums.count=100000", "--set", "video.duration=10"]
    refused_fast(argv, tmp_path / "out", "rigid_chaos.toml", "pendulums.count, video.duration: 4 panels estimated",
                 "draw+encode")
    scene = api.with_table(api.load("rigid_chaos", "pendulums.count=100000", "video.duration=10"),
                                  {"integrator.dt": [1e-3, 5e-4, 2.5e-4, 2e-3]})
    from render.draw.split import layout
    _, _, w, h = layout(scene.video.width, scene.video.height, 4)[0]
    for variant in scene.variants():
        check(variant.replace(video={"width": w, "height": h}), out=tmp_path)  # within the limit alone
    total = estimate.estimate(scene, RATES)
    alone = [estimate.estimate(v, RATES) for v in scene.variants()]
    assert total.parts["simulate"] == pytest.approx(sum(a.parts["simulate"] for a in alone))
    assert total.parts["certificate"] == pytest.approx(sum(a.parts["certificate"] for a in alone))


def test_stiff_light_springs_are_refused_by_the_time_they_take(tmp_path):
    """elastic_fan with springs of 1e12 under µg bobs: "auto" settles on steps of about 1e-10 s."""
    line = refused_fast(["render", "elastic_fan", "--set", "pendulums.stiffness=1e12", "--set",
                         "pendulums.masses=[1e-6,1e-6]"], tmp_path / "out",
                        'elastic_fan.toml: integrator.dt: "auto" needs steps of 1.2', "stiff springs")
    assert "1200 frames x 1348" in line and "x 10 pendulums" in line


def test_the_quality_pilots_count_and_the_costliest_choice_is_assumed():
    """--quality: the pilots (a reference and a bisection per method and precision, each a kernel to compile),
    and the render at the most expensive setting the pilots could choose."""
    from render.trust import quality
    scene = api.load("elastic_fan", quality="high")
    plan = registry.get(scene.system)(scene)
    cands = quality.offered(scene, plan)
    worst = max(cands, key=lambda c: quality.cost(c, scene.video.fps))
    est = estimate.estimate(scene, RATES)
    ladders = {(c["method"], c["precision"]) for c in cands}
    assert est.parts["quality"] > RATES["compile_s"] * (len(ladders) + 1)
    substeps = math.ceil(1 / (scene.video.fps * worst["dt"]) - 1e-9)
    assert est.substeps == substeps and est.parts["simulate"] == pytest.approx(estimate.run_s(
        scene, RATES, worst["method"], worst["precision"], substeps, scene.pendulums.count))
    assert "quality" not in estimate.estimate(api.load("elastic_fan"), RATES).parts
    assert estimate.estimate(api.load("elastic_fan", quality="reference"), RATES).parts["quality"] == 0


def test_a_real_process_is_refused_within_5_s_of_cpu(tmp_path):
    """As a user runs it: Python's start, the imports and the plan take a few CPU seconds (the wall time on a
    loaded machine is the machine's, not the check's)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = run_cli("render", "triple_chaos", "--set", "integrator.dt=1e-7", "--out", tmp_path / "out", "--no-progress",
                timeout=120)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and "over the run-time budget of 1 h" in lines[0], r.stderr
    assert cpu < 5.0 and not (tmp_path / "out").exists(), cpu


def test_a_run_over_a_minute_prints_its_estimate_before_it_starts(tmp_path, no_render):
    """The same springs for 12 frames: minutes, within the hour; the estimate is on stderr before the work."""
    code, lines, cpu = run_main(["render", "elastic_fan", "--set", "pendulums.stiffness=1e12", "--set",
                                  "pendulums.masses=[1e-6,1e-6]", "--set", "video.duration=0.2", "--out",
                                  tmp_path / "out", "--no-progress"])
    assert code == 1 and len(no_render) == 1 and cpu < 5.0, lines  # Started: an unforeseen error, exit 1
    first = no_render[0].strip().splitlines()
    assert len(first) == 1 and first[0] == lines[0], (first, lines)
    assert first[0].startswith("pendulum: elastic_fan__") and re.search(r": estimated \d+ min ", first[0])
    assert "simulate" in first[0] and "certificate" in first[0] and "within the budget of 1 h" in first[0]


def test_a_short_run_prints_nothing(tmp_path, no_render):
    code, lines, _ = run_main(["render", "classic", "--set", "video.duration=0.5", "--out", tmp_path, "--no-progress"])
    assert len(no_render) == 1 and no_render[0] == ""


# ------------------------------------------------------------------ raising the limit


def test_budget_raises_the_limit_as_an_option_and_as_a_key(tmp_path, no_render):
    argv = ["render", "triple_chaos", "--set", "integrator.dt=1e-7", "--out", tmp_path / "out", "--no-progress"]
    run_main([*argv, "--budget", "5h"])  # estimated 3 h 59 min, the certificate's shadow 3 h 34 min of it
    assert len(no_render) == 1 and "within the budget of 5 h" in no_render[0]
    run_main([*argv, "--set", 'budget="4h 10min"'])
    assert len(no_render) == 2 and "within the budget of 4 h 10 min" in no_render[1]
    code, lines, _ = run_main([*argv, "--budget", "3h"])
    assert code == 2 and "over the run-time budget of 3 h" in lines[0] and "--budget 4h" in lines[0]
    assert len(no_render) == 2


def test_a_budget_below_the_default_refuses_sooner(tmp_path):
    code, lines, _ = run_main(["render", "rigid_chaos", "--budget", "30s", "--out", tmp_path, "--no-progress"])
    assert code == 2 and len(lines) == 1 and "over the run-time budget of 30 s" in lines[0], lines
    assert "--budget 10min" in lines[0]


def test_compare_batch_and_simulate_take_budget_too(tmp_path, no_render, monkeypatch):
    monkeypatch.setattr(pipeline, "simulate", lambda *a, **k: (_ for _ in ()).throw(Started()))
    for argv in (["compare", "compare_methods"], ["simulate", "classic"]):  # batch: the next test
        out = tmp_path / "x.npz" if argv[0] == "simulate" else tmp_path / argv[0]
        code, lines, _ = run_main([*argv, "--budget", "5s", "--out", out, "--no-progress"])
        assert code == 2 and len(lines) == 1 and "over the run-time budget of 5 s" in lines[0], (argv, lines)
        assert not out.exists()


def test_several_renders_are_held_to_their_sum(tmp_path, no_render):
    """Each within 2 min, both together not: refused before the first starts."""
    each = [check(api.load(p), out=tmp_path).total for p in ("rigid_chaos", "triple_chaos")]
    assert all(60 < s < 120 for s in each) and sum(each) > 120, each
    for argv in (["render", "rigid_chaos", "triple_chaos"], ["batch", "rigid_chaos", "triple_chaos", "-j", "1"]):
        code, lines, _ = run_main([*argv, "--budget", "2min", "--out", tmp_path / "out", "--no-progress"])
        assert code == 2 and len(lines) == 1 and lines[0].startswith("pendulum: error: 2 renders (rigid_chaos, "
                                                                     "triple_chaos): estimated "), lines
        assert "over the run-time budget of 2 min" in lines[0] and "--budget 10min" in lines[0]
    assert not no_render


@pytest.mark.parametrize("value, why", [('"2 weeks"', "must be a number of seconds or a duration"),
                                        ("0.5", "must be between 1 s and 48 h"), ('"49h"', "must be between"),
                                        ("true", "must be a number"), ("[1]", "must be a number")])
def test_the_budget_key_is_validated(value, why):
    with pytest.raises(SceneError, match=f"presets/classic.toml: budget: {why}"):
        api.load("classic", f"budget={value}")


def test_the_budget_option_is_validated(tmp_path):
    code, lines, _ = run_main(["render", "classic", "--budget", "soon", "--out", tmp_path])
    assert code == 2 and len(lines) == 1 and "--budget" in lines[0] and "'soon'" in lines[0], lines


def test_the_budget_is_not_part_of_the_scene_it_runs():
    """The same frames under any budget: the same hash (folder, batch's up-to-date test), kept in variants."""
    plain, given = api.load("compare_methods"), api.load("compare_methods", budget="90 min")
    assert given.budget == 5400 and given.hash() == plain.hash() and given.to_dict()["budget"] == 5400
    assert "budget" not in plain.to_dict() and all(v.budget == 5400 for v in given.variants())
    assert [keys.seconds(t) for t in ("90", "90 s", "20 min", "2h", "1h30m", "1.5 h")] == [90, 90, 1200, 7200,
                                                                                         5400, 5400]
    assert [keys.seconds(t) for t in ("", "h", "2 weeks", "nan", "1e400", "2hh", True, None)] == [None] * 8


# ------------------------------------------------------------------ the machine's rates


def test_the_rates_in_out_bench_are_read_when_present(tmp_path):
    scene = api.load("triple_chaos", "integrator.dt=1e-5")
    base, source = estimate.load_rates(tmp_path)
    assert base == RATES and source == "built-in rates"
    (tmp_path / "bench").mkdir()
    faster = {"steps_per_s": {"triple_f64": 2 * RATES["steps_per_s"]["triple_f64"]}, "mp4_pixel_s": 1e-9}
    (tmp_path / "bench" / "rates.json").write_text(json.dumps(faster))
    rates, source = estimate.load_rates(tmp_path)
    assert source == f"rates from {tmp_path / 'bench' / 'rates.json'}"
    assert rates["mp4_pixel_s"] == 1e-9 and rates["steps_per_s"]["rigid_f64"] == RATES["steps_per_s"]["rigid_f64"]
    slow, fast = estimate.estimate(scene, base), estimate.estimate(scene, rates)
    assert slow.steps == scene.frames * 1667 * scene.pendulums.count  # 1667 substeps of 1e-5 s a frame
    assert slow.parts["simulate"] - fast.parts["simulate"] == pytest.approx(
        slow.steps / RATES["steps_per_s"]["triple_f64"] / 2)
    assert fast.parts["draw+encode"] < slow.parts["draw+encode"]
    code, lines, _ = run_main(["render", "triple_chaos", "--set", "integrator.dt=1e-7", "--out", tmp_path])
    assert code == 2 and "rates from" in lines[0] and "bench/rates.json" in lines[0]


@pytest.mark.parametrize("link", ["bench", "bench/rates.json"])
def test_rates_behind_a_symlink_out_of_out_are_not_read(tmp_path, link):
    """Tiny rates outside OUT, reached through OUT/bench or OUT/bench/rates.json as a symlink, let a run over
    its budget start: nothing is read outside the output folder."""
    outside, out = tmp_path / "outside", tmp_path / "out"
    outside.mkdir()
    (outside / "rates.json").write_text(json.dumps({"fixed_s": 1e-9, "frame_s": 1e-9}))
    (out / "bench").mkdir(parents=True)
    if link == "bench":
        (out / "bench").rmdir()
        (out / "bench").symlink_to(outside)
    else:
        (out / "bench" / "rates.json").symlink_to(outside / "rates.json")
    assert estimate.load_rates(out) == (RATES, "built-in rates")


@pytest.mark.parametrize("text", [b"not json", b"[1, 2]", b'{"steps_per_s": [1]}', b'{"fixed_s": -1}',
                                  b'{"fixed_s": NaN, "frame_s": "fast", "draw_link_s": true, "gif_pixel_s": 1e400}',
                                  b"\xff\xfe\x00", b""])
def test_a_malformed_rates_file_is_ignored(tmp_path, text):
    (tmp_path / "bench").mkdir()
    (tmp_path / "bench" / "rates.json").write_bytes(text)
    assert estimate.load_rates(tmp_path) == (RATES, "built-in rates")
    check(make_scene(video=SMALL), out=tmp_path)


def test_benchs_rates_reproduce_what_it_measured(tmp_path):
    """The rates `pendulum bench` writes (estimate.measured, from its phases' results), read back by a render."""
    from render.commands.bench import command
    chaos = command.chaos_scene(command.QUICK)
    rows = [{"system": s, "precision": p, "n": n, "taichi": rate * (1 + n / 1e6)}
            for (s, p), rate in {("rigid", "f64"): 3e7, ("rigid", "f32"): 5e7, ("elastic", "f64"): 9e7,
                                 ("elastic", "f32"): 2e8}.items() for n in (100, 10 ** 5, 10 ** 6)]
    res = {"sim": {"rows": rows}, "e2e": {"draw_fps": 80.0, "encode_fps": 50.0, "fixed_s": 4.0}}
    rates = estimate.measured(res, chaos)
    assert rates["steps_per_s"]["rigid_f64"] == 3e7 * 1.1 and rates["fixed_s"] == 4.0  # N = 1e5, not 1e6
    assert rates["steps_per_s"]["triple_f64"] == pytest.approx(RATES["steps_per_s"]["triple_f64"] * 3.3e7 / 2.5e7)
    nothing = {k: 0 for k in ("mp4_frame_s", "mp4_pixel_s", "gif_frame_s", "gif_pixel_s")}
    assert estimate.picture_frame_s(chaos, {**rates, **nothing})[0] == pytest.approx(1 / 80)
    drawless = {k: 0 for k in ("draw_frame_s", "draw_pixel_s", "draw_link_s", "hud_frame_s")}
    assert estimate.picture_frame_s(chaos, {**rates, **drawless})[0] == pytest.approx(1 / 50)
    (tmp_path / "bench").mkdir()
    (tmp_path / "bench" / "rates.json").write_text(json.dumps({**rates, "created": "now", "quick": True}))
    assert estimate.load_rates(tmp_path)[0] == rates


# ------------------------------------------------------------------ steps, memory, disk


def test_a_tiny_pinned_dt_is_refused_as_too_small():
    check(make_scene(integrator={"dt": 1e-8}, video={"fps": 60, "duration": 10.0}))  # 1e9 steps: minutes
    msg = refusal(make_scene(integrator={"dt": 1e-10}, video={"fps": 60, "duration": 10.0}))
    assert "integrator.dt: dt too small" in msg and "over the run-time budget of 1 h" in msg
    assert "600 frames x 166666667 substeps" in msg


def test_the_substeps_counter_and_a_subnormal_dt():
    """Two frames, but more substeps than the kernel's i32 holds; a subnormal dt makes 1/(fps·dt) infinite,
    which must still be a refusal, not an OverflowError."""
    msg = refusal(make_scene(integrator={"dt": 1e-11}, video={"fps": 10, "duration": 0.2}))
    assert "substeps per frame of 1e-11 s exceed the step counter's limit of 2147483647" in msg
    assert "integrator.dt: too small to step by (subnormal)" in refusal(make_scene(integrator={"dt": 5e-324},
                                                                                         video=SMALL))
    # the count in a line one reads: it was 2**64 made up for the subnormal, and 300 digits for 1e-300
    assert "dt too small: about 1e+299 substeps per frame" in refusal(make_scene(integrator={"dt": 1e-300},
                                                                                      video=SMALL))


def test_many_pendulums_for_long_are_refused_naming_count_and_duration():
    msg = refusal(make_scene(count=4_000_000, video={"fps": 60, "duration": 600.0, "formats": ["mp4"]}))
    assert msg.startswith("<test>: pendulums.count, video.duration:") and "over the run-time budget" in msg


def test_simulate_keeps_every_frame_in_memory():
    """Refused at MEMORY_FRACTION of this machine's memory, whatever it has: the frames are sized from it."""
    limit, total = budget.memory_limit()
    assert limit == int(total * budget.MEMORY_FRACTION)
    n, per = 1_000_000, (2 * 2 + 1) * 16  # rigid: state and energy, then a float64 copy, per pendulum a frame
    frames = math.ceil(1.05 * limit / (n * per))  # 5 % over the limit
    scene = make_scene(count=n, integrator={"dt": 0.1}, video={"fps": 10, "duration": frames / 10})
    need, key, _ = budget.memory(scene, registry.get(scene.system), simulate=True)
    assert need == n * (2 * 2 + 3) * 8 + frames * n * per  # state + kept frames, exactly
    assert limit < need < 1.1 * limit
    msg = refusal(scene, simulate=True)
    assert "pendulums.count, video.duration: needs about" in msg and "of this machine's" in msg


def test_holding_every_gif_frame_for_its_palette_counts_as_memory():
    scene = make_scene(video={"width": 1920, "height": 1080, "gif_width": 1920, "fps": 50, "duration": 3600.0},
                       integrator={"dt": 0.02})
    need, key, detail = budget.memory(scene, registry.get(scene.system), simulate=False)
    assert key == "video.gif_width, video.duration" and "GIF frames held for its palette" in detail
    assert need > 1920 * 1080 * 3 * scene.video.gif_fps * 3600  # an hour of GIF frames of 3-byte pixels


def test_output_beyond_the_free_space_is_refused(monkeypatch):
    usage = shutil.disk_usage(".")
    monkeypatch.setattr(budget.shutil, "disk_usage", lambda path: usage._replace(free=10 ** 6))
    msg = refusal(make_scene(video={**SMALL, "duration": 60.0}), out=Path("nowhere/yet"))
    assert "the output needs about" in msg and "more than 90% of the 1 MB free in ." in msg


def test_output_beyond_this_machines_disk_is_refused(tmp_path):
    """Sized from the free space where the output goes: 10 % over DISK_FRACTION of it."""
    free = shutil.disk_usage(tmp_path).free
    per_frame = 3840 * 2160 * budget.MP4_BYTES_PER_PIXEL
    frames = math.ceil(1.1 * budget.DISK_FRACTION * free / per_frame)
    if frames > 240 * 3600:
        pytest.skip(f"{free / 1e9:.0f} GB free: more than the largest video writes")
    scene = make_scene(video={"width": 3840, "height": 2160, "fps": 240, "duration": frames / 240,
                              "formats": ["mp4"]}, integrator={"dt": 0.01})
    assert "the output needs about" in refusal(scene, out=tmp_path)


def test_f32_holds_lengths_and_masses_to_its_range():
    with pytest.raises(SceneError, match=r"pendulums.masses\[1\]: 1e\+06 is beyond what f32 arithmetic holds"):
        make_scene(pendulums={"masses": [1.0, 1e6]}, integrator={"precision": "f32"})
    make_scene(pendulums={"masses": [1.0, 1e6]}, integrator={"precision": "f64"})


def test_counts_and_durations_print_short():
    assert budget.num(1234) == "1234" and budget.num(379_202_580) == "3.79e8"
    assert [budget.duration(s) for s in (42, 59.4, 200, 3600, 7500, 1e7)] == [
        "42 s", "59 s", "3 min 20 s", "1 h", "2 h 5 min", "2.78e+03 h"]
    assert budget.raise_by(2.4 * 3600).startswith("raise the budget: --budget 3h")
    assert budget.raise_by(1e7).startswith("no budget allows it")
