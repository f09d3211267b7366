"""A map in tiles over Dask (`render MAP --scheduler ADDR`, `--tiles N`): the same bytes as the local render
(MP4, GIF, PNG and NAME.npz), a worker killed mid-render, the FTLE map's band edges (its bands run in this
process), and the refusals.

One LocalCluster of two worker processes on loopback serves the module, and one local render is the
reference. The map is small (256x144, so its axes, legend and clock are drawn around a 77x77 plot, 1 s at
10 fps), supersampled (4 samples: a band's points are its pixels' samples, adjacent) and its tolerance tight
enough that some pixels are past their faithful time: the bands must draw the hatch of the whole plot, not
their own.
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import signal
import socket
import threading
import time
import zlib
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("dask.distributed")

import render  # noqa: E402 - after the skip
from render.commands import api  # noqa: E402
from render.commands.cli import main  # noqa: E402
from render.maps import tiles  # noqa: E402
from render.physics import grid  # noqa: E402
from render.video import pipeline, tiled  # noqa: E402

SETS = ["video.width=256", "video.height=144", "video.duration=1", "video.fps=10", "map.samples=4",
        "integrator.tolerance=1e-5", "integrator.min_faithful=0"]


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None) as c, distributed.Client(c, set_as_default=False) as client:
        yield c, client


def scene(name="fractal_flip", *sets):
    return api.load(name, *SETS, *sets)


def digest_of(frames: list) -> str:
    return hashlib.sha256(b"".join(frames)).hexdigest()


def render_to(sc, out: Path, **kw) -> tuple[dict, list[bytes]]:
    frames = []
    meta = pipeline.render(sc, out, frame_hook=lambda f, frame: frames.append(frame.tobytes()), **kw)
    return meta, frames


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    meta, frames = render_to(scene(), out)
    return out / meta["preset"]["name"], meta, frames


def cli(*argv) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as e:  # argparse's usage errors
            code = e.code
    return code, err.getvalue()


def test_bands_cover_the_plot_once():
    assert tiles.bands(77, 3) == [range(0, 25), range(25, 51), range(51, 77)]
    assert tiles.bands(3, 8) == [range(0, 1), range(1, 2), range(2, 3)]  # at most one band a row
    for h, n in [(1, 1), (77, 2), (2058, 7)]:
        rows = [r for band in tiles.bands(h, n) for r in band]
        assert rows == list(range(h))


def test_a_band_keeps_its_own_rows_of_what_it_integrated():
    """Per pixel or per sample (4 a pixel), with a halo row each side: only the band's rows come back."""
    span, rows = range(9, 21), range(10, 20)  # 12 rows integrated, 10 the band's own; 5 pixels a row
    per_pixel = np.arange(12 * 5)
    assert np.array_equal(tiles.inner(per_pixel, rows, span), np.arange(5, 55))
    per_sample = np.arange(12 * 5 * 4).reshape(-1, 1).repeat(2, 1)  # (points, links), as the angles map's q
    assert np.array_equal(tiles.inner(per_sample, rows, span), per_sample[20:220])


def test_tiles_give_the_local_render_byte_for_byte(cluster, local, tmp_path):
    folder, meta, frames = local
    m = meta["map"]
    assert m["samples"] == 4 and m["pixels"] == 77 * 77
    assert 0 < m["events_trusted"] < m["events"] and 0 < m["pending_trusted"] < m["pending"]  # the mask shows
    _, client = cluster
    got, tiled_frames = render_to(scene(), tmp_path, cluster=client, bands=2)
    assert len(tiled_frames) == len(frames) == meta["frames"]
    assert digest_of(tiled_frames) == digest_of(frames)
    name = meta["preset"]["name"]
    assert set(meta["outputs_sha256"]) >= {f"{name}.mp4", f"{name}.gif", f"{name}.png", f"{name}.npz"}
    assert got["outputs_sha256"] == meta["outputs_sha256"]  # the MP4, the GIF, the PNG and the npz
    assert {k: v for k, v in got["map"].items() if k != "tiles"} == m
    assert got["map"]["tiles"]["bands"] == 2 and got["map"]["tiles"]["band_rows"] == [[0, 38], [38, 77]]
    assert got["kernels"] == meta["kernels"] and got["integrator"] == meta["integrator"]
    here, there = render.load_map(folder), render.load_map(tmp_path / name)
    for field in ("value", "cannot_flip", "trusted_until", "trusted", "starts"):
        assert np.array_equal(getattr(here, field), getattr(there, field), equal_nan=True), field
    assert here.value.shape == (77, 77, 4) and here.t == there.t > 0


