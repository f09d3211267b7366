"""What several commands share on their command line: common options, their value types and the
output probes. The Python API (render/commands/api.py) checks its arguments with the same functions."""
from __future__ import annotations

import argparse
import errno
import numbers
import os
import re
import stat
import struct
import sys
import tempfile
from pathlib import Path

try:
    import fcntl
except ImportError:  # not POSIX
    fcntl = None

from ..errors import SceneError
from ..physics.keys import BUDGET_MAX, BUDGET_MIN, seconds
from ..trust.levels import LEVELS

ARCHES = ("cpu", "cuda")  # runtime.init's backends (never ti.gpu)

# Taichi starts one OS thread per thread asked for: 4096 started in under a second here, 100000 hung.
# Beyond 1024 a CPU render only oversubscribes the cores.
MAX_THREADS = 1024


def add_common(p):
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a preset key, dotted, value in TOML (e.g. --set integrator.dt=1e-4); repeatable")
    p.add_argument("--arch", choices=ARCHES, default="cpu",
                   help="Taichi backend; cuda falls back to the CPU with a warning where there is none")


def add_render_options(p):
    """What `render` and `compare` share after the preset: --set/--arch, --out, --name, --quality, --budget,
    --threads and --no-progress."""
    add_common(p)
    p.add_argument("--out", type=out_path, default=Path("out"), help="output root (default: out)")
    add_name(p)
    add_quality(p)
    add_budget(p)
    p.add_argument("--threads", type=thread_count, default=None, help="CPU threads for Taichi (default: all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def add_tiles(p):
    """`render`'s map in tiles over a Dask cluster (render/video/tiled.py)."""
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="render a map in tiles on this Dask scheduler, e.g. tcp://host:8786 (default for a map: "
                        "$DASK_SCHEDULER_ADDRESS); byte-identical to the local render")
    p.add_argument("--tiles", type=positive_int, metavar="N",
                   help="split a map into N bands of rows; without --scheduler, rendered on a local cluster of N "
                        "worker processes, at most one a core (default with --scheduler: one band per worker thread)")


def add_quality(p):
    p.add_argument("--quality", choices=LEVELS,
                   help="a guarantee instead of the preset's integrator: the median pendulum stays faithful for "
                        "50 %% (draft), 75 %% (standard) or 100 %% (high) of the video, met by the cheapest setting "
                        "that pilot runs show meets it; reference: the finest step")


def add_budget(p):
    p.add_argument("--budget", type=budget_seconds, metavar="TIME",
                   help="the longest the run may be estimated to take, in seconds or e.g. 90min or 2h (default: the "
                        "preset's budget key, or 1 h); a run estimated longer is refused before it starts")


def budget_seconds(text: str) -> float:
    """An argparse type: a run-time budget, as the preset's `budget` key takes it (render/physics/keys.py)."""
    secs = seconds(text)
    if secs is None or not BUDGET_MIN <= secs <= BUDGET_MAX:
        raise argparse.ArgumentTypeError(f"must be seconds or a duration such as 90min or 2h, from {BUDGET_MIN:g} s to "
                                         f"{BUDGET_MAX / 3600:g} h, got {text[:40]!r}")
    return secs


def budgeted(scene, args):
    """The scene under the --budget given (its own budget key otherwise)."""
    return scene if getattr(args, "budget", None) is None else scene.replace(budget=args.budget)


def add_name(p):
    p.add_argument("--name", type=folder_name, metavar="NAME2",
                   help="the output folder's name (and the files'), instead of NAME, or NAME__<hash> with "
                        "--set or --quality")


def folder_name(text: str) -> str:
    """An argparse type: a name a scene may have (limits.py), so it is safe as a folder and file name."""
    from .limits import NAME_MAX, NAME_PATTERN, RESERVED_NAMES

    if not re.fullmatch(NAME_PATTERN, text) or len(text) > NAME_MAX:
        raise argparse.ArgumentTypeError(f"must be letters, digits, _ . - (not first . or -), at most {NAME_MAX} "
                                         f"characters, got {text[:40]!r}")
    if text in RESERVED_NAMES:
        raise argparse.ArgumentTypeError(f"{text!r} is what OUT itself holds ({', '.join(RESERVED_NAMES)}): "
                                         f"choose another")
    return text


HASH_CHARS = 8  # of the resolved scene's hash in an override folder's name


