"""The MP4's settings: x264's preset, quality and threads, a finer quantiser where the HUD's text is, and the
`audio` effect's track muxed into the finished file.

Chosen on rigid_chaos (20 s, 1280x720, 60 fps), every setting encoding the same raw frames:
- veryfast at crf 31 was 11.96 MB (crf 20 was 36 MB); crf is the lever for the picture. Near that size "fast"
  gains 0.2-0.4 dB PSNR but made the whole render 2x slower on 2 cores (the render waits on the encoder);
  "medium" costs 2x "veryfast" for 0.4 dB. tune=animation, aq-mode=3, weightp=2, a longer GOP and smaller
  deadzones did not beat plain crf at equal size.
- But crf 31 ghosts the HUD's digits (the last clock's strokes linger in P-frames): the columns beside the
  pendulums' circle, where the HUD and a map's axes live (render/draw/hud.py), get a finer quantiser (x264's
  regions of interest, ffmpeg's addroi, qoffset ROI_QOFFSET) and the rest crf 32. On the first 8 s: the same
  bytes (1.31 vs 1.30 MB), the HUD's corners 38.8 dB instead of 33.3, the whole frame 30.18 dB instead of 30.22.
- "superfast" instead of "veryfast" (2026-12-06, 2-core Xeon with AVX-512): on two cores a render is bound by
  the CPU that x264 and the drawing share, and x264 took half of it. rigid_chaos's 1200 frames, one thread,
  these arguments (`python benchmarks/x264_presets.py --x264 veryfast:32 superfast:32 superfast:33
  superfast:34 ultrafast:32`, 2 interleaved rounds): veryfast 11.68-11.73 s of CPU, 10.95 MB, 30.23 dB (ffmpeg's
  psnr, the planes' mean); superfast at crf 32 7.45-7.53 s, 12.03 MB, 30.09 dB; at crf 33 10.62 MB, 29.50 dB;
  ultrafast 3.2-3.3 s but 21.82 MB. So a third less of x264's CPU for a tenth more bytes and 0.14 dB; at equal
  bytes superfast would cost 0.7 dB, so the crf stays. fractal_flip's map: 4.74 → 3.92 s, 0.54 → 0.70 MB,
  37.68 → 37.78 dB. Whole renders of rigid_chaos 14.67-14.91 s → 12.04-12.30 s (`python
  benchmarks/render_threads.py --warm --x264-preset P`, 3 rounds alternating); the MP4 11.29 → 12.37 MB.
"""
import os
import subprocess

import imageio_ffmpeg
import numpy as np

from .atomic import discard, temp_beside
from .pipe import RESTORE_SIGNALS

PRESET, CRF, ROI_QOFFSET = "superfast", "32", -0.3
ONE_THREAD_CPUS = 2  # see x264_threads()
REACH = 0.46  # of the frame's height: the radius of the circle the canvas draws the pendulums in
# The `audio` effect's track (render/video/audio.py): ffmpeg's own AAC encoder (the bundled build has no libfdk),
# at 48 kHz and 128 kb/s for two channels: 320 kB for a 20 s video beside its
# 12 MB of picture (rigid_chaos, docs/output-format.md).
AUDIO_CODEC, AUDIO_RATE, AUDIO_KBPS = "aac", 48_000, 128


def roi(video) -> list[str]:
    """The columns left and right of the pendulums' circle, a finer quantiser there: the HUD's text reads."""
    side = (video.width - 2 * REACH * video.height) / 2 / video.width
    if side < 0.02:
        return []
    x, q = f"{side:.4f}", ROI_QOFFSET
    return ["-vf", f"addroi=0:0:iw*{x}:ih:{q},addroi=iw*(1-{x}):0:iw*{x}:ih:{q}"]


def x264_threads() -> list[str]:
    """x264 on one thread where this process has at most ONE_THREAD_CPUS CPUs. Its own threads (frame threads
    and a lookahead, 3 or more) cost a fifth more CPU: rigid_chaos's 1200 yuv420p frames took 15.8 s user +
    1.2-1.7 s system at its default, 17.0-17.3 s at threads=2, 13.2 s + 0.9 s at one (ffmpeg from a file,
    2-core Xeon with AVX-512, 2026-12-06). In a render the other core simulates and draws, so what counts on two
    cores is the CPU time, not x264's own wall time: one thread took the whole render from 24.2-24.8 s to
    22.5-22.8 s (alternating, two each), and after this round's cheaper drawing 24.5 s to 22.7 s (3
    interleaved rounds). Since the drawing got cheaper still, one thread no longer clearly pays: renders within
    3 % of two threads' (and of x264's own count), with x264 alone on two threads 4 % above one in CPU (late
    2026-12-06, docs/performance-log.md). It is kept for that CPU, which renders running side by side share
    (`batch`); where x264 is all a render waits for, a fan light to draw, its own threads would be quicker."""
    # config/options.py's usable_cores(), which sits a layer above this one (docs/architecture.md)
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return ["-threads", "1"] if cpus <= ONE_THREAD_CPUS else []


def args(video) -> list[str]:
    """ffmpeg's output arguments for the MP4 (its frames come as yuv420p or rgb24)."""
    return [*roi(video), "-c:v", "libx264", *x264_threads(), "-preset", PRESET, "-crf", CRF,
            "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4"]


def mux(final, tmp, log, rate: int, samples: np.ndarray, running: list | None = None) -> int:
    """Put the track into the finished MP4 at `tmp` (the temporary beside `final`): a second ffmpeg copies the
    video's packets as they are (the same H.264 stream as without audio) and encodes the samples, int16
    (S, 2) at `rate` Hz, piped to it, as AAC at AUDIO_RATE. No sound file is written; its output is another
    temporary beside the final file, renamed onto `tmp`. Returns ffmpeg's exit status (its log: `log`). The
    ffmpeg is put in `running` as it starts, for a caller on another thread to kill (Encoder.close, when it is
    stopped while the mux runs on a thread of its own)."""
    out = temp_beside(final, suffix=".part")
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-y", "-loglevel", "error", "-i", tmp,
           "-f", "s16le", "-ar", str(rate), "-ac", "2", "-i", "-", "-map", "0:v", "-map", "1:a",
           "-c:v", "copy", "-c:a", AUDIO_CODEC, "-ar", str(AUDIO_RATE), "-b:a", f"{AUDIO_KBPS}k",
           "-movflags", "+faststart", "-f", "mp4", out]
    try:
        with subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=log,
                              start_new_session=True, restore_signals=RESTORE_SIGNALS) as proc:
            if running is not None:
                running.append(proc)
            try:
                proc.communicate(memoryview(np.ascontiguousarray(samples, "<i2")).cast("B"))
            except BaseException:  # interrupted while it works: it goes too
                proc.kill()
                raise
        code = proc.returncode
        if code:
            discard(out)
            return code
    except BaseException:
        discard(out)
        raise
    os.replace(out, tmp)  # atomic: at every moment exactly one temporary is ours to remove
    return 0
