"""render/video/encode.py, gif.py, downscale.py and palette.py: the GIF's frames are picked before the pipe,
exactly as ffmpeg's fps filter picked them, and shrunk before it, by their exact area average; its palette is
palettegen's, and its pixels are mapped to it as written here."""
import itertools
import math
import subprocess
import types

import imageio_ffmpeg
import numpy as np
import pytest

from render.video import downscale, encode, gif, palette

EXE = imageio_ffmpeg.get_ffmpeg_exe()


@pytest.fixture(autouse=True, scope="module")
def taichi():
    """The GIF's frames are mapped to its palette on the Taichi a Run starts, as in a render."""
    from render.config.scene import load
    from render.physics.stepper import Run
    Run(load("classic", ["video.duration=0.1"]), "cpu")


def video(fps, gif_fps=20, width=64, height=36, gif_width=32):
    return types.SimpleNamespace(fps=fps, gif_fps=gif_fps, width=width, height=height, gif_width=gif_width,
                                 formats=("gif",), palette="fan")


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
        repeats = gif.repeats(video(fps, gif_fps), frames)
        mine = [i for i, n in enumerate(repeats) for _ in range(n)]
        assert mine == fps_filter_picks(fps, min(fps, gif_fps), frames), (fps, gif_fps, frames)


def test_the_gif_is_byte_identical_to_one_of_the_frames_the_fps_filter_picks(tmp_path):
    """Every frame at 60 fps (shrunk to the GIF's size by the encoder), and only the ones ffmpeg's fps filter
    picks, handed over at the GIF's rate: the same file, bit for bit, while the pipe carries a third of the
    frames."""
    v, n = video(60, 20, 96, 54, 48), 47
    rng = np.random.default_rng(5)
    frames = [rng.integers(0, 255, (54, 96, 3), dtype=np.uint8) for _ in range(n)]
    enc = encode.Encoder(tmp_path, "picked", v, n, formats=["gif"])
    piped = sum(enc.targets[0].repeats)
    for f in frames:
        enc.write(f)
    enc.close()
    picks = fps_filter_picks(60, 20, n)
    enc = encode.Encoder(tmp_path, "filtered", video(20, 20, 48, 28, 48), len(picks), formats=["gif"])
    for i in picks:
        enc.write(downscale.shrink(frames[i], 48, 28))
    enc.close()
    assert (tmp_path / "picked.gif").read_bytes() == (tmp_path / "filtered.gif").read_bytes()
    assert piped == len(picks) == 16 == len(list(itertools.islice(frames, 0, n, 3)))


