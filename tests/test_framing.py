"""Framing: the view fits everywhere a pendulum can reach, so no bob ever leaves the frame."""
import numpy as np
import pytest

from render.physics import registry
from render.physics.stepper import Run
from render.config.scene import load

W, H, FPS = 256, 144, 30


def bob_pixels_over_the_run(name, *sets):
    """Every bob's pixel position (the canvas's own transform) at every frame of the whole run."""
    scene = load(name, [f"video.width={W}", f"video.height={H}", f"video.fps={FPS}", 'effects=["bobs"]', *sets])
    from render.draw.canvas import Canvas

    run = Run(scene)
    sim = run.sim
    canvas = Canvas(scene, sim)
    seen = []
    for _ in run.frames():
        canvas.launch("bob_pixels")
        seen.append(canvas.pos.to_numpy())
    return scene, sim, canvas, np.stack(seen)  # (frames, N, bobs, 2)


@pytest.mark.parametrize("stiffness", [50, 200])
def test_soft_springs_never_leave_the_frame(stiffness):
    scene, sim, canvas, px = bob_pixels_over_the_run("elastic_fan", f"pendulums.stiffness={stiffness}")
    assert scene.frames == FPS * 20 and px.shape[1:] == (10, 2, 2)
    assert np.isfinite(px).all()
    assert (px[..., 0] >= 0).all() and (px[..., 0] <= W - 1).all(), (px[..., 0].min(), px[..., 0].max())
    assert (px[..., 1] >= 0).all() and (px[..., 1] <= H - 1).all(), (px[..., 1].min(), px[..., 1].max())
    # the springs do stretch well beyond the old fixed frame of 1.15 x the rest lengths: it would have cut them
    radius_m = np.hypot(px[..., 0] - W / 2, px[..., 1] - H / 2).max() / canvas.scale
    assert radius_m > 1.15 * sum(scene.pendulums.lengths)
    assert radius_m <= sim.reach()


def test_the_energy_bound_is_tight_for_stiff_springs_and_rigid_chains_use_their_length():
    def reach(name, *sets):
        scene = load(name, list(sets))
        return registry.get(scene.system)(scene).reach()

    assert 2.0 < reach("elastic_fan") < 2.0 * 1.2  # the default stiffness barely stretches
    assert reach("elastic_fan", "pendulums.stiffness=50") > 2 * reach("elastic_fan", "pendulums.stiffness=1e5") > 4
    assert reach("rigid_chaos") == 2.0 and reach("triple_chaos") == 3.0


def test_a_rigid_fan_fills_but_stays_in_the_frame():
    scene, sim, canvas, px = bob_pixels_over_the_run("rigid_chaos", "video.duration=10")
    assert (px[..., 0] >= 0).all() and (px[..., 0] <= W - 1).all()
    assert (px[..., 1] >= 0).all() and (px[..., 1] <= H - 1).all()
    # fills: the chain's full length spans most of the half-height, and the bobs, flipping, reach it
    reach_px = canvas.scale * sim.reach()
    assert reach_px > 0.8 * H / 2, (reach_px, H)
    assert np.hypot(px[..., 0] - canvas.cx, px[..., 1] - canvas.cy).max() > 0.95 * reach_px
