"""The wheel works outside the repository: built from a clean copy of the working tree, installed into a fresh
venv in /tmp, run from a folder with no presets/, it lists the shipped presets and renders one.

The fresh venv gets the wheel alone (`pip install --no-deps`); the dependencies (Taichi, numpy, ...) come
from this interpreter's site-packages through a .pth line, so the test needs no download beyond the build
backend (setuptools, fetched by pip's build isolation as for any clean build). Lines of a .pth only add
folders to sys.path; the .pth files inside them, among them this checkout's editable-install hook, do not
run, so `render` can only come from the wheel (the test checks it does).
"""
import os
import shutil
import site
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from conftest import ROOT

pytestmark = pytest.mark.slow


def clean_copy(dest: Path) -> Path:
    """The files a clean clone would have, with this working tree's edits: tracked and untracked, not ignored."""
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to know which files a clean clone holds")
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.split("\0")
    for name in filter(None, files):
        if (ROOT / name).is_file():  # a tracked file deleted in the working tree is gone from it
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, dest / name)
    return dest


def run(cmd, cwd, env=None):
    r = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{cmd}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("wheel")
    src = clean_copy(tmp / "src")
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", tmp / "dist", src], cwd=tmp)
    [whl] = (tmp / "dist").glob("*.whl")
    return whl


def test_the_wheel_holds_the_package_and_every_preset(wheel):
    assert wheel.name.startswith("taichi_pendulum-")
    names = zipfile.ZipFile(wheel).namelist()
    presets = sorted(p.name for p in (ROOT / "presets").glob("*.toml"))
    assert sorted(Path(n).name for n in names if n.startswith("render/presets/")) == presets
    assert {"render/physics/systems/rigid.py", "render/physics/kernels/rigid.py", "render/commands/api.py"} <= set(names)
    assert not any(n.startswith(("tests/", "presets/", "benchmarks/")) for n in names)
    meta = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "Requires-Python: >=3.11" in meta
    entry = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith("entry_points.txt"))).decode()
    assert "pendulum = render.commands.cli:main" in entry


def test_the_installed_wheel_lists_and_renders_the_presets_outside_the_repo(wheel, tmp_path):
    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", "--without-pip", venv], cwd=tmp_path)
    py = venv / "bin" / "python"
    run([sys.executable, "-m", "pip", "--python", py, "install", "--no-deps", "--quiet", wheel], cwd=tmp_path)
    target = Path(run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=tmp_path).strip())
    deps = {sysconfig.get_paths()["purelib"], *site.getsitepackages()}
    (target / "_pendulum_test_deps.pth").write_text("\n".join(sorted(deps)) + "\n")

    away = tmp_path / "elsewhere"  # no presets/ here, and not under the repository
    away.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PENDULUM_PRESETS")}
    listed = run([venv / "bin" / "pendulum", "presets"], cwd=away, env=env).splitlines()
    names = sorted(line.split()[0] for line in listed)
    assert names == sorted(p.stem for p in (ROOT / "presets").glob("*.toml")), listed
    assert not any("INVALID" in line for line in listed)

    code = ("import render, pathlib\n"
            "assert pathlib.Path(render.__file__).is_relative_to(pathlib.Path(r'%s')), render.__file__\n"
            "r = render.render(render.load('classic', **{'video.duration': 0.5}, video={'width': 160, "
            "'height': 90, 'fps': 20}), out='o')\n"
            "assert r.paths['mp4'].stat().st_size > 0 and r.certificate['fraction_faithful'] == 1.0\n"
            "print(r.frames, render.__file__)\n") % venv
    out = run([py, "-c", code], cwd=away, env=env)
    assert out.split()[0] == "10" and (away / "o" / "classic" / "classic.gif").is_file()
