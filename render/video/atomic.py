"""Files appear whole or not at all: write beside the target, rename onto it only on success.

A temporary file is hidden and names its owner: .NAME.<host>-<pid>.<random>.part, where <host> is a short
hash of the host name. A process killed with SIGKILL cannot remove its temporaries, so whoever next writes
into that folder sweeps the ones whose owner is gone (sweep_stale): on this host, a process that no longer
exists; from another host sharing the folder (a Dask cluster), where liveness cannot be seen from here,
only after FOREIGN_STALE_S without a write. A live writer's file is never touched, and neither is a folder
reached through a symlink at its end: that may lead out of the output folder, to files not ours to judge.
"""
import contextlib
import contextvars
import errno
import hashlib
import os
import re
import signal
import socket
import tempfile
import threading
import time
import zlib
from contextlib import contextmanager
from pathlib import Path

FOREIGN_STALE_S = 7 * 24 * 3600  # a week: far longer than any render the step budget lets start
HOST = f"{zlib.crc32(socket.gethostname().encode()):08x}"
SUFFIXES = (".part", ".jpg", ".npz")  # the temporaries this package makes (a poster, a trajectory: their writers' own)
# What temp_beside creates, exactly: mkstemp's 8 characters and one of SUFFIXES. A looser pattern took a user's
# own .db.deadbeef-1.snap.gz for a dead writer's temporary and removed it.
_OWNED = re.compile(r"\..+\.([0-9a-f]{8})-(\d+)\.[a-z0-9_]{8}(?:%s)" % "|".join(map(re.escape, SUFFIXES)))


def temp_beside(path: Path, suffix: str = ".part") -> Path:
    """A new, empty, hidden file in the same directory as `path` (so the final rename is atomic); stale
    temporaries of dead writers in that directory are swept first."""
    path = Path(path)
    if suffix not in SUFFIXES:
        raise ValueError(f"temp_beside: suffix {suffix!r} is not one the sweeper knows ({', '.join(SUFFIXES)})")
    sweep_stale(path.parent)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{HOST}-{os.getpid()}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    return Path(tmp)


def sweep_stale(folder: Path) -> list[Path]:
    """Remove the temporaries in `folder` whose writer is gone; returns what was removed."""
    removed = []
    try:
        if os.path.islink(folder):
            return removed
        with os.scandir(folder) as it:
            entries = list(it)
    except OSError:
        return removed  # a folder not there yet holds nothing to sweep
    for entry in entries:
        m = _OWNED.fullmatch(entry.name)
        if not m or not entry.is_file(follow_symlinks=False):
            continue
        host, pid = m.group(1), int(m.group(2))
        try:
            if host == HOST:
                stale = not _alive(pid)
            else:
                stale = time.time() - entry.stat(follow_symlinks=False).st_mtime > FOREIGN_STALE_S
            if stale:
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            pass  # gone already (another sweeper), or not ours to remove: leave it
    return removed


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)  # signal 0: only asks whether the process exists
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True  # exists, owned by someone else (or a pid no process can have: be careful, keep it)
    return True


def discard(path: Path):
    """Remove a file of ours while cleaning up after a failure: if that fails too (a folder made unwritable
    meanwhile), the failure being cleaned up after is still the one reported, and the cleanup goes on."""
    with contextlib.suppress(OSError):
        Path(path).unlink(missing_ok=True)


def publish(tmp: Path, path: Path):
    """Rename a finished temporary file onto its final path, readable like any other output."""
    try:
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError as e:  # name the file the user asked for, not our hidden temporary
        raise OSError(e.errno, e.strerror, str(path)) from e


