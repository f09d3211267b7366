"""Every bad input: exit 2, one line on stderr naming the file and the key, nothing written."""
import pytest

from conftest import run_cli
from render.commands import cli

GOOD = """\
system = "rigid"
[pendulums]
count = 3
theta1 = 2.0
theta2 = 2.5
spread = 0.01
lengths = [1.0, 1.0]
masses = [1.0, 1.0]
[integrator]
method = "rk4"
dt = 1e-3
[video]
width = 64
height = 48
fps = 10
duration = 0.2
"""

STIFF = GOOD.replace('system = "rigid"', 'system = "elastic"').replace("masses = [1.0, 1.0]",
                                                                     "masses = [1.0, 1.0]\nstiffness = 1e7")


def edit(old, new, base=GOOD):
    assert old in base, old
    return base.replace(old, new, 1)


# (case id, preset text or None for GOOD, extra CLI args, substrings the one-line message must contain)
CASES = [
    ("malformed_toml", edit("count = 3", "count = = 3"), [], ["bad.toml", "malformed TOML"]),
    ("unknown_top_key", "colour = 1\n" + GOOD, [], ["bad.toml", "colour", "unknown key"]),
    ("unknown_key_hint", edit("count = 3", "cout = 3\ncount = 3"), [], ["pendulums.cout", "did you mean 'pendulums.count'"]),
    ("unknown_section", edit("[video]", "[vidoe]"), [], ["vidoe", "did you mean 'video'"]),
    ("other_systems_key_misspelt", edit("count = 3", "count = 3\nstiffnes = 2e3"), [],
     ["pendulums.stiffnes", "did you mean 'pendulums.stiffness', a key of system elastic"]),
    ("a_sections_key_at_the_top", "count = 5\n" + GOOD, [], ["bad.toml", "count: unknown key",
                                                             "did you mean 'pendulums.count'"]),
    ("section_not_table", "pendulums = 3\n" + GOOD.split("[pendulums]")[0], [], ["pendulums", "must be a table"]),
    ("missing_system", edit('system = "rigid"\n', ""), [], ["bad.toml", "system", "missing"]),
    ("missing_count", edit("count = 3\n", ""), [], ["pendulums.count", "missing"]),
    ("count_string", edit("count = 3", 'count = "ten"'), [], ["pendulums.count", "integer"]),
    ("count_float", edit("count = 3", "count = 1.5"), [], ["pendulums.count", "integer"]),
    ("count_zero", edit("count = 3", "count = 0"), [], ["pendulums.count", "between"]),
    ("count_negative", edit("count = 3", "count = -4"), [], ["pendulums.count", "between"]),
    ("count_absurd", edit("count = 3", "count = 2_000_000_000"), [], ["pendulums.count", "between"]),
    ("theta_nan", edit("theta1 = 2.0", "theta1 = nan"), [], ["pendulums.theta1", "finite"]),
    ("theta_string", edit("theta1 = 2.0", 'theta1 = "up"'), [], ["pendulums.theta1", "number"]),
    ("length_negative", edit("lengths = [1.0, 1.0]", "lengths = [1.0, -1.0]"), [], ["pendulums.lengths", "> 0"]),
    ("length_inf", edit("lengths = [1.0, 1.0]", "lengths = [inf, 1.0]"), [], ["pendulums.lengths", "finite"]),
    ("lengths_one", edit("lengths = [1.0, 1.0]", "lengths = [1.0]"), [], ["pendulums.lengths", "two numbers"]),
    ("mass_zero", edit("masses = [1.0, 1.0]", "masses = [0.0, 1.0]"), [], ["pendulums.masses", "> 0"]),
    ("gravity_inf", edit("spread = 0.01", "spread = 0.01\ngravity = inf"), [], ["pendulums.gravity", "finite"]),
    ("stiffness_zero", edit('system = "rigid"', 'system = "elastic"').replace("spread = 0.01", "spread = 0.01\nstiffness = 0"),
     [], ["pendulums.stiffness", "> 0"]),
    ("damping_negative", edit("spread = 0.01", "spread = 0.01\ndamping = -1.0"), [], ["pendulums.damping", ">= 0"]),
    ("dt_negative", edit("dt = 1e-3", "dt = -1e-3"), [], ["integrator.dt", "> 0"]),
    ("dt_zero", edit("dt = 1e-3", "dt = 0.0"), [], ["integrator.dt", "> 0"]),
    ("dt_word", edit("dt = 1e-3", 'dt = "fast"'), [], ["integrator.dt", "auto"]),
    ("fps_zero", edit("fps = 10", "fps = 0"), [], ["video.fps", "between"]),
    ("fps_float", edit("fps = 10", "fps = 29.97"), [], ["video.fps", "integer"]),
    ("duration_negative", edit("duration = 0.2", "duration = -1.0"), [], ["video.duration", "> 0"]),
    ("duration_nan", edit("duration = 0.2", "duration = nan"), [], ["video.duration", "finite"]),
    ("width_odd", edit("width = 64", "width = 65"), [], ["video.width", "even"]),
    ("width_huge", edit("width = 64", "width = 100000"), [], ["video.width", "between"]),
    ("resolution_over_4k", edit("width = 64", "width = 7680").replace("height = 48", "height = 4320"), [],
     ["video.width", "larger than 4K"]),
    ("height_tiny", edit("height = 48", "height = 8"), [], ["video.height", "between"]),
    ("unknown_method", edit('method = "rk4"', 'method = "rk5"'), [], ["integrator.method", "rk5", "did you mean 'rk4'"]),
    ("method_wrong_system", edit('method = "rk4"', 'method = "verlet"'), [], ["integrator.method", "verlet"]),
    ("unknown_precision", edit("dt = 1e-3", 'dt = 1e-3\nprecision = "f16"'), [], ["integrator.precision", "f16"]),
    ("unknown_system", edit('system = "rigid"', 'system = "springy"'), [], ["system", "springy"]),
    ("unknown_effect", 'effects = ["rods", "sparkles"]\n' + GOOD, [], ["effects", "sparkles"]),
    ("springs_on_rigid", 'effects = ["springs", "bobs"]\n' + GOOD, [], ["effects", "springs", "elastic"]),
    ("damping_effect_without_damping", 'effects = ["rods", "damping"]\n' + GOOD, [], ["effects", "damping"]),
    ("fractal_without_grid", 'effects = ["fractal"]\n' + GOOD, [], ["effects", "grid"]),
    ("unknown_format", edit("duration = 0.2", 'duration = 0.2\nformats = ["avi"]'), [], ["video.formats", "avi"]),
    ("allow_unstable_string", edit("dt = 1e-3", 'dt = 1e-3\nallow_unstable = "yes"'), [], ["integrator.allow_unstable"]),
    ("unstable_dt", STIFF.replace("dt = 1e-3", "dt = 0.01").replace('method = "rk4"', 'method = "verlet"'), [],
     ["integrator.dt", "stability limit", "omega_max", "dt <"]),
    ("set_no_equals", None, ["--set", "pendulums.count"], ["--set", "KEY=VALUE"]),
    ("set_bad_value", None, ["--set", "pendulums.lengths=[1.0,"], ["pendulums.lengths", "cannot parse"]),
    ("set_unknown_key", None, ["--set", "pendulums.cuont=4"], ["pendulums.cuont", "did you mean 'pendulums.count'"]),
    ("set_bad_section", None, ["--set", "videoo.fps=4"], ["videoo", "did you mean 'video'"]),
    ("set_wrong_type", None, ["--set", "video.fps=fast"], ["video.fps", "integer"]),
]


