"""The Python API (render/commands/api.py): load's overrides, render's and simulate's results, their errors, and how
the results display in a notebook (_repr_html_)."""
import base64
import html.parser
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import render
from render.errors import SceneError, SimulationError

SMALL = {"video.duration": 1, "video.fps": 20}  # 20 frames: every path of a render, in seconds
FRAME = {"width": 160, "height": 90}


class Media(html.parser.HTMLParser):
    """The <video> and <img> elements of an HTML fragment and their src."""

    def __init__(self):
        super().__init__()
        self.media = []

    def handle_starttag(self, tag, attrs):
        if tag in ("video", "img"):
            self.media.append((tag, dict(attrs).get("src")))


def media_of(page: str) -> list[tuple[str, str]]:
    p = Media()
    p.feed(page)
    return p.media


def test_import_render_starts_no_taichi():
    code = ("import sys, render; assert 'taichi' not in sys.modules, 'taichi'; "
            "assert {'load', 'render', 'simulate'} <= set(dir(render)); print(render.__version__)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == render.__version__, r.stderr


def test_load_takes_dotted_keys_nested_dicts_and_set_strings():
    dotted = render.load("classic", **{"video.duration": 2, "pendulums.lengths": [1.0, 0.5]})
    nested = render.load("classic", video={"duration": 2}, pendulums={"lengths": (1.0, 0.5)})
    settings = render.load("classic", "video.duration=2", "pendulums.lengths=[1.0, 0.5]")
    assert dotted == nested == settings
    assert dotted.video.duration == 2 and dotted.pendulums.lengths == (1.0, 0.5)
    assert dotted.frames == 120 and dotted.name == "classic"
    assert render.load("classic", video={"fps": np.int64(30)}).video.fps == 30  # numpy scalars are plain values
    with pytest.raises(AttributeError):  # the Scene is frozen
        dotted.name = "x"


@pytest.mark.parametrize("kwargs, needles", [
    ({"video.fsp": 10}, ["classic.toml", "video.fsp", "did you mean 'video.fps'"]),
    ({"video": {"duration": -1}}, ["classic.toml", "video.duration"]),
    ({"name": {"x": 1}}, ["classic.toml", "name: not a section"]),
    ({"quality": "superb"}, ["classic.toml", "unknown level 'superb'"]),
    ({"pendulums": {"gravity": 1j}}, ["pendulums.gravity=1j", "a number, a string"]),
    ({"video": {"fps": object()}}, ["video.fps=", "a number, a string"]),
])
def test_load_refuses_bad_overrides_naming_file_and_key(kwargs, needles):
    quality = kwargs.pop("quality", None)
    with pytest.raises(SceneError) as e:
        render.load("classic", quality=quality, **kwargs)
    assert all(n in str(e.value) for n in needles), str(e.value)
    assert "\n" not in str(e.value)


def test_load_takes_only_strings_as_set_settings():
    with pytest.raises(SceneError, match="settings are strings as --set takes them"):
        render.load("classic", 5)


def test_an_unknown_preset_is_a_scene_error():
    with pytest.raises(SceneError, match="no such preset.*did you mean 'classic'"):
        render.load("clasic")


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = tmp_path_factory.mktemp("api") / "renders"
    scene = render.load("classic", **SMALL, video=FRAME)
    return scene, out, render.render(scene, out=out)


def test_render_returns_paths_metadata_and_certificate(rendered):
    scene, out, result = rendered
    assert result.dir == out / "classic"
    assert set(result.paths) == {"mp4", "gif", "metadata"} and all(p.is_file() for p in result.paths.values())
    assert result.metadata == json.loads(result.paths["metadata"].read_text())
    assert result.certificate == result.metadata["faithfulness"] and result.certificate["fraction_faithful"] == 1.0
    assert result.frames == scene.frames == 20
    assert result.line().startswith("classic: 20 frames 160x90@20 | rk4")


def test_render_result_displays_its_video_and_a_table(rendered, monkeypatch):
    _, out, result = rendered
    monkeypatch.chdir(out.parent)  # Jupyter resolves a relative src against the notebook's folder, its cwd
    page = result._repr_html_()
    assert media_of(page) == [("video", "renders/classic/classic.mp4")]
    assert (out.parent / "renders/classic/classic.mp4").is_file()
    for needle in ("frames", "20 (160x90 at 20 fps", "method", "rk4", "faithful until the end", "wall time"):
        assert needle in page, needle


def test_a_gif_only_render_embeds_the_gif_when_small(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = render.render(render.load("classic", **SMALL, video={**FRAME, "formats": ["gif"]}), out="o")
    assert set(result.paths) == {"gif", "metadata"}
    [(tag, src)] = media_of(result._repr_html_())
    assert tag == "img" and src.startswith("data:image/gif;base64,")
    assert base64.b64decode(src.split(",", 1)[1]) == result.paths["gif"].read_bytes()
    still = render.render(render.load("classic", **SMALL, video={**FRAME, "formats": ["png"]}), out="p")
    [(tag, png)] = media_of(still._repr_html_())  # a still only: it shows, not "(no video file)"
    assert tag == "img" and base64.b64decode(png.split(",", 1)[1]) == still.paths["png"].read_bytes()
    monkeypatch.setattr("render.commands.results.EMBED_BYTES", 10)  # a large GIF is linked, not embedded
    [(tag, src)] = media_of(result._repr_html_())
    assert tag == "img" and src == "o/classic/classic.gif" and Path(src).is_file()


def test_render_refuses_before_any_work(tmp_path):
    (tmp_path / "classic").write_text("a file where the render's folder goes")
    with pytest.raises(SceneError, match="is a file"):
        render.render(render.load("classic", **SMALL), out=tmp_path)
    with pytest.raises(SceneError, match="not a writable directory"):
        render.render(render.load("classic", **SMALL), out=tmp_path / "classic" / "below")
    assert [p.name for p in tmp_path.iterdir()] == ["classic"]


def test_simulate_returns_the_arrays_the_npz_holds(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = render.load("classic", **SMALL)
    traj = render.simulate(scene)
    assert not any(tmp_path.iterdir())  # no file unless asked
    assert list(traj) == ["t", "energy", "theta", "omega"] and traj.path is None
    assert traj.theta.shape == traj.omega.shape == (20, 1, 2) and traj.energy.shape == (20, 1)
    assert traj["t"][0] == 0 and traj.t[-1] == pytest.approx(0.95)
    assert all(v.dtype == np.float64 for v in traj.values())
    written = render.simulate(scene, out="t.npz")
    assert written.path == Path("t.npz")
    with np.load("t.npz") as npz:
        assert sorted(npz.files) == sorted(traj) and all(np.array_equal(npz[k], traj[k]) for k in traj)
    page = traj._repr_html_()
    assert "<table>" in page and "theta 20x1x2" in page and "not written" in page
    assert traj.energy_drift() < 1e-6 and traj.certificate["fraction_faithful"] == 1.0
    (tmp_path / "d.npz").mkdir()
    (tmp_path / "file").write_text("a file")
    for bad, says in (("d.npz", "is a directory"), ("file/x.npz", "not a writable directory"), ("x.txt", ".npz")):
        with pytest.raises(SceneError, match=says):  # as simulate(out=) refuses it, before compressing anything
            traj.save(bad)
    assert traj.save("new/t.npz") == Path("new/t.npz") and (tmp_path / "new" / "t.npz").is_file()


def test_simulate_errors_are_the_clis_typed_exceptions(tmp_path):
    with pytest.raises(SceneError, match="must end in .npz"):
        render.simulate(render.load("classic", **SMALL), out=tmp_path / "t.csv")
    untrue = render.load("classic", **{"integrator.method": "symplectic_euler", "pendulums.lengths": [1.0, 0.1],
                                       "video.duration": 10, "integrator.allow_unstable": True})  # past its
    # energy limit (render/physics/stability.py): what this tests is the faithfulness watchdog
    with pytest.raises(SimulationError, match="min_faithful=0"):  # the faithfulness watchdog: exit 1 in the CLI
        render.simulate(untrue, out=tmp_path / "t.npz")
    assert not any(tmp_path.iterdir())


def test_compare_renders_the_split_screen_and_refuses_what_cannot_vary(tmp_path):
    small = {**SMALL, "video.width": 256, "video.height": 144}
    scene = render.load("rigid_chaos", **small, **{"pendulums.count": 4})
    result = render.compare(scene, vary={"integrator.precision": ["f32", "f64"]}, out=tmp_path)
    assert result.dir == tmp_path / "compare" / "rigid_chaos" and result.paths["mp4"].is_file()
    variants = result.metadata["compare"]["variants"]
    assert [v["integrator"]["precision"] for v in variants] == ["f32", "f64"]
    assert "rigid_chaos" in result.line() and str(result.dir) in result.line()
    with pytest.raises(SceneError, match="video.fps"):
        render.compare(scene, vary={"video.fps": [10, 20]}, out=tmp_path / "no")
    with pytest.raises(SceneError, match="no \\[compare\\] table"):
        render.compare(scene, out=tmp_path / "no")
    assert not (tmp_path / "no").exists()
    assert callable(render.compare)  # the function, not a module of that name


# ------------------------------------------------------------------ the API checks what the CLI checks
class Ran(Exception):
    """Raised by a stand-in for the pipeline: the call got past every check."""


@pytest.fixture
def no_pipeline(monkeypatch):
    """pipeline.render and .simulate replaced: a refusal must come before them; what reaches them is kept."""
    seen = []

    def stand_in(scene, *args, **kwargs):
        seen.append((scene, kwargs))
        raise Ran()

    # named by path, so the API module is imported here even when no earlier test in this worker loaded it
    monkeypatch.setattr("render.commands.api.pipeline.render", stand_in)
    monkeypatch.setattr("render.commands.api.pipeline.simulate", stand_in)
    return seen


VARY = {"integrator.precision": ["f32", "f64"]}


@pytest.mark.parametrize("call, kwargs, needles", [
    ("render", {"arch": "tpu"}, ["arch='tpu'", "cpu, cuda"]),
    ("simulate", {"arch": "gpu"}, ["arch='gpu'", "cpu, cuda"]),
    ("compare", {"arch": "opengl", "vary": VARY}, ["arch='opengl'"]),
    ("render", {"threads": 0}, ["threads=0", "positive integer up to 1024"]),
    ("render", {"threads": 1025}, ["threads=1025", "up to 1024"]),
    ("compare", {"threads": -2, "vary": VARY}, ["threads=-2", "up to 1024"]),
    ("render", {"threads": "2"}, ["threads='2'", "an integer from 1 to 1024"]),
    ("render", {"threads": 2.0}, ["threads=2.0", "an integer"]),
    ("render", {"threads": True}, ["threads=True", "an integer"]),
    ("compare", {"vary": 42}, ["vary=int", "a dict", "--vary"]),
    ("compare", {"vary": {}}, ["vary={}", "each key to vary"]),
    ("compare", {"vary": {5: [1, 2]}}, ["5: not a key name"]),
    ("render", {"scheduler": 5}, ["scheduler=5", "an address string"]),
    ("render", {"progress": "yes"}, ["progress='yes'", "True or False"]),
    ("simulate", {"progress": 1}, ["progress=1", "True or False"]),
    ("compare", {"vary": "integrator.dt=1e-3"}, ["--vary integrator.dt", "1 value(s)", "2 to 4"]),
    ("compare", {"vary": ["integrator.tolerance=1e-3,1e-2"]}, ["--vary integrator.tolerance", "cannot vary"]),
    ("compare", {"vary": {"integrator.dt": [1e-3, 5e-4], "integrator": {"dt": [2e-3, 5e-4]}}},
     ["integrator.dt", "given twice"]),
])
def test_the_api_refuses_what_the_cli_refuses_before_any_work(tmp_path, no_pipeline, call, kwargs, needles):
    scene = render.load("rigid_chaos", **SMALL)
    with pytest.raises(SceneError) as e:
        getattr(render, call)(scene, out=tmp_path / ("o.npz" if call == "simulate" else "o"), **kwargs)
    assert all(n in str(e.value) for n in needles) and "\n" not in str(e.value), str(e.value)
    assert no_pipeline == [] and not any(tmp_path.iterdir())


@pytest.mark.parametrize("call", ["render", "simulate", "compare"])
def test_an_empty_out_is_refused_not_taken_as_the_current_folder(tmp_path, monkeypatch, no_pipeline, call):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match="out='': must name a folder or file"):
        extra = {"vary": VARY} if call == "compare" else {}
        getattr(render, call)(render.load("rigid_chaos", **SMALL), out="", **extra)
    assert no_pipeline == [] and not any(tmp_path.iterdir())


def test_load_refuses_a_key_given_dotted_and_nested():
    with pytest.raises(SceneError, match="video.fps: given twice"):
        render.load("classic", video={"fps": 30}, **{"video.fps": 60})


def test_compare_takes_the_clis_vary_strings_as_the_dict(tmp_path, no_pipeline):
    scene = render.load("rigid_chaos", **SMALL)
    as_dict = {"integrator.method": ["rk4", "rk2"], "integrator": {"dt": [1e-3, 5e-4]}}
    for vary in (as_dict, ["integrator.method=rk4,rk2", "integrator.dt=1e-3,5e-4"]):
        with pytest.raises(Ran):
            render.compare(scene, vary=vary, out=tmp_path, threads=np.int64(2))
    with pytest.raises(Ran):
        render.compare(scene, vary="integrator.dt=1e-3,5e-4", out=tmp_path)
    (a, kw), (b, _), (c, _) = no_pipeline
    assert a.compare == b.compare == (("integrator.method", ("rk4", "rk2")), ("integrator.dt", (1e-3, 5e-4)))
    assert c.compare == (("integrator.dt", (1e-3, 5e-4)),) and kw["threads"] == 2 and kw["arch"] == "cpu"
