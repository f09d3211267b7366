"""A poster for each video: one still frame, shown by the gallery (and any <video poster=...>) before it plays.

Cut from the MP4 at mid-video, where the trails have grown and the fan has started to spread, by the same
ffmpeg that encoded it, downscaled to the gallery's card size. Made on demand and kept beside the video as
NAME.poster.jpg; made again when the video is newer. Best effort: a video ffmpeg cannot read gets no poster
(the gallery then marks it broken when the browser fails to load it too).

The video is one the gallery has checked is a regular file inside OUT (render/commands/confined.py). ffmpeg reads it
as a file and as MP4 only (file:, -f mov): probing would let a file named .mp4 that is a playlist pull in
others from anywhere. A poster there that is not a regular file (a symlink) is replaced, never followed.
"""
from __future__ import annotations

import os
import stat
import subprocess
from pathlib import Path

from .atomic import replacing

WIDTH = 640  # twice the smallest card of the gallery, and never upscaled
TIMEOUT_S = 60  # one frame from a local file; only a hung ffmpeg could take this long


def poster_path(video: Path) -> Path:
    return video.with_name(video.stem + ".poster.jpg")


def ensure(video: Path, at_s: float) -> Path | None:
    """The poster of `video` (cut at `at_s` seconds), made if missing or older than the video; None when
    ffmpeg cannot make it."""
    import imageio_ffmpeg

    video, path = Path(video), poster_path(video)
    try:
        if _regular_mtime(path) >= os.lstat(video).st_mtime:
            return path
        if path.is_dir() and not path.is_symlink():  # nothing to replace it with: the page goes on without
            return None
        with replacing(path, suffix=".jpg") as tmp:
            cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-nostdin", "-y", "-ss", f"{max(at_s, 0):.3f}",
                   "-f", "mov", "-i", f"file:{os.path.abspath(video)}", "-frames:v", "1",
                   "-vf", f"scale='min({WIDTH},iw)':-2", "-q:v", "3", "-f", "image2", "-c:v", "mjpeg", str(tmp)]
            subprocess.run(cmd, check=True, capture_output=True, timeout=TIMEOUT_S)
            if tmp.stat().st_size == 0:  # seeking past the end writes nothing, and says nothing
                raise OSError("no frame")
    except (OSError, RuntimeError, subprocess.SubprocessError):  # RuntimeError: imageio-ffmpeg found no ffmpeg
        return None
    return path


def _regular_mtime(path: Path) -> float:
    """The mtime of a regular file at `path`; -inf when none is there (missing, a symlink, a FIFO)."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return float("-inf")
    return st.st_mtime if stat.S_ISREG(st.st_mode) else float("-inf")
