"""Reading a file the user names, or that an output folder holds, without trusting what it is: only a regular
file is read, never past a size cap, and opening it never blocks (a FIFO given as a preset hung the command,
/dev/zero filled the machine's memory). Presets are read this way (render/config/scene.py, catalog.py), and the
output folder's metadata.json files (render/commands/confined.py, which adds what it takes from them;
render/video/pipeline.py's superseded()). It sits beside atomic.py, which writes them, below every layer that reads.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path


class Refused(ValueError):
    """A file, or a folder under OUT, that is not read; the message says why."""


def read_regular(path: Path, limit: int, follow: bool = True) -> bytes:
    """The bytes of `path`, a regular file of at most `limit` bytes; Refused otherwise, its message what the
    file is ("a FIFO, not a regular file") for the caller to put after the file's name; OSError when it cannot
    be opened at all. With follow=False a symlink is not opened (OSError ELOOP)."""
    flags = os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC | (0 if follow else os.O_NOFOLLOW)
    fd = os.open(path, flags)  # O_NONBLOCK: opening a FIFO returns at once instead of waiting for a writer
    try:
        st = os.fstat(fd)  # of what was opened: a file swapped in after a stat of the path is still caught
        if not stat.S_ISREG(st.st_mode):
            raise Refused(f"{kind(st.st_mode)}, not a regular file")
        if st.st_size > limit:
            raise Refused(f"{st.st_size} bytes, over the {limit}-byte limit")
        chunks, size = [], 0  # read to the end, one byte past the cap at most: it may have grown since fstat
        while size <= limit and (chunk := os.read(fd, limit + 1 - size)):
            chunks.append(chunk)
            size += len(chunk)
    finally:
        os.close(fd)
    if size > limit:
        raise Refused(f"over the {limit}-byte limit")
    return b"".join(chunks)


def kind(mode: int) -> str:
    kinds = {stat.S_ISDIR: "a folder", stat.S_ISFIFO: "a FIFO", stat.S_ISCHR: "a device", stat.S_ISBLK: "a device",
             stat.S_ISSOCK: "a socket", stat.S_ISLNK: "a symlink", stat.S_ISREG: "a file"}
    return next((what for test, what in kinds.items() if test(mode)), "not a file")
