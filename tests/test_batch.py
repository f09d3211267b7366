"""`pendulum batch`: parallel local renders, skip/force, failure isolation, Dask, sweeps and the gallery.

Renders are tiny (320x240, 6 frames) so the cost is mostly process start-up and Taichi init; one module
fixture renders the shared batch that the skip, force, Dask and gallery tests then reuse.
"""
from __future__ import annotations

import contextlib
import html.parser
import io
import json
import re
from pathlib import Path

import pytest

from render.commands import batch_plan, gallery
from render.commands.cli import main

PRESET = """description = "{desc}"
system = "{system}"
[pendulums]
count = 3
damping = {damping}
[integrator]
method = "{method}"
dt = {dt}
{extra}
[video]
width = 320
height = 240
fps = 20
duration = {duration}
gif_width = 160
formats = ["mp4", "gif"]
"""
GOOD = {
    "a_rigid": dict(system="rigid", method="rk4", dt=1e-3, damping=0.0, duration=0.3),
    "b_elastic": dict(system="elastic", method="verlet", dt='"auto"', damping=0.0, duration=0.3),
    "c_damped": dict(system="rigid", method="rk4", dt=1e-3, damping=0.5, duration=0.3),
}
BROKEN = {
    "bad_value": dict(system="rigid", method="rk4", dt=-1.0, damping=0.0, duration=0.3),  # fails validation
    # Explicit Euler far past its stability limit: the watchdog stops it inside a worker.
    "blows_up": dict(system="elastic", method="symplectic_euler", dt=0.05, damping=0.0, duration=1.0,
                     extra="allow_unstable = true\nmin_faithful = 0"),  # past the faithfulness watchdog
}


def write_presets(folder: Path, presets: dict) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, kw in presets.items():
        kw = {"desc": f"test preset {name}", "extra": "", **kw}
        (folder / f"{name}.toml").write_text(PRESET.format(**kw))
    return folder


