"""Where presets are found: the user's folders first, then the presets that ship inside the package.

The search path, first match wins (so a user's `classic.toml` stands in for the shipped one):
1. each folder in $PENDULUM_PRESETS (os.pathsep-separated, like PATH);
2. `./presets/` in the current directory;
3. the shipped presets: `render/presets/` in an installed wheel, found through importlib.resources. The
   repository keeps one copy of them, the top-level `presets/`, mapped into the package at build time
   (pyproject.toml); an editable install maps no data folder into the package, so a source checkout reads
   that folder directly.
"""
from __future__ import annotations

import errno
import importlib.resources
import os
import stat
from pathlib import Path

from ..video.files import kind
from ..errors import SceneError
from .checks import hint

ENV = "PENDULUM_PRESETS"
# The most a preset file may hold. The largest shipped one is about 1 kB; a file over 1 MiB is no preset (a
# wrong path, a log, /dev/zero behind a link), and reading it whole would only fill memory.
PRESET_MAX_BYTES = 1 << 20


def shipped_dir() -> Path:
    """The presets that come with the package."""
    packaged = importlib.resources.files("render") / "presets"
    if packaged.is_dir():  # an installed wheel (always unpacked on disk, so this is a real Path)
        return Path(str(packaged))
    return Path(__file__).resolve().parents[2] / "presets"  # a source checkout: render/config/ -> the root


PRESET_DIR = shipped_dir()


def search_path() -> list[Path]:
    """The preset folders, in the order they are searched; each existing folder once. A folder that is not
    there is skipped, as PATH skips one; one that cannot be read (a symlink loop, no permission) or is a
    file is refused (SceneError), not skipped: the preset found instead would not be the one meant."""
    user = [Path(p) for p in os.environ.get(ENV, "").split(os.pathsep) if p]
    out, seen = [], set()
    for folder, what in [*((p, f"${ENV}: ") for p in user), (Path("presets"), ""), (PRESET_DIR, "")]:
        if not _there(folder, what, folder=True):
            continue
        key = folder.resolve()
        if key not in seen:  # in a checkout ./presets is the shipped folder itself
            seen.add(key)
            out.append(folder)
    return out


def _there(path: Path, what: str = "", folder: bool = False) -> bool:
    """Whether `path` exists (a folder, or a regular file); SceneError naming it and the OS's reason when it
    cannot be looked at or is the wrong kind. pathlib's is_dir() and is_file() say False to a symlink loop."""
    try:
        mode = path.stat().st_mode
    except (FileNotFoundError, NotADirectoryError):  # not there, or a file where a folder of its path is
        return False
    except OSError as e:
        raise SceneError(f"{what}{path}: {e.strerror or e}") from None
    if stat.S_ISDIR(mode) != folder:
        raise SceneError(f"{what}{path}: {os.strerror(errno.ENOTDIR if folder else errno.EISDIR)}")
    if not folder and not stat.S_ISREG(mode):  # a FIFO's read waits for a writer, a device's may never end
        raise SceneError(f"{what}{path}: {kind(mode)}, not a regular file")
    return True


def list_presets() -> list[Path]:
    """Every preset file, one per name (the first on the search path), sorted by name."""
    found: dict[str, Path] = {}
    for folder in search_path():
        for path in folder.glob("*.toml"):
            found.setdefault(path.stem, path)
    return [found[name] for name in sorted(found)]


def preset_path(ref: str) -> Path:
    """A preset name from the search path, or a path to a .toml file."""
    p = Path(ref)
    if p.suffix == ".toml" or "/" in ref:
        if not _there(p):
            raise SceneError(f"{ref}: preset file not found")
        return p
    for folder in search_path():
        cand = folder / f"{ref}.toml"
        if _there(cand):
            return cand
    names = [q.stem for q in list_presets()]
    raise SceneError(f"{ref}: no such preset{hint(ref, names)} (see 'pendulum presets')")
