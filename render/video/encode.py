"""Stream raw frames into the ffmpeg bundled with imageio-ffmpeg: MP4 and GIF from one pass.

Each format has its own ffmpeg process writing to a hidden temporary file beside the final one; close()
renames them into place only when every process succeeded, abort() removes them.

Pipelining: each ffmpeg process is fed by a thread of its own from a small bounded queue (render/video/pipe.py),
so simulating and drawing the next frames overlaps with encoding the previous ones, a slow GIF never stalls the
MP4 (or the other way round), and memory stays flat.
"""
from __future__ import annotations

import os
import queue
import subprocess
import tempfile
import threading
from pathlib import Path

import imageio_ffmpeg
import numpy as np

from . import gif, mp4, palette
from .pipe import RESTORE_SIGNALS, Pipe, ends, os_error
from .atomic import discard, publish_all, temp_beside
from ..errors import EncodeError

class _Still:
    """The "png" format: the last frame as a PNG (a map at its end time), written when the video closes."""

    def __init__(self, final: Path):
        self.final, self.tmp, self.frame = final, temp_beside(final, suffix=".part"), None

    def finish(self):
        import imageio.v3 as iio
        try:
            iio.imwrite(self.tmp, self.frame, extension=".png")
        except OSError as e:  # name the file the user asked for, not the hidden temporary
            raise OSError(e.errno, e.strerror, str(self.final)) from e


