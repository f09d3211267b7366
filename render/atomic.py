"""Files appear whole or not at all: write beside the target, rename onto it only on success."""
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path


def temp_beside(path: Path, suffix: str = ".part") -> Path:
    """A new, empty, hidden file in the same directory as `path` (so the final rename is atomic)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    return Path(tmp)


def publish(tmp: Path, path: Path):
    """Rename a finished temporary file onto its final path, readable like any other output."""
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


@contextmanager
def replacing(path: Path, suffix: str = ".part"):
    """Yield a temporary path beside `path`; publish it onto `path` if the block succeeds, else remove it."""
    tmp = temp_beside(path, suffix)
    try:
        yield tmp
        publish(tmp, Path(path))
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_atomic(path: Path, data: bytes | str):
    with replacing(path) as tmp:
        tmp.write_bytes(data.encode() if isinstance(data, str) else data)
