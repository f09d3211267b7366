"""A fast start: `pendulum --help`, `pendulum render --help` and a mistyped command import neither Taichi nor scipy
(a second and more of imports before anything runs); only the module of the command given is imported. Listing
the presets and refusing a bad one import no scipy (Taichi still: the loader reads the systems' declarations
from their Taichi classes)."""
import re
import subprocess
import sys

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


def test_presets_and_a_bad_preset_start_without_scipy(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "presets" / "classic.toml").read_text().replace("[pendulums]\n", "[pendulums]\nbogus = 1\n"))
    for args, code, says in [(["presets"], 0, "classic "), (["render", "nosuch"], 2, "nosuch: no such preset"),
                             (["render", str(bad), "--out", str(tmp_path / "out")], 2, "pendulums.bogus: unknown key")]:
        r, modules = importtime(*args)
        assert r.returncode == code and says in r.stdout + r.stderr, r.stderr[-2000:]
        assert "render.config.scene" in modules  # the report is read
        scipy = sorted(m for m in modules if m.split(".")[0] == "scipy")
        assert not scipy, (args, scipy[:10])
    assert not (tmp_path / "out").exists()


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
