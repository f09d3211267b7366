"""The up-front budget (render/budget.py): each estimate, its limit, and what the refusal says."""
import shutil
from pathlib import Path

import pytest

from conftest import make_scene
from render import budget, pipeline, registry, runtime
from render.errors import SceneError

SMALL = {"width": 64, "height": 48, "fps": 10, "duration": 1.0}


def check(scene, out=Path("."), simulate=False):
    budget.check(scene, registry.get(scene.system), out, simulate)


def refusal(scene, **kw) -> str:
    with pytest.raises(SceneError) as e:
        check(scene, **kw)
    return str(e.value)


def test_a_small_scene_passes():
    check(make_scene(video=SMALL))
    check(make_scene(video=SMALL), simulate=True)


def test_a_tiny_pinned_dt_is_refused_as_too_small():
    check(make_scene(integrator={"dt": 1e-9}, video={"fps": 60, "duration": 10.0}))  # 1.0e10 steps: within
    msg = refusal(make_scene(integrator={"dt": 1e-10}, video={"fps": 60, "duration": 10.0}))
    assert "integrator.dt: dt too small" in msg and "exceed the step budget of 1e11" in msg
    assert "600 frames x 166666667 substeps" in msg


def test_the_substeps_counter_and_a_subnormal_dt():
    """Two frames within the budget, but more substeps than the kernel's i32 holds; a subnormal dt makes
    1/(fps·dt) infinite, which must still be a refusal, not an OverflowError."""
    msg = refusal(make_scene(integrator={"dt": 1e-11}, video={"fps": 10, "duration": 0.2}))
    assert "substeps per frame exceed the step counter's limit of 2147483647" in msg
    assert "integrator.dt" in refusal(make_scene(integrator={"dt": 5e-324}, video=SMALL))


def test_many_pendulums_for_long_are_refused_naming_count_and_duration():
    msg = refusal(make_scene(count=4_000_000, video={"fps": 60, "duration": 600.0, "formats": ["mp4"]}))
    assert msg.startswith("<test>: pendulums.count, video.duration:") and "step budget" in msg


def test_simulate_keeps_every_frame_in_memory():
    scene = make_scene(count=4_000_000, integrator={"dt": 0.1}, video={"fps": 10, "duration": 3600.0})
    need, key, _ = budget.memory(scene, registry.get(scene.system), simulate=True)
    assert need == 4_000_000 * (2 * 2 + 3) * 8 + 36_000 * 4_000_000 * 5 * 16  # state + kept frames, exactly
    msg = refusal(scene, simulate=True)
    assert "pendulums.count, video.duration: needs about" in msg and "TB of memory" in msg and "limit" in msg


def test_ffmpeg_holding_every_gif_frame_counts_as_memory():
    scene = make_scene(video={"width": 1920, "height": 1080, "gif_width": 1920, "fps": 50, "duration": 3600.0},
                       integrator={"dt": 0.02})
    need, key, detail = budget.memory(scene, registry.get(scene.system), simulate=False)
    assert key == "video.gif_width, video.duration" and "GIF frames held by ffmpeg" in detail
    assert need > 1920 * 1080 * 4 * scene.video.gif_fps * 3600  # an hour of GIF frames of 4-byte pixels
    assert "video.gif_width, video.duration: needs about" in refusal(scene)


def test_output_beyond_the_free_space_is_refused(monkeypatch):
    usage = shutil.disk_usage(".")
    monkeypatch.setattr(budget.shutil, "disk_usage", lambda path: usage._replace(free=10 ** 6))
    msg = refusal(make_scene(video={**SMALL, "duration": 60.0}), out=Path("nowhere/yet"))
    assert "the output needs about" in msg and "1 MB free in ." in msg


def test_the_system_checks_the_auto_step_again_before_any_field():
    """Stiff springs under light bobs: "auto" is known only once the System has its rate."""
    runtime.init("cpu", "f64")
    elastic = next(n for n in registry.names() if "stiffness" in registry.get(n).preset_keys())
    scene = make_scene(elastic, 10, pendulums={"stiffness": 1e12, "masses": [1e-6, 1e-6]},
                       video={"fps": 60, "duration": 20.0})
    check(scene)  # with the step of AUTO_DT it would fit
    before = dict(runtime.allocated)
    with pytest.raises(SceneError, match='integrator.dt: "auto" needs steps of .* exceed the step budget'):
        pipeline.make_system(scene)
    assert runtime.allocated == before


def test_f32_holds_lengths_and_masses_to_its_range():
    with pytest.raises(SceneError, match=r"pendulums.masses\[1\]: 1e\+06 is beyond what f32 arithmetic holds"):
        make_scene(pendulums={"masses": [1.0, 1e6]}, integrator={"precision": "f32"})
    make_scene(pendulums={"masses": [1.0, 1e6]}, integrator={"precision": "f64"})


def test_counts_print_short_unless_rounding_reads_as_the_limit():
    assert budget.num(1234) == "1234" and budget.num(379_202_580) == "3.79e8"
    assert budget.num(budget.STEP_LIMIT + 2) == "100,000,000,002"
