"""A scene pays only for the effects it calls for: kernels launched and fields allocated prove it."""
import numpy as np
import pytest

from conftest import make_scene
from render.video import pipeline
from render.physics import runtime
from render.physics.stepper import Run

VIDEO = {"width": 160, "height": 90, "fps": 10, "duration": 0.5}
PEND = {"theta1": 2.0, "theta2": 2.6, "spread": 0.1}


def render(tmp_path, system="rigid", effects=("rods", "bobs"), video=VIDEO, **pend):
    scene = make_scene(system, 4, effects=list(effects), pendulums={**PEND, **pend}, video=video)
    frames = []
    meta = pipeline.render(scene, tmp_path / "_".join(effects), frame_hook=lambda f, fr: frames.append(fr.copy()))
    return meta, np.stack(frames)


def trail_or_spring(names):
    return [n for n in names if "trail" in n or "spring" in n]


def test_rigid_without_trails_launches_no_spring_or_trail_kernel(tmp_path):
    meta, _ = render(tmp_path, effects=("rods", "bobs"))
    assert trail_or_spring(meta["kernels"]) == []
    assert trail_or_spring(meta["fields"]) == []
    assert not [n for n in meta["kernels"] + list(meta["fields"]) if "energy" in n]
    assert meta["effects"] == ["rods", "bobs"]


def test_trails_add_exactly_the_trail_work(tmp_path):
    base, without = render(tmp_path, effects=("rods", "bobs"))
    more, with_trails = render(tmp_path, effects=("rods", "bobs", "trails"))
    added = [k for k in more["kernels"] if k not in base["kernels"]]
    assert added and all("trail" in k for k in added), added
    assert [k for k in base["kernels"] if k not in more["kernels"]] == []
    new_fields = set(more["fields"]) - set(base["fields"])
    assert new_fields and all("trail" in f for f in new_fields), new_fields
    assert more["field_bytes"] - base["field_bytes"] == sum(more["fields"][f] for f in new_fields)
    # max compositing: trails only ever add light to the same drawing
    assert (with_trails >= without).all() and (with_trails > without).any()


def test_energy_bookkeeping_is_only_paid_for_when_asked_and_changes_no_pixel(tmp_path):
    base, frames = render(tmp_path, effects=("rods", "bobs"))
    more, frames_e = render(tmp_path, effects=("rods", "bobs", "energy"))
    assert base["energy"] is None and more["energy"]["max_rel_drift"] < 1e-6
    added = [k for k in more["kernels"] if k not in base["kernels"]]
    assert added == ["rigid_energy"]
    np.testing.assert_array_equal(frames, frames_e)


def test_elastic_scene_draws_coils_with_spring_kernels_only(tmp_path):
    meta, frames = render(tmp_path, system="elastic", effects=("springs", "bobs"))
    assert any("spring" in k and "draw" in k for k in meta["kernels"])
    assert "spring_advance" in meta["kernels"] and not any("rod" in k for k in meta["kernels"])
    assert frames.max() > 0


def test_simulate_allocates_no_framebuffer_and_draws_nothing(tmp_path):
    scene = make_scene("rigid", 4, pendulums=PEND, video=VIDEO)
    info = pipeline.simulate(scene, tmp_path / "t.npz")
    assert info["kernels"] == ["rigid_energy", "rigid_advance"]
    assert not [f for f in runtime.allocated if f.startswith("canvas")], runtime.allocated


def test_damping_is_simulated_only_when_called_for(tmp_path):
    """Damping on: energy only falls. Damping off (the same scene, damping 0): conserved to 1e-9."""
    damped, _ = render(tmp_path, effects=("rods", "energy"), damping=0.5)
    assert "damping" in damped["effects"]
    assert damped["energy"]["max_rel_drift"] < 1e-9  # drift counts gains only for a damped scene
    free, _ = render(tmp_path, effects=("rods", "energy"))
    assert "damping" not in free["effects"] and free["energy"]["max_rel_drift"] < 1e-9

    scene = make_scene("rigid", 4, effects=["energy"], pendulums={**PEND, "damping": 0.5}, video=VIDEO)
    run = Run(scene)
    sim = run.sim
    for _ in run.frames():
        pass
    assert (sim.e.to_numpy() < sim.e0.to_numpy()).all()


@pytest.mark.parametrize("effects", [["springs"], ["fractal"], ["rods", "fractal"], ["fractal", "hud"],
                                     ["fractal", "glow"]])
def test_invalid_combinations_are_bad_input(effects):
    from render.config.scene import SceneError
    with pytest.raises(SceneError, match="effects"):
        make_scene("rigid", 2, effects=effects, pendulums=PEND, video=VIDEO)


def hud_work(names):
    return [n for n in names if n.startswith(("hud", "font", "text_"))]


def test_the_hud_is_only_paid_for_when_asked_and_only_adds_light(tmp_path):
    # at 320x180 the HUD fits around the pendulums' nominal view (at 160x90 its corners would reach into it,
    # and the view would shrink to keep clear of them: render/draw/framing.py)
    video = {**VIDEO, "width": 320, "height": 180}
    base, without = render(tmp_path, effects=("rods", "bobs"), video=video)
    assert hud_work(base["kernels"]) == [] and hud_work(base["fields"]) == []
    more, with_hud = render(tmp_path, effects=("rods", "bobs", "hud"), video=video)
    added = [k for k in more["kernels"] if k not in base["kernels"]]
    assert sorted(added) == ["hud_draw", "hud_spread", "text_bytes"], added  # text_bytes once, for the static text
    new_fields = set(more["fields"]) - set(base["fields"])
    assert new_fields == {"hud.spread", "hud.history", "hud.layer", "font.glyphs"}, new_fields
    assert more["field_bytes"] - base["field_bytes"] == sum(more["fields"][f] for f in new_fields)
    # drawn over the finished frame with a max: the pendulums are all still there, and text was added
    assert (with_hud >= without).all() and (with_hud > without).any()


@pytest.mark.parametrize("effects", [["glow"], ["energy", "glow"]])
def test_glow_without_anything_drawn_is_bad_input(effects):
    from render.config.scene import SceneError
    with pytest.raises(SceneError, match="effects: 'glow'"):
        make_scene("rigid", 2, effects=effects, pendulums=PEND, video=VIDEO)
