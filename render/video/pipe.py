"""One ffmpeg process fed raw frames through a pipe by a thread of its own, and what its log says when it fails.

The thread takes frames from a small bounded queue, so the caller's next frame is simulated and drawn while
ffmpeg encodes the previous ones, and a slow encoder holds back only its own queue; the queue holds the
caller's arrays, not copies. The pipe is enlarged so a frame goes over in a few system calls.
"""
from __future__ import annotations

import errno
import os
import queue
import subprocess
import threading
from pathlib import Path

import numpy as np

try:
    import fcntl
except ImportError:  # not POSIX: default pipe sizes
    fcntl = None

QUEUE_FRAMES = 6  # per ffmpeg process: at most ~14 distinct 720p frames (2.8 MB each) are ever waiting
PIPE_BYTES = 1 << 20  # Linux's default ceiling for an unprivileged pipe (/proc/sys/fs/pipe-max-size)
F_SETPIPE_SZ = getattr(fcntl, "F_SETPIPE_SZ", 1031)  # Linux; elsewhere the call fails harmlessly


# Every ffmpeg we start keeps Python's SIGXFSZ and SIGPIPE ignored (Popen's restore_signals): then a write past
# the file-size limit fails with EFBIG, which ffmpeg logs and os_error() reads, where the signal's default action
# killed it with nothing said ("ffmpeg failed: exit status -25"; tests/test_hardening.py).
RESTORE_SIGNALS = False

# What ffmpeg reports in the system's own words (av_strerror is strerror) when the file system fails it: then
# the user reads that reason and the file, as for any other write, not ffmpeg's account of its muxer.
FILE_ERRORS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EROFS, errno.EACCES, errno.EPERM,
               errno.ENOENT, errno.ESTALE)


def os_error(log: str) -> int | None:
    """The errno of the first file-system error an ffmpeg log names, if any."""
    found = [(log.find(os.strerror(code)), code) for code in FILE_ERRORS if os.strerror(code) in log]
    return min(found)[1] if found else None


def ends(log: str) -> str:
    """An ffmpeg log's first and last lines, or its one line."""
    lines = [line.strip() for line in log.splitlines() if line.strip()]
    return lines[0] if len(lines) == 1 else f"{lines[0]} ... {lines[-1]}"


class Pipe:
    """One ffmpeg process, the thread that feeds it, and where its output goes (render/video/encode.py's Encoder
    holds one per format)."""

    def __init__(self, final: Path, tmp: Path, proc: subprocess.Popen, log, repeats: list[int] | None = None,
                 small: tuple[int, int] | None = None, planar: bool = False):
        self.final, self.tmp, self.proc, self.log = final, tmp, proc, log
        self.planar = planar  # fed yuv420p (render/video/yuv.py), not rgb24
        self.repeats = repeats  # per frame, how many times it goes to this ffmpeg (None: once each)
        self.small = small  # the GIF's (width, height): it is fed frames of that size only
        self.kept: list | None = None  # a GIF's frames, mapped to its palette at the end (Encoder._gif)
        self.step, self.rate = 1, None  # then every step-th is fed, for the palette; the GIF's frames a second
        self.last_counted = -1  # the index of the last of those
        self.ended = False  # its end (None) queued: no more frames for this ffmpeg
        self.queue: queue.Queue = queue.Queue(QUEUE_FRAMES)
        self.error: BaseException | None = None
        try:
            fcntl.fcntl(proc.stdin.fileno(), F_SETPIPE_SZ, PIPE_BYTES)
        except (OSError, AttributeError):
            pass  # a smaller pipe only means more system calls
        self.thread = threading.Thread(target=self._pump, name=f"encode-{final.suffix[1:]}", daemon=True)
        self.thread.start()

    def _pump(self):
        fd = self.proc.stdin.fileno()
        while True:
            frame = self.queue.get()
            if frame is None:
                try:
                    self.proc.stdin.close()  # EOF: ffmpeg flushes (a GIF's palette needs every frame it counts)
                except OSError:
                    pass
                return
            if self.error is not None:
                continue  # keep draining so the producer never blocks on a dead encoder
            try:
                view = memoryview(np.ascontiguousarray(frame)).cast("B")
                while view:  # os.write releases the GIL while it blocks on the pipe
                    view = view[os.write(fd, view):]
            except BaseException as e:  # a dead ffmpeg: report it from the main thread
                self.error = e
