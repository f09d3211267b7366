"""A fast start: `pendulum --help`, `pendulum render --help` and a mistyped command import neither Taichi nor scipy
(a second and more of imports before anything runs); only the module of the command given is imported. Listing
the presets and refusing a bad one import neither either: the loader reads the systems' declarations, which
import no Taichi (their Taichi side is imported where a run is built), and so does planning a scene's step,
initial state and budget."""
import json
import re
import subprocess
import sys
import textwrap

import pytest

from conftest import ROOT
from render.commands import cli

HEAVY = ("taichi", "scipy")
LISTED = ("render", "simulate", "presets", *cli.COMMANDS)  # every subcommand --help lists


def importtime(*args) -> tuple[subprocess.CompletedProcess, set[str]]:
    """`python -X importtime -m render ARGS`, and the modules it reports as imported."""
    r = subprocess.run([sys.executable, "-X", "importtime", "-m", "render", *args], capture_output=True, text=True,
                       cwd=ROOT, timeout=120)
    return r, set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*(\S+)$", r.stderr, re.M))


@pytest.mark.parametrize("args, code", [(["--help"], 0), (["render", "--help"], 0), (["nosuch"], 2)])
def test_the_command_line_starts_without_taichi_or_scipy(args, code):
    r, modules = importtime(*args)
    assert r.returncode == code, r.stderr[-2000:]
    assert {"render.commands.cli", "render.config.options", "argparse"} <= modules  # the report is read
    heavy = sorted(m for m in modules if m.split(".")[0] in HEAVY)
    assert not heavy, heavy[:10]


def test_listing_the_presets_starts_without_taichi_or_scipy():
    r, modules = importtime("presets")
    assert r.returncode == 0 and not [line for line in r.stderr.splitlines() if not line.startswith("import time:")]
    assert {"render.config.scene", "render.physics.plan"} <= modules  # the report is read
    listed = r.stdout.splitlines()
    assert [line.split()[0] for line in listed] == sorted(p.stem for p in (ROOT / "presets").glob("*.toml"))
    assert not [line for line in listed if " INVALID " in line]
    heavy = sorted(m for m in modules if m.split(".")[0] in HEAVY)
    assert not heavy, heavy[:10]


def edited(tmp_path, name: str, old: str, new: str) -> str:
    """presets/classic.toml with `old` replaced by `new`, as tmp_path/NAME.toml."""
    text = (ROOT / "presets" / "classic.toml").read_text()
    assert old in text
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace(old, new, 1))
    return str(path)


def test_a_bad_preset_is_refused_without_taichi_or_scipy(tmp_path):
    out = tmp_path / "out"
    cases = [(["render", "nosuch"], "nosuch: no such preset"),
             (["render", edited(tmp_path, "bogus", "[pendulums]\n", "[pendulums]\nbogus = 1\n"), "--out", str(out)],
              "bogus.toml: pendulums.bogus: unknown key"),
             (["render", edited(tmp_path, "fps", "\nfps = 60\n", "\nfps = -1\n"), "--out", str(out)],
              "fps.toml: video.fps: must be between 1 and 240, got -1"),
             (["render", "classic", "--set", "video.fps=-1", "--out", str(out)], "video.fps: must be between"),
             (["simulate", edited(tmp_path, "system", 'system = "rigid"', 'system = "rigd"'), "--out",
               str(tmp_path / "t.npz")], "system.toml: system: unknown value 'rigd' (did you mean 'rigid'?)")]
    for args, says in cases:
        r, modules = importtime(*args)
        errors = [line for line in r.stderr.splitlines() if not line.startswith("import time:")]
        assert r.returncode == 2 and len(errors) == 1 and says in errors[0], (args, errors)
        assert "render.config.validate" in modules  # the report is read
        heavy = sorted(m for m in modules if m.split(".")[0] in HEAVY)
        assert not heavy, (args, heavy[:10])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bogus.toml", "fps.toml", "system.toml"]  # nothing written


def test_planning_every_preset_imports_neither():
    """What refuses a scene before any run is planned without Taichi or scipy: its step (limit and substeps),
    initial state, memory and output, and the simulation's part of its time estimate (with --quality's
    candidates too); its system's Taichi class is a separate import (registry.kernels)."""
    code = textwrap.dedent("""
        import json, sys
        from render.config import budget, estimate
        from render.config.scene import list_presets, load
        from render.physics import registry
        out = {}
        small = ["video.duration=1", "video.width=320", "video.height=180"]  # a map's grid: its plot's pixels
        for path, quality in [*((p, None) for p in list_presets()),
                              *((p, "standard") for p in ("rigid_chaos", "elastic_fan", "triple_classic"))]:
            scene = load(str(path), small, quality)
            cls = registry.get(scene.system)
            plan = cls(scene)
            memory, output = budget.memory(scene, cls, False)[0], budget.output(scene, cls, False)[0]
            seconds = [sum(estimate.physics(v, estimate.RATES)[0].values())
                       for v in (scene.variants() if scene.compare else [scene]) if not v.has("lyapunov")]
            out[f"{scene.name} {quality}"] = [plan.n, scene.pendulums.count, plan.h * plan.substeps,
                                              1 / scene.video.fps, memory, output, seconds]
        heavy = sorted(m for m in sys.modules if m.split(".")[0] in ("taichi", "scipy"))
        registry.kernels("rigid")
        print(json.dumps([out, heavy, "taichi" in sys.modules]))
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    planned, heavy, taichi_after = json.loads(r.stdout.splitlines()[-1])
    assert len(planned) == len(list((ROOT / "presets").glob("*.toml"))) + 3
    for name, (n, count, frame, frame_s, memory, output, seconds) in planned.items():
        assert n == count and frame == pytest.approx(frame_s, rel=1e-12) and memory > 0 and output > 0, name
        assert seconds and all(s > 0 for s in seconds), name
    assert not heavy, heavy[:10]
    assert taichi_after  # the check sees Taichi where it is imported


def test_help_lists_every_subcommand():
    r, _ = importtime("--help")
    listed = re.findall(r"^    (\w+) ", r.stdout, re.M)
    assert listed == list(LISTED), r.stdout
    assert "{" + ",".join(LISTED) + "}" in r.stdout


@pytest.mark.parametrize("command", sorted(cli.COMMANDS))
def test_a_command_listed_unimported_is_listed_as_its_module_says(command):
    """The line --help lists a command with, its module not imported, is the one its module's parser gives; and
    the command given gets its module's parser (its run), the others only their line."""
    def lines(argv):
        sub = next(a for a in cli.build_parser(argv)._actions if a.dest == "command")
        return {a.dest: a.help for a in sub._choices_actions}, sub.choices

    listed, placeholders = lines([])
    own, parsers = lines([command])
    assert listed[command] == own[command] == cli.COMMANDS[command][1]
    assert parsers[command].get_default("func") is not None
    assert placeholders[command].get_default("func") is None
    assert all(parsers[c].get_default("func") is None for c in cli.COMMANDS if c != command)
    assert parsers["render"].get_default("func") is cli.cmd_render  # cli's own are always complete
