"""render/video/encode.py: the GIF's frames are picked before the pipe, exactly as ffmpeg's fps filter picked them."""
import itertools
import subprocess
import types

import imageio_ffmpeg
import numpy as np
import pytest

from render.video import encode

EXE = imageio_ffmpeg.get_ffmpeg_exe()


def video(fps, gif_fps=20, width=64, height=36, gif_width=32):
    return types.SimpleNamespace(fps=fps, gif_fps=gif_fps, width=width, height=height, gif_width=gif_width,
                                 formats=("gif",))


def fps_filter_picks(fps: int, gif_fps: int, frames: int) -> list[int]:
    """Which input frames ffmpeg's fps filter (eof_action=pass) keeps: each frame is painted with its index."""
    raw = np.repeat(np.arange(frames, dtype=np.uint8), 8 * 8 * 3)
    cmd = [EXE, "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "8x8",
           "-r", str(fps), "-i", "-", "-vf", f"fps={gif_fps}:eof_action=pass", "-f", "rawvideo",
           "-pix_fmt", "rgb24", "-"]
    out = subprocess.run(cmd, input=raw.tobytes(), capture_output=True, check=True).stdout
    return list(np.frombuffer(out, np.uint8)[:: 8 * 8 * 3])


@pytest.mark.parametrize("fps,gif_fps", [(10, 20), (24, 20), (30, 20), (50, 20), (60, 20), (60, 25), (60, 50),
                                         (100, 20), (120, 25), (25, 10)])
def test_gif_picks_are_the_fps_filters(fps, gif_fps):
    for frames in (1, 2, 3, 4, 7, 31, 60, 61, 121):
        repeats = encode.gif_repeats(video(fps, gif_fps), frames)
        mine = [i for i, n in enumerate(repeats) for _ in range(n)]
        assert mine == fps_filter_picks(fps, min(fps, gif_fps), frames), (fps, gif_fps, frames)


def test_the_gif_is_byte_identical_to_the_one_the_fps_filter_made(tmp_path):
    """Every frame through ffmpeg's fps filter (as before) and only the picked ones at the GIF's rate: the same
    file, bit for bit, while the pipe carries a third of the frames."""
    v, n = video(60, 20, 96, 54, 48), 47
    rng = np.random.default_rng(5)
    frames = [rng.integers(0, 255, (54, 96, 3), dtype=np.uint8) for _ in range(n)]
    enc = encode.Encoder(tmp_path, "picked", v, n, formats=["gif"])
    piped = sum(enc.targets[0].repeats)
    for f in frames:
        enc.write(f)
    enc.close()
    graph = "fps=20:eof_action=pass," + encode.gif_args(v)[1]
    cmd = [EXE, "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "96x54",
           "-r", "60", "-i", "-", "-an", "-vf", graph, "-loop", "0", "-f", "gif", str(tmp_path / "filtered.gif")]
    subprocess.run(cmd, input=b"".join(f.tobytes() for f in frames), check=True)
    assert (tmp_path / "picked.gif").read_bytes() == (tmp_path / "filtered.gif").read_bytes()
    assert piped == 16 and piped == len(list(itertools.islice(frames, 0, n, 3)))