def test_ftle_bands_draw_the_barrier_across_their_edges():
    """The FTLE map's barrier curve reads each point's neighbours: its bands integrate a halo row each side.
    Its bands run here, in this process (render_band is the task as a worker runs it), against the local map."""
    h, w = 32, 96  # too small for axes: the plot fills the frame, and its barrier's oval is flat at the top
    sc = api.load("fractal_lyapunov", f"video.width={w}", f"video.height={h}", "video.duration=0.2", "video.fps=10",
                  "integrator.min_faithful=0")
    src = pipeline.Source(sc)
    whole = [src.next_frame().copy() for _ in range(sc.frames)]
    inside = src.canvas.inside.reshape(h, w)  # E < B
    # the bands meet where a pixel is on the curve only through its neighbour across the cut
    cut = next(r for r in range(4, h - 3) if on_curve_across(inside, r) or on_curve_across(inside[::-1], h - r))
    mine, summary = src.canvas.result(), src.canvas.summary()
    results = [tiles.render_band(src.scene, rows, src.cert) for rows in (range(0, cut), range(cut, h))]
    asm = tiles.Assembly(src.scene, results)
    for f in range(sc.frames):
        assert np.array_equal(asm.frame(f), whole[f]), f
    theirs = asm.result()
    for k in ("value", "claim", "cannot_flip", "until"):
        assert np.array_equal(mine[k], theirs[k]), k
    assert asm.summary() == summary and summary["barrier_pixels"] > 0


def on_curve_across(inside, r) -> bool:
    """Whether a pixel of row r - 1 is inside the barrier (E < B) with only its neighbour below, in row r,
    outside: on the curve only by a neighbour that a band ending at row r does not hold."""
    if not 2 <= r < len(inside):
        return False
    mid = inside[r - 1, 1:-1]
    return bool((mid & ~inside[r, 1:-1] & inside[r - 2, 1:-1] & inside[r - 1, :-2] & inside[r - 1, 2:]).any())


def test_a_worker_killed_mid_render_is_retried(cluster, local, tmp_path):
    """SIGKILL to the worker process running a band, while it runs: Dask reruns the band, the MP4 is the same."""
    c, client = cluster
    client.wait_for_workers(2, timeout=60)
    pids = client.run(os.getpid)  # worker address -> its process
    killed, seen, stop = [], set(), threading.Event()

    def killer():
        while not stop.is_set() and not killed:
            for worker, keys in client.processing().items():
                seen.update(str(k) for k in keys)
                if any(str(k).startswith("pendulum-tile-") for k in keys) and worker in pids:
                    os.kill(pids[worker], signal.SIGKILL)
                    killed.append(worker)
                    return
            time.sleep(0.01)

    thread = threading.Thread(target=killer, daemon=True)
    thread.start()
    try:
        code, err = cli("render", "fractal_flip", *(a for s in SETS for a in ("--set", s)), "--out", tmp_path,
                        "--scheduler", c.scheduler_address, "--tiles", 2, "--no-progress")
    finally:
        stop.set()
        thread.join(5)
    assert killed, "no band was seen running"
    folder, meta, _ = local
    assert code == 0, err  # the band ran again on a worker alive: the render is whole
    (mp4,) = tmp_path.glob("fractal_flip__*/*.mp4")  # --set: the folder NAME__<hash>
    assert mp4.read_bytes() == (folder / "fractal_flip.mp4").read_bytes()
    digest = json.loads((mp4.parent / "metadata.json").read_text())["preset_hash"]
    assert all(k.startswith(f"pendulum-tile-{digest[:16]}-") for k in seen)  # the tasks name their scene


def test_only_a_map_is_tiled(tmp_path):
    code, err = cli("render", "classic", "--tiles", 2, "--out", tmp_path / "out", "--no-progress")
    assert code == 2 and err.count("\n") == 1 and "classic.toml" in err and "--tiles" in err, err
    assert not (tmp_path / "out").exists()
    code, err = cli("render", "fractal_flip", "--scheduler", "tcp://host:99999", "--out", tmp_path / "out")
    assert code == 2 and "--scheduler" in err and err.count("\n") == 1
    code, err = cli("render", "fractal_flip", "--tiles", 0, "--out", tmp_path / "out")
    assert code == 2 and "--tiles" in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_an_unreachable_scheduler_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(tiled, "CONNECT_TIMEOUT", "1s")  # Client retries a refused connection until then
    with socket.socket() as sock:  # a loopback port that no one listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    code, err = cli("render", "fractal_flip", *(a for s in SETS for a in ("--set", s)), "--out", tmp_path / "out",
                    "--scheduler", f"127.0.0.1:{port}", "--no-progress")
    assert code == 1 and err.count("\n") == 1 and "cannot reach the Dask scheduler" in err, err
    assert not (tmp_path / "out").exists()


