"""The talk's own scenes, exactly as the seed ran them, read back from metadata.json; the stiff one refused at
the seed's step and rendered at ours; the coarse one running, its certificate showing how early it is untrue."""
import json
import math

import pytest

from conftest import out_folder, run_cli

SHORT = ["--set", "video.duration=0.3", "--set", "video.width=160", "--set", "video.height=90", "--no-progress"]


def render(tmp_path, preset, *args):
    r = run_cli("render", preset, *SHORT, *args, "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    return json.loads((out_folder(tmp_path, preset) / "metadata.json").read_text()), r


def test_seed_rigid_has_the_talks_values(tmp_path):
    meta, _ = render(tmp_path, "seed_rigid")
    p, i = meta["preset"]["pendulums"], meta["integrator"]
    assert p["count"] == 100 and p["theta1"] == p["theta2"] == math.pi  # both arms upright
    assert p["spread"] / p["count"] == pytest.approx(1e-4)  # θ2 = π − 0.01·i/N: 1e-4 between neighbours
    assert p["lengths"] == [0.2, 0.2] and p["masses"] == [1.0, 1.0] and p["gravity"] == 9.8
    assert meta["fps"] == 100 and i["substeps"] == 100 and i["dt"] == pytest.approx(1e-4)  # 0.01 s = 100 steps
    assert (i["method"], i["precision"]) == ("symplectic_euler", "f32")
    assert meta["preset"]["integrator"]["dt"] == 1e-4 and meta["preset"]["integrator"]["min_faithful"] == 0


def test_seed_elastic_has_the_talks_values(tmp_path):
    meta, _ = render(tmp_path, "seed_elastic")
    p, i = meta["preset"]["pendulums"], meta["integrator"]
    assert p["count"] == 10 and p["stiffness"] == 2e3 and p["lengths"] == [0.2, 0.2] and p["masses"] == [1.0, 1.0]
    assert p["spread"] / p["count"] == pytest.approx(math.pi / 20)  # neighbours π/20 apart on the second bob
    assert (i["method"], i["precision"], i["dt"]) == ("symplectic_euler", "f32", pytest.approx(2e-3))
    assert meta["preset"]["integrator"]["dt"] == 2e-3 and meta["preset"]["integrator"]["min_faithful"] == 0


def test_seed_elastic_stiff_refuses_the_seeds_step_and_renders_at_ours(tmp_path):
    r = run_cli("render", "seed_elastic_stiff", *SHORT, "--set", "integrator.dt=2e-3", "--out", tmp_path)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "stability limit" in lines[0] and "dt < 0.00124 s" in lines[0], r.stderr
    assert not any(tmp_path.rglob("*"))
    meta, _ = render(tmp_path, "seed_elastic_stiff")
    assert meta["integrator"]["dt"] < 1.24e-3 / 5  # a tenth of the limit, rounded to a whole number per frame


def test_seed_rigid_coarse_runs_and_its_certificate_says_how_early_it_is_untrue(tmp_path):
    meta, r = render(tmp_path, "seed_rigid_coarse", "--set", "video.duration=1")
    assert meta["integrator"]["substeps"] == 1 and meta["integrator"]["dt"] == pytest.approx(0.01)
    f = meta["faithfulness"]
    assert f["faithful_until_s"] < 0.3 and f["median_until_s"] < 0.5 and f["fraction_faithful"] < 0.05
    assert f"faithful until {f['faithful_until_s']:.2f} s" in r.stdout