@pytest.mark.parametrize("case, text, args, needles", CASES, ids=[c[0] for c in CASES])
def test_bad_preset_exits_2_with_one_line(tmp_path, capsys, case, text, args, needles):
    preset = tmp_path / "bad.toml"
    preset.write_text(GOOD if text is None else text)
    out = tmp_path / "out"
    code = cli.main(["render", str(preset), "--out", str(out), "--no-progress", *args])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    assert "bad.toml" in lines[0], lines[0]  # --set's mistakes too: the file the key was set on
    assert not out.exists() or not any(out.rglob("*")), "bad input must write nothing"


def test_good_preset_is_accepted_by_the_same_path(tmp_path, capsys):
    """The fixture itself is valid, so every failure above comes from its one edit."""
    preset = tmp_path / "good.toml"
    preset.write_text(GOOD)
    assert cli.main(["render", str(preset), "--out", str(tmp_path / "o"), "--no-progress"]) == 0
    assert (tmp_path / "o" / "good" / "good.mp4").stat().st_size > 0


@pytest.mark.parametrize("args, needles", [
    (["render", "no_such_preset_xyz"], ["no_such_preset_xyz", "no such preset"]),
    (["render", "rigid_chos"], ["rigid_chos", "did you mean 'rigid_chaos'"]),
    (["render", "missing/file.toml"], ["missing/file.toml", "not found"]),
    (["render", "classic", "--arch", "opengl"], ["--arch", "opengl"]),
    (["render", "classic", "--quality", "ultra"], ["--quality", "ultra"]),
    (["render", "classic", "--out", "/proc/pendulum-out"], ["--out", "/proc/pendulum-out", "not a writable"]),
    (["simulate", "classic", "--out", "x.csv"], ["--out", "x.csv", ".npz"]),
    (["gallery", "--out", "no_renders_here"], ["--out", "no_renders_here", "not a directory"]),
    (["frobnicate"], ["frobnicate"]),
])
def test_bad_command_lines_in_a_real_process(tmp_path, args, needles):
    """Real exit code 2, one line, no traceback, no output files."""
    r = run_cli(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    assert not any(tmp_path.rglob("*")), list(tmp_path.rglob("*"))


def test_out_path_that_is_a_file(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert cli.main(["render", "classic", "--out", str(blocker), "--no-progress"]) == 2
    assert "not a writable directory" in capsys.readouterr().err
    assert blocker.read_text() == "x"


@pytest.mark.parametrize("key, value", [("pendulums.spread", "0.1"), ("pendulums.gap", "1e-6"),
                                        ("video.palette", '"rainbow"'), ("video.trail_seconds", "2")])
def test_a_fans_key_in_a_map_is_refused_not_ignored(tmp_path, capsys, key, value):
    """A map's pendulums are its pixels: these rendered the same bytes as without them, into a new folder."""
    out = tmp_path / "out"
    assert cli.main(["render", "fractal", "--set", f"{key}={value}", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{key}: applies to a fan, and does nothing in a map" in err[0] and not out.exists()
    from render.config.scene import load
    assert load("fractal", ["pendulums.spread=1e-4"]).fractal == "angles"  # at its default: what a map's dict holds
    assert load("fractal").replace(video={"fps": 30}).video.palette == "fan"  # so a map's own dict round-trips
