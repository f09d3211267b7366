"""Refusals that must come before any work, and run-time failures in the OS's words (issue 22's audit).

Each case runs the CLI as a user would, in a subprocess (conftest.run_cli), and asserts exit 2 with exactly one
line on stderr naming the file, key or path (and the OS's reason where there is one), no traceback, nothing
written. "Before any work" is checked on Taichi itself: each process gets its own Taichi offline cache
folder, which the first compiled kernel creates, so a refusal that came after the simulation leaves it there.

Tests run as root, whom permission bits do not stop: unwritable outputs are made with what stops root too
(chattr +i, a file where a folder must be, /proc), the full disk with a small tmpfs (mount, as root).
"""
import errno
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import sys
import threading
import time
from pathlib import Path

import pytest

from conftest import ROOT, immutable, run_cli
from render.commands.show import DISPLAY_TIMEOUT_S

SMALL = ["--set", "video.width=256", "--set", "video.height=144", "--set", "video.duration=1"]
PERM = os.strerror(errno.EPERM)  # "Operation not permitted"


def cli(tmp_path, *args, env=None, timeout=120):
    """run_cli in tmp_path with a Taichi cache of its own (tmp_path/ticache), which only a started Taichi makes."""
    env = {**os.environ, "TI_OFFLINE_CACHE_FILE_PATH": str(tmp_path / "ticache"), **(env or {})}
    return run_cli(*args, cwd=tmp_path, env=env, timeout=timeout)


def refused(r, tmp_path, *needles):
    """Exit 2, one line holding every needle, no traceback, nothing on stdout, and Taichi never compiled."""
    assert r.returncode == 2, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr and r.stdout == "", r.stderr
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    assert not (tmp_path / "ticache").exists(), "the refusal came after Taichi had started"
    return lines[0]


def tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.name != "ticache")


# ------------------------------------------------------------------ 1. the preset search path
def test_a_symlink_loop_on_the_preset_path_is_one_line(tmp_path):
    (tmp_path / "loop").symlink_to("loop")
    env = {"PENDULUM_PRESETS": str(tmp_path / "loop")}
    for args in (["render", "classic", *SMALL], ["presets"]):
        r = cli(tmp_path, *args, env=env)
        refused(r, tmp_path, "$PENDULUM_PRESETS", str(tmp_path / "loop"), os.strerror(errno.ELOOP))
    (tmp_path / "self.toml").symlink_to("self.toml")  # a preset file that is a loop
    refused(cli(tmp_path, "render", "self.toml"), tmp_path, "self.toml", os.strerror(errno.ELOOP))
    assert tree(tmp_path) == ["loop", "self.toml"]


def test_a_file_on_the_preset_path_is_refused_and_a_missing_folder_skipped(tmp_path):
    (tmp_path / "notes.txt").write_text("not a folder")
    r = cli(tmp_path, "render", "classic", env={"PENDULUM_PRESETS": str(tmp_path / "notes.txt")})
    refused(r, tmp_path, "$PENDULUM_PRESETS", "notes.txt", os.strerror(errno.ENOTDIR))
    r = cli(tmp_path, "presets", env={"PENDULUM_PRESETS": str(tmp_path / "not_there")})  # as PATH skips one
    assert r.returncode == 0 and "classic" in r.stdout, r.stderr


# ------------------------------------------------------------------ 2. compare into a file
def test_compare_into_an_out_whose_compare_is_a_file_is_refused_up_front(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "compare").write_text("a file where the comparisons' folder goes")
    r = cli(tmp_path, "compare", "rigid_chaos", "--vary", "integrator.precision=f32,f64", "--out", out, *SMALL)
    refused(r, tmp_path, f"--out {out}", f"{out / 'compare'} is a file", "rigid_chaos")
    assert tree(out) == ["compare"] and (out / "compare").read_text().startswith("a file")


def test_render_into_a_folder_that_is_a_symlink_out_of_out_is_refused_up_front(tmp_path):
    """OUT/NAME/ a symlink to a folder elsewhere: the render would write there, outside OUT."""
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "small").symlink_to(elsewhere)
    preset = tmp_path / "small.toml"  # the preset as written (no --set), so it renders into OUT/small/
    preset.write_text((ROOT / "presets" / "classic.toml").read_text().replace("duration = 20.0", "duration = 1.0"))
    r = cli(tmp_path, "render", preset, "--out", out)
    refused(r, tmp_path, f"--out {out}", f"{out / 'small'} is a symlink")
    assert tree(elsewhere) == [] and tree(out) == ["small"]



