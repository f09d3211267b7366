"""The hostile-input audit (issue 13): each case run as a user runs it, in a real process limited to 60 s and
8 GB of address space. Each asserts the exit code, at most one stderr line, no traceback, and that nothing
was written where nothing should be.

Taichi reserves 1 GiB of virtual memory when it starts (its host memory pool): under RLIMIT_AS = 1 GiB it
cannot start at all, under 2 GiB a render runs. 8 GB is the audit's limit and holds every case here.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, out_folder, run_cli

ADDRESS_SPACE = 8 << 30  # bytes
TINY = ["--set", "video.width=32", "--set", "video.height=32", "--set", "video.duration=0.2", "--no-progress"]
GOOD = """\
name = "{name}"
system = "rigid"
[pendulums]
count = 2
[video]
width = 32
height = 32
fps = 10
duration = 0.3
gif_width = 32
"""


def run_user(*args, cwd, fsize=None, env=None):
    """`pendulum ARGS` in a real process, within 60 s and ADDRESS_SPACE (and at most `fsize` bytes a file)."""
    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
        if fsize is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
    return run_cli(*args, cwd=cwd, timeout=60, preexec_fn=limits, env=env)


def one_line(r, code: int, *needles: str) -> str:
    """The run exited with `code` and said so in one stderr line holding every needle, with no traceback."""
    assert r.returncode == code, r.stderr
    assert "Traceback" not in r.stderr, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    return lines[0]


def nothing_in(folder: Path) -> bool:
    return not folder.exists() or not any(folder.rglob("*"))


# ------------------------------------------------------------------ refused up front: exit 2, nothing written

REFUSED = {
    "dt_1e-12_render": (["render", "classic", "--out", "{out}", *TINY, "--set", "integrator.dt=1e-12"],
                        ["classic.toml", "integrator.dt", "dt too small", "steps", "exceed the step counter"]),
    "dt_1e-12_simulate": (["simulate", "classic", "--out", "{out}/c.npz", "--set", "integrator.dt=1e-12"],
                          ["classic.toml", "integrator.dt", "dt too small", "steps", "exceed the step counter"]),
    "omega_1e200": (["render", "classic", "--out", "{out}", *TINY, "--set", "pendulums.omega1=1e200"],
                    ["classic.toml", "pendulums.omega1", "1e+200"]),
    "lengths_1e-200": (["render", "classic", "--out", "{out}", *TINY, "--set", "pendulums.lengths=[1e-200,1e-200]"],
                       ["classic.toml", "pendulums.lengths", "1e-200", "> 0"]),
    "simulate_100_GB": (["simulate", "rigid_chaos", "--out", "{out}/x.npz", "--set", "pendulums.count=4000000",
                         "--set", "video.duration=60"],
                        ["rigid_chaos.toml", "pendulums.count", "needs about", "TB of memory", "limit"]),
    "simulate_out_is_a_directory": (["simulate", "classic", "--out", "{tmp}/dir.npz"],
                                    ["--out", "dir.npz", "is a directory"]),
    "render_threads_0": (["render", "classic", "--out", "{out}", *TINY, "--threads", "0"], ["--threads", "'0'"]),
    "render_threads_-1": (["render", "classic", "--out", "{out}", *TINY, "--threads", "-1"], ["--threads", "'-1'"]),
    "batch_threads_0": (["batch", "classic", "--out", "{out}", "--threads", "0"], ["--threads", "'0'"]),
    "batch_threads_-1": (["batch", "classic", "--out", "{out}", "--threads", "-1"], ["--threads", "'-1'"]),
    "batch_scheduler_bad_port": (["batch", "classic", "--out", "{out}", "--scheduler", "tcp://127.0.0.1:abc"],
                                 ["--scheduler", "tcp://127.0.0.1:abc", "port"]),
    # the preset's own 20 s: 1.6e12 steps, hours (12 frames of TINY would be 1.6e10, minutes, within the budget)
    "stiff_light_springs_step_budget": (["render", "elastic_fan", "--out", "{out}", *TINY[:4], "--no-progress",
                                         "--set",
                                         "pendulums.stiffness=1e12", "--set", "pendulums.masses=[1e-6,1e-6]"],
                                        ["elastic_fan.toml", "integrator.dt", "over the run-time budget"]),
    "damping_1000_symplectic_euler": (["render", "classic", "--out", "{out}", *TINY, "--set",
                                       "pendulums.damping=1000", "--set", "integrator.dt=0.01", "--set",
                                       "integrator.method=symplectic_euler"],
                                      ["classic.toml", "integrator.dt", "stability limit", "damping 1000"]),
    "fractal_on_springs": (["render", "elastic_fan", "--out", "{out}", *TINY, "--set", 'effects=["fractal"]',
                            "--set", "pendulums.layout=grid", "--set", "pendulums.count=1024"],
                           ["elastic_fan.toml", "effects", "fractal", "angles"]),
}


@pytest.mark.parametrize("case", REFUSED, ids=list(REFUSED))
def test_refused_up_front_with_one_line(tmp_path, case):
    args, needles = REFUSED[case]
    out = tmp_path / "out"
    (tmp_path / "dir.npz").mkdir()
    r = run_user(*[a.format(out=out, tmp=tmp_path) for a in args], cwd=tmp_path)
    one_line(r, 2, *needles)
    assert nothing_in(out), list(out.rglob("*"))
    assert nothing_in(tmp_path / "dir.npz")


def test_a_250_character_name_is_refused(tmp_path):
    preset = tmp_path / "long.toml"
    preset.write_text(GOOD.format(name="n" * 250))
    r = run_user("render", preset, "--out", tmp_path / "out", "--no-progress", cwd=tmp_path)
    one_line(r, 2, "long.toml", "name", "longer than the limit of 100 characters")
    assert nothing_in(tmp_path / "out")


def test_two_presets_with_the_same_name_are_refused_naming_both(tmp_path):
    for stem in ("first", "second"):
        (tmp_path / f"{stem}.toml").write_text(GOOD.format(name="same"))
    r = run_user("render", "first.toml", "second.toml", "--out", "out", "--no-progress", cwd=tmp_path)
    one_line(r, 2, "first.toml", "second.toml", "name", "'same'")
    assert nothing_in(tmp_path / "out")


def test_a_file_where_the_render_folder_goes_is_refused(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "classic").write_text("mine")
    r = run_user("render", "classic", "--out", "out", "--no-progress", cwd=tmp_path)  # no --set: out/classic
    one_line(r, 2, "--out", "classic is a file")
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["classic"]
    assert (tmp_path / "out" / "classic").read_text() == "mine"


# ------------------------------------------------------------------ runs, or fails cleanly while running


def test_no_gravity_is_a_still_pendulum(tmp_path):
    """classic without gravity and at rest: nothing limits the step (omega_max = 0), nothing moves."""
    r = run_user("simulate", "classic", "--out", "c.npz", "--set", "pendulums.gravity=0",
                 "--set", "video.duration=0.5", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    theta = np.load(tmp_path / "c.npz")["theta"]
    assert theta.shape == (30, 1, 2) and np.all(theta == theta[0])
    np.testing.assert_allclose(theta[0, 0], [math.radians(120), math.radians(-10)])
    r = run_user("render", "classic", "--out", "out", *TINY, "--set", "pendulums.gravity=0", cwd=tmp_path)
    assert r.returncode == 0 and not r.stderr.strip(), r.stderr
    folder = out_folder(tmp_path / "out", "classic")
    assert (folder / f"{folder.name}.mp4").stat().st_size > 0


def test_simulate_to_a_full_disk_fails_with_one_line_and_leaves_nothing(tmp_path):
    """RLIMIT_FSIZE makes every write past 1 MB fail with EFBIG, as a full disk fails with ENOSPC (Python
    ignores SIGXFSZ). Taichi's kernel cache goes to a private folder: a write it cannot finish must not
    leave a truncated entry in the user's cache."""
    env = {**os.environ, "TI_OFFLINE_CACHE_FILE_PATH": str(tmp_path / "taichi-cache")}
    out = tmp_path / "out" / "chaos.npz"  # 600 frames x 100 pendulums x 5 float64: ~2.4 MB
    r = run_user("simulate", "rigid_chaos", "--out", out, "--set", "video.duration=10", "--no-progress",
                 cwd=tmp_path, fsize=1 << 20, env=env)
    one_line(r, 1, "failed", "File too large", "chaos.npz")
    assert nothing_in(tmp_path / "out"), list((tmp_path / "out").rglob("*"))


