"""`pendulum accuracy --quick` end to end: files, exact CSV columns, every method, valid PNGs, sane orders."""
import csv

import imageio.v3 as iio
import numpy as np

from conftest import run_cli
from render.physics import registry
from render.commands import accuracy
from render.commands.accuracy import COLUMNS
from render.config.limits import METHODS

THEORY = {"symplectic_euler": 1, "verlet": 2, "rk2": 2, "implicit_midpoint": 2, "rk4": 4, "yoshida4": 4}
PNGS = (*(f"{chart}_{s}.png" for s in registry.names() for chart in ("work_precision", "energy_drift")),
        "divergence.png", "work_precision_rigid_chaos.png", "faithful_rigid_chaos.png")


def test_accuracy_quick_writes_tables_and_charts(tmp_path):
    out = tmp_path / "acc"
    # the timeout is a safety net, not a speed check: --quick takes 3 min quiet and over 7 on a loaded machine
    r = run_cli("accuracy", "--quick", "--out", out, timeout=900)
    assert r.returncode == 0, r.stderr
    assert "accuracy [" in r.stderr  # progress on stderr
    assert sorted(p.name for p in out.iterdir()) == sorted([*PNGS, "accuracy.csv", "accuracy.md", "quality.md",
                                                                  "summary.md"])
    assert sorted(accuracy.outputs(registry.names())) == sorted(p.name for p in out.iterdir())  # what it checks

    with open(out / "accuracy.csv", newline="") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == COLUMNS
        assert COLUMNS == ("system", "method", "precision", "dt", "traj_error", "energy_drift", "ns_per_step",
                           "order")
        rows = list(reader)
    seen = {(r["system"], r["method"], r["precision"]) for r in rows}
    assert seen == {(s, m, p) for s in METHODS for m in METHODS[s] for p in ("f32", "f64")}
    for r in rows:
        assert float(r["traj_error"]) > 0 and float(r["ns_per_step"]) > 0 and float(r["energy_drift"]) >= 0
        if r["precision"] == "f64" and r["order"]:  # quick rungs are in the asymptotic regime in f64
            assert abs(float(r["order"]) - THEORY[r["method"]]) <= 0.3, r
    assert sum(1 for r in rows if r["order"]) == len(rows) // 2  # one order per pair of rungs

    md = (out / "accuracy.md").read_text()
    assert "| " + " | ".join(COLUMNS) + " |" in md
    table = [ln for ln in md.splitlines() if ln.startswith(tuple(f"| {s} |" for s in METHODS)) and ln.count("|") == 9]
    assert len(table) == len(rows)
    assert "## Energy over" in md
    assert "## rigid_chaos: faithful time against cost" in md
    quality = (out / "quality.md").read_text()
    levels = [ln.split("|")[1].strip() for ln in quality.splitlines() if ln.startswith("| ") and "---" not in ln][1:]
    assert levels == ["draft", "standard", "high", "reference"], quality

    for name in PNGS:
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        img = iio.imread(out / name)
        assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 400
        assert np.asarray(img[..., :3], dtype=float).std() > 5  # something was drawn


def test_accuracy_bad_input_exits_2(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    r = run_cli("accuracy", "--out", blocker / "sub")
    assert r.returncode == 2 and "--out" in r.stderr and "Traceback" not in r.stderr
    r = run_cli("accuracy", "--system", "chaotic")
    assert r.returncode == 2
    (tmp_path / "acc" / "summary.md").mkdir(parents=True)  # found before the measurements, not after them
    r = run_cli("accuracy", "--quick", "--out", tmp_path / "acc", timeout=60)
    assert r.returncode == 2 and "summary.md: is a folder" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert [p.name for p in (tmp_path / "acc").iterdir()] == ["summary.md"]


def test_the_quality_table_writes_nothing_outside_the_output_folder(monkeypatch):
    """It timed `simulate` with its .npz written into a temporary folder under $TMPDIR: outside --out, and a
    full /tmp failed the command naming a file the user never named. The file is compressed into memory now."""
    import tempfile
    from render.commands import flagship

    def in_tmpdir_refused(real):  # a folder given (Taichi's cache probe, say) is not $TMPDIR
        def made(*a, **k):
            if k.get("dir") is None and len(a) < 3:
                raise AssertionError(f"a temporary under $TMPDIR, outside the output folder: {real.__name__}")
            return real(*a, **k)
        return made

    for name in ("mkdtemp", "mkstemp", "TemporaryDirectory", "NamedTemporaryFile"):
        monkeypatch.setattr(tempfile, name, in_tmpdir_refused(getattr(tempfile, name)))
    rows = flagship.quality_table("cpu", True, lambda line: None)
    assert [r["level"] for r in rows] == list(flagship.LEVELS) and all(r["wall_s"] > r["simulate_s"] for r in rows)
