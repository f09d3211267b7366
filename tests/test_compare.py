"""`pendulum compare` and [compare] presets: the split screen decoded back, its labels and metadata, the keys
a comparison may vary, determinism; and the override folders (`--set` never touches OUT/NAME/)."""
import contextlib
import hashlib
import io
import json
import re
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import ROOT
from render.commands import batch_plan, cli
from render.draw import hud_text, split, split_text
from render.video import pipeline
from render.draw.font import Font, text_height, text_width
from render.config.options import output_name
from render.config.scene import load

# rigid_chaos as shipped, but small and short enough for a test: the fan still parts under f32 by 9 s.
SMALL_VIDEO = "[video]\nwidth = 320\nheight = 180\nfps = 15\nduration = 9.0\nformats = [\"mp4\", \"gif\"]\n"


def preset_copy(folder: Path, name: str, video: str = SMALL_VIDEO, extra: str = "", source: str = "rigid_chaos"):
    """presets/SOURCE.toml with its [video] table replaced (and `extra` appended), as folder/NAME.toml."""
    text = (ROOT / "presets" / f"{source}.toml").read_text()
    text = re.sub(r"(?ms)^\[video\].*?(?=^\[|\Z)", "", text) + "\n" + video + extra
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def main(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def panels(frame, meta, band, hud=0):
    """Each panel of a decoded frame below its label band (and above its bottom `hud` rows), as int arrays."""
    return [frame[p["y"] + band:p["y"] + p["height"] - hud, p["x"]:p["x"] + p["width"]].astype(int)
            for p in meta["compare"]["panels"]]


def near(region, rgb, tol=60) -> int:
    """How many pixels of region are within tol (per channel) of the colour rgb in [0, 1]."""
    return int(np.all(np.abs(region - np.array(rgb) * 255) < tol, axis=-1).sum())


@pytest.fixture(scope="module")
def precision(tmp_path_factory):
    """The done-when command: `pendulum compare rigid_chaos --vary integrator.precision=f32,f64`."""
    tmp = tmp_path_factory.mktemp("compare")
    preset = preset_copy(tmp, "rigid_chaos")
    code, out, err = main("compare", preset, "--vary", "integrator.precision=f32,f64", "--out", tmp / "out",
                          "--no-progress")
    assert code == 0, err
    folder = tmp / "out" / "compare" / "rigid_chaos"
    return folder, json.loads((folder / "metadata.json").read_text()), out


def test_the_two_panels_start_equal_and_part(precision):
    folder, meta, stdout = precision
    assert sorted(p.name for p in folder.iterdir()) == ["metadata.json", "rigid_chaos.gif", "rigid_chaos.mp4"]
    video = iio.imread(folder / "rigid_chaos.mp4")
    assert video.shape == (135, 180, 320, 3)
    band = 2 + 4 * 13  # four label lines of the 6x13 font
    hud = 42  # the spread graph and the clock, which each panel draws by its own certificate's times
    early = [np.abs(np.subtract(*panels(video[f], meta, band, hud))).mean() for f in (0, 8, 15)]
    late = np.abs(np.subtract(*panels(video[-1], meta, band, hud))).mean()
    assert max(early) < 3, early  # the same picture, up to H.264 noise
    assert late > 10, late  # the f32 fan has scattered differently
    gif = iio.imread(folder / "rigid_chaos.gif")
    assert gif.shape[1:3] == (180, 320)  # narrower than gif_width: kept at its size
    assert meta["outputs"].keys() == {"rigid_chaos.mp4", "rigid_chaos.gif"}
    assert "-> " + str(folder) in stdout and "parts at" in stdout


def test_labels_show_the_variant_the_cost_and_the_live_error(precision):
    folder, meta, _ = precision
    video = iio.imread(folder / "rigid_chaos.mp4")
    f32, f64 = meta["compare"]["panels"]
    label = lambda f, p: video[f, p["y"]:p["y"] + 56, p["x"]:p["x"] + p["width"]].astype(int)  # noqa: E731
    # the error line is green while the f32 panel stays within the tolerance, orange once it has parted
    close, parted = split_text.COLOURS["close"], split_text.COLOURS["parted"]
    assert near(label(0, f32), close) > 20 and near(label(0, f32), parted) < 5
    assert near(label(-1, f32), parted) > 20
    assert near(label(-1, f64), split_text.COLOURS["finest"]) > 20  # the finest says so
    v32, v64 = meta["compare"]["variants"]
    assert meta["compare"]["finest"] == 1 and v64["divergence_s"] is None
    assert 0.5 < v32["divergence_s"] < 8 and v32["max_error"] > 0.1 and v32["tolerance"] == 1e-3
    for v, prec in ((v32, "f32"), (v64, "f64")):
        assert v["integrator"]["precision"] == prec and v["cost_s_per_simulated_s"] > 0
        assert v["force_evaluations_per_simulated_s"] == 4 * v["integrator"]["substeps"] * meta["fps"]
        assert v["faithfulness"]["shadow"]["precision"] == "f64" and v["timings_s"]["simulate"] > 0
    assert v32["faithfulness"]["median_until_s"] < v64["faithfulness"]["median_until_s"]
    assert meta["integrator"] == v64["integrator"] and meta["faithfulness"] == v64["faithfulness"]
    assert v32["max_error"] <= np.pi and "wrapped to [0, π]" in meta["compare"]["error"]  # the fan has scattered


@pytest.fixture(scope="module")
def methods_source():
    # overridden as `pendulum compare compare_methods --set ...` is: the scene is named for its folder
    scene = output_name(load("compare_methods", ["video.width=256", "video.height=144", "video.fps=10",
                                                  "video.duration=2"]), True)
    yield lambda threads: pipeline.open_source(scene, threads=threads)


def digest(src) -> str:
    h = hashlib.sha256()
    for _ in range(src.frames):
        h.update(src.next_frame().tobytes())
    return h.hexdigest()


def test_two_runs_of_a_comparison_draw_the_same_frames_labels_and_all():
    """At 640x360 every label line is drawn, the cost too: two runs give the same bytes. The cost was the wall time
    each variant's simulation took, measured anew in every run, so no two runs of one comparison matched."""
    scene = output_name(load("compare_methods", ["video.width=640", "video.height=360", "video.fps=10",
                                                  "video.duration=1"]), True)
    first = pipeline.open_source(scene)
    text = [t for t, *_ in first.labels(0)]
    assert any(t.startswith("cost 4000 force evaluations") for t in text), text  # drawn whole, not cut
    assert digest(first) == digest(pipeline.open_source(scene))


def test_the_split_screen_is_a_frame_source_deterministic_at_any_thread_count(methods_source):
    one = methods_source(1)
    assert re.fullmatch(r"compare_methods__[0-9a-f]{8}", one.name) and (one.frames, one.index) == (20, -1)
    first = digest(one)
    assert one.index == 19
    one.reset()
    assert one.index == -1 and digest(one) == first  # reset() replays the same frames
    assert digest(methods_source(2)) == first
    lines = [text for text, _ in one.label_lines(0, 19)]
    # the step once, as run: the variant names it, so the integrator's line says only the precision
    assert lines[:3] == ["method = symplectic_euler, dt = 2.5e-4 s", "f64",
                         "cost 4000 force evaluations per simulated s"]  # 1 per step of 0.25 ms: equal cost
    assert one.runs[0]["integrator"]["dt"] == 2.5e-4  # as run: whole steps fit a frame at 10 fps
    assert re.fullmatch(r"Δθ \S+ rad(, parted at \d+\.\d\d s)?", lines[3]), lines
    assert re.fullmatch(r"faithful to (the end|\d+\.\d\d s)", lines[4]), lines
    assert one.runs[one.ref]["integrator"]["method"] == "rk4"  # equal cost: rk4 is the finest
    items = [text for text, *_ in one.labels(0)]
    assert any(text.startswith("parted: Δθ > 0.001") for text in items)  # the legend, 4th cell
    legend = split.layout(256, 144, 4)[3]
    titles = [text for text, x, y, _ in one.labels(0) if (x, y) == (legend[0] + 4, legend[1] + 2)]
    assert titles == ["compare_methods"]  # the legend's title: the preset, not the folder NAME__<hash>


@pytest.mark.parametrize("x, text", [(0.0, "Δθ 0 rad"), (1e-4, "Δθ 1.0e-04 rad"), (-0.42, "Δθ 0.42 rad"),
                                     (144.0, "Δθ 0.51 rad"), (2 * np.pi + 1e-3, "Δθ 1.0e-03 rad"),
                                     (np.pi, "Δθ 3.1 rad"), (-np.pi, "Δθ 3.1 rad")])
def test_an_angle_error_is_wrapped(x, text):
    assert split_text.error_text("Δθ", x, True) == text  # 144 rad is 23 turns less 0.513 rad


def test_an_angle_error_never_reads_above_pi():
    xs = np.concatenate([np.linspace(-150, 150, 30001), [144.0, np.pi, -np.pi, 3 * np.pi, np.nextafter(np.pi, 4)]])
    read = [float(split_text.error_text("Δθ", x, True).split()[1]) for x in xs]
    assert max(read) <= np.pi and max(read) == 3.1
    wrapped = split_text.turned(xs)
    assert np.all((wrapped > -np.pi) & (wrapped <= np.pi))  # (−π, π]
    assert np.allclose(np.cos(wrapped), np.cos(xs)) and np.allclose(np.sin(wrapped), np.sin(xs))  # the same angle
    assert split_text.error_text("Δx/L", 44.0, False) == "Δx/L 44"  # a spring's stretch is not an angle


def test_the_legend_is_titled_by_the_preset_not_its_folder():
    for sets, name in (([], None), (["video.fps=30"], None), (["video.fps=30"], "mine")):
        scene = output_name(load("compare_methods", sets), bool(sets), name)
        assert split_text.preset_name(scene) == "compare_methods", scene.name
    assert split_text.preset_name(scene.variants()[1]) == "compare_methods"  # a variant's source names the preset


@pytest.fixture(scope="module")
def precision_frames():
    """compare_precision, small, as rendered: its split screen's raw frames. At 10 fps over 10 s the f64
    panel's own certificate ends before the video does (the f32 one's after a few seconds)."""
    scene = load("compare_precision", ["video.width=256", "video.height=144", "video.fps=10", "video.duration=10"])
    src = pipeline.open_source(scene)
    return src, [src.next_frame() for _ in range(src.frames)]


def clock_colours(src, frames, i) -> list[str]:
    """Panel i's HUD clock's colour at each frame: of white, amber and red, the one most of the pixels in the
    clock's box have exactly (the HUD draws it under max: a glyph pixel is the colour, unless a rod is there)."""
    x0, y0, _, _ = src.rects[i]
    h = src.panels[i].canvas.hud
    width, height = text_width("t = 99.99 s", h.bs, h.big), text_height("t", h.bs, h.big)
    right, bottom = x0 + h.w - h.m, y0 + h.h - h.m
    names = {"white": hud_text.WHITE, "amber": hud_text.AMBER, "red": hud_text.RED}
    out = []
    for frame in frames:
        box = frame[bottom - height:bottom, right - width:right].astype(int)
        counts = {k: int(np.all(box == np.floor(np.array(c) * 255 + 0.5), axis=-1).sum()) for k, c in names.items()}
        assert max(counts.values()) > 20, counts  # the clock is there
        out.append(max(counts, key=counts.get))
    return out


def test_each_panels_clock_turns_at_its_own_certificates_times(precision_frames):
    src, frames = precision_frames
    fps, duration = src.scene.video.fps, src.scene.video.duration
    assert [r["integrator"]["precision"] for r in src.runs] == ["f32", "f64"] and src.ref == 1
    for i, run in enumerate(src.runs):
        cert = run["cert"]
        assert cert.faithful_until_s < duration  # the finest too: its own certificate ends before the video
        seen = clock_colours(src, frames, i)
        first = round(cert.faithful_until_s * fps) + 1  # the first frame after its last faithful one
        assert seen[:first] == ["white"] * first, (i, seen)
        assert seen[first] != "white", (i, seen)
        want = ["red" if f / fps > cert.median_until_s + 1e-9 else "amber" for f in range(first, len(frames))]
        assert seen[first:] == want, (i, seen)
        label = src.label_lines(i, 0)[-1][0]
        assert label == f"faithful to {cert.faithful_until_s:.2f} s", label  # said from the first frame on
    f32, f64 = (run["cert"] for run in src.runs)
    assert f32.faithful_until_s < f64.faithful_until_s  # each its own: the f64 one from its own shadow run


def test_one_shared_clock_is_drawn_big_across_the_top(precision_frames):
    src, frames = precision_frames
    top = split.band(144) - split.GAP
    size, scale = split.clock_face(144)
    assert text_height("t", scale, size) >= 13 and split.clock_face(720) == ("10x20", 2)  # 40 px tall at 720p
    font = Font()
    for f in (0, 37, 99):
        alone = np.zeros((top, 256, 3), np.uint8)
        font.draw(alone, f"t = {f / 10:5.2f} s", 128, split.pad(144), colour=split_text.COLOURS["clock"], size=size,
                  scale=scale, ha="center")
        assert np.array_equal(frames[f][:top], alone), f  # the band holds the clock and nothing else
        assert (frames[f][top:top + split.GAP] == split.DIVIDER).all()  # then the grey line over the panels
    assert all(y >= split.band(144) for _, y, _, _ in src.rects)


BAD = [
    (["--vary", "video.fps=30,60"], ["--vary video.fps", "cannot vary", "one video"]),
    (["--vary", "video.width=320,640"], ["--vary video.width", "cannot vary"]),
    (["--vary", "name=a,b"], ["--vary name", "cannot vary"]),
    (["--vary", 'effects=["rods"],["bobs"]'], ["--vary effects", "cannot vary"]),
    (["--vary", "pendulums.theta1=1,2"], ["--vary pendulums.theta1", "same initial states"]),
    (["--vary", "integrator.tolerance=1e-3,1e-2"], ["--vary integrator.tolerance", "does not change the motion"]),
    (["--vary", "integrator.precision=f32"], ["--vary integrator.precision", "1 value(s)", "2 to 4"]),
    (["--vary", "integrator.dt=1e-3,2e-3,3e-3,4e-3,5e-4"], ["--vary integrator.dt", "5 value(s)", "2 to 4"]),
    (["--vary", "integrator.precison=f32,f64"], ["--vary integrator.precison", "did you mean 'integrator.precision'"]),
    (["--vary", "integrator.precision=f32,f16"], ["rigid_chaos.toml", "variant 2", "integrator.precision", "f16"]),
    (["--vary", "integrator.dt=1e-3,-1"], ["rigid_chaos.toml", "variant 2", "integrator.dt", "> 0"]),
    (["--vary", "integrator.method=rk4,rk2", "--vary", "integrator.dt=1e-3"], ["--vary integrator.dt", "1 value"]),
    (["--vary", "integrator.method=rk4,rk2", "--vary", "integrator.dt=1e-3,2e-3,3e-3"], ["paired"]),
    (["--vary", "integrator.dt=1e-3,1e-3"], ["compare.vary", "the same variant"]),
    (["--quality", "draft", "--vary", "integrator.dt=1e-3,5e-4"],
     ["compare.vary.integrator.dt", "every panel's integrator"]),
    (["--set", "video.width=64", "--set", "video.height=36", "--vary", "integrator.dt=1e-3,5e-4,2.5e-4"],
     ["video.height: 36 px leaves panels 6 px high"]),
    (["--vary", "integrator.method=rk2,rk4,rk2", "--vary", "integrator.dt=1e-3,1e-3,1e-3"], ["the same variant"]),
    ([], ["rigid_chaos.toml", "compare", "no [compare] table", "--vary"]),
]


@pytest.mark.parametrize("args, needles", BAD, ids=[" ".join(a) or "no vary" for a, _ in BAD])
def test_bad_comparisons_exit_2_with_one_line_and_write_nothing(tmp_path, args, needles):
    code, _, err = main("compare", "rigid_chaos", *args, "--out", tmp_path / "out")
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert all(n in lines[0] for n in needles), lines[0]
    assert not (tmp_path / "out").exists()


def test_a_grid_of_two_keys_repeats_each_value_and_is_four_distinct_panels():
    """docs/comparisons.md's 2×2: paired --vary lists repeat values (rk2 twice, f32 twice); only panels that are
    the same as a whole are refused (above)."""
    from render.commands import api
    from render.config.scene import load
    scene = api.with_vary(load("rigid_chaos"), ["integrator.method=rk2,rk2,rk4,rk4",
                                                "integrator.precision=f32,f64,f32,f64"])
    assert [(v.integrator.method, v.integrator.precision) for v in scene.variants()] == [
        ("rk2", "f32"), ("rk2", "f64"), ("rk4", "f32"), ("rk4", "f64")]


@pytest.mark.parametrize("table, needles", [
    ('vary = { "video.fps" = [30, 60] }', ["compare.vary.video.fps", "cannot vary"]),
    ('vary = { "integrator.precision" = ["f32"] }', ["compare.vary.integrator.precision", "2 to 4"]),
    ('vary = { integrator.dt = [1e-3, 0.5] }', ["variant 2", "integrator.dt", "stability limit"]),
    ('varry = { "integrator.dt" = [1e-3, 2e-3] }', ["compare.varry", "did you mean 'compare.vary'"]),
    ('vary = { "pendulums.stiffness" = [1.0, 2.0] }',
     ["compare.vary.pendulums.stiffness", "belongs to system elastic"]),
    ('vary = { "integrator.dt" = [1e-3, 2e-3], "integrator.method" = ["rk4", "rk2", "rk4"] }', ["paired"]),
    ('vary = { "integrator.dt" = [1979-05-27, 1e-3] }', ["compare.vary.integrator.dt", "numbers, strings"]),
])
def test_a_bad_compare_table_is_bad_input_naming_file_and_key(tmp_path, table, needles):
    preset = preset_copy(tmp_path, "mine", extra=f"\n[compare]\n{table}\n")
    code, _, err = main("render", preset, "--out", tmp_path / "out", "--no-progress")
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert "mine.toml" in lines[0] and all(n in lines[0] for n in needles), lines[0]
    assert not (tmp_path / "out").exists()


def test_compare_presets_render_into_out_compare_and_keep_their_tables():
    for name, keys in (("compare_precision", ["integrator.precision"]),
                       ("compare_methods", ["integrator.method", "integrator.dt"])):
        scene = load(name)
        assert [k for k, _ in scene.compare] == keys and scene.out_dir("out") == Path("out/compare") / name
        assert 2 <= len(scene.variants()) <= 4
    methods = load("compare_methods").variants()
    evals = {"symplectic_euler": 1, "rk2": 2, "rk4": 4}  # equal cost: evaluations per step x steps per second
    assert len({evals[v.integrator.method] / v.integrator.dt for v in methods}) == 1
    assert "equal cost" in load("compare_methods").description
    assert load("rigid_chaos").to_dict().keys() == load("rigid_chaos").replace().to_dict().keys()
    assert "compare" not in load("rigid_chaos").to_dict()  # scenes without one hash as before


# ------------------------------------------------------------------ override folders


def snapshot(folder: Path) -> dict:
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in sorted(folder.iterdir())}