def test_a_scheduler_without_workers_is_one_line_not_a_silent_wait(tmp_path, monkeypatch):
    monkeypatch.setattr(tiled, "WORKERS_TIMEOUT_S", 2.0)
    with tiled.quiet(), distributed.LocalCluster(n_workers=0, host="127.0.0.1", dashboard_address=None) as empty:
        t = time.perf_counter()
        code, err = cli("render", "fractal_flip", *(a for s in SETS for a in ("--set", s)), "--out",
                        tmp_path / "out", "--scheduler", empty.scheduler_address, "--no-progress")
    assert code == 1 and err.count("\n") == 1 and "has no worker (waited 2 s)" in err, err
    assert time.perf_counter() - t < 30 and not (tmp_path / "out").exists()


def test_a_cluster_that_loses_every_worker_mid_render_is_one_line_not_a_silent_wait(tmp_path, monkeypatch):
    """Its one worker retired while a band runs: the scheduler would hold the bands left for a worker forever.
    After WORKERS_TIMEOUT_S with no worker the render fails, saying so, and writes nothing."""
    monkeypatch.setattr(tiled, "WORKERS_TIMEOUT_S", 2.0)
    with tiled.quiet(), distributed.LocalCluster(n_workers=1, processes=True, threads_per_worker=1, host="127.0.0.1",
                                                 dashboard_address=None) as one, \
            distributed.Client(one, set_as_default=False) as client:
        client.wait_for_workers(1, timeout=60)
        retired, stop = threading.Event(), threading.Event()

        def retire():  # as soon as a band runs, the cluster scales to no worker
            while not stop.is_set():
                if any(str(k).startswith("pendulum-tile-") for keys in client.processing().values() for k in keys):
                    one.scale(0)
                    retired.set()
                    return
                time.sleep(0.01)

        thread = threading.Thread(target=retire, daemon=True)
        thread.start()
        try:
            code, err = cli("render", "fractal_flip", *(a for s in SETS for a in ("--set", s)), "--out",
                            tmp_path / "out", "--scheduler", one.scheduler_address, "--tiles", 2, "--no-progress")
        finally:
            stop.set()
            thread.join(5)
    assert retired.is_set(), "no band was seen running"
    assert code == 1 and err.count("\n") == 1, err
    assert "the Dask cluster has had no worker for 2 s, with bands of the map still to run" in err, err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.*")), list((tmp_path / "out").rglob("*"))


def test_assembly_undoes_the_deltas():
    """The bands' frames travel as XOR deltas, zlib-compressed: they come back exactly."""
    sc = scene()
    lay = grid.plot(sc)
    rng = np.random.default_rng(1)
    whole = rng.integers(0, 256, (3, lay.height, lay.width, 3), dtype=np.uint8)
    bands = tiles.bands(lay.h, 2)
    results = []
    for i, rows in enumerate(bands):
        part = whole if i == 0 else whole[:, lay.y0 + rows.start:lay.y0 + rows.stop, lay.x0:lay.x0 + lay.w]
        deltas = [part[0]] + [part[f] ^ part[f - 1] for f in range(1, 3)]
        results.append({"rows": (rows.start, rows.stop), "shape": part.shape[1:],
                        "frames": [zlib.compress(np.ascontiguousarray(d).tobytes()) for d in deltas]})
    asm = tiles.Assembly(sc, results)
    for f in range(3):
        assert np.array_equal(asm.frame(f), whole[f])


def test_ctrl_c_during_a_tiled_render_is_one_line(tmp_path):
    """Ctrl-C goes to the terminal's whole process group, the local cluster's worker processes too: each printed
    its KeyboardInterrupt's traceback (67-86 lines) beside our one line. Sent as the workers start."""
    import subprocess
    import sys

    from conftest import ROOT
    proc = subprocess.Popen([sys.executable, "-m", "render", "render", "fractal_flip",
                             *(a for s in SETS for a in ("--set", s)), "--set", "video.duration=30", "--tiles", "2",
                             "--out", str(tmp_path / "out"), "--no-progress"], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.time() + 120
        while time.time() < deadline and not any("multiprocessing.spawn" in p.read_bytes().decode(errors="replace")
                                                 for p in Path("/proc").glob("[0-9]*/cmdline")
                                                 if _child_of(p.parent, proc.pid)):
            time.sleep(0.02)
        time.sleep(0.3)  # the workers are importing: where a Ctrl-C made them print
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130 and err.splitlines() == ["pendulum: interrupted; no partial output was left"], err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.*"))


def _child_of(proc_dir: Path, pid: int) -> bool:
    try:
        return int((proc_dir / "stat").read_text().rsplit(")", 1)[1].split()[1]) == pid
    except (OSError, ValueError, IndexError):
        return False
