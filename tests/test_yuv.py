"""render/video/yuv.py: the MP4's frames converted before the pipe are BT.601 at limited range, as ffmpeg's own
conversion of rgb24 made them, and an MP4 made from them decodes back to its frames."""
import subprocess
import types

import imageio.v3 as iio
import imageio_ffmpeg
import numpy as np
import pytest

from render.video import encode, yuv

EXE = imageio_ffmpeg.get_ffmpeg_exe()


@pytest.fixture(autouse=True, scope="module")
def taichi():
    """The kernel runs on the Taichi a Run starts, as in a render."""
    from render.config.scene import load
    from render.physics.stepper import Run
    Run(load("classic", ["video.duration=0.1"]), "cpu")


def frame(w: int, h: int, seed: int = 0) -> np.ndarray:
    """Random colours over a black frame with a few lit patches: black groups, lit ones and groups of both."""
    rng = np.random.default_rng(seed)
    f = np.zeros((h, w, 3), np.uint8)
    for _ in range(6):
        y, x = rng.integers(0, h - 4), rng.integers(0, w - 4)
        dy, dx = rng.integers(1, 12), rng.integers(1, 20)
        f[y:y + dy, x:x + dx] = rng.integers(0, 256, (min(dy, h - y), min(dx, w - x), 3))
    f[-2:, -3:] = 255  # white in the last group's corner
    return f


def reference(f: np.ndarray) -> np.ndarray:
    """BT.601, limited range, in floating point from its definition (Y' = 0.299 R + 0.587 G + 0.114 B, scaled to
    16..235, chroma to 16..240 from each 2×2 block's mean colour)."""
    rgb = f.astype(np.float64) / 255.0
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    luma = 0.299 * r + 0.587 * g + 0.114 * b
    h, w = luma.shape
    mean = rgb.reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
    ml = 0.299 * mean[..., 0] + 0.587 * mean[..., 1] + 0.114 * mean[..., 2]
    cb, cr = (mean[..., 2] - ml) / 1.772, (mean[..., 0] - ml) / 1.402
    planes = [16 + 219 * luma, 128 + 224 * cb, 128 + 224 * cr]
    return np.concatenate([np.floor(p + 0.5).ravel() for p in planes])


# 68 and 44: rows of 17 and 11 groups, a run of yuv.LANES and a short one, and a short one alone
@pytest.mark.parametrize("w,h,seed", [(64, 36, 0), (128, 72, 1), (1280, 720, 2), (68, 36, 3), (44, 10, 4)])
def test_matches_bt601_within_one_level(w, h, seed):
    f = frame(w, h, seed)
    got, want = yuv.convert(f).astype(int), reference(f)
    assert got.shape == (yuv.size(w, h),)
    diff = np.abs(got - want)
    assert diff.max() <= 1  # fixed point against exact arithmetic: a tie may round the other way
    assert (diff == 0).mean() > 0.995
    black = yuv.convert(np.zeros_like(f))
    assert (black[:w * h] == 16).all() and (black[w * h:] == 128).all()


def test_luma_is_ffmpegs_own():
    """ffmpeg's conversion of the same rgb24 frame, which the MP4 got before: the same Y within a level."""
    f = frame(64, 36, 3)
    cmd = [EXE, "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", "64x36", "-i", "-",
           "-pix_fmt", "yuv420p", "-f", "rawvideo", "-"]
    theirs = np.frombuffer(subprocess.run(cmd, input=f.tobytes(), capture_output=True, check=True).stdout, np.uint8)
    n = 64 * 36
    assert np.abs(yuv.convert(f)[:n].astype(int) - theirs[:n]).max() <= 1


@pytest.mark.parametrize("w,planar", [(64, True), (66, True), (64, False)])  # 66: not yuv.fits(), ffmpeg converts
def test_mp4_decodes_back(tmp_path, w, planar):
    h, n = 36, 12
    v = types.SimpleNamespace(fps=30, gif_fps=20, width=w, height=h, gif_width=32, formats=("mp4",), palette="fan")
    assert yuv.fits(w, h) == (w % 4 == 0)
    frames = [np.roll(np.kron(frame(w // 2, h // 2, 4), np.ones((2, 2, 1), np.uint8)), 2 * i, axis=1)
              for i in range(n)]
    enc = encode.Encoder(tmp_path, "x", v, n, planar=planar)
    assert [t.planar for t in enc.targets] == [planar and w % 4 == 0]
    for f in frames:
        enc.write(f)
    enc.close()
    back = list(iio.imiter(tmp_path / "x.mp4", plugin="FFMPEG"))
    assert len(back) == n
    for f, b in zip(frames, back):
        mse = ((b.astype(float) - f) ** 2).mean()
        assert 10 * np.log10(255 ** 2 / mse) > 24


@pytest.mark.parametrize("w", [320, 322])  # 322: not yuv.fits(), so the MP4's pipe is fed the frames themselves
def test_a_render_drawing_over_one_frame_encodes_what_new_frames_would(tmp_path, w):
    """pipeline.render draws every frame into one array where the Encoder does not queue it (yuv420p is
    converted within write()); a frame_hook turns that off. Both give the same MP4, byte for byte."""
    from render.config.scene import load
    from render.video import pipeline
    scene = load("classic", [f"video.width={w}", "video.height=180", "video.fps=30", "video.duration=2",
                             'video.formats=["mp4"]'])
    mp4 = []
    for hook, out in ((None, tmp_path / "one"), (lambda f, frame: None, tmp_path / "new")):
        pipeline.render(scene, out, frame_hook=hook)
        mp4.append((scene.out_dir(out) / "classic.mp4").read_bytes())
    assert mp4[0] == mp4[1]


@pytest.mark.parametrize("name, w, h", [("rigid_chaos", 320, 180), ("rainbow_1000", 320, 180),
                                        ("elastic_fan", 324, 182), ("triple_chaos", 640, 360), ("classic", 320, 180)])
def test_the_tiles_a_canvas_calls_dark_are_black_and_are_not_read(name, w, h):
    """A fan's Source says which tiles of the frame it drew last may hold anything but black (render/draw/compose.py's
    lit_tiles: what the frame pass composed, and the HUD's boxes), and the MP4's conversion reads no other: every
    tile it calls dark is black, and the yuv420p frames are those of reading every pixel. Over 4 s of chaos
    (trails fading out tile by tile, the HUD's clock), drawn over one frame as a render does, under max and glow
    compositing, at a width of whole tiles (word rows) and one that is not (324)."""
    from render.config.scene import load
    from render.video import pipeline
    scene = load(name, [f"video.width={w}", f"video.height={h}", "video.fps=30", "video.duration=4"])
    src, frame = pipeline.Source(scene), None
    for _ in range(scene.frames):
        frame = src.next_frame(frame)
        tiles, side = src.lit_tiles()
        dark = np.repeat(np.repeat(tiles == 0, side, axis=0), side, axis=1)[:h, :w]
        assert dark.any() and not frame[dark].any()
        np.testing.assert_array_equal(yuv.convert(frame, (tiles, side)), yuv.convert(frame))
    with pytest.raises(ValueError, match="do not tile"):
        yuv.convert(frame, (tiles[1:], side))


def test_a_frame_something_else_draws_into_has_no_dark_tiles():
    """A Poincaré section draws its half of the frame after the frame pass: its Source knows no dark tiles."""
    from render.config.scene import load
    from render.video import pipeline
    src = pipeline.Source(load("poincare_shell", ["video.width=320", "video.height=180", "video.duration=0.1"]))
    src.next_frame()
    assert src.canvas.section is not None and src.lit_tiles() is None
