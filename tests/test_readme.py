"""The README's API example runs as written: the first ```python block under "## Python API", in a fresh
interpreter and an empty folder."""
import re
import subprocess
import sys

from conftest import ROOT


def api_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## Python API\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_api_example_runs_as_written(tmp_path):
    code = api_example()
    assert "render.render(" in code and "render.simulate(" in code and "render.load(" in code
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "classic 120 2.0"
    assert lines[1].startswith("classic: 120 frames 640x360@60 | ")
    assert lines[2].startswith("out/classic/classic.mp4 2.0 ")  # faithful to the end of the 2 s
    assert lines[3] == "(120,) (120, 1, 2) (120, 1)"
    assert "classic.toml: video.fps" in lines[4]
    assert all((tmp_path / "out/classic" / f).is_file() for f in ("classic.mp4", "classic.gif", "metadata.json"))