@pytest.mark.parametrize("fmt, limit", [("mp4", 100_000), ("gif", 400_000)])
def test_a_video_past_the_file_size_limit_is_named_as_the_os_says(tmp_path, fmt, limit):
    """RLIMIT_FSIZE as a full disk: ffmpeg's write past it fails with EFBIG, and the one line names the file the
    user asked for. ffmpeg had SIGXFSZ's default action restored by Popen and died of the signal, saying nothing:
    "ffmpeg failed: exit status -25" (the MP4) or "[Errno 32] Broken pipe" (the GIF, whose pipe it left)."""
    env = {**os.environ, "TI_OFFLINE_CACHE_FILE_PATH": str(tmp_path / "taichi-cache")}
    r = run_user("render", "seed_rigid", "--out", "out", "--no-progress", "--set", "video.width=320",
                 "--set", "video.height=180", "--set", "video.duration=4", "--set", f'video.formats=["{fmt}"]',
                 cwd=tmp_path, fsize=limit, env=env)
    one_line(r, 1, "failed", "File too large", "out/seed_rigid__", f".{fmt}")
    assert nothing_in(tmp_path / "out"), list((tmp_path / "out").rglob("*"))


def test_a_render_that_fails_after_its_videos_are_finished_publishes_none_of_them(tmp_path, monkeypatch):
    """The MP4, GIF, still and map data are finished in their temporaries and published only with metadata.json:
    a failure in between (a full disk as the metadata is written) leaves none of them, and no temporary."""
    import errno
    from render.config.scene import load
    from render.video import pipeline

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(pipeline, "metadata", full)
    scene = load("fractal_flip", ["video.width=64", "video.height=36", "video.duration=0.2",
                                  'video.formats=["mp4", "gif", "png"]'])
    with pytest.raises(OSError, match=os.strerror(errno.ENOSPC)):
        pipeline.render(scene, tmp_path)
    assert not list(tmp_path.rglob("*"))  # no file, no temporary, and the folder made for them is gone


