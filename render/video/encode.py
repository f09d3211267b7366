"""Stream raw frames into the ffmpeg bundled with imageio-ffmpeg: MP4 and GIF from one pass.

Each format has its own ffmpeg process writing to a hidden temporary file beside the final one; close()
renames them into place only when every process succeeded, abort() removes them.

Pipelining: each ffmpeg process has its own writer thread fed from its own small bounded queue, so
simulating and drawing the next frames overlaps with encoding the previous ones, a slow GIF never stalls the
MP4 (or the other way round), and memory stays flat (the queues share the frame arrays, they do not copy
them). The pipes are enlarged so a writer hands over a frame in a few system calls.
"""
from __future__ import annotations

import errno
import os
import queue
import subprocess
import tempfile
import threading
from pathlib import Path

import imageio_ffmpeg
import numpy as np

from . import gif
from .atomic import publish, temp_beside
from ..errors import EncodeError

try:
    import fcntl
except ImportError:  # not POSIX: default pipe sizes
    fcntl = None

QUEUE_FRAMES = 6  # per ffmpeg process: at most ~14 distinct 720p frames (2.8 MB each) are ever waiting
PIPE_BYTES = 1 << 20  # Linux's default ceiling for an unprivileged pipe (/proc/sys/fs/pipe-max-size)
F_SETPIPE_SZ = getattr(fcntl, "F_SETPIPE_SZ", 1031)  # Linux; elsewhere the call fails harmlessly


# Chosen on rigid_chaos (20 s, 1280x720, 60 fps), every setting encoding the same raw frames:
# - MP4: veryfast at crf 31 was 11.96 MB (crf 20 was 36 MB); crf is the lever for the picture. Near that
#   size "fast" gains 0.2-0.4 dB PSNR but made the whole render 2x slower on 2 cores (the render waits on
#   the encoder); "medium" costs 2x "veryfast" for 0.4 dB. tune=animation, aq-mode=3, weightp=2, a longer
#   GOP and smaller deadzones did not beat plain crf at equal size. But crf 31 ghosts the HUD's digits (the
#   last clock's strokes linger in P-frames): the columns beside the pendulums' circle, where the HUD and a
#   map's axes live (render/draw/hud.py), get a finer quantiser (x264's regions of interest, ffmpeg's addroi,
#   qoffset ROI_QOFFSET) and the rest crf 32. On the first 8 s: the same bytes (1.31 vs 1.30 MB), the HUD's
#   corners 38.8 dB instead of 33.3, the whole frame 30.18 dB instead of 30.22.
# - GIF: its frames come drawn at its own size (render/video/gif.py). The trails fade every frame, so nearly
#   every lit pixel changes in every frame and dithering is not what makes the file big; pixels x frames x
#   palette size is. 352 px x 20 fps x 48 colours makes 4.69 MB (64 colours made 5.11 MB of the drawn frames,
#   4.77 MB of the area-averaged ones, whose thin lines and text were smeared into fewer distinct pixels; 480 px
#   x 25 fps x 256 colours was 14.7 MB); 48 colours cost the clock's corner 0.2 dB. Bayer dithering costs
#   nothing here and keeps the fractal's gradients from banding. A rainbow (video.palette) is the exception:
#   one small palette for the whole GIF keeps a few greens and purples of the hue circle, so it gets 256
#   colours chosen for each frame (stats_mode=single, new=1). On rainbow_1000 (20 s) the hue distance of its
#   GIF to its MP4 (tests/test_gif.py's measure) is 0.72 with 48 colours for the whole GIF, 0.28 with 256 for
#   the whole GIF (9.3 MB) or 96 per frame (8.5 MB), 0.14 with 256 per frame; but that GIF is 11.1 MB, not 5.8.
MP4_PRESET, MP4_CRF, ROI_QOFFSET = "veryfast", "32", -0.3
X264_ONE_THREAD_CPUS = 2  # see x264_threads()
GIF_COLOURS, RAINBOW_COLOURS = 48, 256
# The GIF's palette is chosen from its frames' colours cut to PALETTE_BITS bits per channel (the centre of each
# step), and its frames are mapped to it at full depth. palettegen's median cut sorts every distinct colour of
# the whole GIF, after its last frame, on one thread: rigid_chaos's 400 GIF frames hold 1.83 M colours (773 k at
# 7 bits, 194 k at 6), and the Encoder's close() took 7.83 s after the last frame (7 bits: 4.57 s; 6: 3.07 s;
# medians of 3 rounds, `python benchmarks/gif_palette.py --rounds 3`, a 2-core AVX2 EPYC). Against its raw
# frames 7 bits cost 0.04 dB (0.10 in the clock's corner), 6 bits 0.18 (0.96).
PALETTE_BITS = 7
# And palettegen sees PALETTE_FPS of the GIF's frames a second, not all of them. Counting every changed pixel's
# colour is its cost (a hash whose buckets are searched one entry at a time): rigid_chaos's first 100 GIF
# frames, a coherent fan of few colours, took it 0.09 s, its last 100, in chaos, 1.1 s. Its 400 GIF frames
# through the shipped graph took 4.9 s of CPU seen whole, 2.9 s at every 4th frame, and decoded back as close to
# the frames drawn: 26.50 and 26.96 dB over the frame, 34.45 and 34.08 dB in the clock's corner (2-core Xeon,
# 2026-12-06; every 2nd: 3.8 s, 27.08 dB; every 8th: 2.6 s, 27.19 dB).
PALETTE_FPS = 5
REACH = 0.46  # of the frame's height: the radius of the circle the canvas draws the pendulums in
# The `audio` effect's track (render/video/audio.py): ffmpeg's own AAC encoder (the bundled build has no libfdk),
# at 48 kHz and 128 kb/s for two channels: 320 kB for a 20 s video beside its 11.25 MB of picture.
AUDIO_CODEC, AUDIO_RATE, AUDIO_KBPS = "aac", 48_000, 128


