"""A poster for each video: one still frame, shown by the gallery (and any <video poster=...>) before it plays.

Cut from the MP4 at mid-video, where the trails have grown and the fan has started to spread, by the same
ffmpeg that encoded it, downscaled to the gallery's card size. Made on demand and kept beside the video as
NAME.poster.jpg; made again when the video is newer. Best effort: a video ffmpeg cannot read gets no poster
(the gallery then marks it broken when the browser fails to load it too).
"""
from __future__ import annotations

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
        if path.is_file() and path.stat().st_mtime >= video.stat().st_mtime:
            return path
        with replacing(path, suffix=".jpg") as tmp:
            cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-nostdin", "-y", "-ss", f"{max(at_s, 0):.3f}",
                   "-i", str(video), "-frames:v", "1", "-vf", f"scale='min({WIDTH},iw)':-2", "-q:v", "3",
                   "-f", "image2", "-c:v", "mjpeg", str(tmp)]
            subprocess.run(cmd, check=True, capture_output=True, timeout=TIMEOUT_S)
            if tmp.stat().st_size == 0:  # seeking past the end writes nothing, and says nothing
                raise OSError("no frame")
    except (OSError, RuntimeError, subprocess.SubprocessError):  # RuntimeError: imageio-ffmpeg found no ffmpeg
        return None
    return path
