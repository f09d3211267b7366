"""What several commands share on their command line: common options, their value types and the
output-directory probe."""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

from .errors import SceneError
from .quality import LEVELS
from .validate import NAME_MAX, NAME_PATTERN

# Taichi starts one OS thread per thread asked for: 4096 started in under a second here, 100000 hung.
# Beyond 1024 a CPU render only oversubscribes the cores.
MAX_THREADS = 1024


def add_common(p):
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a preset key, dotted, value in TOML (e.g. --set integrator.dt=1e-4); repeatable")
    p.add_argument("--arch", choices=("cpu", "cuda"), default="cpu",
                   help="Taichi backend; cuda falls back to the CPU with a warning where there is none")


def add_render_options(p):
    """What `render` and `compare` share after the preset: --set/--arch, --out, --name, --quality, --threads
    and --no-progress."""
    add_common(p)
    p.add_argument("--out", type=Path, default=Path("out"), help="output root (default: out)")
    add_name(p)
    add_quality(p)
    p.add_argument("--threads", type=thread_count, default=None, help="CPU threads for Taichi (default: all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def add_quality(p):
    p.add_argument("--quality", choices=LEVELS,
                   help="a guarantee instead of the preset's integrator: the median pendulum stays faithful for "
                        "50 %% (draft), 75 %% (standard) or 100 %% (high) of the video, met by the cheapest setting "
                        "that pilot runs show meets it; reference: the finest step")


def add_name(p):
    p.add_argument("--name", type=folder_name, metavar="NAME2",
                   help="the output folder's name (and the files'), instead of NAME, or NAME__<hash> with "
                        "--set or --quality")


def folder_name(text: str) -> str:
    """An argparse type: a name a scene may have (validate.py), so it is safe as a folder and file name."""
    if not re.fullmatch(NAME_PATTERN, text) or len(text) > NAME_MAX:
        raise argparse.ArgumentTypeError(f"must be letters, digits, _ . - (not first . or -), at most {NAME_MAX} "
                                         f"characters, got {text[:40]!r}")
    return text


HASH_CHARS = 8  # of the resolved scene's hash in an override folder's name


def output_name(scene, overridden: bool, name: str | None = None):
    """The scene under the name of the folder it renders to. OUT/NAME/ is only ever the preset as written:
    with overrides (--set, --quality) the folder is NAME__<short hash of the resolved scene>, the same for
    the same result however the overrides were spelled, unless --name gives it a name."""
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


def check_writable(path: Path, what: str = "--out"):
    """Bad input if the output cannot be created; checked before any work so nothing is half-written."""
    if "\0" in str(path):  # no file system takes it; pathlib would only fail later, in mkdir
        raise SceneError(f"{what} {str(path)!r}: a path cannot contain a NUL character")
    probe = path
    while not probe.exists():
        probe = probe.parent
    try:
        if not probe.is_dir():
            raise NotADirectoryError(probe)
        tempfile.TemporaryFile(dir=probe).close()  # os.access says yes to root even where writing fails
    except OSError:
        raise SceneError(f"{what} {path}: not a writable directory ({probe})") from None


def progress_wanted(args) -> bool:
    return not args.no_progress and sys.stderr.isatty()