def roi(video) -> list[str]:
    """The columns left and right of the pendulums' circle, a finer quantiser there: the HUD's text reads."""
    side = (video.width - 2 * REACH * video.height) / 2 / video.width
    if side < 0.02:
        return []
    x, q = f"{side:.4f}", ROI_QOFFSET
    return ["-vf", f"addroi=0:0:iw*{x}:ih:{q},addroi=iw*(1-{x}):0:iw*{x}:ih:{q}"]


def x264_threads() -> list[str]:
    """x264 on one thread where this process has at most X264_ONE_THREAD_CPUS CPUs. Its own threads (frame
    threads and a lookahead, 3 or more) cost a fifth more CPU: rigid_chaos's 1200 yuv420p frames took 15.8 s
    user + 1.2-1.7 s system at its default, 17.0-17.3 s at threads=2, 13.2 s + 0.9 s at one (ffmpeg from a
    file, 2-core Xeon with AVX-512, 2026-12-06). In a render the other core simulates and draws, so what counts
    on two cores is the CPU time, not x264's own wall time: one thread took the whole render from 24.2-24.8 s to
    22.5-22.8 s (alternating, two each). Where x264 is the render's slowest part, a fan light to draw, its own
    threads would be quicker: one thread pays off while the rest of the render costs at least about 4/5 of
    x264's CPU time."""
    return ["-threads", "1"] if _cpus() <= X264_ONE_THREAD_CPUS else []


def _cpus() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def mp4_args(video) -> list[str]:
    return [*roi(video), "-c:v", "libx264", *x264_threads(), "-preset", MP4_PRESET, "-crf", MP4_CRF,
            "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4"]


def palette_cut(bits: int | None = None) -> tuple[int, int]:
    """(mask, centre): a channel value v counts for the GIF's palette as (v & mask) | centre, cut to `bits`
    (default PALETTE_BITS)."""
    drop = 8 - (PALETTE_BITS if bits is None else bits)
    return (0xFF << drop) & 0xFF, (1 << drop) >> 1


def palette_step(video) -> int:
    """Every how many GIF frames palettegen counts one (PALETTE_FPS)."""
    return max(1, round(gif.rate(video) / PALETTE_FPS))


def gif_args(video) -> list[str]:
    """The GIF's frames arrive at its own size (render/video/gif.py): only the palette is made here."""
    make, use = (f"stats_mode=single:max_colors={RAINBOW_COLOURS}", "new=1:") if video.palette == "rainbow" else \
        (f"stats_mode=diff:max_colors={GIF_COLOURS}", "")
    cut = ""  # a rainbow's palettes are made per frame, as frames come: every frame counts, and no tail to cut
    if video.palette != "rainbow":
        step = palette_step(video)
        cut = f"select='not(mod(n\\,{step}))'," if step > 1 else ""
        if PALETTE_BITS < 8:
            keep, centre = palette_cut()
            cut += "lutrgb=" + ":".join(f"{c}='bitor(bitand(val\\,{keep})\\,{centre})'" for c in "rgb") + ","
    graph = f"split[a][b];[a]{cut}palettegen={make}[p];[b][p]paletteuse={use}dither=bayer:bayer_scale=3"
    return ["-vf", graph, "-loop", "0", "-f", "gif"]


