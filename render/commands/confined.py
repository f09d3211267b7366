"""Reading what an output root holds as untrusted input: never outside it, never blocking, never without end.

Whoever could write into OUT wrote its metadata.json files, so the gallery and `batch`'s up-to-date test take
nothing there on trust. A metadata.json may be a FIFO (a plain open blocks until a writer comes), a symlink to
/dev/zero (a read without end) or to a file outside OUT, 100000 lists deep (json raises RecursionError) or a
list where a dict belongs; its `outputs` may name `../../x.mp4` or an absolute path; a render folder may be a
symlink out of OUT. So nothing here follows a symlink: a folder is taken only when lstat finds a real directory
at every step below the root, a file only when it is a regular one, opened with O_NOFOLLOW | O_NONBLOCK and
checked with fstat before a byte is read, and a file name from metadata only when it is one plain name in its
own folder. Whatever is refused raises Refused, whose message says why in a few words, for the card that
shows it (render/commands/gallery.py). A preset is read the same way (render/video/files.py), symlinks
followed: a user's preset may be a link, but a FIFO or /dev/zero given as one must not hang the command or fill
memory.
"""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path

from ..video.files import Refused, kind, read_regular

META_MAX_BYTES = 1 << 20  # 1 MiB; a render's metadata.json is a few kB (a histogram replaces long per-pendulum lists)
INT_DIGITS_MAX = 18  # every count and byte size a render records fits in int64; 10**400 fits no float
# The sections a card reads, each an object when present (metadata from older versions may lack some); those in
# NULLABLE may be null too: "energy" is, wherever the energy effect is off, as on every map.
SECTIONS = ("preset", "integrator", "energy", "timings_s", "versions", "faithfulness", "outputs", "outputs_sha256")
NULLABLE = ("energy",)


def folder(root: Path, path: Path) -> Path:
    """`path` (below `root`), when each step from `root` down is a real directory, not a symlink that may
    lead out of it; FileNotFoundError when one is missing."""
    here = Path(root)
    for part in Path(path).relative_to(root).parts:
        here = here / part
        mode = os.lstat(here).st_mode
        if stat.S_ISLNK(mode):
            raise Refused(f"{here.name} is a symlink (to {_short(os.readlink(here))}), and only what is inside "
                          f"the output folder is read")
        if not stat.S_ISDIR(mode):
            raise Refused(f"{here.name} is {kind(mode)}, not a folder")
    return Path(path)


def member(where: Path, name) -> Path | None:
    """where/name for a file name taken from metadata: one plain name (no '/', not '..') of a regular file
    there (not a symlink, FIFO or device); None when no such file is there."""
    if not isinstance(name, str) or name in ("", ".", "..") or "/" in name or "\0" in name:
        raise Refused(f"outputs names {_short(name)!r}, which is not a file in its own folder")
    path = Path(where) / name
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None  # deleted since the render: the card shows what is left
    except OSError as e:  # e.g. a name over the file system's 255 bytes
        raise Refused(f"outputs {_short(name)!r}: {e.strerror}") from None
    if not stat.S_ISREG(mode):
        raise Refused(f"outputs {_short(name)!r} is {kind(mode)}, not a regular file")
    return path


def read_json(path: Path):
    """The parsed JSON of `path`, a regular file of at most META_MAX_BYTES; Refused otherwise (OSError
    when it cannot be opened at all)."""
    path = Path(path)
    try:
        data = read_regular(path, META_MAX_BYTES, follow=False)
    except Refused as e:
        raise Refused(f"{path.name} is {e}") from None
    except OSError:
        if os.path.islink(path):  # O_NOFOLLOW's ELOOP
            raise Refused(f"{path.name} is a symlink (to {_short(os.readlink(path))}), not a file") from None
        raise
    try:
        return json.loads(data, parse_int=_int)
    except RecursionError:
        raise Refused(f"{path.name} is nested too deeply to parse") from None
    except ValueError as e:  # UnicodeDecodeError included
        raise Refused(f"{path.name} does not parse: {_short(str(e))}") from None


def metadata(where: Path) -> tuple[dict, dict[str, Path]]:
    """A render folder's metadata (its SECTIONS objects, or null where NULLABLE) and its outputs that are still there
    (name -> path, each checked by member)."""
    meta = read_json(Path(where) / "metadata.json")
    if not isinstance(meta, dict):
        raise Refused(f"metadata.json holds {_json_kind(meta)}, not an object")
    for key in SECTIONS:
        if key in meta and not isinstance(meta[key], dict) and not (key in NULLABLE and meta[key] is None):
            raise Refused(f"metadata.json: {key} is {_json_kind(meta[key])}, not an object"
                          f"{' or null' if key in NULLABLE else ''}")
    outputs = meta.get("outputs", {})
    for name, size in outputs.items():
        if not isinstance(size, int) or isinstance(size, bool) or size < 0:
            what = f"{size}" if isinstance(size, int) and not isinstance(size, bool) else _json_kind(size)
            raise Refused(f"metadata.json: outputs {_short(name)!r} has {what} where its size in bytes belongs")
    files = {name: path for name in outputs if (path := member(where, name)) is not None}
    return meta, files


def _int(text: str) -> int:
    if len(text.lstrip("-")) > INT_DIGITS_MAX:
        raise ValueError(f"an integer of {len(text.lstrip('-'))} digits, more than any count or size")
    return int(text)


def _json_kind(value) -> str:
    if isinstance(value, bool) or value is None:
        return "true, false or null"
    return {dict: "an object", list: "a list", str: "a string"}.get(type(value), "a number")


def _short(text, most: int = 60) -> str:
    text = str(text)
    return text if len(text) <= most else text[:most - 3] + "..."