def test_a_set_render_leaves_the_preset_folder_byte_identical(tmp_path):
    small = "[video]\nwidth = 160\nheight = 90\nfps = 10\nduration = 0.5\nformats = [\"mp4\", \"gif\"]\n"
    preset = preset_copy(tmp_path, "rigid_chaos", small)
    out = tmp_path / "out"
    code, stdout, err = main("render", preset, "--out", out, "--no-progress")
    assert code == 0, err
    assert stdout.rstrip().endswith(f"-> {out / 'rigid_chaos'}/")
    before = snapshot(out / "rigid_chaos")

    code, stdout, err = main("render", preset, "--out", out, "--no-progress", "--set", "pendulums.gravity=9.81")
    assert code == 0, err
    assert snapshot(out / "rigid_chaos") == before  # bytes and modification times
    made = [p for p in out.iterdir() if p.name != "rigid_chaos"]
    assert len(made) == 1 and re.fullmatch(r"rigid_chaos__[0-9a-f]{8}", made[0].name), made
    assert stdout.rstrip().endswith(f"-> {made[0]}/")  # it says where it wrote
    meta = json.loads((made[0] / "metadata.json").read_text())
    assert meta["preset"]["pendulums"]["gravity"] == 9.81 and (made[0] / f"{made[0].name}.mp4").stat().st_size
    # the same result however spelled: the hash is of the resolved scene
    assert batch_plan.plan([str(preset)], ["pendulums.gravity=9.810"], [])[0]["name"] == made[0].name

    code, stdout, err = main("render", preset, "--out", out, "--no-progress", "--set", "pendulums.gravity=9.81",
                             "--name", "heavier")
    assert code == 0, err
    assert (out / "heavier" / "heavier.mp4").is_file() and f"-> {out / 'heavier'}/" in stdout
    assert snapshot(out / "rigid_chaos") == before
    code, _, err = main("render", preset, "--out", out, "--set", "pendulums.gravity=9.7", "--name", "rigid_chaos")
    assert code == 2 and "--name rigid_chaos" in err and "as written" in err


