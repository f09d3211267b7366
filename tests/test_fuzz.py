"""Fuzzing the loader and the command line (issue 13): random TOML values and types, --set strings and option
values. For every case: exit 0 or 2, one stderr line when not 0, never a traceback, nothing written on 2.

Most cases run `cli.main` in this process with the Taichi work replaced by a dry run that stops where the
first kernel would compile: the preset is loaded, validated and budgeted, and the System is built (stable
step, step budget, initial state) on placeholder fields. Taichi compiles a render's kernels anew for every
System (about 2 s each), which would allow a dozen cases a minute; the dry run allows hundreds. A handful of
valid scenes at the edges of every range then render for real, and a few cases run as real processes.
"""
from __future__ import annotations

import contextlib
import datetime
import io
import json
import math
import random
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import out_folder, run_cli
from render.commands import batch, batch_plan, cli
from render.config import budget, estimate
from render.video import pipeline
from render.physics import registry, runtime
from render.errors import SceneError
from render.config.limits import EFFECTS, FORMATS, LAYOUTS, METHODS, PRECISIONS, SYSTEMS
from render.config.scene import SCHEMA

BASE = {"system": SYSTEMS[0], "pendulums": {"count": 2, "theta1": 2.0, "theta2": 2.5},
        "video": {"width": 16, "height": 16, "fps": 10, "duration": 0.2, "gif_width": 16}}
KEYS = ([("name",), ("description",), ("system",), ("effects",)]
        + [(sec, k) for sec, table in SCHEMA.items() if isinstance(table, dict) for k in table]
        + [("pendulums", "bogus"), ("video", "colour"), ("integrator",), ("video",), ("extra",)])
CHOICES = sorted({*EFFECTS, *FORMATS, *LAYOUTS, *PRECISIONS, *SYSTEMS, "auto",
                  *(m for ms in METHODS.values() for m in ms)})
EDGES = [0, -1, 1, 2, 16, 0.0, -0.0, 1e-300, 5e-324, 1e-12, 1e-6, 1e6, 1e12, 1e308, 2 ** 31, 2 ** 63, 10 ** 400,
         4_000_001, 7680, math.inf, -math.inf, math.nan]

hostile = st.one_of(
    st.sampled_from(EDGES), st.integers(), st.floats(), st.booleans(), st.text(max_size=20),
    st.dates(), st.times(), st.datetimes(),
)
plausible = st.one_of(
    st.floats(-10, 10), st.integers(-2, 64), st.sampled_from(CHOICES),
    st.lists(st.floats(0.05, 3.0), min_size=1, max_size=3), st.lists(st.sampled_from(CHOICES), min_size=1, max_size=3),
)
# Values each key accepts, so that a good share of cases pass validation and reach the budget and the System.
floats = st.floats  # within a range that reaches 0, hypothesis draws subnormals too
even = lambda lo, hi: st.integers(lo // 2, hi // 2).map(lambda i: 2 * i)  # noqa: E731
VALID = {
    "name": st.from_regex(r"[A-Za-z0-9_][A-Za-z0-9_.\-]{0,30}", fullmatch=True), "description": st.text(max_size=40),
    "system": st.sampled_from(SYSTEMS), "effects": st.lists(st.sampled_from(["rods", "bobs", "trails", "energy"]),
                                                            min_size=1, max_size=4, unique=True),
    "count": st.one_of(st.integers(1, 50), st.integers(1, 4_000_000)), "layout": st.just("fan"),
    "spread": floats(-1e3, 1e3), "gap": floats(-1e-3, 1e-3), "gravity": floats(0, 1e4), "damping": floats(0, 1e3),
    "stiffness": floats(1e-6, 1e12), "lengths": st.lists(floats(1e-6, 1e6), min_size=2, max_size=3),
    "masses": st.lists(floats(1e-6, 1e6), min_size=2, max_size=3),
    "method": st.sampled_from(sorted({m for ms in METHODS.values() for m in ms})),
    "dt": st.one_of(st.just("auto"), floats(1e-4, 0.1), floats(5e-324, 1.0)), "precision": st.sampled_from(PRECISIONS),
    "allow_unstable": st.booleans(), "max_drift": floats(1e-6, 1e6), "tolerance": floats(1e-9, 1.0),
    "min_faithful": floats(0, 1), "width": even(16, 64), "height": even(16, 64), "fps": st.integers(1, 30),
    "duration": st.one_of(floats(0.05, 1.0), floats(0.05, 3600.0)), "trail_seconds": floats(0.01, 60),
    "formats": st.lists(st.sampled_from(FORMATS), min_size=1, max_size=2, unique=True), "gif_width": even(16, 64),
    "gif_fps": st.integers(1, 50),
}
VALID.update({f"theta{k}": floats(-1e3, 1e3) for k in (1, 2, 3)})
VALID.update({f"omega{k}": floats(-1e4, 1e4) for k in (1, 2, 3)})

values = st.recursive(st.one_of(hostile, plausible), lambda inner: st.one_of(
    st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=6), inner, max_size=2)), max_leaves=6)
