"""render/video/encode.py and gif.py: the GIF's frames are picked before the pipe, exactly as ffmpeg's fps filter picked
them, and shrunk before it, exactly as an area average does."""
import itertools
import math
import subprocess
import types

import imageio_ffmpeg
import numpy as np
import pytest

from render.video import encode, gif

EXE = imageio_ffmpeg.get_ffmpeg_exe()


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


def test_the_gif_is_byte_identical_to_the_one_the_fps_filter_made(tmp_path):
    """Every frame (shrunk to the GIF's size) through ffmpeg's fps filter, and only the picked ones at the GIF's
    rate, shrunk by the encoder: the same file, bit for bit, while the pipe carries a third of the frames."""
    v, n = video(60, 20, 96, 54, 48), 47
    rng = np.random.default_rng(5)
    frames = [rng.integers(0, 255, (54, 96, 3), dtype=np.uint8) for _ in range(n)]
    enc = encode.Encoder(tmp_path, "picked", v, n, formats=["gif"])
    piped = sum(enc.targets[0].repeats)
    for f in frames:
        enc.write(f)
    enc.close()
    graph = "fps=20:eof_action=pass," + encode.gif_args(v)[1]
    cmd = [EXE, "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "48x28",
           "-r", "60", "-i", "-", "-an", "-vf", graph, "-loop", "0", "-f", "gif", str(tmp_path / "filtered.gif")]
    subprocess.run(cmd, input=b"".join(gif.shrink(f, 48, 28).tobytes() for f in frames), check=True)
    assert (tmp_path / "picked.gif").read_bytes() == (tmp_path / "filtered.gif").read_bytes()
    assert piped == 16 and piped == len(list(itertools.islice(frames, 0, n, 3)))


def test_the_gif_palette_is_chosen_from_colours_cut_to_palette_bits_and_maps_the_full_frames(tmp_path):
    """The Encoder's GIF is, bit for bit, the GIF of a palette made (by ffmpeg's own palettegen, with the
    shipped settings) from every palette_step-th frame cut in numpy to PALETTE_BITS per channel at each step's
    centre, mapped onto all the uncut frames; and cutting, or counting every frame, changes the palette of
    these frames, so the test can tell."""
    v, n = video(20, 20, 48, 28, 48), 12
    rng = np.random.default_rng(11)
    frames = [rng.integers(0, 256, (28, 48, 3), dtype=np.uint8) for _ in range(n)]
    enc = encode.Encoder(tmp_path, "cut", v, n, formats=["gif"])
    for f in frames:
        enc.write(f)
    enc.close()
    mask, centre = encode.palette_cut()
    assert encode.PALETTE_BITS < 8 and bin(mask).count("1") == encode.PALETTE_BITS
    make = f"stats_mode=diff:max_colors={encode.GIF_COLOURS}"

    def two_inputs(stats: list[np.ndarray], name: str) -> bytes:
        (tmp_path / "stats.raw").write_bytes(b"".join(f.tobytes() for f in stats))
        (tmp_path / "frames.raw").write_bytes(b"".join(f.tobytes() for f in frames))
        raw = ["-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "48x28", "-r", "20", "-i"]
        cmd = [EXE, "-nostdin", "-loglevel", "error", *raw, str(tmp_path / "stats.raw"), *raw,
               str(tmp_path / "frames.raw"), "-an", "-lavfi",
               f"[0]palettegen={make}[p];[1][p]paletteuse=dither=bayer:bayer_scale=3", "-loop", "0", "-f", "gif",
               str(tmp_path / name)]
        subprocess.run(cmd, check=True)
        return (tmp_path / name).read_bytes()

    step = encode.palette_step(v)
    assert step == 4
    cut = two_inputs([(f & mask) | centre for f in frames[::step]], "cut_ref.gif")
    assert (tmp_path / "cut.gif").read_bytes() == cut
    assert two_inputs(frames[::step], "uncut.gif") != cut
    assert two_inputs([(f & mask) | centre for f in frames], "every.gif") != cut


def area_reference(frame: np.ndarray, w: int, h: int) -> np.ndarray:
    """An area average written independently: each output pixel integrates the frame, upsampled by the least
    common multiple of the sizes (so every output pixel covers whole sub-pixels), over its rectangle."""
    H, W = frame.shape[:2]
    ly, lx = math.lcm(H, h), math.lcm(W, w)
    up = frame.astype(np.float64).repeat(ly // H, 0).repeat(lx // W, 1)
    return up.reshape(h, ly // h, w, lx // w, 3).mean(axis=(1, 3))


@pytest.mark.parametrize("size", [(96, 54, 48, 28), (128, 72, 35, 20), (64, 36, 64, 36), (50, 30, 7, 4)])
def test_shrink_is_an_area_average(size):
    W, H, w, h = size
    frame = np.random.default_rng(7).integers(0, 256, (H, W, 3), dtype=np.uint8)
    got = gif.shrink(frame, w, h)
    assert got.shape == (h, w, 3) and got.dtype == np.uint8
    assert np.abs(got.astype(np.float64) - area_reference(frame, w, h)).max() <= 0.5 + 1e-9  # rounding only
    flat = np.full((H, W, 3), 200, np.uint8)
    assert (gif.shrink(flat, w, h) == 200).all()  # a flat frame stays flat: the weights sum to one


@pytest.mark.parametrize("n, m", [(720, 198), (144, 99), (1080, 198), (500, 499), (300, 7), (64, 64)])
def test_the_rows_are_summed_cell_by_cell_as_reduceat_sums_them(n, m):
    """shrink's first pass sums each cell of rows in whole-row passes, not with reduceat: the same integers,
    the last cell running to the end where k[m] rounds down (500 rows into 499: 499.99999 -> 499)."""
    frame = np.random.default_rng(n + m).integers(0, 256, (n, 40, 3), dtype=np.uint8)
    k = np.floor(np.arange(m + 1) * (n / m)).astype(np.int64)
    want = np.add.reduceat(frame, k[:-1], axis=0, dtype=np.int64)
    got = gif._cell_sums(frame, k)
    assert got.shape == want.shape and (got == want).all()


def test_a_gif_frame_of_the_wrong_size_is_refused(tmp_path):
    v = video(20, 20, 96, 54, 48)
    enc = encode.Encoder(tmp_path, "x", v, 2, formats=["gif"])
    with pytest.raises(ValueError, match="48x28"):
        enc.write(np.zeros((54, 96, 3), np.uint8), np.zeros((54, 96, 3), np.uint8))
    enc.abort()
    assert not list(tmp_path.iterdir())
