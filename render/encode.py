"""Stream raw frames into the ffmpeg bundled with imageio-ffmpeg: MP4 and GIF from one pass.

Each format has its own ffmpeg process writing to a hidden temporary file beside the final one; close()
renames them into place only when every process succeeded, abort() removes them. Frames go through a small
bounded queue to a writer thread, so drawing the next frame overlaps with encoding this one and memory stays
flat.
"""
from __future__ import annotations

import os
import queue
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import imageio_ffmpeg
import numpy as np

QUEUE_FRAMES = 8


def mp4_args(video) -> list[str]:
    return ["-c:v", "libx264", "-preset", "veryfast", "-crf", "20", "-pix_fmt", "yuv420p",
            "-movflags", "+faststart", "-f", "mp4"]


def gif_args(video) -> list[str]:
    fps = min(video.gif_fps, video.fps)
    graph = (f"fps={fps},scale={video.gif_width}:-2:flags=lanczos,split[a][b];"
             f"[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=bayer:bayer_scale=3")
    return ["-vf", graph, "-loop", "0", "-f", "gif"]


ARGS = {"mp4": mp4_args, "gif": gif_args}


class EncodeError(RuntimeError):
    pass


class Encoder:
    """Writes `frames` to out_dir/NAME.<fmt> for each format; use as a context manager or call close/abort."""

    def __init__(self, out_dir: Path, name: str, video, formats=None):
        self.targets: list[tuple[Path, Path, subprocess.Popen, object]] = []
        self.busy_s = 0.0
        self.error: BaseException | None = None
        exe = imageio_ffmpeg.get_ffmpeg_exe()
        try:
            for fmt in formats or video.formats:
                final = out_dir / f"{name}.{fmt}"
                fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=f".{fmt}.part", dir=out_dir)
                os.close(fd)
                log = tempfile.TemporaryFile()
                cmd = [exe, "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
                       "-s", f"{video.width}x{video.height}", "-r", str(video.fps), "-i", "-", "-an",
                       *ARGS[fmt](video), tmp]
                proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=log,
                                        start_new_session=True)  # Ctrl-C reaches us, and we clean up
                self.targets.append((final, Path(tmp), proc, log))
        except BaseException:
            self.abort()
            raise
        self.queue: queue.Queue = queue.Queue(QUEUE_FRAMES)
        self.thread = threading.Thread(target=self._pump, daemon=True)
        self.thread.start()

    def _pump(self):
        while True:
            frame = self.queue.get()
            if frame is None:
                return
            t = time.perf_counter()
            try:
                if self.error is None:
                    buf = memoryview(np.ascontiguousarray(frame)).cast("B")
                    for _, _, proc, _ in self.targets:
                        proc.stdin.write(buf)
            except BaseException as e:  # a dead ffmpeg: report it from the main thread
                self.error = e
            self.busy_s += time.perf_counter() - t

    def write(self, frame: np.ndarray):
        if self.error is not None:
            raise EncodeError(f"ffmpeg stopped: {self._logs() or self.error}")
        self.queue.put(frame)

    def close(self) -> dict[str, int]:
        """Finish encoding and rename into place; returns file name -> bytes."""
        t = time.perf_counter()
        self.queue.put(None)
        self.thread.join()
        codes = []
        for _, _, proc, _ in self.targets:
            try:
                proc.stdin.close()
            except OSError:
                pass
            codes.append(proc.wait())
        self.busy_s += time.perf_counter() - t
        if self.error is not None or any(codes):
            msg = self._logs() or str(self.error)
            self.abort()
            raise EncodeError(f"ffmpeg failed: {msg}")
        sizes = {}
        for final, tmp, _, log in self.targets:
            os.chmod(tmp, 0o644)
            os.replace(tmp, final)
            sizes[final.name] = final.stat().st_size
            log.close()
        self.targets = []
        return sizes

    def abort(self):
        """Stop ffmpeg and remove the temporary files; safe to call more than once."""
        if hasattr(self, "queue"):
            self.error = self.error or EncodeError("aborted")
            try:
                self.queue.put_nowait(None)
            except queue.Full:
                pass
        for _, tmp, proc, log in self.targets:
            proc.kill()
            proc.wait()
            tmp.unlink(missing_ok=True)
            log.close()
        self.targets = []

    def _logs(self) -> str:
        out = []
        for _, _, _, log in self.targets:
            log.seek(0)
            out.append(log.read().decode(errors="replace").strip())
        return " | ".join(x.splitlines()[-1] for x in out if x)


def ffmpeg_version() -> str:
    return imageio_ffmpeg.get_ffmpeg_version()
