"""The GIF drawn at its own size and rate (render/video/gif.py): its clock reads back, its rainbow stays a rainbow,
its frames are the small canvas's, the pipe never carries a frame larger than gif_width, and the bytes do
not depend on the thread count."""
import dataclasses
import shutil

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import ocr_line
from render.config.scene import load
from render.video import downscale, encode, gif, palette, pipe, pipeline

# A frame larger than the GIF's and a rate higher than its own, so the GIF has a canvas of its own; short, since
# every render compiles its kernels.
W, H, FPS, SECONDS = 480, 270, 30, 1.5
GW = 352  # the shipped gif_width: the size its HUD is designed for


def scene_of(name, *sets):
    return load(name, [f"video.width={W}", f"video.height={H}", f"video.fps={FPS}", f"video.duration={SECONDS}",
                       'video.formats=["mp4", "gif"]', f"video.gif_width={GW}", *sets])


def render(scene, out, threads=1):
    """Render `scene`, keeping what the GIF's pipe was given (every queued frame's shape; its end as ("end", the
    index of the video frame being written then, or None in close())) and the GIF frames the pipeline handed the
    encoder (video frame index -> frame)."""
    piped, small, writing = [], {}, [None]
    real_init, real_write = pipe.Pipe.__init__, encode.Encoder.write

    def init(self, *a, **kw):
        real_init(self, *a, **kw)
        if self.small is not None:
            put = self.queue.put
            self.queue.put = lambda x, *b, **c: (piped.append(("end", writing[0]) if x is None else x.shape),
                                                 put(x, *b, **c))

    def write(self, frame, gif_frame=None, lit=None):
        if gif_frame is not None:
            small[self.written] = gif_frame.copy()
        writing[0] = self.written
        try:
            return real_write(self, frame, gif_frame, lit)
        finally:
            writing[0] = None

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pipe.Pipe, "__init__", init)
        mp.setattr(encode.Encoder, "write", write)
        pipeline.render(scene, out, threads=threads)
    d = scene.out_dir(out)
    return d / f"{scene.name}.gif", d / f"{scene.name}.mp4", piped, small


@pytest.fixture(scope="module")
def rigid(tmp_path_factory):
    scene = scene_of("rigid_chaos")
    return (scene, *render(scene, tmp_path_factory.mktemp("rigid")))


def picks(scene) -> list[int]:
    """The video frame each GIF frame shows (ffmpeg's fps filter's choice, gif.repeats)."""
    return [i for i, n in enumerate(gif.repeats(scene.video, scene.frames)) for _ in range(n)]


# ---------------------------------------------------------------- (1) the clock reads back
def read_clock(img: np.ndarray) -> float | None:
    """The clock's seconds in a crop around it, by tesseract (conftest.ocr_line); None if it read no clock: every
    blur must read the whole "t = 1.23 s"."""
    return ocr_line(img, "0123456789.ts= ", r"\s*t\s*=\s*(\d+\.\d\d)\s*s\s*")


def clock_read_back(scene, path, crop):
    """Every GIF frame's clock, read back: each time read is the time of the video frame that GIF frame shows
    (within a frame), and nearly all frames read (tesseract misses the odd one; it never made one up here)."""
    frames = iio.imread(path)
    shown = picks(scene)
    assert len(frames) == len(shown)
    read = [read_clock(frame[crop]) for frame in frames]
    for k, (got, f) in enumerate(zip(read, shown)):
        t = f / scene.video.fps  # what the clock must say
        assert got is None or abs(got - t) <= 1 / scene.video.fps + 0.005, (k, got, t)
    assert sum(got is not None for got in read) >= 0.9 * len(read), read
    assert len({got for got in read if got is not None}) >= 0.9 * len(read) - 1  # the clock moves


needs_tesseract = pytest.mark.skipif(shutil.which("tesseract") is None, reason="tesseract is not installed")


@needs_tesseract
def test_the_clock_reads_back_from_the_gif(rigid):
    scene, path = rigid[0], rigid[1]
    clock_read_back(scene, path, np.s_[:17, :90])  # the HUD's clock, top left, in the 6x13 face at 198 px


