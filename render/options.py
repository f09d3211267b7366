"""What several commands share on their command line: common options and the output-directory probe."""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from .errors import SceneError
from .quality import LEVELS


def add_common(p):
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a preset key, dotted, value in TOML (e.g. --set integrator.dt=1e-4); repeatable")
    p.add_argument("--arch", choices=("cpu", "cuda"), default="cpu",
                   help="Taichi backend; cuda falls back to the CPU with a warning where there is none")


def add_quality(p):
    p.add_argument("--quality", choices=LEVELS,
                   help="a guarantee instead of the preset's integrator: the median pendulum stays faithful for "
                        "50 %% (draft), 75 %% (standard) or 100 %% (high) of the video, met by the cheapest setting "
                        "that pilot runs show meets it; reference: the finest step")


def check_writable(path: Path, what: str = "--out"):
    """Bad input if the output cannot be created; checked before any work so nothing is half-written."""
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