def output_name(scene, overridden: bool, name: str | None = None):
    """The scene under the name of the folder it renders to. OUT/NAME/ is only ever the preset as written:
    with overrides (--set, --quality) the folder is NAME__<short hash of the resolved scene>, the same for
    the same result however the overrides were spelled, unless --name gives it a name."""
    from .limits import NAME_MAX

    if name is not None:
        if overridden and name == scene.name:
            raise SceneError(f"--name {name}: is the folder of the preset as written; name the render with "
                             f"overrides otherwise")
        return scene.replace(name=name)
    if not overridden:
        return scene
    return scene.replace(name=f"{scene.name[:NAME_MAX - HASH_CHARS - 2]}__{scene.hash()[:HASH_CHARS]}")


def positive_int(text: str, most: int | None = None) -> int:
    """An argparse type: an integer >= 1 (and <= most); anything else is a usage error (exit 2)."""
    text = text.strip()
    digits = text.isascii() and text.isdigit() and len(text) <= 18  # int() of thousands of digits is refused
    if not digits or int(text) < 1 or (most is not None and int(text) > most):
        limit = f" up to {most}" if most is not None else ""
        raise argparse.ArgumentTypeError(f"must be a positive integer{limit}, got {text[:40]!r}")
    return int(text)


def thread_count(text: str) -> int:
    return positive_int(text, MAX_THREADS)


def out_path(text: str) -> Path:
    """An argparse type for --out: a path, never an empty one, which an unset shell variable gives and which
    would quietly mean the current folder ('.' says so)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must name a folder or file, got an empty string ('.' is the current "
                                         "folder)")
    return Path(text)


def check_out(out, what: str = "out") -> Path:
    """The API's out=: a path (str or os.PathLike), not empty; SceneError otherwise."""
    if not isinstance(out, (str, os.PathLike)) or not str(os.fspath(out)).strip():
        raise SceneError(f"{what}={out!r}: must name a folder or file (a str or a path; '.' is the current folder)")
    if "\0" in str(os.fspath(out)):
        raise SceneError(f"{what}={str(os.fspath(out))!r}: a path cannot contain a NUL character")
    return Path(out)


def check_arch(arch) -> str:
    """The API's arch=: what --arch accepts (SceneError otherwise)."""
    from .checks import clip

    if not isinstance(arch, str) or arch not in ARCHES:
        raise SceneError(f"arch={clip(repr(arch))}: must be one of {', '.join(ARCHES)}")
    return arch


def usable_cores() -> int:
    """The cores this process may run on (its affinity, where the OS says), for sizing workers."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def check_tiles(tiles) -> int | None:
    """The API's tiles=: None or what --tiles accepts (SceneError otherwise)."""
    from .checks import clip

    if tiles is None:
        return None
    if isinstance(tiles, bool) or not isinstance(tiles, numbers.Integral) or tiles < 1:
        raise SceneError(f"tiles={clip(repr(tiles))}: must be a positive integer, or None")
    return int(tiles)


def check_threads(threads) -> int | None:
    """The API's threads=: None (all cores) or what --threads accepts (SceneError otherwise)."""
    from .checks import clip

    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise SceneError(f"threads={clip(repr(threads))}: must be an integer from 1 to {MAX_THREADS}, or None for "
                         f"all cores")
    try:
        return thread_count(str(int(threads)))
    except argparse.ArgumentTypeError as e:
        raise SceneError(f"threads={clip(repr(threads))}: {e}") from None


def check_writable(path: Path, what: str = "--out"):
    """Bad input if the output cannot be created; checked before any work so nothing is half-written."""
    if "\0" in str(path):  # no file system takes it; pathlib would only fail later, in mkdir
        raise SceneError(f"{what} {str(path)!r}: a path cannot contain a NUL character")
    probe = path
    while not probe.exists():
        if probe.is_symlink():  # a link to nothing, or a loop: no folder can be made there
            try:
                os.stat(probe)
            except OSError as e:
                raise SceneError(f"{what} {path}: not a writable directory ({probe} -> {os.readlink(probe)}: "
                                 f"{e.strerror or e})") from None
        probe = probe.parent
    if not probe.is_dir():
        raise SceneError(f"{what} {path}: not a writable directory ({probe} is a file)")
    try:
        tempfile.TemporaryFile(dir=probe).close()  # os.access says yes to root even where writing fails
    except OSError as e:
        raise SceneError(f"{what} {path}: not a writable directory ({probe}: cannot create a file there: "
                         f"{e.strerror or e})") from None