def publish_all(pairs: list[tuple[Path, Path]]):
    """Rename each finished temporary onto its final path, all of them or none: a render's videos, data and
    metadata.json are one result. A final file already there (an earlier run's) is first kept under a hidden
    hard link, and put back if a later rename fails, so a failure leaves the earlier result whole, never half of
    each; without hard links (a file system that has none) a failure leaves none of the files it replaced.
    SIGINT, SIGTERM and SIGHUP that arrive meanwhile are acted on when the renames are done (signals_held). On
    a failure every temporary not yet renamed is removed too."""
    with signals_held():
        kept: list[Path | None] = []
        done = 0
        try:
            for _, path in pairs:
                kept.append(_keep(path))
            for tmp, path in pairs:
                publish(tmp, path)
                done += 1
        except BaseException:
            for (_, path), old in zip(pairs[:done], kept):  # put the earlier result back, or none of this one
                if old is None:
                    discard(path)
                else:
                    with contextlib.suppress(OSError):
                        os.replace(old, path)
            for waiting, _ in pairs[done:]:
                discard(waiting)
            raise
        finally:
            for old in kept:
                if old is not None:
                    discard(old)


def _keep(path: Path) -> Path | None:
    """A hidden hard link to the file at `path`, if there is one (swept like a temporary if we die)."""
    if not path.is_file() or path.is_symlink():
        return None
    link = temp_beside(path)
    try:
        link.unlink()
        os.link(path, link)
    except OSError:
        discard(link)
        return None
    return link


@contextmanager
def signals_held():
    """SIGINT, SIGTERM and SIGHUP arriving within the block are delivered when it ends, so that a run of renames is
    never cut in two. Only the main thread can set handlers: elsewhere the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    for s in before:
        signal.signal(s, lambda sig, frame: caught.append(sig))
    try:
        yield
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)
        if caught:
            signal.raise_signal(caught[0])  # as it would have come: its handler (KeyboardInterrupt, ...) runs now


# The files finished within together()'s block, (temporary, final), in this thread or task; None outside one.
_held: contextvars.ContextVar[list | None] = contextvars.ContextVar("held", default=None)


@contextmanager
def replacing(path: Path, suffix: str = ".part"):
    """Yield a temporary path beside `path`; publish it onto `path` if the block succeeds (within together(),
    when together()'s block does), else remove it."""
    tmp = temp_beside(path, suffix)
    try:
        with naming(path):
            yield tmp
        held = _held.get()
        if held is None:
            publish(tmp, Path(path))
        else:
            held.append((tmp, Path(path)))
    except BaseException:
        discard(tmp)
        raise


@contextmanager
def naming(path: Path):
    """An OSError in the block that names no file (a write to an open file, on a full disk) names `path`, the
    file the user asked for, and not our hidden temporary."""
    try:
        yield
    except OSError as e:
        if e.filename is None:
            raise OSError(e.errno, e.strerror, str(path)) from e
        raise


@contextmanager
def output_dir(path: Path):
    """Make the folder (with its missing parents); if the block fails, remove again what was made here and is
    left empty: a failed or interrupted command leaves no empty folder behind."""
    made = []  # the folders made here, the deepest first
    here = Path(path)
    while not os.path.lexists(here):
        made.append(here)
        here = here.parent
    Path(path).mkdir(parents=True, exist_ok=True)
    try:
        yield Path(path)
    except BaseException:
        for folder in made:
            with contextlib.suppress(OSError):  # not empty: something else was put there meanwhile
                folder.rmdir()
        raise


@contextmanager
def together(folder: Path | None = None):
    """A command's files appear together or not at all: within the block, each file replacing() and
    write_atomic() finish stays in its temporary; all are published, in the order written, when the block
    succeeds, and none is when it fails (their temporaries are removed). A chart written before a failing
    table is not left behind without it. `folder`, where they go, is made here if missing (output_dir)."""
    with output_dir(folder) if folder is not None else contextlib.nullcontext(), _together():
        yield


@contextmanager
def _together():
    held: list[tuple[Path, Path]] = []
    token = _held.set(held)
    try:
        yield
    except BaseException:
        for tmp, _ in held:
            discard(tmp)
        raise
    finally:
        _held.reset(token)
    for _, path in held:  # the one rename that fails in a folder we could write: onto a folder
        if path.is_dir() and not path.is_symlink():
            for tmp, _ in held:
                discard(tmp)
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    publish_all(held)  # together or not at all, the files they replace kept until then


def write_atomic(path: Path, data: bytes | str):
    with replacing(path) as tmp:
        tmp.write_bytes(data.encode() if isinstance(data, str) else data)


def digest(path: Path) -> str:
    """sha256 of a file's bytes, read in chunks (outputs can be large)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()