def decoded(path) -> np.ndarray:
    out = subprocess.run([EXE, "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                         capture_output=True, check=True).stdout
    return np.frombuffer(out, np.uint8)


def test_the_gif_palette_is_palettegens_of_sampled_cut_frames_and_each_pixel_its_dithered_nearest(tmp_path):
    """The Encoder's GIF decodes back to: the palette ffmpeg's palettegen makes (run here, with the shipped
    settings) of every palette_step-th frame cut in numpy to PALETTE_BITS per channel at each step's centre;
    each pixel the first palette colour nearest, in RGB, to its full colour plus the 8x8 Bayer dither of its
    place, written here from the matrix's definition. And cutting, or counting every frame, changes the
    palette of these frames, so the test can tell."""
    v, n = video(20, 20, 48, 28, 48), 12
    rng = np.random.default_rng(11)
    frames = [rng.integers(0, 256, (28, 48, 3), dtype=np.uint8) for _ in range(n)]
    enc = encode.Encoder(tmp_path, "cut", v, n, formats=["gif"])
    for f in frames:
        enc.write(f)
    enc.close()
    mask, centre = palette.palette_cut()
    assert palette.PALETTE_BITS < 8 and bin(mask).count("1") == palette.PALETTE_BITS
    step = palette.palette_step(v)
    assert step == 4

    def colours(stats: list[np.ndarray]) -> np.ndarray:
        cmd = [EXE, "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "48x28", "-r",
               "20", "-i", "-", "-vf", f"palettegen=stats_mode=diff:max_colors={palette.GIF_COLOURS}", "-f",
               "rawvideo", "-pix_fmt", "rgba", "-"]
        rgba = np.frombuffer(subprocess.run(cmd, input=b"".join(f.tobytes() for f in stats), capture_output=True,
                                            check=True).stdout, np.uint8).reshape(256, 4)
        opaque = [tuple(c[:3]) for c in rgba if c[3] == 255]
        return np.array(list(dict.fromkeys(opaque)), np.int64)  # in order, each once

    pal = colours([(f & mask) | centre for f in frames[::step]])
    assert not np.array_equal(colours(frames[::step]), pal) and not np.array_equal(
        colours([(f & mask) | centre for f in frames]), pal)
    bayer = np.array([[0]])
    while len(bayer) < 8:  # the Bayer matrix: each level 4x the last, offset by 0, 2, 3, 1 in its quadrants
        bayer = np.block([[4 * bayer, 4 * bayer + 2], [4 * bayer + 3, 4 * bayer + 1]])
    d = np.tile(bayer // 8 - 4, (4, 6))[:28, :48, None]
    want = []
    for f in frames:
        c = np.clip(f.astype(np.int64) + d, 0, 255)
        want.append(pal[((c[:, :, None, :] - pal[None, None]) ** 2).sum(-1).argmin(-1)])  # argmin: the first
    np.testing.assert_array_equal(decoded(tmp_path / "cut.gif").reshape(n, 28, 48, 3), np.stack(want))


@pytest.mark.parametrize("size", [(96, 54, 48, 28), (128, 72, 35, 20), (64, 36, 64, 36), (50, 30, 7, 4),
                                  (1280, 720, 352, 198), (101, 37, 100, 36), (30, 20, 29, 19)])
def test_shrink_is_the_exact_area_mean_rounded_half_up(size):
    """Every byte is the area mean of what it covers, exactly, rounded to nearest with a half up: the frame
    upsampled by the least common multiple of the sizes, whole blocks summed in integers, and divided."""
    W, H, w, h = size
    frame = np.random.default_rng(W + h).integers(0, 256, (H, W, 3), dtype=np.uint8)
    ly, lx = math.lcm(H, h), math.lcm(W, w)
    up = frame.astype(np.int64).repeat(ly // H, 0).repeat(lx // W, 1)
    total, count = up.reshape(h, ly // h, w, lx // w, 3).sum(axis=(1, 3)), (ly // h) * (lx // w)
    assert (downscale.shrink(frame, w, h) == (2 * total + count) // (2 * count)).all()
    assert (downscale.shrink(np.full((H, W, 3), 200, np.uint8), w, h) == 200).all()  # the shares sum to one
    tie = np.array([[[0, 3, 250], [1, 4, 251]]], np.uint8)  # means 0.5, 3.5 and 250.5: a half goes up
    assert downscale.shrink(tie, 1, 1).tolist() == [[[1, 4, 251]]]


def test_a_gif_frame_of_the_wrong_size_is_refused(tmp_path):
    v = video(20, 20, 96, 54, 48)
    enc = encode.Encoder(tmp_path, "x", v, 2, formats=["gif"])
    with pytest.raises(ValueError, match="48x28"):
        enc.write(np.zeros((54, 96, 3), np.uint8), np.zeros((54, 96, 3), np.uint8))
    enc.abort()
    assert not list(tmp_path.iterdir())


def test_an_ffmpeg_failure_names_its_cause_not_only_where_it_stopped(tmp_path, monkeypatch):
    """At -loglevel error an ffmpeg that lacks a filter logs the cause first ("No such filter") and last only
    what it stopped: the message carries both (an ffmpeg 4.2 without addroi had said only the last)."""
    from render.config.scene import load
    from render.video import mp4
    monkeypatch.setattr(mp4, "roi", lambda video: ["-vf", "nosuchfilter"])
    v = load("classic", ["video.width=64", "video.height=36", "video.duration=0.1"]).video
    enc = encode.Encoder(tmp_path, "broken", v, 6, formats=["mp4"])
    with pytest.raises(encode.EncodeError) as failed:
        for _ in range(6):
            enc.write(np.zeros((36, 64, 3), np.uint8))
        enc.close()
    message = str(failed.value)
    assert "No such filter: 'nosuchfilter'" in message and len(message.splitlines()) == 1, message
    assert not any(tmp_path.iterdir())