@pytest.mark.parametrize("command, folder, name", [
    (["render", "classic", "--name", "x"], "x", "metadata.json"),
    (["render", "classic", "--name", "x"], "x", "x.gif"),
    (["render", "fractal_flip", "--name", "x"], "x", "x.npz"),
    (["compare", "classic", "--vary", "integrator.precision=f32,f64", "--name", "x"], "compare/x", "metadata.json"),
    (["lyapunov", "classic", "--set", "video.duration=0.5"], "classic__5995f708", "lyapunov.json"),
])
def test_a_folder_where_an_output_file_goes_is_refused_up_front(tmp_path, command, folder, name):
    """A file is renamed onto its name when it is finished: onto a folder that fails, after all the work, with
    the outputs before it published. So it is bad input, refused before the work, and nothing is written."""
    out = tmp_path / "out"
    (out / folder / name).mkdir(parents=True)
    args = [*command, *(SMALL if command[0] != "lyapunov" else []), "--out", out]
    refused(cli(tmp_path, *args), tmp_path, str(out / folder / name), "is a folder")
    assert tree(out / folder) == [name]


def test_lyapunov_into_a_folder_that_is_a_symlink_out_of_out_is_refused_up_front(tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "classic").symlink_to(elsewhere)
    refused(cli(tmp_path, "lyapunov", "classic", "--out", out), tmp_path, f"{out / 'classic'} is a symlink")
    assert tree(elsewhere) == []



def test_a_bad_scheduler_from_the_environment_is_refused_before_the_first_render(tmp_path):
    """$DASK_SCHEDULER_ADDRESS tiles the maps of a `render`: checked, and named, before any preset renders (a
    fan before the map was rendered first); an empty --scheduler is refused, not taken as none."""
    out = tmp_path / "out"
    r = cli(tmp_path, "render", "classic", "fractal_flip", *SMALL, "--out", out,
            env={"DASK_SCHEDULER_ADDRESS": "tcp://host:abc"})
    refused(r, tmp_path, "$DASK_SCHEDULER_ADDRESS 'tcp://host:abc'", "expected an address")
    r = cli(tmp_path, "render", "fractal_flip", *SMALL, "--scheduler", "", "--out", out)
    refused(r, tmp_path, "--scheduler ''")
    for bare in ("localhost", "tcp://[::1]"):  # no port: Client failed after 20 s, with a traceback
        r = cli(tmp_path, "render", "fractal_flip", *SMALL, "--scheduler", bare, "--out", out)
        refused(r, tmp_path, f"--scheduler {bare!r}", "expected an address")
    r = cli(tmp_path, "render", "classic", *SMALL, "--out", "")
    assert r.returncode == 2 and "--out: must name a folder or file" in r.stderr, r.stderr
    assert not out.exists() and tree(tmp_path) == []


# ------------------------------------------------------------------ 3. outputs even root cannot write
def test_simulate_onto_an_immutable_file_is_refused_up_front(tmp_path):
    target = tmp_path / "t.npz"
    target.write_bytes(b"keep me")
    with immutable(target):
        r = cli(tmp_path, "simulate", "classic", "--out", target, *SMALL)
        refused(r, tmp_path, f"--out {target}", "cannot be replaced", PERM, "immutable")
    assert target.read_bytes() == b"keep me" and tree(tmp_path) == ["t.npz"]  # no temporary beside it


def test_render_onto_an_immutable_output_file_is_refused_up_front(tmp_path):
    folder = tmp_path / "out" / "classic"
    folder.mkdir(parents=True)
    (folder / "classic.gif").write_bytes(b"an older render")
    with immutable(folder / "classic.gif"):
        r = cli(tmp_path, "render", "classic", "--out", tmp_path / "out")
        refused(r, tmp_path, str(folder / "classic.gif"), "cannot be replaced", PERM)
    assert tree(tmp_path / "out") == ["classic", "classic/classic.gif"]


@pytest.mark.parametrize("where, needles", [
    ("immutable/t.npz", ["immutable", "cannot create a file there", PERM]),
    ("a_file/t.npz", ["a_file is a file"]),
    ("/proc/t.npz", ["/proc", "cannot create a file there"]),
    ("loop/t.npz", ["loop", os.strerror(errno.ELOOP)]),
], ids=["immutable-folder", "parent-is-a-file", "proc", "symlink-loop"])
def test_simulate_into_a_folder_root_cannot_write_is_refused_up_front(tmp_path, where, needles):
    (tmp_path / "immutable").mkdir()
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "loop").symlink_to("loop")
    before = tree(tmp_path)
    if where.startswith("immutable"):
        with immutable(tmp_path / "immutable"):
            r = cli(tmp_path, "simulate", "classic", "--out", where, *SMALL)
    else:
        r = cli(tmp_path, "simulate", "classic", "--out", where, *SMALL)
    refused(r, tmp_path, f"--out {where}", *needles)
    assert tree(tmp_path) == before