def test_a_publish_that_fails_names_the_file_asked_for_not_the_temporary(tmp_path):
    import errno
    from render.video import atomic
    (tmp_path / "x.mp4").mkdir()
    tmp = atomic.temp_beside(tmp_path / "x.mp4")
    with pytest.raises(IsADirectoryError) as e:
        atomic.publish(tmp, tmp_path / "x.mp4")
    assert e.value.filename == str(tmp_path / "x.mp4") and str(tmp_path / "x.mp4") in str(e.value)
    with pytest.raises(OSError) as e:  # a write into the temporary that fails names no file: the final is named
        with atomic.replacing(tmp_path / "y.json"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert e.value.filename == str(tmp_path / "y.json") and not list(tmp_path.glob(".y.json*"))


def test_files_written_together_appear_together_or_not_at_all(tmp_path):
    """atomic.together(), as accuracy, lyapunov and the gallery write: a chart finished before a failing table is
    not left behind; when the block succeeds every file appears, in its final name only."""
    from render.video import atomic
    with pytest.raises(OSError):
        with atomic.together():
            atomic.write_atomic(tmp_path / "chart.png", b"png")
            with atomic.replacing(tmp_path / "poster.jpg", suffix=".jpg") as tmp:
                tmp.write_bytes(b"jpg")
            assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == []
            (tmp_path / "table.csv").mkdir()
            atomic.write_atomic(tmp_path / "table.csv", b"csv")  # renamed onto a folder: fails at the end
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"]  # only the folder that was there
    (tmp_path / "table.csv").rmdir()
    with atomic.together():
        atomic.write_atomic(tmp_path / "chart.png", b"png")
        atomic.write_atomic(tmp_path / "table.csv", b"csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chart.png", "table.csv"]
    atomic.write_atomic(tmp_path / "alone.txt", b"x")  # outside a block: published at once, as before
    assert (tmp_path / "alone.txt").read_bytes() == b"x"


def test_an_interrupt_while_the_gifs_frames_are_set_up_leaves_nothing(tmp_path, monkeypatch):
    """The encoders' temporaries exist from Encoder() on: a Ctrl-C while the GIF's own canvas is built (between
    them and the frame loop) left them and the new folder, while the CLI said no partial output was left."""
    from render.config.scene import load
    from render.video import gif, pipeline

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(gif, "Frames", interrupted)
    scene = load("classic", ["video.width=64", "video.height=36", "video.duration=0.2", "video.fps=10"])
    with pytest.raises(KeyboardInterrupt):
        pipeline.render(scene, tmp_path / "out")
    assert nothing_in(tmp_path / "out"), list((tmp_path / "out").rglob("*"))


def test_an_interrupt_while_the_track_is_muxed_stops_the_mux_and_leaves_nothing(tmp_path, monkeypatch):
    """Ctrl-C as the audio track is muxed (its ffmpeg on a thread, in a session of its own): the mux's ffmpeg
    went on after we had exited, writing a hidden MP4 nobody would remove. Here the mux's ffmpeg would sleep a
    minute; it is killed, the render stops at once and leaves nothing."""
    import signal
    import imageio_ffmpeg
    from render.config.scene import load
    from render.video import mp4, pipeline

    real_exe = imageio_ffmpeg.get_ffmpeg_exe()
    fake = tmp_path / "ffmpeg"
    fake.write_text(f'#!/bin/sh\ncase "$*" in *" -c:a "*) exec sleep 60;; esac\nexec "{real_exe}" "$@"\n')
    fake.chmod(0o755)
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: str(fake))
    real_mux, procs = mp4.mux, []

    def mux(final, tmp, log, rate, samples, running=None):
        class Started(list):
            def append(self, proc):
                if running is not None:
                    running.append(proc)
                procs.append(proc)
                os.kill(os.getpid(), signal.SIGINT)  # the main thread is waiting for the mux, or mapping the GIF
        return real_mux(final, tmp, log, rate, samples, Started())

    monkeypatch.setattr(mp4, "mux", mux)
    scene = load("rigid_chaos", ["video.width=160", "video.height=90", "video.duration=0.5", "video.fps=10",
                                 "pendulums.count=8"])
    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        pipeline.render(scene, tmp_path / "out")
    assert time.perf_counter() - t < 30 and procs and procs[0].poll() is not None  # killed, not waited out
    assert nothing_in(tmp_path / "out"), list((tmp_path / "out").rglob("*"))


@pytest.mark.parametrize("formats", ['["mp4"]', '["mp4", "gif"]'])
def test_an_ffmpeg_that_writes_nothing_and_exits_0_fails_the_render(tmp_path, formats):
    """A broken or stand-in ffmpeg (IMAGEIO_FFMPEG_EXE) that reads its frames and exits 0: a 0-byte MP4 was
    published with exit 0, and the GIF's empty palette read "unexpected error: ValueError"."""
    fake = tmp_path / "ffmpeg"
    fake.write_text("#!/bin/sh\ncat > /dev/null\nexit 0\n")
    fake.chmod(0o755)
    r = run_user("render", "classic", "--out", "out", *TINY, "--set", f"video.formats={formats}", cwd=tmp_path,
                 env={**os.environ, "IMAGEIO_FFMPEG_EXE": str(fake)})
    one_line(r, 1, "failed", "ffmpeg")
    assert "unexpected" not in r.stderr and nothing_in(tmp_path / "out"), (r.stderr, list(tmp_path.rglob("*")))


def test_a_cleanup_that_fails_too_does_not_hide_the_failure(tmp_path, monkeypatch):
    """A full disk as metadata.json is written, in a folder where the temporaries cannot be removed either: the
    error reported is the full disk's, not the cleanup's (which named a hidden temporary), and every temporary
    that can go is tried."""
    import errno
    import pathlib
    from render.config.scene import load
    from render.video import pipeline

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    real, tried = pathlib.Path.unlink, []

    def stuck(self, missing_ok=False):
        if self.name.endswith(".part"):
            tried.append(self.name)
            raise PermissionError(errno.EPERM, os.strerror(errno.EPERM), str(self))
        return real(self, missing_ok=missing_ok)

    monkeypatch.setattr(pipeline, "metadata", full)
    monkeypatch.setattr(pathlib.Path, "unlink", stuck)
    scene = load("classic", ["video.width=64", "video.height=36", "video.duration=0.2", "video.fps=10"])
    with pytest.raises(OSError) as e:
        pipeline.render(scene, tmp_path)
    assert e.value.errno == errno.ENOSPC, e.value
    assert sum(".mp4." in n for n in tried) >= 1 and sum(".gif." in n for n in tried) >= 1, tried  # each tried