option_text = st.one_of(st.sampled_from(["0", "-1", "1", "2", "1024", "1025", "99999999999", "", " 3", "٣", "x"]),
                        st.text(max_size=8))


# ------------------------------------------------------------------ a tiny TOML writer for arbitrary values


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, (datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{toml_string(k)} = {toml_value(x)}" for k, x in v.items()) + "}"


def toml_string(text: str) -> str:
    """A TOML basic string: JSON's escapes are TOML's, except that TOML also escapes DEL and has no
    surrogate pairs (so non-ASCII stays as it is)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def toml_doc(doc: dict) -> str:
    lines = [f"{toml_string(k)} = {toml_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append(f"[{toml_string(k)}]")
            lines += [f"{toml_string(kk)} = {toml_value(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ the dry run


class Placeholder:
    """Stands for a Taichi field in the dry run: takes the initial state, holds nothing."""

    def from_numpy(self, array):
        assert array.size == 0 or math.isfinite(float(abs(array).max())), "non-finite initial state"

    def __setitem__(self, key, value):
        pass


def dry_render(scene, out_root, arch="cpu", progress=False, threads=None, frame_hook=None):
    sim = registry.kernels(scene.system)(scene)  # everything a render does before its first kernel
    d = scene.video.duration  # (the certificate's runs are kernels too: a perfect one stands in)
    return {"preset": {"name": scene.name}, "frames": scene.frames, "width": scene.video.width,
            "height": scene.video.height, "fps": scene.video.fps, "duration": d, "energy": None,
            "integrator": {"method": sim.method, "dt": sim.h, "substeps": sim.substeps,
                           "precision": scene.integrator.precision},
            "faithfulness": {"faithful_until_s": d, "median_until_s": d, "fraction_faithful": 1.0,
                             "tolerance": scene.integrator.tolerance, "unit": "rad"},
            "quality": {"level": scene.quality, "met": True},
            "timings_s": {"simulate": 0.0, "draw": 0.0, "encode": 0.0, "total": 0.0}}


def dry_simulate(scene, out_file, arch="cpu", progress=False):
    registry.kernels(scene.system)(scene)
    return {"frames": scene.frames, "line": "faithful (a stand-in)"}


@contextlib.contextmanager
def dry_run():
    runtime.init("cpu", "f64")  # the System asks the runtime for its float type (no re-init if it is this one)
    saved = pipeline.render, pipeline.simulate, runtime.field
    pipeline.render, pipeline.simulate = dry_render, dry_simulate
    runtime.field = lambda *args, **kw: Placeholder()
    try:
        yield
    finally:
        pipeline.render, pipeline.simulate, runtime.field = saved


def run_main(argv) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cli.main(argv)
        except SystemExit as e:  # argparse's usage errors, as `python -m render` would exit with them
            code = e.code
    return code, err.getvalue()


def assert_contract(code, err, written, argv):
    assert "Traceback" not in err, (argv, err)
    assert code in (0, 2), (argv, code, err)
    if code:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("pendulum"), (argv, err)
    if code == 2:
        assert not written, (argv, written)


OUTCOMES: dict[int, int] = {}


@st.composite
def cases(draw):
    doc = json.loads(json.dumps(BASE))
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(KEYS))
        node = doc
        for part in path[:-1]:
            node = node.setdefault(part, {}) if isinstance(node.get(part, {}), dict) else {}
        kind = draw(st.sampled_from(["valid", "valid", "valid", "any", "any", "drop"]))
        if kind == "drop":
            node.pop(path[-1], None)
        elif kind == "valid" and path[-1] in VALID:
            node[path[-1]] = draw(VALID[path[-1]])
        else:
            node[path[-1]] = draw(values)
    # sometimes not TOML at all, or not even text
    text = draw(st.sampled_from([toml_doc(doc)] * 18 + [None, None])) or draw(
        st.one_of(st.text(max_size=60), st.binary(max_size=60)))
    sets = []
    for _ in range(draw(st.integers(0, 2))):
        kind = draw(st.sampled_from(["valid", "valid", "any", "text"]))
        path = draw(st.sampled_from(KEYS))
        if kind == "valid" and path[-1] in VALID:
            sets.append(".".join(path) + "=" + toml_value(draw(VALID[path[-1]])))
        elif kind != "text":
            sets.append(".".join(path) + "=" + draw(st.one_of(values.map(toml_value), st.text(max_size=12))))
        else:
            sets.append(draw(st.text(max_size=24)))
    command = draw(st.sampled_from(["render", "simulate"]))
    options = []
    if command == "render":
        for option, valid in (("--threads", st.integers(1, 4).map(str)),
                              ("--quality", st.sampled_from(["draft", "standard", "high", "reference"]))):
            kind = draw(st.sampled_from(["none", "none", "valid", "any"]))
            if kind != "none":
                options += [option, draw(valid if kind == "valid" else option_text)]
    kind = draw(st.sampled_from(["none", "none", "none", "valid", "any"]))
    if kind != "none":
        options += ["--arch", "cpu" if kind == "valid" else draw(option_text)]
    return text, sets, command, options


@settings(max_examples=600, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(cases())
def fuzz_case(case):
    text, sets, command, options = case
    with tempfile.TemporaryDirectory() as tmp, dry_run():
        preset = Path(tmp) / "fuzz.toml"
        preset.write_bytes(text if isinstance(text, bytes) else text.encode())
        out = Path(tmp) / "out"
        target = out / "fuzz.npz" if command == "simulate" else out
        argv = [command, str(preset), "--out", str(target), "--no-progress", *options]
        for item in sets:
            argv += ["--set", item]
        code, err = run_main(argv)
        OUTCOMES[code] = OUTCOMES.get(code, 0) + 1
        assert_contract(code, err, out.exists() and list(out.rglob("*")), argv)


def test_fuzzed_presets_sets_and_options_exit_0_or_2_with_one_line():
    """Every case keeps the contract; and the case mix is not degenerate: a good share of cases pass every
    check (and a good share not). One test, so the census always follows the cases it counts."""
    OUTCOMES.clear()
    fuzz_case()  # hypothesis runs every example here
    total = sum(OUTCOMES.values())
    assert total >= 600 and OUTCOMES.get(0, 0) >= total // 10 and OUTCOMES.get(2, 0) >= total // 2, OUTCOMES


@settings(max_examples=300, deadline=None, derandomize=True, database=None)
@given(st.text(max_size=40), st.lists(st.one_of(st.text(max_size=30), st.sampled_from(KEYS).map(".".join).flatmap(
    lambda key: st.text(max_size=20).map(lambda vals: f"{key}={vals}"))), max_size=2))
def test_fuzzed_batch_options_are_accepted_or_refused_as_bad_input(scheduler, sweeps):
    """batch's own option parsers (--scheduler, --sweep): a value, or SceneError (exit 2), never another error."""
    try:
        address = batch.scheduler_address(scheduler)
        assert address is None or "://" in address
    except SceneError:
        pass
    try:
        for key, vals in batch_plan.parse_sweeps(sweeps):
            assert vals and all(name == batch_plan._sanitize(name) for _, name in vals)
    except SceneError:
        pass


