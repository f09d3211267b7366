"""A preset path that is no preset file: a FIFO, a device, a socket, or a regular file far too big.

A plain read of a FIFO waits for a writer that never comes, and of /dev/zero never ends (it filled 24 GB
before the cap). Each case runs the CLI as a user would (conftest.run_cli) with a timeout, so a hang fails the
test instead of the suite, and asserts exit 2, one line on stderr naming the file, and no --out written.
"""
import os
import resource
import socket

import pytest

from conftest import run_cli
from render.config import catalog

TIMEOUT_S = 60  # a refusal takes well under a second; a hang runs into this
FIFO = "a FIFO, not a regular file"


def cli(tmp_path, *args, env=None, **kw):
    return run_cli(*args, cwd=tmp_path, env={**os.environ, **(env or {})}, timeout=TIMEOUT_S, **kw)


def refused(r, *needles) -> str:
    """Exit 2, one line on stderr holding every needle, no traceback, nothing on stdout."""
    assert r.returncode == 2, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr and r.stdout == "", r.stderr
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    return lines[0]


@pytest.mark.parametrize("command", ["render", "simulate", "batch"])
def test_a_fifo_preset_path_is_refused(tmp_path, command):
    presets = tmp_path / "p"
    presets.mkdir()
    fifo = presets / "fifo.toml"
    os.mkfifo(fifo)
    out = tmp_path / "out"
    args = {"render": ["render", fifo, "--out", out], "simulate": ["simulate", fifo, "--out", out / "x.npz"],
            "batch": ["batch", presets / "*.toml", "--out", out]}[command]  # the glob, as a shell would pass it
    refused(cli(tmp_path, *args), f"{fifo}: {FIFO}")
    assert not out.exists()


def test_a_socket_preset_path_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(path))
        refused(cli(tmp_path, "render", path, "--out", tmp_path / "out"), f"{path}: a socket, not a regular file")
    assert not (tmp_path / "out").exists()


def test_dev_zero_as_a_preset_path_is_refused(tmp_path):
    def cap_memory():  # the code before the fix read /dev/zero until memory ran out: fail at 2 GiB instead
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    r = cli(tmp_path, "render", "/dev/zero", "--out", tmp_path / "out", preexec_fn=cap_memory)
    refused(r, "/dev/zero: a device, not a regular file")
    assert not (tmp_path / "out").exists()


def test_a_preset_over_the_cap_is_refused(tmp_path):
    cap, big = catalog.PRESET_MAX_BYTES, tmp_path / "big.toml"
    big.write_text("#" * cap + "\n")  # one TOML comment, one byte over
    r = cli(tmp_path, "render", big, "--out", tmp_path / "out")
    refused(r, f"big.toml: {cap + 1} bytes, over the {cap}-byte limit")
    assert not (tmp_path / "out").exists()


def test_a_fifo_on_the_search_path(tmp_path):
    """Named like a shipped preset, a FIFO there stands in for it and is refused, as a symlink loop there is;
    `pendulum presets` lists it as INVALID among the others, as it does a malformed preset, and a misspelled
    name's "did you mean" search passes it by."""
    folder = tmp_path / "mine"
    folder.mkdir()
    os.mkfifo(folder / "classic.toml")
    env = {"PENDULUM_PRESETS": str(folder)}
    out = tmp_path / "out"
    refused(cli(tmp_path, "render", "classic", "--out", out, env=env), f"{folder / 'classic.toml'}: {FIFO}")
    refused(cli(tmp_path, "render", "clasic", "--out", out, env=env), "clasic: no such preset", "'classic'")
    assert not out.exists()
    r = cli(tmp_path, "presets", env=env)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    rows = {line.split()[0]: line for line in r.stdout.splitlines()}
    assert "INVALID" in rows["classic"] and f"{folder / 'classic.toml'}: {FIFO}" in rows["classic"]
    assert "INVALID" not in rows["fractal"]  # the others are still listed, and read


def test_a_fifo_where_the_bench_rates_go_is_ignored_not_waited_on(tmp_path):
    """OUT/bench/rates.json, which the budget reads before a render, may be anything a user put there: a FIFO
    is passed over for the built-in rates (as a malformed file is), and the render runs."""
    (tmp_path / "out" / "bench").mkdir(parents=True)
    os.mkfifo(tmp_path / "out" / "bench" / "rates.json")
    r = cli(tmp_path, "render", "classic", "--set", "video.duration=0.1", "--set", "video.width=64", "--set",
            "video.height=36", "--no-progress", "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr
