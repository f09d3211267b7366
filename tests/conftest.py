"""Shared fixtures. Taichi has one runtime per process; tests call runtime.init with what they need."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")

ROOT = Path(__file__).resolve().parent.parent


def pytest_addoption(parser):
    parser.addoption("--update-goldens", action="store_true",
                     help="rewrite tests/golden/<preset>/*.png from the current renderer instead of comparing")


@pytest.fixture
def update_goldens(request):
    return request.config.getoption("--update-goldens")


def make_scene(system="rigid", count=1, **sections):
    """A Scene from keyword sections, e.g. make_scene(pendulums={"theta1": 1.0}, video={"fps": 50})."""
    from render.scene import from_dict
    raw = {"system": system, "pendulums": {"count": count}}
    for key, val in sections.items():
        if isinstance(val, dict):
            raw.setdefault(key, {}).update(val)
        else:
            raw[key] = val
    return from_dict(raw, "<test>")


def out_folder(out, name: str) -> Path:
    """Where a render of preset `name` went: OUT/NAME/, or with --set or --quality its OUT/NAME__<hash>/."""
    found = [p for p in Path(out).iterdir() if p.name == name or p.name.startswith(f"{name}__")]
    assert len(found) == 1, found
    return found[0]


def run_cli(*args, cwd=None, timeout=300, **kw):
    """`python -m render ARGS` in a subprocess: the real exit code, stdout and stderr."""
    return subprocess.run([sys.executable, "-m", "render", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=timeout, **kw)