def test_a_publish_that_fails_halfway_puts_the_earlier_result_back(tmp_path, monkeypatch):
    """atomic.publish_all: the third rename fails after two new files had replaced an earlier run's; those two are
    put back, the new ones are gone, and nothing hidden is left (neither temporaries nor the kept links)."""
    import errno
    from render.video import atomic
    names = ["a.mp4", "b.gif", "metadata.json"]
    for n in names:
        (tmp_path / n).write_text(f"old {n}")
    pairs = []
    for n in names:
        tmp = atomic.temp_beside(tmp_path / n)
        tmp.write_text(f"new {n}")
        pairs.append((tmp, tmp_path / n))
    real, calls = atomic.publish, []

    def publish(tmp, path):
        calls.append(path.name)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        real(tmp, path)

    monkeypatch.setattr(atomic, "publish", publish)
    with pytest.raises(OSError, match=os.strerror(errno.ENOSPC)):
        atomic.publish_all(pairs)
    assert calls == names
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)  # nothing hidden left
    assert all((tmp_path / n).read_text() == f"old {n}" for n in names)
    monkeypatch.setattr(atomic, "publish", real)
    fresh = tmp_path / "fresh"  # no earlier result: a failure leaves none of the new one
    fresh.mkdir()
    pairs = [(atomic.temp_beside(fresh / n), fresh / n) for n in names]
    calls.clear()
    monkeypatch.setattr(atomic, "publish", publish)
    with pytest.raises(OSError):
        atomic.publish_all(pairs)
    assert not list(fresh.iterdir())


def test_a_publish_that_cannot_keep_the_earlier_files_removes_its_temporaries(tmp_path, monkeypatch):
    """Keeping the earlier result fails (the folder made unwritable, say) before any rename: nothing is renamed,
    the earlier files stay, and no temporary of ours is left."""
    import errno
    from render.video import atomic
    (tmp_path / "a.mp4").write_text("old")
    pairs = [(atomic.temp_beside(tmp_path / n), tmp_path / n) for n in ("a.mp4", "metadata.json")]
    real = atomic._keep

    def keep(path):
        if path.name == "metadata.json":
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real(path)

    monkeypatch.setattr(atomic, "_keep", keep)
    with pytest.raises(PermissionError):
        atomic.publish_all(pairs)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mp4"] and (tmp_path / "a.mp4").read_text() == "old"


def test_a_signal_during_the_renames_comes_after_them(tmp_path):
    """SIGINT as the renames go (the second one here) is delivered when all are done: a render is published whole,
    then interrupted, never cut between its video and its metadata.json."""
    import signal
    from render.video import atomic
    pairs = [(atomic.temp_beside(tmp_path / n), tmp_path / n) for n in ("a.mp4", "metadata.json")]
    real, seen = atomic.publish, []

    def publish(tmp, path):
        if path.name == "metadata.json":
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler would run here, between two bytecodes
        real(tmp, path)
        seen.append(path.name)

    atomic.publish, old = publish, atomic.publish
    try:
        with pytest.raises(KeyboardInterrupt):
            atomic.publish_all(pairs)
    finally:
        atomic.publish = old
    assert seen == ["a.mp4", "metadata.json"] and sorted(p.name for p in tmp_path.iterdir()) == ["a.mp4",
                                                                                                   "metadata.json"]