# ------------------------------------------------------------------ valid extremes, rendered for real


def extremes(seed: int) -> list[str]:
    """--set items of a valid scene at the edges of its ranges (seeded: the same cases every run)."""
    rng = random.Random(seed)
    system = SYSTEMS[seed % len(SYSTEMS)]
    links = len(registry.get(system).LINKS)
    edge = lambda lo, hi: rng.choice([lo, hi, rng.uniform(lo, hi)])  # noqa: E731
    sets = [f"system={json.dumps(system)}", f"integrator.method={rng.choice(METHODS[system])}",
            f"integrator.precision={rng.choice(PRECISIONS)}", "pendulums.count=3", 'effects=["rods", "bobs"]'
            if "rod" in registry.get(system).LINKS else 'effects=["springs", "bobs"]',
            f"pendulums.lengths=[{', '.join(repr(edge(0.01, 100.0)) for _ in range(links))}]",
            f"pendulums.masses=[{', '.join(repr(edge(0.001, 1000.0)) for _ in range(links))}]",
            f"pendulums.gravity={edge(0.0, 1e4)!r}", f"pendulums.damping={rng.choice([0.0, 1e-3, 10.0])!r}",
            f"pendulums.spread={edge(-1e3, 1e3)!r}", f"pendulums.theta1={edge(-1e3, 1e3)!r}",
            f"pendulums.omega1={edge(-50.0, 50.0)!r}",
            "integrator.min_faithful=0"]  # an untrue run's exit 1 is the faithfulness watchdog's, tested apart
    if "stiffness" in registry.get(system).preset_keys():
        sets.append(f"pendulums.stiffness={edge(1.0, 1e6)!r}")
    return sets