def cli(*argv) -> tuple[int, str]:
    """Run `pendulum ARGV` in this process; (exit code, stdout)."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["batch", *map(str, argv), "--no-progress"])
    return code, buf.getvalue()


def results(out: Path) -> dict[str, dict]:
    return {r["preset"]: r for r in json.loads((out / "batch.json").read_text())["results"]}


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("batch")
    good = write_presets(root / "good", GOOD)
    broken = write_presets(root / "broken", BROKEN)
    out = root / "out"
    code, stdout = cli(good / "*.toml", broken / "*.toml", "--out", out, "--jobs", 2, "--digest")
    return {"root": root, "good": good, "out": out, "code": code, "stdout": stdout, "results": results(out),
            "index": (out / "index.html").read_text()}  # later tests rebuild the page


def test_local_batch_renders_in_parallel(local_run):
    out, res = local_run["out"], local_run["results"]
    assert json.loads((out / "batch.json").read_text())["mode"] == "local, 2 job(s)"
    for name in GOOD:
        assert res[name]["status"] == "ok"
        assert res[name]["frames"] == 6
        assert re.fullmatch(r"[0-9a-f]{64}", res[name]["raw_frames_sha256"])
        for f in (f"{name}.mp4", f"{name}.gif", "metadata.json"):
            assert (out / name / f).stat().st_size > 0
        meta = json.loads((out / name / "metadata.json").read_text())
        assert meta["preset"]["name"] == name and meta["outputs"].keys() == {f"{name}.mp4", f"{name}.gif"}
    assert not list(out.rglob("*.part"))


def test_broken_presets_fail_alone(local_run):
    out, res, stdout = local_run["out"], local_run["results"], local_run["stdout"]
    assert local_run["code"] == 1
    assert [res[n]["status"] for n in GOOD] == ["ok"] * 3
    assert res["bad_value"]["status"] == res["blows_up"]["status"] == "failed"
    assert "integrator.dt" in res["bad_value"]["error"] and "bad_value.toml" in res["bad_value"]["error"]
    assert "energy drift" in res["blows_up"]["error"] or "NaN" in res["blows_up"]["error"]
    rows = {line.split()[0]: line for line in stdout.splitlines()[1:] if line.strip()}
    assert rows["bad_value"].split()[1] == "failed" and res["bad_value"]["error"] in rows["bad_value"]
    assert rows["blows_up"].split()[1] == "failed" and res["blows_up"]["error"] in rows["blows_up"]
    assert all(rows[n].split()[1] == "ok" for n in GOOD)
    assert "3 ok, 0 skipped, 2 failed" in stdout
    assert not (out / "bad_value").exists() and not (out / "blows_up").exists()  # nothing half-written


def test_second_run_skips_and_force_redoes(local_run):
    good, out = local_run["good"], local_run["out"]
    mtimes = {n: (out / n / "metadata.json").stat().st_mtime_ns for n in GOOD}
    code, stdout = cli(good / "*.toml", "--out", out, "--jobs", 2)
    assert code == 0 and "0 ok, 3 skipped, 0 failed" in stdout
    assert all(r["status"] == "skipped" for r in results(out).values())
    assert mtimes == {n: (out / n / "metadata.json").stat().st_mtime_ns for n in GOOD}

    (out / "c_damped" / "c_damped.gif").unlink()  # an output gone: no longer up to date
    code, stdout = cli(good / "*.toml", "--out", out, "--jobs", 2)
    assert code == 0 and {n: r["status"] for n, r in results(out).items()} == {
        "a_rigid": "skipped", "b_elastic": "skipped", "c_damped": "ok"}

    code, stdout = cli(good / "*.toml", "--out", out, "--jobs", 2, "--force")
    assert code == 0 and "3 ok, 0 skipped, 0 failed" in stdout
    assert all(mtimes[n] < (out / n / "metadata.json").stat().st_mtime_ns for n in GOOD)


def test_dask_cluster_renders_the_same_frames(local_run, tmp_path, monkeypatch):
    distributed = pytest.importorskip("dask.distributed")
    out = tmp_path / "dask_out"
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        code, stdout = cli(local_run["good"] / "*.toml", "--out", out, "--digest",
                           "--scheduler", cluster.scheduler_address)
        assert code == 0, stdout
        res = results(out)
        for name in GOOD:
            assert res[name]["status"] == "ok"
            assert res[name]["raw_frames_sha256"] == local_run["results"][name]["raw_frames_sha256"]
            assert sorted(p.name for p in (out / name).iterdir()) == \
                sorted(p.name for p in (local_run["out"] / name).iterdir())
        # The usual Dask variable selects the cluster too.
        monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", cluster.scheduler_address)
        code, _ = cli(local_run["good"] / "a_rigid.toml", "--out", out, "--force")
        assert code == 0
        assert json.loads((out / "batch.json").read_text())["mode"] == f"dask {cluster.scheduler_address}"


def test_sweep_names_are_deterministic_and_valid(local_run):
    preset = str(local_run["good"] / "a_rigid.toml")
    sweeps = batch_plan.parse_sweeps(["pendulums.spread=1e-5,0.00002", "integrator.method=rk4,symplectic_euler"])
    jobs = batch_plan.plan([preset], [], sweeps)
    names = [j["name"] for j in jobs]
    assert names == ["a_rigid__pendulums.spread_1e-05__integrator.method_rk4",
                     "a_rigid__pendulums.spread_1e-05__integrator.method_symplectic_euler",
                     "a_rigid__pendulums.spread_2e-05__integrator.method_rk4",
                     "a_rigid__pendulums.spread_2e-05__integrator.method_symplectic_euler"]
    assert all(re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*", n) for n in names)
    assert jobs[2]["scene"].pendulums.spread == 2e-5 and jobs[3]["scene"].integrator.method == "symplectic_euler"
    odd = batch_plan.plan([preset], [], batch_plan.parse_sweeps(['pendulums.lengths=[1.0, 2],[0.5,0.5]']))
    assert [j["name"] for j in odd] == ["a_rigid__pendulums.lengths_1.0_2", "a_rigid__pendulums.lengths_0.5_0.5"]


def test_sweep_renders_each_variant(local_run, tmp_path):
    code, _ = cli(local_run["good"] / "a_rigid.toml", "--sweep", "pendulums.theta2=1.0,2.5",
                  "--out", tmp_path, "--jobs", 2)
    assert code == 0
    for value in (1.0, 2.5):
        meta = json.loads((tmp_path / f"a_rigid__pendulums.theta2_{value}" / "metadata.json").read_text())
        assert meta["preset"]["pendulums"]["theta2"] == value


class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.urls = []

    def handle_starttag(self, tag, attrs):
        self.urls += [v for k, v in attrs if k in ("src", "href")]


def test_gallery_links_every_gif_relatively(local_run):
    out = local_run["out"]
    page = (out / "index.html").read_text()
    parser = Links()
    parser.feed(page)
    for url in parser.urls:
        assert not url.startswith(("/", "file:", "http")), url
        assert (out / url).is_file(), url
    for name in GOOD:
        assert f"{name}/{name}.gif" in parser.urls and f"{name}/{name}.mp4" in parser.urls
    assert "bad_value" in local_run["index"] and "integrator.dt" in local_run["index"]  # last batch's failures


def test_gallery_escapes_metadata(tmp_path):
    d = tmp_path / "x"
    d.mkdir()
    (d / "x.gif").write_bytes(b"GIF89a")
    meta = {"preset": {"name": "x", "description": "<script>alert(1)</script> & co"}, "outputs": {"x.gif": 6},
            "integrator": {"method": "rk4", "dt": 1e-3, "substeps": 17, "precision": "f64"},
            "energy": {"max_rel_drift": 1e-9}, "timings_s": {"total": 1.5}}
    (d / "metadata.json").write_text(json.dumps(meta))
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "metadata.json").write_text("{not json")  # skipped, not fatal
    page = gallery.write_index(tmp_path, [("y", "a <b> error")]).read_text()
    assert page.count("<script") == 1  # the page's own (it marks videos that fail to load), none from metadata
    assert "&lt;script&gt;alert(1)&lt;/script&gt; &amp; co" in page
    assert "a &lt;b&gt; error" in page and 'src="x/x.gif"' in page and "rk4" in page


@pytest.mark.parametrize("argv, needle", [
    (["no_such_preset_xyz"], "no such preset"),
    (["zz_no_match_*"], "matches no preset"),
    (["--sweep", "pendulums.spred=1,2"], "did you mean 'pendulums.spread'"),
    (["--sweep", "pendulums.spread"], "expected KEY=V1,V2"),
    (["--set", "video.fsp=10"], "did you mean 'video.fps'"),
])
def test_bad_command_line_exits_2(argv, needle, tmp_path, capsys):
    assert main(["batch", *argv, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())


def test_a_batch_that_can_render_nothing_is_bad_input(tmp_path, capsys):
    """Every preset refused before any work (a malformed file, one over its budget): exit 2, one line, nothing
    written, as for a lone render; not a batch that ran and failed (exit 1, batch.json)."""
    bad = tmp_path / "bad.toml"
    bad.write_text('system = "rigid\n')
    out = tmp_path / "out"
    assert main(["batch", str(bad), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(bad) in err[0] and not out.exists()
    assert main(["batch", str(bad), "classic", "--set", "integrator.dt=1e-9", "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "and 1 more preset(s)" in err[0] and not out.exists()


def test_a_batch_never_renders_through_a_symlinked_folder(tmp_path, capsys):
    """OUT/NAME a symlink that leads out of OUT: that preset is refused before any work, as `render` refuses it."""
    out, outside = tmp_path / "out", tmp_path / "outside"
    out.mkdir()
    outside.mkdir()
    sets = ["video.duration=0.1", "video.width=64", "video.height=36"]
    (out / batch_plan.plan(["classic"], sets, [])[0]["name"]).symlink_to(outside)
    assert main(["batch", "classic", *(a for s in sets for a in ("--set", s)), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is a symlink" in err[0]
    assert not list(outside.iterdir())


def test_bad_jobs_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["batch", "--jobs", "0"])
    assert e.value.code == 2 and "positive integer" in capsys.readouterr().err


@pytest.mark.parametrize("sets, needle", [
    (["effects=[\"rods\",\"bobs\",\"lyapunov\"]", "video.duration=0.05"], "the spectrum's error needs at least"),
    (["video.height=36"], "leaves panels 6 px high"),
])
def test_a_batch_refuses_before_any_work_what_render_refuses(sets, needle, tmp_path, capsys):
    """batch checked the folder and the budget only: a spectrum too short for its error was rendered with NaN in
    metadata.json (not JSON), and a comparison's too-small panels failed in a worker after its simulation."""
    preset = "compare_methods" if "panels" in needle else "classic"
    base = ["video.width=64", "video.height=36", "video.duration=0.05", *sets]
    out = tmp_path / "out"
    assert main(["batch", preset, *(a for s in base for a in ("--set", s)), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and not out.exists(), err


def test_a_batch_whose_own_files_cannot_be_written_is_refused_before_rendering(tmp_path, capsys):
    """OUT/index.html a folder: every render ran, then the batch failed writing its gallery."""
    (tmp_path / "index.html").mkdir()
    assert main(["batch", "classic", "--set", "video.duration=0.05", "--out", str(tmp_path), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "index.html: is a folder" in err[0]
    assert [p.name for p in tmp_path.iterdir()] == ["index.html"]


@pytest.mark.parametrize("name", ["index.html", "batch.json", "compare", "bench"])
def test_a_scene_may_not_take_a_name_that_out_itself_holds(name, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["render", "classic", "--name", name, "--out", str(tmp_path)])
    assert e.value.code == 2 and "what OUT itself holds" in capsys.readouterr().err
    (tmp_path / "p.toml").write_text(f'name = "{name}"\n' + (Path(__file__).parents[1] / "presets/classic.toml").read_text())
    assert main(["render", str(tmp_path / "p.toml"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "name: " in err[0] and not (tmp_path / "out").exists()