def test_a_render_that_fails_as_it_publishes_leaves_the_earlier_render_whole(tmp_path, monkeypatch):
    """Into OUT/NAME holding a complete render: its metadata.json's rename fails after the new MP4 and GIF had
    replaced the old ones. The folder holds the earlier render again, byte for byte, and nothing else."""
    import errno
    from render.config.scene import load
    from render.video import atomic, pipeline

    def scene(seconds):
        return load("classic", ["video.width=64", "video.height=36", f"video.duration={seconds}", "video.fps=10",
                                'video.formats=["mp4", "gif"]']).replace(name="x")

    pipeline.render(scene(0.5), tmp_path)
    before = {p.name: p.read_bytes() for p in (tmp_path / "x").iterdir()}
    real = atomic.publish

    def publish(tmp, path):
        if path.name == "metadata.json":
            raise OSError(errno.EIO, os.strerror(errno.EIO), str(path))
        real(tmp, path)

    monkeypatch.setattr(atomic, "publish", publish)
    with pytest.raises(OSError, match=os.strerror(errno.EIO)):
        pipeline.render(scene(0.8), tmp_path)
    assert {p.name: p.read_bytes() for p in (tmp_path / "x").iterdir()} == before


def test_a_gallery_whose_page_is_a_folder_is_refused_before_any_poster(tmp_path):
    r = run_cli("render", "classic", *TINY, "--name", "x", "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    (tmp_path / "out" / "index.html").mkdir()
    g = run_cli("gallery", "--out", tmp_path / "out")
    assert g.returncode == 2 and len(g.stderr.strip().splitlines()) == 1 and "is a folder" in g.stderr, g.stderr
    assert not list((tmp_path / "out" / "x").glob("*poster*"))


def test_a_render_removes_the_files_of_an_earlier_render_it_does_not_write_again(tmp_path):
    """OUT/NAME holds one render: the GIF an earlier render listed in its metadata.json goes when the next one,
    its formats changed, writes no GIF; a file of another kind, or one the old metadata did not list, stays."""
    def render(*formats):
        r = run_cli("render", "classic", *TINY, "--set", f"video.formats={list(formats)!r}".replace("'", '"'),
                    "--name", "x", "--out", tmp_path)
        assert r.returncode == 0, r.stderr
        return sorted(p.name for p in (tmp_path / "x").iterdir())

    assert render("mp4", "gif") == ["metadata.json", "x.gif", "x.mp4"]
    (tmp_path / "x" / "x.webm").write_text("mine")
    (tmp_path / "x" / "x.png").write_text("mine too: not in the metadata")
    assert render("mp4") == ["metadata.json", "x.mp4", "x.png", "x.webm"]
    assert (tmp_path / "x" / "x.png").read_text() == "mine too: not in the metadata"
    assert render("gif") == ["metadata.json", "x.gif", "x.png", "x.webm"]


def group_alive(pgid: int) -> list[int]:
    """The processes of a process group still running (zombies aside)."""
    alive = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            alive.append(int(stat.parent.name))
    return alive


STOPPED = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_batch_on_two_workers_stopped_mid_render_exits_and_leaves_nothing(tmp_path, sig, code):
    """Ctrl-C (or SIGTERM) to the whole group, as a terminal sends it, while the workers render: the batch exits
    with its code, no worker lives on and no temporary is left. A worker stopped inside a render had gone on
    waiting for another task, and the batch waited for it forever after saying it was interrupted."""
    proc = subprocess.Popen([sys.executable, "-m", "render", "batch", "rigid_chaos", "classic", "--jobs", "2",
                             "--out", str(tmp_path / "out"), "--no-progress", "--set", "video.width=160",
                             "--set", "video.height=90", "--set", "video.duration=60"],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    deadline = time.time() + 180
    def encoded():  # both renders in their frame loops: frames written into both videos' temporaries
        return [p for p in (tmp_path / "out").rglob(".*.mp4.*.part") if p.exists() and p.stat().st_size]

    while len(encoded()) < 2 and time.time() < deadline:
        time.sleep(0.05)
    try:
        assert len(encoded()) >= 2, "no render started encoding"
        os.killpg(proc.pid, sig)
        _, err = proc.communicate(timeout=90)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == code, err
    deadline = time.time() + 10
    while group_alive(proc.pid) and time.time() < deadline:  # the workers were told to go; give them a moment
        time.sleep(0.1)
    left = group_alive(proc.pid)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not left, f"processes left behind: {left}"
    # Neither render finished, so no folder is left, OUT included (it was, empty); stderr has the estimate and
    # the stop, a line each (the resource tracker had added two: the workers' progress bars' semaphores, leaked)
    assert not (tmp_path / "out").exists(), list((tmp_path / "out").rglob("*"))
    lines = err.strip().splitlines()
    assert len(lines) == 2 and "estimated" in lines[0] and lines[1].startswith(f"pendulum: {STOPPED[sig]}"), err


def test_a_batch_output_corrupted_in_place_is_rendered_again(tmp_path):
    (tmp_path / "p.toml").write_text(GOOD.format(name="p"))
    first = run_user("batch", "p.toml", "--out", "out", "--jobs", "1", "--no-progress", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    mp4 = tmp_path / "out" / "p" / "p.mp4"
    meta = json.loads((mp4.parent / "metadata.json").read_text())
    good = mp4.read_bytes()
    assert meta["outputs"]["p.mp4"] == len(good) and len(meta["outputs_sha256"]["p.mp4"]) == 64

    again = run_user("batch", "p.toml", "--out", "out", "--jobs", "1", "--no-progress", cwd=tmp_path)
    assert again.returncode == 0 and "0 ok, 1 skipped" in again.stdout, again.stdout  # intact: skipped

    bad = bytearray(good)
    bad[len(bad) // 2] ^= 0xFF  # one byte flipped: same size, other content
    mp4.write_bytes(bytes(bad))
    r = run_user("batch", "p.toml", "--out", "out", "--jobs", "1", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0 and "1 ok, 0 skipped" in r.stdout, r.stdout + r.stderr
    assert not r.stderr.strip() and "Traceback" not in r.stderr, r.stderr
    redone = json.loads((mp4.parent / "metadata.json").read_text())["outputs_sha256"]["p.mp4"]
    assert mp4.read_bytes() != bytes(bad) and redone == hashlib.sha256(mp4.read_bytes()).hexdigest()


def test_a_render_killed_with_sigkill_leaves_parts_that_the_next_render_sweeps(tmp_path):
    slow = subprocess.Popen([sys.executable, "-m", "render", "render", "rigid_chaos", "--out", str(tmp_path),
                             "--no-progress", "--set", "video.width=320", "--set", "video.height=180",
                             "--name", "killed"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    target = tmp_path / "killed"  # named: the next render, with other --set, writes into the same folder
    deadline = time.time() + 120
    while len(list(target.glob(".*.part"))) < 2 and time.time() < deadline:  # MP4 and GIF under way
        time.sleep(0.05)
    slow.send_signal(signal.SIGKILL)
    slow.wait(timeout=30)
    left = list(target.glob(".*.part"))
    assert len(left) == 2, left  # what SIGKILL leaves: nothing could clean up

    r = run_user("render", "rigid_chaos", "--out", tmp_path, *TINY, "--name", "killed", cwd=tmp_path)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert not list(tmp_path.rglob("*.part")), list(tmp_path.rglob("*.part"))
    assert (target / "killed.mp4").stat().st_size > 0


def test_another_live_writers_parts_are_left_alone(tmp_path):
    """Only the temporaries of a dead process are swept: one of a live process (here: this one) stays."""
    from render.video import atomic

    mine = atomic.temp_beside(tmp_path / "x.mp4")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    stale = tmp_path / f".x.mp4.{atomic.HOST}-{dead}.abcdefgh.part"
    stale.write_bytes(b"left by a killed render")
    foreign = tmp_path / f".x.mp4.{'0' * 8 if atomic.HOST != '0' * 8 else '1' * 8}-1.abcdefgh.part"
    foreign.write_bytes(b"another host's live render")
    unrelated = tmp_path / ".x.mp4.notes.part"
    unrelated.write_bytes(b"not ours")
    assert atomic.sweep_stale(tmp_path) == [stale]
    assert mine.exists() and foreign.exists() and unrelated.exists() and not stale.exists()
    old = time.time() - atomic.FOREIGN_STALE_S - 60
    os.utime(foreign, (old, old))  # a week without a write: its host's render is long over
    assert atomic.sweep_stale(tmp_path) == [foreign]


# ------------------------------------------------------------------ no traceback from anywhere


def test_an_unexpected_error_is_one_line_and_debug_shows_the_traceback(tmp_path):
    """Taichi cannot start under 1 GiB of address space (it reserves 1 GiB): nobody's fault in the input,
    so exit 1 with one line; --debug and PENDULUM_DEBUG=1 add the traceback."""
    def tight():
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    args = ["render", "classic", "--out", "out", *TINY]
    r = run_cli(*args, cwd=tmp_path, timeout=60, preexec_fn=tight)
    line = one_line(r, 1, "unexpected error", "--debug")
    assert nothing_in(tmp_path / "out")
    for argv, env in ((["--debug", *args], None), ([*args, "--debug"], None),
                      (args, {**os.environ, "PENDULUM_DEBUG": "1"})):
        r = run_cli(*argv, cwd=tmp_path, timeout=60, preexec_fn=tight, env=env)
        assert r.returncode == 1 and "Traceback" in r.stderr and r.stderr.strip().splitlines()[-1] == line


def test_an_unwritable_kernel_cache_is_replaced_with_one_warning_not_a_crash(tmp_path):
    """Taichi 1.7.4 segfaults at exit where its cache folder cannot be made ($HOME read-only or missing): exit
    139 after the file was written. The run caches under the temporary folder instead and says so."""
    env = {k: v for k, v in os.environ.items() if k not in ("TI_OFFLINE_CACHE_FILE_PATH", "XDG_CACHE_HOME")}
    (tmp_path / "tmp").mkdir()
    env.update(HOME="/proc/no-such-home", TMPDIR=str(tmp_path / "tmp"))
    r = run_cli("simulate", "classic", "--out", tmp_path / "c.npz", *TINY, env=env)
    assert r.returncode == 0, (r.returncode, r.stderr)
    [line] = r.stderr.splitlines()
    assert line.startswith("warning: Taichi's kernel cache /proc/no-such-home/") and str(tmp_path / "tmp") in line
    assert (tmp_path / "c.npz").exists() and any((tmp_path / "tmp").iterdir())


def hiding(tmp_path, module: str) -> dict:
    """An environment in which `module` cannot be imported, as a partial install would lack it."""
    (tmp_path / "hide").mkdir()
    (tmp_path / "hide" / "sitecustomize.py").write_text(
        "import sys\n"
        "class Hide:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        f"        if name.partition('.')[0] == {module!r}:\n"
        "            raise ModuleNotFoundError(f'No module named {name!r}', name=name)\n"
        "sys.meta_path.insert(0, Hide())\n")
    return {**os.environ, "PYTHONPATH": str(tmp_path / "hide")}


@pytest.mark.parametrize("module, argv, need", [
    ("matplotlib", ["lyapunov", "classic", "--set", "video.duration=3", "--set", "video.fps=10"], "matplotlib"),
    ("distributed", ["render", "fractal_flip", "--tiles", "2", *TINY], "dask[distributed]")])
def test_a_missing_dependency_is_one_line_naming_what_to_install_and_leaves_no_folder(tmp_path, module, argv, need):
    """matplotlib, imported only where a chart is drawn: the spectrum is measured, then the chart fails, and the
    folders made for it go again. distributed, for tiles: dask raises an ImportError of its own about it."""
    r = run_cli(*argv, "--out", tmp_path / "out", "--no-progress", env=hiding(tmp_path, module))
    assert r.returncode == 1 and r.stderr.splitlines() == [
        f"pendulum: failed: this needs the Python package {need}, which is not installed here: "
        f"pip install '{need}'"], r.stderr
    assert not (tmp_path / "out").exists()  # nor the folders made for it