def test_batch_follows_the_same_rule():
    plain = batch_plan.plan(["classic"], [], [])[0]
    assert plain["name"] == "classic"
    over = batch_plan.plan(["classic"], ["video.fps=30"], [])[0]
    assert re.fullmatch(r"classic__[0-9a-f]{8}", over["name"]) and over["scene"].name == over["name"]
    swept = batch_plan.plan(["classic"], [], batch_plan.parse_sweeps(["video.fps=30,40"]))
    assert [j["name"] for j in swept] == ["classic__video.fps_30", "classic__video.fps_40"]
    both = batch_plan.plan(["classic"], ["pendulums.gravity=9.7"], batch_plan.parse_sweeps(["video.fps=30"]))[0]["name"]
    assert re.fullmatch(r"classic__video\.fps_30__[0-9a-f]{8}", both)


def test_a_fractal_map_cannot_be_compared_and_a_fan_hashes_without_map_keys(tmp_path):
    preset = preset_copy(tmp_path, "mapcmp", video="", source="fractal",
                         extra='\n[compare]\nvary = { "integrator.precision" = ["f32", "f64"] }\n')
    code, _, err = main("render", preset, "--out", tmp_path / "out", "--no-progress")
    assert code == 2 and "mapcmp.toml" in err and "compare" in err and "fractal" in err, err
    assert not (tmp_path / "out").exists()
    fan = load("rigid_chaos").to_dict()
    assert "fractal" not in fan and "map" not in fan  # scenes without a map hash as before there were maps
    assert load("fractal_flip").to_dict()["map"]["trust_stride"] == 16