@needs_tesseract
def test_the_shared_clock_reads_back_from_a_comparisons_gif(tmp_path):
    scene = scene_of("compare_precision", "video.duration=1.0")
    path = render(scene, tmp_path)[0]
    clock_read_back(scene, path, np.s_[:18, GW // 2 - 50:GW // 2 + 50])  # the split screen's band, top centre


# ---------------------------------------------------------------- (3) the GIF's frames are the small canvas's
def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return 99.0 if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


def test_the_gif_frames_are_the_gif_canvas_frames(rigid):
    scene, path, _, piped, small = rigid
    w, h = gif.size(scene.video)
    assert (w, h) == (GW, 198)
    shown = picks(scene)
    assert sorted(small) == sorted(set(shown))  # a GIF frame was drawn for exactly the video frames it shows
    frames = iio.imread(path)[..., :3]
    for k, f in enumerate(shown):
        # palette quantisation (48 colours, dithered) is all that parts them
        assert psnr(frames[k], small[f]) >= 24.0, (k, psnr(frames[k], small[f]))
    # ... and they are not the video's frame shrunk: the text and the rods are drawn for this size
    assert all(s.shape == (h, w, 3) for s in small.values())
    # the pipe: only frames of the GIF's size, every palette_step-th GIF frame (for the palette), then the end,
    # with the frame that brought the last of those (palettegen makes the palette while the rest are drawn)
    step = palette.palette_step(scene.video)
    assert step > 1 and set(piped[:-1]) == {(h, w, 3)}
    assert len(piped) - 1 == len(shown[::step]) and piped[-1] == ("end", shown[::step][-1])
    assert shown[::step][-1] < scene.frames - 1  # so before the last frame, here


@pytest.mark.parametrize("name", ["rigid_chaos", "rainbow_1000"])  # max compositing, and glow's hairlines
def test_skipped_frames_leave_the_path_that_stamping_every_frame_leaves(name):
    """The GIF's canvas keeps where the last bob was at each video frame it skips and stamps the path through
    those points with the next frame it draws: the same bytes as a canvas that stamps its trail at every video
    frame (what a trail is: the curve the bob drew), at one launch per skipped frame, not two."""
    scene = scene_of(name, "video.fps=60", "video.duration=1.0")  # 60 -> 20 fps: two frames skipped in a row
    src = pipeline.Source(scene)
    frames = gif.Frames(src, scene.video, {"draw": 0.0})
    assert gif.gap(frames.repeats) == 2
    w, h = gif.size(scene.video)
    ref = gif._Canvas(src, w, h, gif.rate(scene.video), 0).canvas  # follows nothing: stamped below, every frame
    launches = []
    mine = frames.own.canvas
    real = mine.launch
    mine.launch = lambda kernel, *a: (launches.append(kernel), real(kernel, *a))[1]
    drawn = 0
    for f in range(src.frames):
        src.next_frame()
        before = len(launches)
        got = frames.frame(f, None)
        if got is None:
            assert len(launches) - before <= 1
            if ref.frame_no:
                ref.launch("bob_pixels")
                ref.launch("stamp_trails", 0, 0)
            continue
        want = ref.draw(None, f / scene.video.fps)
        assert got.tobytes() == want.tobytes(), f"video frame {f}"
        drawn += 1
    assert drawn == sum(map(bool, frames.repeats)) == 20 and "trail_path_pixels" in launches


def test_gap_is_the_longest_run_of_skipped_frames():
    assert gif.gap([1, 0, 0, 1, 0, 1]) == 2 and gif.gap([1, 1]) == 0 and gif.gap([0, 0, 0]) == 3
    v = load("rigid_chaos").video
    for fps, gap in ((60, 2), (30, 1), (20, 0), (50, 2)):
        assert gif.gap(gif.repeats(dataclasses.replace(v, fps=fps), 5 * fps)) == gap, fps


def test_the_gif_is_drawn_not_shrunk(rigid, tmp_path):
    """The small canvas's frames beat the video's frame area-averaged at reading the HUD: they have its text's
    full contrast (white glyph pixels) where the shrunk frame has grey."""
    scene, path, mp4, _, small = rigid
    first = min(small)
    big = iio.imread(mp4, index=first)  # decoded: close enough to the raw frame for its text's contrast
    w, h = gif.size(scene.video)
    shrunk = downscale.shrink(big, w, h)[:17, :90].max(axis=2)
    drawn = small[first][:17, :90].max(axis=2)
    assert (drawn >= 230).sum() > 3 * max((shrunk >= 230).sum(), 1)


# ---------------------------------------------------------------- (4) thread count
def test_the_gif_is_byte_identical_at_one_and_two_threads(rigid, tmp_path):
    scene, path = rigid[0], rigid[1]
    again = render(scene, tmp_path, threads=2)[0]
    assert again.read_bytes() == path.read_bytes()


def test_a_gif_alone_is_the_same_bytes_and_no_frame_of_the_videos_size_is_drawn(rigid, tmp_path):
    """formats = ["gif"]: the GIF's canvas draws from the System as before, and the video's canvas, whose frames
    nothing would take, draws none (they were half of such a render's time)."""
    from render.draw.canvas import Canvas
    scene, path = rigid[0], rigid[1]
    alone = dataclasses.replace(scene, video=dataclasses.replace(scene.video, formats=("gif",)))
    sizes, real_draw = [], Canvas.draw

    def draw(self, *a, **kw):
        sizes.append((self.w, self.h))
        return real_draw(self, *a, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Canvas, "draw", draw)
        pipeline.render(alone, tmp_path, threads=1)
    d = alone.out_dir(tmp_path)
    assert sorted(p.name for p in d.iterdir()) == ["metadata.json", f"{alone.name}.gif"]
    assert (d / f"{alone.name}.gif").read_bytes() == path.read_bytes()
    assert set(sizes) == {gif.size(scene.video)} and len(sizes) == len(picks(scene))


# ---------------------------------------------------------------- (2) the rainbow stays a rainbow
BINS = 36


def hue_histogram(frames) -> np.ndarray:
    """The hue of the coloured pixels (brightest channel > 0.25, chroma > 0.35 of it), in 36 bins of 10°,
    normalised to sum to one."""
    counts = np.zeros(BINS)
    for f in frames:
        x = f[..., :3].astype(np.float64) / 255
        hi, lo = x.max(-1), x.min(-1)
        c = hi - lo
        sel = (hi > 0.25) & (c > 0.35 * hi)
        r, g, b, c, hi = x[..., 0][sel], x[..., 1][sel], x[..., 2][sel], c[sel], hi[sel]
        h = np.where(hi == r, ((g - b) / c) % 6, np.where(hi == g, (b - r) / c + 2, (r - g) / c + 4)) / 6
        counts += np.bincount(np.minimum((h * BINS).astype(int), BINS - 1), minlength=BINS)
    return counts / counts.sum()


def hue_distance(p, q) -> float:
    """Total variation between hue histograms: the share of the coloured pixels whose hue lies in another 10°
    bin (0: the same hues, 1: none in common). A palette that gathers the spectrum on a few hues leaves most
    bins empty and scores high, even when its few hues are spread around the circle."""
    return 0.5 * float(np.abs(p - q).sum())


def test_hue_distance_is_the_share_of_pixels_moved():
    p = np.zeros(BINS)
    p[3] = 1
    flat = np.full(BINS, 1 / BINS)
    assert hue_distance(p, p) == 0 and hue_distance(p, np.roll(p, 1)) == 1
    assert hue_distance(flat, p) == pytest.approx(1 - 1 / BINS)
    assert hue_distance(flat, np.where(np.arange(BINS) % 2, 2 / BINS, 0)) == pytest.approx(0.5)  # every other hue


# Measured at this test's settings (480x270 at 30 fps, 2 s, the GIF 352 px at 20 fps): the video's frame
# area-averaged with one 64 colour palette (as before) 0.49; drawn at 352 px with one 48 colour palette 0.55;
# drawn with 256 colours per frame (as now) 0.32. What is left is mostly the drawing, not the palette: thin
# lines of light cover a larger share of a smaller frame, so its coloured pixels are not weighted alike.
HUE_LIMIT = 0.4


def test_the_rainbow_gif_keeps_the_videos_hues(tmp_path):
    """rainbow_1000's GIF against its MP4: the hues of the coloured pixels, compared as histograms. With one
    small palette for the whole GIF its hues gather on a few greens and purples; 256 colours per frame keep
    the spectrum (HUE_LIMIT)."""
    # without its minimal HUD: the amber clock and the chart's colours are a larger share of the small frame,
    # and what is measured here is the palette's hold on the pendulums' spectrum
    scene = scene_of("rainbow_1000", "video.duration=2.0", 'effects=["rods", "trails", "energy", "glow"]')
    path, mp4 = render(scene, tmp_path)[:2]
    d = hue_distance(hue_histogram(iio.imiter(mp4)), hue_histogram(iio.imiter(path)))
    assert d < HUE_LIMIT, d


def test_a_gif_of_the_videos_size_and_rate_keeps_every_frame(tmp_path):
    """Such a GIF takes the video's own frames, into which a render draws the next frame: each is kept as it
    was handed over (all had been the last one, and the palette was sampled from frames being redrawn)."""
    scene = load("classic", ["video.width=160", "video.height=90", "video.fps=10", "video.duration=2",
                             'video.formats=["mp4", "gif"]'])
    path, _, _, small = render(scene, tmp_path)
    decoded = iio.imread(path, index=None)[..., :3]
    assert len(decoded) == len(small) == scene.frames
    last = small[scene.frames - 1]
    for i, frame in small.items():
        assert psnr(decoded[i], frame) > 30, i
        if psnr(frame, last) < 30:  # a frame unlike the last one: the GIF's is not the last one either
            assert psnr(decoded[i], last) < psnr(decoded[i], frame), i
    again, _, _, _ = render(scene, tmp_path / "again", threads=2)
    assert again.read_bytes() == path.read_bytes()
