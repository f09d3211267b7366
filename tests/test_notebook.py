"""The example notebook runs under nbclient, and the render shows inline as a <video> of a file that exists.

Skipped when nbclient or ipykernel is missing (both are test extras in pyproject.toml). The kernel is this
interpreter, named by a kernelspec written for the test, so a `python3` kernel installed elsewhere on the
machine cannot stand in for it.
"""
import json
import sys
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parent / "notebooks" / "quickstart.ipynb"


def test_the_quickstart_notebook_runs_and_shows_the_video(tmp_path, monkeypatch):
    nbclient = pytest.importorskip("nbclient")
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("ipykernel")
    spec = tmp_path / "jupyter" / "kernels" / "pendulum-test"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "pendulum test", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    work = tmp_path / "work"  # the notebook's folder: it renders into work/out/
    work.mkdir()

    nb = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "commit the notebook cleared"
    nbclient.NotebookClient(nb, timeout=600, kernel_name="pendulum-test",
                            resources={"metadata": {"path": str(work)}}).execute()  # raises on a failing cell

    html = [o["data"]["text/html"] for c in nb.cells if c.cell_type == "code" for o in c.outputs
            if "text/html" in o.get("data", {})]
    assert len(html) == 2, html  # the render and the trajectory
    assert '<video src="out/classic/classic.mp4"' in html[0] and (work / "out/classic/classic.mp4").is_file()
    assert "faithful until" in html[0] and "wall time" in html[0]
    assert "theta 20x1x2" in html[1]
    last = nb.cells[-1].outputs[0]["data"]["text/plain"]
    assert last == "(20, 1, 2)"
