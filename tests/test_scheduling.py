"""`make test`'s scheduling (tests/conftest.py), on a small suite of its own run by two xdist workers: the files
in SHARE_A_WORKER build their session fixture once between them, every file runs whole on one worker, and the
HEAVY_FIRST files go out first. xdist's loadgroup stopped grouping under pytest 9 without a word: this notices."""
import os
import subprocess
import sys

from conftest import HEAVY_FIRST, ROOT, SHARE_A_WORKER

CONFTEST = f"""
import importlib.util, os, pytest
spec = importlib.util.spec_from_file_location("suite_conftest", {str(ROOT / "tests" / "conftest.py")!r})
suite = importlib.util.module_from_spec(spec)
spec.loader.exec_module(suite)
pytest_xdist_make_scheduler, pytest_collection_modifyitems = (suite.pytest_xdist_make_scheduler,
                                                              suite.pytest_collection_modifyitems)

def log(line):
    with open("log.txt", "a") as f:
        f.write(line + "\\n")

@pytest.fixture(scope="session")
def shared():
    log("session fixture built")

@pytest.fixture(autouse=True)
def where(request):
    log(f"{{os.environ['PYTEST_XDIST_WORKER']}} {{request.node.path.name}}")
"""
SHARING = "import pytest\n@pytest.mark.parametrize('k', range(6))\ndef test_uses(shared, k):\n    pass\n"
PLAIN = "import pytest\n@pytest.mark.parametrize('k', range(12))\ndef test_plain(k):\n    pass\n"


def test_shared_files_build_their_fixture_once_each_file_whole_heaviest_first(tmp_path):
    sharing = sorted(SHARE_A_WORKER)
    assert len(sharing) >= 2 and len(set(SHARE_A_WORKER.values())) == 1
    heavy = next(name for name in HEAVY_FIRST if name not in SHARE_A_WORKER)
    (tmp_path / "conftest.py").write_text(CONFTEST)
    for name in sharing:
        (tmp_path / name).write_text(SHARING)
    for name in ("test_a_plain.py", "test_b_plain.py", "test_c_plain.py", heavy):
        (tmp_path / name).write_text(PLAIN)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "PYTHONPATH"))}  # not this run's
    r = subprocess.run([sys.executable, "-m", "pytest", "-n", "2", "--dist", "loadfile", "-p", "no:cacheprovider",
                        "-q"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"{6 * len(sharing) + 12 * 4} passed" in r.stdout, r.stdout
    lines = (tmp_path / "log.txt").read_text().splitlines()
    assert lines.count("session fixture built") == 1, lines
    runs = [line.split() for line in lines if line != "session fixture built"]
    workers = {}
    for worker, name in runs:
        workers.setdefault(name, set()).add(worker)
    assert all(len(w) == 1 for w in workers.values()), workers  # each file whole on one worker
    assert len({next(iter(workers[name])) for name in sharing}) == 1, workers  # the sharing files together
    assert len({w for ws in workers.values() for w in ws}) == 2, workers  # and both workers had work
    firsts = {}
    for worker, name in runs:
        firsts.setdefault(worker, name)
    assert heavy in firsts.values(), firsts  # a heavy file is one worker's first, not left for the end