# ------------------------------------------------------------------ 4. a [compare] key given twice
PRESET = (ROOT / "presets" / "rigid_chaos.toml").read_text()


@pytest.mark.parametrize("table", [
    '[compare.vary]\n"integrator.dt" = [1e-3, 5e-4]\nintegrator.dt = [2e-3, 5e-4]\n',
    '[compare]\nvary = { "integrator.dt" = [1e-3, 5e-4], integrator.dt = [2e-3, 5e-4] }\n',
    '[compare.vary]\n"integrator.dt" = [1e-3, 5e-4]\n\n[compare.vary.integrator]\ndt = [2e-3, 5e-4]\n',
], ids=["quoted-and-dotted", "inline-table", "quoted-and-sub-table"])
def test_a_compare_key_given_twice_is_refused_naming_file_and_key(tmp_path, table):
    assert "[compare" not in PRESET
    (tmp_path / "twice.toml").write_text(f"{PRESET}\n{table}")
    r = cli(tmp_path, "render", "twice.toml", "--out", tmp_path / "out", *SMALL)
    refused(r, tmp_path, "twice.toml", "compare.vary.integrator.dt", "given twice")
    assert tree(tmp_path) == ["twice.toml"]


# ------------------------------------------------------------------ 5. a full disk while encoding
@pytest.fixture
def small_disk(tmp_path):
    """An 8 MB tmpfs at tmp_path/disk (as root); skips, saying why, where it cannot be mounted."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if shutil.which("mount") is None:
        pytest.skip("no mount command")
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=8m", "tmpfs", str(disk)], capture_output=True,
                          text=True)
    if made.returncode:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {made.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def fill(disk: Path):
    """Write zeros into disk/filler until the file system is full."""
    with open(disk / "filler", "wb") as f:
        try:
            while True:
                f.write(bytes(1 << 16))
                f.flush()
        except OSError as e:
            assert e.errno == errno.ENOSPC, e


def test_a_disk_filling_up_during_a_compare_says_the_os_reason_and_the_file(small_disk, tmp_path):
    """The budget sees room for the outputs; the disk fills once ffmpeg writes them (found by their hidden
    temporaries): exit 1, one line with the OS's reason and the file ffmpeg was writing, nothing left."""
    out = small_disk / "out"
    cmd = [sys.executable, "-m", "render", "compare", "rigid_chaos", "--vary", "integrator.precision=f32,f64",
           "--out", str(out), "--set", "video.width=256", "--set", "video.height=144", "--set", "video.fps=10",
           "--set", "video.duration=10", "--no-progress"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 240
        while len(list(out.glob("compare/*/.*.part"))) < 2 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.005)
        parts = list(out.glob("compare/*/.*.part"))
        assert len(parts) == 2, (parts, proc.poll())
        fill(small_disk)
        stdout, stderr = proc.communicate(timeout=240)
    finally:
        proc.kill()
    assert proc.returncode == 1, stderr
    lines = stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr and stdout == "", stderr
    folder = parts[0].parent
    named = [f"{folder / folder.name}.{fmt}" for fmt in ("mp4", "gif")]
    assert lines[0].startswith(f"pendulum: failed: {os.strerror(errno.ENOSPC)}: "), lines[0]
    assert lines[0].split(": ", 3)[3] in named, lines[0]
    assert "ffmpeg" not in lines[0]
    assert [p.name for p in small_disk.iterdir()] == ["filler"]  # no video, no temporary, no empty folder


# ------------------------------------------------------------------ 7. `show` on a display that never answers
class SilentX:
    """An X server that accepts connections on a free display and never says a word (Linux's abstract unix
    socket, where libX11 looks first: nothing is created on disk)."""

    def __init__(self):
        if not sys.platform.startswith("linux"):
            pytest.skip("abstract unix sockets are Linux's")
        for n in range(4217, 4317):
            self.sock = socket.socket(socket.AF_UNIX)
            try:
                if os.path.exists(f"/tmp/.X11-unix/X{n}"):
                    raise OSError("taken")
                self.sock.bind(f"\0/tmp/.X11-unix/X{n}")
                break
            except OSError:
                self.sock.close()
        else:
            pytest.skip("no free display number")
        self.display, self.held, self.accepted = f":{n}", [], threading.Event()
        self.sock.listen(4)
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.held.append(conn)  # kept open, never answered
            self.accepted.set()

    def close(self):
        self.sock.close()
        for conn in self.held:
            conn.close()


