"""The canvas draws into the frame it drew last without clearing it (render/draw/canvas.py: kept): the frame
pass zeroes the tiles that held light and are dark now, and the HUD's boxes at every frame. The bytes must be
those of a new, zeroed frame, for every effect that draws into the frame."""
import numpy as np
import pytest

from render.config.scene import load
from render.draw import canvas as canvas_module
from render.draw.canvas import Canvas
from render.physics.stepper import Run
from render.video import pipeline


def force_bands(monkeypatch) -> list:
    """Every canvas made from now on draws in a band per thread, however light its frame (BANDED_WORK);
    returns the list their band counts are appended to."""
    monkeypatch.setattr(canvas_module, "BANDED_WORK", 0)
    bands, init = [], Canvas.__init__

    def counted(self, *args, **kwargs):
        init(self, *args, **kwargs)
        bands.append(self.bands)
    monkeypatch.setattr(Canvas, "__init__", counted)
    return bands


@pytest.mark.parametrize("name", ["rigid_chaos", "rainbow_1000"])  # max compositing, and glow's light
def test_drawing_in_bands_gives_the_same_bytes_at_any_thread_count(tmp_path, name, monkeypatch):
    """On the CPU each thread can draw every primitive into a band of rows of its own: one band at 1 thread,
    bands of uneven height at 3, thin ones at 8, and the same frames from each, and from a frame light enough
    to draw on the launching thread alone, as these small ones are unless bands are forced."""
    scene = load(name, ["video.width=320", "video.height=180", "video.duration=1", 'video.formats=["mp4"]'])
    runs = []

    def render(threads, out):
        frames = []
        pipeline.render(scene, out, threads=threads, frame_hook=lambda f, fr: frames.append(fr.tobytes()))
        runs.append(frames)
    render(8, tmp_path / "light")
    bands = force_bands(monkeypatch)
    for threads in (1, 3, 8):
        render(threads, tmp_path / str(threads))
    assert len(runs[0]) == scene.frames and runs[0] == runs[1] == runs[2] == runs[3]
    assert {1, 3, 8} <= set(bands), bands


@pytest.mark.parametrize("name, banded", [("rigid_chaos", False), ("rigid_chaos", True), ("rainbow_1000", True),
                                          ("elastic_fan", False), ("poincare_shell", False)])
def test_drawing_over_the_last_frame_gives_the_bytes_of_a_new_frame(name, banded, monkeypatch):
    # rigid_chaos: the HUD's clock changes its digits every frame, and its trails fade out tile by tile
    if banded:
        force_bands(monkeypatch)
    scene = load(name, ["video.width=320", "video.height=180", "video.fps=30", "video.duration=4"])
    runs = []
    for kept in (False, True):
        run = Run(scene)
        canvas = Canvas(scene, run.sim)
        frame, frames = canvas.new_frame(), []
        for _ in run.frames():
            frames.append(canvas.draw(frame if kept else None).tobytes())
        runs.append(frames)
    assert len(runs[1]) == scene.frames and runs[0] == runs[1]


def test_a_frame_drawn_into_that_is_not_the_last_one_is_cleared_first():
    scene = load("rigid_chaos", ["video.width=320", "video.height=180", "video.fps=30", "video.duration=1"])
    run = Run(scene)
    canvas = Canvas(scene, run.sim)
    a, b = canvas.new_frame(), np.full((180, 320, 3), 255, np.uint8)
    for f in run.frames():
        want = canvas.draw(a).copy()
        if f == 20:
            break
    canvas.restart()
    run.sim.restart()
    for f in run.frames():
        got = canvas.draw(b if f % 2 else a)  # alternating: neither is the frame drawn last
        if f == 20:
            break
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("name", ["rigid_chaos", "triple_chaos", "elastic_fan"])
def test_a_layer_of_bytes_gives_the_frames_a_layer_of_floats_gives(name, monkeypatch):
    """The byte of a max is the max of the bytes, to the bit: over 12 s of chaos, with trails and the HUD, in an
    f64 runtime (where a primitive's colour times its coverage is an f64 value, rounded to the f32 a layer of
    floats holds before its byte is taken)."""
    scene = load(name, ["video.width=320", "video.height=180", "video.fps=30", "video.duration=12"])
    runs = []
    for byte_layer in (False, True):
        monkeypatch.setattr(canvas_module, "BYTE_LAYER", byte_layer)
        run = Run(scene)
        canvas = Canvas(scene, run.sim)
        assert canvas.rgb.dtype == (canvas_module.ti.u8 if byte_layer else canvas_module.ti.f32)
        frames = [canvas.draw().tobytes() for _ in run.frames()]
        runs.append(frames)
    bad = [f for f, (a, b) in enumerate(zip(*runs)) if a != b]
    assert len(runs[1]) == scene.frames and not bad, f"{len(bad)} frames differ, the first {bad[:1]}"


@pytest.mark.parametrize("name, byte_layer", [("rigid_chaos", True), ("rigid_chaos", False), ("triple_chaos", True),
                                              ("elastic_fan", True)])
def test_rows_written_as_words_give_the_bytes_written_one_by_one(name, byte_layer, monkeypatch):
    """Where the width is whole tiles the frame pass writes a tile's row as words (render/draw/compose.py's
    put_row): the same frames as byte by byte, drawn over the last frame (tiles that go dark are zeroed as words
    too), with a partial row of tiles at the bottom (180 = 22.5 tiles), trails, the HUD, and a layer of bytes or
    of floats. A frame the words cannot alias is refused, not drawn into a copy."""
    monkeypatch.setattr(canvas_module, "BYTE_LAYER", byte_layer)
    scene = load(name, ["video.width=320", "video.height=180", "video.fps=30", "video.duration=6"])
    runs = []
    for words in (False, True):
        run = Run(scene)
        canvas = Canvas(scene, run.sim)
        assert canvas.word_rows  # 320 = 40 tiles
        canvas.word_rows = words  # before the first draw compiles draw_frame for this canvas
        frame = canvas.new_frame()
        runs.append([canvas.draw(frame).tobytes() for _ in run.frames()])
    bad = [f for f, (a, b) in enumerate(zip(*runs)) if a != b]
    assert len(runs[1]) == scene.frames and not bad, f"{len(bad)} frames differ, the first {bad[:1]}"
    for wrong in (np.zeros((180, 640, 3), np.uint8)[:, ::2], np.zeros((90, 640, 3), np.uint8)):
        with pytest.raises(ValueError, match="C-contiguous 180x320x3 uint8"):
            canvas.draw(wrong)