@pytest.mark.parametrize("seed", range(6))
def test_valid_extremes_render_for_real_or_are_refused(tmp_path, monkeypatch, seed):
    """Heavy masses over light ones and strong gravity make the stable step tiny (omega_max bounds of 1e7
    rad/s): such a scene is valid and within the real budget, and would run for minutes. A budget of a second
    beyond a render's fixed start keeps each case to seconds; whatever exceeds it is refused up front (exit 2),
    as it would be."""
    monkeypatch.setattr(budget, "DEFAULT_LIMIT_S", estimate.RATES["fixed_s"] + 1.0)
    preset = tmp_path / "edge.toml"
    preset.write_text(toml_doc({**BASE, "video": {**BASE["video"], "duration": 0.3}}))
    argv = ["render", str(preset), "--out", str(tmp_path / "out"), "--no-progress"]
    for item in extremes(seed):
        argv += ["--set", item]
    code, err = run_main(argv)
    assert_contract(code, err, list((tmp_path / "out").rglob("*")) if code == 2 else [], argv)
    if code == 0:
        folder = out_folder(tmp_path / "out", "edge")
        assert (folder / f"{folder.name}.mp4").stat().st_size > 0


# ------------------------------------------------------------------ a few as real processes


@pytest.mark.parametrize("argv", [
    ["render", "classic", "--set", "\n=\x01", "--out", "out"],
    ["simulate", "classic", "--out", "out/x.npz", "--set", 'name="a\\nb"'],
    ["render", "nope\nnope", "--threads", "٣", "--out", "out"],
])
def test_hostile_command_lines_in_real_processes(tmp_path, argv):
    r = run_cli(*argv, cwd=tmp_path, timeout=60)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "out").exists()