@pytest.fixture
def silent_x():
    server = SilentX()
    yield server
    server.close()


def show(tmp_path, display):
    env = {**os.environ, "DISPLAY": display, "TI_OFFLINE_CACHE_FILE_PATH": str(tmp_path / "ticache")}
    env.pop("WAYLAND_DISPLAY", None)
    return subprocess.Popen([sys.executable, "-m", "render", "show", "classic"], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_show_on_a_silent_display_exits_2_in_seconds(silent_x, tmp_path):
    proc = show(tmp_path, silent_x.display)
    try:
        assert silent_x.accepted.wait(120), "show never connected"
        t = time.monotonic()
        stdout, stderr = proc.communicate(timeout=DISPLAY_TIMEOUT_S + 10)
        waited = time.monotonic() - t
    finally:
        proc.kill()
    assert proc.returncode == 2, stderr
    assert DISPLAY_TIMEOUT_S - 1 < waited < DISPLAY_TIMEOUT_S + 5, waited
    lines = stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr and stdout == "", stderr
    assert silent_x.display in lines[0] and "did not answer" in lines[0] and "pendulum render classic" in lines[0]
    assert not (tmp_path / "ticache").exists()


def test_show_waiting_on_a_silent_display_honours_sigterm(silent_x, tmp_path):
    proc = show(tmp_path, silent_x.display)
    try:
        assert silent_x.accepted.wait(120), "show never connected"
        time.sleep(0.5)  # inside XOpenDisplay, waiting for the answer
        proc.send_signal(signal.SIGTERM)
        stdout, stderr = proc.communicate(timeout=3)
    finally:
        proc.kill()
    assert proc.returncode == 143, stderr
    assert len(stderr.splitlines()) == 1 and "terminated" in stderr and "Traceback" not in stderr, stderr


def test_show_refuses_the_thread_counts_render_refuses(tmp_path):
    for bad in ("0", "1025", "-2"):
        r = cli(tmp_path, "show", "classic", "--threads", bad, env={"DISPLAY": ":4216"})
        refused(r, tmp_path, "--threads", bad)


def test_a_sigterm_that_lands_in_a_finalizer_still_terminates_and_prints_nothing(tmp_path):
    """Python only prints an exception raised in a __del__ (llvmlite's, during a bench) and goes on: the SIGTERM
    was lost and a traceback printed. cli.on_signals sends it again, outside the finalizer."""
    code = """if True:
        import os, signal, time
        from render.commands import cli
        cli.on_signals()
        class Finalized:
            def __del__(self):
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.01)  # the handler raises here, inside the finalizer
        try:
            x = Finalized()
            del x
            time.sleep(2)
            print("not terminated")
        except cli.Terminated:
            print("terminated")
    """
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.stdout.strip() == "terminated" and r.stderr == "", (r.stdout, r.stderr)



@pytest.mark.parametrize("sig, code, said", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_a_signal_whose_exception_is_swallowed_or_replaced_is_still_the_one_reported(sig, code, said):
    """Ctrl-C while Taichi decorates a kernel, or while numpy views an mmap, came out as "unexpected error:
    TaichiSyntaxError ..." or "BufferError ...", exit 1, or was lost and the run ended 0. The signal is the
    cause: main() reports it, whatever it turned into on the way out."""
    code_text = f"""if True:
        import os, signal, sys
        from render.commands import cli
        from render.video import pipeline

        def render(*a, **k):
            try:
                os.kill(os.getpid(), {int(sig)})
            except BaseException:
                raise RuntimeError("cannot close exported pointers exist")  # as an mmap's close said
        pipeline.render = render
        sys.exit(cli.main(["render", "classic", "--out", sys.argv[1], "--no-progress"]))
    """
    for variant in (code_text, code_text.replace('raise RuntimeError("cannot close exported pointers exist")',
                                                 "pass  # swallowed")):
        with tempfile.TemporaryDirectory() as out:
            r = subprocess.run([sys.executable, "-c", variant, out], cwd=ROOT, capture_output=True, text=True,
                               timeout=120)
        assert r.returncode == code and r.stderr.strip().splitlines() == [f"pendulum: {said}; no partial output "
                                                                          f"was left"], r.stderr