class Encoder:
    """Writes `frames` to out_dir/NAME.<fmt> for each format: write() each frame, then close(), or abort()."""

    def __init__(self, out_dir: Path, name: str, video, frames: int, formats=None, planar: bool = False):
        """planar: convert the MP4's frames to yuv420p before its pipe, in a Taichi kernel (render/video/yuv.py),
        which needs the Taichi a Run started; else ffmpeg converts the rgb24 it is fed."""
        self.yuv = None
        if planar:
            from . import yuv  # Taichi: not for a plan (render/config/budget.py reads this module)
            self.yuv = yuv if yuv.fits(video.width, video.height) else None
        self.targets: list[Pipe] = []
        self.written = 0
        self.stills: list[_Still] = []
        self.muxers: list = []  # the audio mux's ffmpeg while it runs (close())
        self.size = (video.width, video.height)
        exe = imageio_ffmpeg.get_ffmpeg_exe()
        loose = None  # a format's temporary, ffmpeg and log until self.targets holds them, where abort() sees them
        try:
            for fmt in formats or video.formats:
                final = out_dir / f"{name}.{fmt}"
                if fmt == "png":
                    self.stills.append(_Still(final))
                    continue
                loose = [temp_beside(final, suffix=".part"), None, None]
                tmp = loose[0]
                log = loose[2] = tempfile.TemporaryFile()
                rate, (w, h) = (gif.rate(video), gif.size(video)) if fmt == "gif" else (video.fps, self.size)
                planar = fmt == "mp4" and self.yuv is not None
                # a GIF's ffmpeg gives its palette (render/video/palette.py), a rainbow's writes it
                own = fmt == "gif" and video.palette != "rainbow"
                out = palette.stats_args() if own else \
                    [*(mp4.args(video) if fmt == "mp4" else palette.rainbow_args()), tmp]
                cmd = [exe, "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo",
                       "-pix_fmt", "yuv420p" if planar else "rgb24",
                       "-s", f"{w}x{h}", "-r", str(rate), "-i", "-", "-an", *out]
                # start_new_session: Ctrl-C reaches us, not ffmpeg, and we clean up
                proc = loose[1] = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=log, start_new_session=True,
                                                   stdout=subprocess.PIPE if own else subprocess.DEVNULL,
                                                   restore_signals=RESTORE_SIGNALS)
                t = Pipe(final, tmp, proc, log, gif.repeats(video, frames) if fmt == "gif" else None,
                         gif.size(video) if fmt == "gif" else None, planar)
                if own:
                    t.kept, t.step, t.rate = [], palette.palette_step(video), rate
                    t.last_counted = (sum(t.repeats) - 1) // t.step * t.step
                self.targets.append(t)
                loose = None
        except BaseException:
            if loose is not None:  # stopped between making them and handing them on
                tmp, proc, log = loose
                if proc is not None:
                    proc.kill()
                    proc.wait()
                if log is not None:
                    log.close()
                discard(tmp)
            self.abort()
            raise

    @property
    def queues_frames(self) -> bool:
        """Whether write() queues the frame itself for a pipe (an rgb24 MP4): then it must not change after
        write(). Fed yuv420p and the GIF's own frames, the Encoder reads the frame only within write(), and a
        still keeps whatever the frame holds at close()."""
        return any(not t.planar and t.small is None for t in self.targets)

    def write(self, frame: np.ndarray, small: np.ndarray | None = None, lit: tuple[np.ndarray, int] | None = None):
        """Queue one H×W×3 uint8 frame; blocks only while an encoder is QUEUE_FRAMES behind. `small` is the
        GIF's frame for it, drawn at the GIF's size (render/video/gif.py), where the GIF keeps this frame;
        without it the GIF gets `frame` area-averaged to its size. No frame larger reaches the GIF's pipe.
        `lit`: the tiles of `frame` that may hold anything but black, if its canvas knows (render/video/yuv.py).

        The frames are shared, not copied: do not modify them after writing them.
        """
        for t in self.targets:
            if t.error is not None:
                try:
                    t.proc.wait(timeout=5)  # its pipe broke as it exits: its log is then complete
                except subprocess.TimeoutExpired:
                    pass
                raise self._failure("stopped", t.error)
        yuv_frame = self.yuv.convert(frame, lit) if any(t.planar for t in self.targets) else None
        for t in self.targets:
            n = 1 if t.repeats is None else t.repeats[self.written]
            if n and t.small is not None:
                mine = small
                if small is None:
                    from .downscale import shrink  # Taichi: not for a plan (render/config/budget.py reads this module)
                    mine = shrink(frame, *t.small)
                if mine.shape != (t.small[1], t.small[0], 3):
                    raise ValueError(f"a GIF frame of {mine.shape[1]}x{mine.shape[0]}, not {t.small[0]}x{t.small[1]}")
            for _ in range(n):
                if t.kept is None:
                    t.queue.put(yuv_frame if t.planar else frame if t.small is None else mine)
                    continue
                if len(t.kept) % t.step == 0:  # the frames palettegen counts
                    t.queue.put(mine)
                    if len(t.kept) == t.last_counted:  # its last: EOF now, and the palette is made (0.38 s
                        t.queue.put(None)  # for rigid_chaos) while the video's last frames are drawn
                        t.ended = True
                t.kept.append(mine)  # mapped to the palette at close()
        self.written += 1
        for s in self.stills:
            s.frame = frame  # shared like the queues' frames: only the last one is kept

    def close(self, audio: tuple[int, np.ndarray] | None = None, publish: bool = True) -> dict[str, int]:
        """Finish encoding and rename into place; returns file name -> bytes. `audio`, (rate, int16 samples
        (S, 2)), is muxed into the MP4 (see _mux). publish=False leaves the finished files in their temporaries
        (done()) until publish(), so that a caller can publish them together with files of its own; until then
        abort() removes them."""
        for t in self.targets:
            if not t.ended:
                t.queue.put(None)
        for t in self.targets:
            t.thread.join()  # and its pipe closed: EOF
        # The MP4's ffmpeg ends first (x264 has a few frames left; palettegen had its EOF with the last frame it
        # counts, write()): its track is muxed on a thread of its own (a second ffmpeg: 0.54 s for rigid_chaos)
        # while the GIF is mapped here.
        muxed = []  # what the muxing thread raised, if anything
        muxing = None
        try:
            for t in sorted(self.targets, key=lambda t: t.final.suffix != ".mp4"):
                rgba = t.proc.stdout.read() if t.kept is not None else None  # 1 kB: it fits the pipe
                code = t.proc.wait()
                if t.error is not None or code:
                    raise self._failure("failed", t.error or f"exit status {code}")  # before abort() kills the rest
                if audio is not None and t.final.suffix == ".mp4":
                    muxing = threading.Thread(target=_catching, args=(muxed, self._mux, t, *audio), daemon=True)
                    muxing.start()
                if t.kept is not None:
                    self._gif(t, palette.read(rgba))
            for s in self.stills:
                s.finish()
            if muxing is not None:
                muxing.join()
        except BaseException:  # a failure, or stopped (Ctrl-C) in any of it, the mux's wait too
            if muxing is not None:
                for proc in self.muxers:
                    proc.kill()  # in a session of its own: no signal of ours reached it
                muxing.join()  # its temporary file is removed, or renamed onto the MP4's, before abort() runs
            self.abort()
            raise
        if muxed:
            self.abort()
            raise muxed[0]
        for t in self.targets:
            t.log.close()
        sizes = {t.final.name: t.tmp.stat().st_size for t in [*self.targets, *self.stills]}
        if not all(sizes.values()):  # an ffmpeg that exits 0 having written nothing (a broken or stand-in one)
            empty = [name for name, size in sizes.items() if not size]
            self.abort()
            raise EncodeError(f"ffmpeg wrote nothing into {', '.join(empty)}, and said nothing")
        if publish:
            self.publish()
        return sizes

    def done(self) -> list[tuple[Path, Path]]:
        """(temporary, final) of each finished file, after close(publish=False)."""
        return [(t.tmp, t.final) for t in [*self.targets, *self.stills]]

    def publish(self, *others: tuple[Path, Path]):
        """Rename the finished files into place (after close(publish=False)), with the caller's own finished
        (temporary, final) pairs: all of them or none (atomic.publish_all)."""
        try:
            publish_all(self.done() + list(others))
        finally:
            self.targets, self.stills = [], []  # published, or removed by publish_all

    def abort(self):
        """Stop ffmpeg and remove the temporary files; safe to call more than once."""
        for t in self.targets:
            t.error = t.error or EncodeError("aborted")
            t.proc.kill()  # unblocks a writer stuck on a full pipe: its write fails and it drains the queue
        for t in self.targets:
            t.proc.wait()
            try:
                t.queue.put(None, timeout=5)  # the writer drains, so there is room soon
            except queue.Full:
                pass
            t.thread.join(timeout=5)
            discard(t.tmp)
            t.log.close()
        for s in self.stills:
            discard(s.tmp)
        self.targets, self.stills = [], []

    def _mux(self, t: Pipe, rate: int, samples: np.ndarray):
        """The track into the finished MP4 (mp4.mux)."""
        code = mp4.mux(t.final, t.tmp, t.log, rate, samples, self.muxers)
        if code:
            raise self._failure("failed adding the audio", f"exit status {code}")

    def _gif(self, t: Pipe, colours: np.ndarray):
        """A GIF's kept frames mapped to its palette and written at t.tmp (render/video/dither.py)."""
        from . import dither  # Taichi: not for a plan (render/config/budget.py reads this module)
        code, t.error = dither.write(t.kept, colours, t.small, t.rate, t.tmp, t.log)
        if t.error is not None or code:
            raise self._failure("failed", t.error or f"exit status {code}")
        t.kept = []

    def _failure(self, how: str, fallback) -> Exception:
        """What to raise when an ffmpeg process failed: the OS's reason and the file when the file system
        failed it (OSError, e.g. "No space left on device: out/NAME/NAME.mp4"), else EncodeError with the
        first and last line of each ffmpeg's log: at -loglevel error the first names the cause ("No such
        filter: 'addroi'", from an ffmpeg too old), the last only what it stopped ("Error while processing the
        decoded data for stream #0:0")."""
        logs = [self._log(t) for t in self.targets]
        for t, log in zip(self.targets, logs):
            code = os_error(log)
            if code is not None:
                return OSError(code, os.strerror(code), str(t.final))
        return EncodeError(f"ffmpeg {how}: {' | '.join(ends(x) for x in logs if x.strip()) or fallback}")

    @staticmethod
    def _log(t: Pipe) -> str:
        t.log.seek(0)
        return t.log.read().decode(errors="replace").strip()


def _catching(caught: list, fn, *args):
    """fn(*args) on a thread: what it raises goes into `caught`, for the thread that joins it."""
    try:
        fn(*args)
    except BaseException as e:
        caught.append(e)


def ffmpeg_version() -> str:
    return imageio_ffmpeg.get_ffmpeg_version()