ARGS = {"mp4": mp4_args, "gif": gif_args}

# What ffmpeg reports in the system's own words (av_strerror is strerror) when the file system fails it: then
# the user reads that reason and the file, as for any other write, not ffmpeg's account of its muxer.
FILE_ERRORS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EROFS, errno.EACCES, errno.EPERM,
               errno.ENOENT, errno.ESTALE)


def os_error(log: str) -> int | None:
    """The errno of the first file-system error an ffmpeg log names, if any."""
    found = [(log.find(os.strerror(code)), code) for code in FILE_ERRORS if os.strerror(code) in log]
    return min(found)[1] if found else None


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


class _Target:
    """One ffmpeg process, the thread that feeds it, and where its output goes."""

    def __init__(self, final: Path, tmp: Path, proc: subprocess.Popen, log, repeats: list[int] | None = None,
                 small: tuple[int, int] | None = None, planar: bool = False):
        self.final, self.tmp, self.proc, self.log = final, tmp, proc, log
        self.planar = planar  # fed yuv420p (render/video/yuv.py), not rgb24
        self.repeats = repeats  # per frame, how many times it goes to this ffmpeg (None: once each)
        self.small = small  # the GIF's (width, height): it is fed frames of that size only
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
                return
            if self.error is not None:
                continue  # keep draining so the producer never blocks on a dead encoder
            try:
                view = memoryview(np.ascontiguousarray(frame)).cast("B")
                while view:  # os.write releases the GIL while it blocks on the pipe
                    view = view[os.write(fd, view):]
            except BaseException as e:  # a dead ffmpeg: report it from the main thread
                self.error = e


