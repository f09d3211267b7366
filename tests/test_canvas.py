"""The canvas draws into the frame it drew last without clearing it (render/draw/canvas.py: kept): the frame
pass zeroes the tiles that held light and are dark now, and the HUD's boxes at every frame. The bytes must be
those of a new, zeroed frame, for every effect that draws into the frame."""
import numpy as np
import pytest

from render.config.scene import load
from render.draw.canvas import Canvas
from render.physics.stepper import Run


@pytest.mark.parametrize("name", ["rigid_chaos", "rainbow_1000", "elastic_fan", "poincare_shell"])
def test_drawing_over_the_last_frame_gives_the_bytes_of_a_new_frame(name):
    # rigid_chaos: the HUD's clock changes its digits every frame, and its trails fade out tile by tile
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