def check_out_folder(scene, out: Path, files: tuple[str, ...] | None = None):
    """Bad input before any work: OUT cannot be written, the scene's folder there (OUT/NAME/, a comparison's
    OUT/compare/NAME/) or OUT/compare/ is a file, a symlink or cannot be written, or an output file in it (a
    render's, or `files`) cannot be replaced. Each would fail only after the simulation."""
    check_writable(out)
    folder = scene.out_dir(out)
    for above in (folder, folder.parent):
        if above != out and above.is_symlink():  # it may lead out of OUT, and a run writes only inside OUT
            raise SceneError(f"--out {out}: {above} is a symlink; {scene.name} renders only inside {out}{os.sep}")
        if above != out and above.exists() and not above.is_dir():
            raise SceneError(f"--out {out}: {above} is a file; {scene.name} renders into {folder}{os.sep}")
    check_writable(folder)  # e.g. an immutable OUT/NAME/
    if files is None:  # a render's: its videos and still, a map's data, its metadata
        files = (*(f"{scene.name}.{fmt}" for fmt in scene.video.formats), *([f"{scene.name}.npz"] if scene.fractal
                                                                            else []), "metadata.json")
    for name in files:
        check_replaceable(folder / name)


def check_npz(out: Path, name: str) -> None:
    """Refuse (SceneError) a trajectory file that cannot be written, before any work."""
    if out.suffix != ".npz":
        raise SceneError(f"--out {out}: must end in .npz")
    if out.is_dir():
        raise SceneError(f"--out {out}: is a directory; give the file to write, e.g. {out / name}.npz")
    check_writable(out.parent, f"--out {out}: its folder")
    check_replaceable(out)


def check_replaceable(path: Path, what: str = "--out"):
    """Bad input if `path` is a folder, or a file that is there and cannot be replaced by renaming a finished
    file onto it (render/video/atomic.py), which would fail only after the work. Even root cannot replace an
    immutable or append-only file (chattr +i, +a); no one but its owner, the folder's or root one in a sticky
    folder."""
    try:
        st, folder = os.lstat(path), os.stat(Path(path).parent)
    except OSError:
        return  # not there: check_writable judges its folder
    why = None
    if stat.S_ISDIR(st.st_mode):  # a file is renamed onto its name: never onto a folder
        raise SceneError(f"{what} {path}: is a folder, where a file of that name is written; move it away")
    if _pinned(path, st):
        why = "the file is immutable or append-only; lsattr shows which"
    elif folder.st_mode & stat.S_ISVTX and os.geteuid() not in (0, st.st_uid, folder.st_uid):
        why = "another user's file in a sticky folder"
    if why:
        raise SceneError(f"{what} {path}: cannot be replaced: {os.strerror(errno.EPERM)} ({why})")


# Linux's FS_IOC_GETFLAGS, _IOR('f', 1, long), and the flags of chattr's +i and +a.
FS_IOC_GETFLAGS = 2 << 30 | struct.calcsize("l") << 16 | ord("f") << 8 | 1
FS_IMMUTABLE_FL, FS_APPEND_FL = 0x10, 0x20


def _pinned(path: Path, st: os.stat_result) -> bool:
    """Whether a file is immutable or append-only: st_flags on BSD and macOS, the inode's flags on Linux."""
    flags = getattr(st, "st_flags", None)
    if flags is not None:
        return bool(flags & (stat.UF_IMMUTABLE | stat.UF_APPEND | stat.SF_IMMUTABLE | stat.SF_APPEND))
    if not sys.platform.startswith("linux") or not stat.S_ISREG(st.st_mode):
        return False  # a symlink is replaced itself, whatever it points to
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        flags = int.from_bytes(fcntl.ioctl(fd, FS_IOC_GETFLAGS, bytes(8))[:4], sys.byteorder)
    except OSError:  # a file system without inode flags
        return False
    finally:
        os.close(fd)
    return bool(flags & (FS_IMMUTABLE_FL | FS_APPEND_FL))


def progress_wanted(args) -> bool:
    return not args.no_progress and sys.stderr.isatty()