class Encoder:
    """Writes `frames` to out_dir/NAME.<fmt> for each format: write() each frame, then close(), or abort()."""

    def __init__(self, out_dir: Path, name: str, video, frames: int, formats=None, planar: bool = False):
        """planar: convert the MP4's frames to yuv420p before its pipe, in a Taichi kernel (render/video/yuv.py),
        which needs the Taichi a Run started; else ffmpeg converts the rgb24 it is fed."""
        self.yuv = None
        if planar:
            from . import yuv  # Taichi: not for a plan (render/config/budget.py reads this module)
            self.yuv = yuv if yuv.fits(video.width, video.height) else None
        self.targets: list[_Target] = []
        self.written = 0
        self.stills: list[_Still] = []
        self.size = (video.width, video.height)
        exe = imageio_ffmpeg.get_ffmpeg_exe()
        try:
            for fmt in formats or video.formats:
                final = out_dir / f"{name}.{fmt}"
                if fmt == "png":
                    self.stills.append(_Still(final))
                    continue
                tmp = temp_beside(final, suffix=".part")
                log = tempfile.TemporaryFile()
                rate, (w, h) = (gif.rate(video), gif.size(video)) if fmt == "gif" else (video.fps, self.size)
                planar = fmt == "mp4" and self.yuv is not None
                cmd = [exe, "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo",
                       "-pix_fmt", "yuv420p" if planar else "rgb24",
                       "-s", f"{w}x{h}", "-r", str(rate), "-i", "-", "-an",
                       *ARGS[fmt](video), tmp]
                try:
                    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=log,
                                            start_new_session=True)  # Ctrl-C reaches us, and we clean up
                except BaseException:
                    tmp.unlink(missing_ok=True)
                    log.close()
                    raise
                self.targets.append(_Target(final, tmp, proc, log, gif.repeats(video, frames) if fmt == "gif"
                                            else None, gif.size(video) if fmt == "gif" else None, planar))
        except BaseException:
            self.abort()
            raise

    @property
    def queues_frames(self) -> bool:
        """Whether write() queues the frame itself for a pipe (an rgb24 MP4): then it must not change after
        write(). Fed yuv420p and the GIF's own frames, the Encoder reads the frame only within write(), and a
        still keeps whatever the frame holds at close()."""
        return any(not t.planar and t.small is None for t in self.targets)

    def write(self, frame: np.ndarray, small: np.ndarray | None = None):
        """Queue one H×W×3 uint8 frame; blocks only while an encoder is QUEUE_FRAMES behind. `small` is the
        GIF's frame for it, drawn at the GIF's size (render/video/gif.py), where the GIF keeps this frame;
        without it the GIF gets `frame` area-averaged to its size. No frame larger reaches the GIF's pipe.

        The frames are shared, not copied: do not modify them after writing them.
        """
        for t in self.targets:
            if t.error is not None:
                try:
                    t.proc.wait(timeout=5)  # its pipe broke as it exits: its log is then complete
                except subprocess.TimeoutExpired:
                    pass
                raise self._failure("stopped", t.error)
        yuv_frame = self.yuv.convert(frame) if any(t.planar for t in self.targets) else None
        for t in self.targets:
            n = 1 if t.repeats is None else t.repeats[self.written]
            if n and t.small is not None:
                mine = gif.shrink(frame, *t.small) if small is None else small
                if mine.shape != (t.small[1], t.small[0], 3):
                    raise ValueError(f"a GIF frame of {mine.shape[1]}x{mine.shape[0]}, not {t.small[0]}x{t.small[1]}")
            for _ in range(n):
                t.queue.put(yuv_frame if t.planar else frame if t.small is None else mine)
        self.written += 1
        for s in self.stills:
            s.frame = frame  # shared like the queues' frames: only the last one is kept

    def close(self, audio: tuple[int, np.ndarray] | None = None) -> dict[str, int]:
        """Finish encoding and rename into place; returns file name -> bytes. `audio`, (rate, int16 samples
        (S, 2)), is muxed into the MP4 (see _mux)."""
        for t in self.targets:
            t.queue.put(None)
        for t in self.targets:
            t.thread.join()
            try:
                t.proc.stdin.close()  # EOF: ffmpeg flushes (the GIF's palette needs every frame first)
            except OSError:
                pass
        # The MP4's ffmpeg ends long before the GIF's, whose palette needs every frame first (rigid_chaos: 0.16 s
        # after EOF against 2.0 s): its track is muxed meanwhile, on the core the GIF's one-threaded palettegen
        # leaves idle, not after it.
        try:
            for t in sorted(self.targets, key=lambda t: t.final.suffix != ".mp4"):
                code = t.proc.wait()
                if t.error is not None or code:
                    raise self._failure("failed", t.error or f"exit status {code}")  # before abort() kills the rest
                if audio is not None and t.final.suffix == ".mp4":
                    self._mux(t, *audio)
            for s in self.stills:
                s.finish()
        except BaseException:
            self.abort()
            raise
        sizes = {}
        for t in [*self.targets, *self.stills]:
            publish(t.tmp, t.final)
            sizes[t.final.name] = t.final.stat().st_size
        for t in self.targets:
            t.log.close()
        self.targets, self.stills = [], []
        return sizes

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
            t.tmp.unlink(missing_ok=True)
            t.log.close()
        for s in self.stills:
            s.tmp.unlink(missing_ok=True)
        self.targets, self.stills = [], []

    def _mux(self, t: _Target, rate: int, samples: np.ndarray):
        """Put the track into the finished MP4: a second ffmpeg copies the video's packets as they are (the
        same H.264 stream as without audio) and encodes the samples, piped to it, as AAC at AUDIO_RATE
        (resampled from `rate` where that differs). No sound file is written; its output is another
        temporary beside the final file, renamed onto the first."""
        tmp = temp_beside(t.final, suffix=".part")
        cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-y", "-loglevel", "error", "-i", t.tmp,
               "-f", "s16le", "-ar", str(rate), "-ac", "2", "-i", "-", "-map", "0:v", "-map", "1:a",
               "-c:v", "copy", "-c:a", AUDIO_CODEC, "-ar", str(AUDIO_RATE), "-b:a", f"{AUDIO_KBPS}k",
               "-movflags", "+faststart", "-f", "mp4", tmp]
        try:  # run() kills ffmpeg if we are interrupted while it works
            code = subprocess.run(cmd, input=memoryview(np.ascontiguousarray(samples, "<i2")).cast("B"),
                                  stdout=subprocess.DEVNULL, stderr=t.log, start_new_session=True).returncode
            if code:
                raise self._failure("failed adding the audio", f"exit status {code}")
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        os.replace(tmp, t.tmp)  # atomic: at every moment exactly one temporary is ours to remove

    def _failure(self, how: str, fallback) -> Exception:
        """What to raise when an ffmpeg process failed: the OS's reason and the file when the file system
        failed it (OSError, e.g. "No space left on device: out/NAME/NAME.mp4"), else EncodeError with the
        last line of each ffmpeg's log."""
        logs = [self._log(t) for t in self.targets]
        for t, log in zip(self.targets, logs):
            code = os_error(log)
            if code is not None:
                return OSError(code, os.strerror(code), str(t.final))
        return EncodeError(f"ffmpeg {how}: {' | '.join(x.splitlines()[-1] for x in logs if x) or fallback}")

    @staticmethod
    def _log(t: _Target) -> str:
        t.log.seek(0)
        return t.log.read().decode(errors="replace").strip()


def ffmpeg_version() -> str:
    return imageio_ffmpeg.get_ffmpeg_version()
