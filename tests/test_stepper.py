"""The frame loop (render/physics/stepper.py): Taichi started by the run that needs it, frames at their times
against DOP853, the watchdog on the certified run and off where a blow-up is a measurement."""
import numpy as np
import pytest
import taichi as ti

from conftest import make_scene
from render.errors import SimulationError
from render.physics import reference, runtime, stepper
from render.physics.stepper import Run
from render.trust import certify

PEND = {"theta1": 2.0, "theta2": 2.6, "spread": 0.2}
# A stiff spring (ω ≈ 1000/s) at a step 7x past RK4's stability limit (hω < 2.8): it grows ~1e4x a step.
BLOWS_UP = {"pendulums": {"theta1": 1.0, "theta2": 1.5, "spread": 0.2, "stiffness": 1e6},
            "integrator": {"method": "rk4", "dt": 0.02, "allow_unstable": True, "min_faithful": 0.0},
            "video": {"fps": 10, "duration": 2.0}}


def test_a_run_starts_taichi_in_its_scenes_precision_and_a_stale_one_says_so():
    r64 = Run(make_scene("rigid", 3, pendulums=PEND, video={"fps": 10, "duration": 0.3}))
    again = Run(make_scene("rigid", 2, pendulums=PEND, video={"fps": 10, "duration": 0.3}))
    assert again.generation == r64.generation and r64.current  # the same settings: no restart
    assert runtime.real() == ti.f64 and r64.sim.q.to_numpy().dtype == np.float64
    r32 = Run(make_scene("rigid", 3, pendulums=PEND, video={"fps": 10, "duration": 0.3},
                         integrator={"precision": "f32"}))
    assert runtime.real() == ti.f32 and r32.sim.q.to_numpy().dtype == np.float32
    assert r32.current and not r64.current
    with pytest.raises(RuntimeError, match="restarted since this run was built"):
        next(r64.frames())
    assert list(r32.frames()) == [0, 1, 2]


def test_a_run_may_hold_its_scene_in_another_precision_and_add_to_the_log():
    """What a comparison's drawing pass needs: f32 variants' states held in f64, every panel in one log."""
    s32 = make_scene("rigid", 3, pendulums=PEND, video={"fps": 10, "duration": 0.3}, integrator={"precision": "f32"})
    a = Run(s32, precision="f64")
    assert runtime.real() == ti.f64 and a.sim.q.to_numpy().dtype == np.float64
    one = dict(runtime.allocated)
    b = Run(s32, precision="f64", keep_log=True)
    assert b.generation == a.generation and runtime.allocated["state.q"] == 2 * one["state.q"]
    Run(s32, precision="f64")
    assert runtime.allocated == one  # afresh


def test_every_frame_is_at_its_time_and_on_the_dop853_trajectory():
    scene = make_scene("rigid", 4, pendulums=PEND, video={"fps": 20, "duration": 0.5}, effects=["energy"])
    run = Run(scene)
    times = np.arange(scene.frames) / scene.video.fps
    q0, v0 = reference.initial_state(scene)
    truth, _ = reference.solve(scene, (q0, v0), times[-1], t_eval=times, rtol=1e-12, atol=1e-12)
    timings = {"simulate": 0.0}
    seen = []
    for f in run.frames(timings=timings):
        assert run.sim.t == pytest.approx(times[f], abs=1e-12)
        np.testing.assert_allclose(run.sim.q.to_numpy(), truth[f], rtol=0, atol=1e-8)
        seen.append(f)
    assert seen == list(range(scene.frames)) and timings["simulate"] > 0
    assert 0 < run.sim.drift[None] < 1e-9  # the energy was measured every frame, frame 0 the reference


def test_the_certified_run_has_the_watchdog_and_names_the_scenes_pendulum():
    scene = make_scene("elastic", 8, **BLOWS_UP)
    with pytest.raises(SimulationError, match=r"blew up at t=.*\(pendulum 2: NaN/inf") as e:
        certify.certify(scene, indices=np.array([2, 5]))  # subset index 0 is the scene's pendulum 2
    assert "frame " in str(e.value) and "frame 0" not in str(e.value)



@pytest.mark.parametrize("system, over", [("rigid", {}), ("rigid", {"precision": "f32"}), ("rigid", {"trig": "libm"}),
                                          ("triple", {}), ("elastic", {"method": "symplectic_euler"})])
def test_a_run_recorded_in_one_launch_is_the_frame_by_frame_run_to_the_bit(system, over):
    """Run.record (the certificate's runs) steps every frame inside one kernel; Run.frames launches a frame at a
    time. 37 pendulums: three groups of lanes, the last padded (one at a time under libm)."""
    scene = make_scene(system, 37, pendulums=PEND, video={"fps": 10, "duration": 1.2}, integrator=over)
    run = Run(scene)
    one = run.record(scene.frames, watch=True)
    t = run.sim.t
    run.sim.restart()
    each = np.empty_like(one)
    for f in run.frames(energy=False):
        run.sim.q_into(each, f)
    assert run.sim.t == pytest.approx(t, rel=1e-12) and one.shape == (scene.frames, 37, run.sim.D)
    assert np.array_equal(one, each) and not np.array_equal(one[1], one[0])
    n, h = 2 * run.sim.substeps, run.sim.h / 2  # the shadow's way: a finer step
    run.sim.restart()
    fine = run.record(scene.frames, n, h)
    run.sim.restart()
    for _ in run.frames(substeps=n, h=h, energy=False):
        pass
    assert np.array_equal(fine[-1], run.sim.q.to_numpy().reshape(37, -1)) and not np.array_equal(fine, one)


def test_a_recorded_run_that_blows_up_names_the_frame_and_pendulum_the_watchdog_names():
    scene = make_scene("elastic", 8, **BLOWS_UP)
    run = Run(scene)
    with pytest.raises(SimulationError) as each:
        for f in run.frames(energy=False):
            pass
    run.sim.restart()
    with pytest.raises(SimulationError) as one:
        run.record(scene.frames, watch=True)
    assert str(one.value) == str(each.value) and "blew up" in str(one.value)

def test_where_the_watchdog_is_off_a_blow_up_is_a_result():
    """The pilots and the measurements (quality.py, flagship.py) read a blow-up as a broken run."""
    scene = make_scene("elastic", 8, **BLOWS_UP)
    q, _ = certify.trajectory(scene, np.array([2, 5]), "cpu")
    assert q.shape[0] == scene.frames and np.isfinite(q[0]).all() and not np.isfinite(q[-1]).all()


def test_a_free_system_with_the_same_constants_is_reused_and_gives_the_same_states():
    """stepper.build: a second run of the same constants at another step reuses the first's compiled system once
    nothing holds it, and steps exactly as a new one would; a system still held is never shared."""
    import gc
    scene = make_scene("rigid", 5, pendulums=PEND, video={"fps": 10, "duration": 0.5}, integrator={"dt": 2e-3})
    fine = scene.replace(integrator={"dt": 1e-3})

    def last(run):
        for _ in run.frames():
            pass
        return run.sim.q.to_numpy().copy(), dict(runtime.allocated)

    first = Run(scene)
    first_id, (q_coarse, fields) = id(first.sim), last(first)
    held = Run(fine)
    assert id(held.sim) != first_id  # `first` still holds its system
    q_fresh, _ = last(held)
    del first, held
    gc.collect()
    again = Run(fine)
    assert id(again.sim) in {first_id} | {id(b[2]) for b in stepper._built}  # a built one, not a new one
    q_again, fields_again = last(again)
    assert np.array_equal(q_again, q_fresh) and not np.array_equal(q_again, q_coarse)
    assert fields_again == fields  # the run reports the fields it holds, as a new one does
    other = Run(scene.replace(pendulums={"masses": [1.0, 2.0]}))  # another constant: its own kernels
    assert other.sim is not again.sim


def test_a_scene_is_planned_once_and_its_kept_start_cannot_be_written_through(monkeypatch):
    """render/physics/plan.py keeps a scene's start and step: planning it again (under another name, or a
    subset) runs no initial_state, returns the same values, and a caller writing into what it got changes
    nothing kept; starts beyond PLANNED_BYTES are planned afresh every time."""
    from render.config.scene import load
    from render.physics import plan, registry

    monkeypatch.setattr(plan, "_PLANNED", {})
    scene = load("fractal_flip", ["video.width=160", "video.height=90"])
    cls = registry.get(scene.system)
    calls, state = [], cls.initial_state
    monkeypatch.setattr(cls, "initial_state", lambda self: (calls.append(self.scene.name), state(self))[1])
    first = cls(scene)
    fresh_q, fresh_v = state(first)
    q, v = first.start(scene.replace(name="other"))
    assert len(calls) == 1 and np.array_equal(q, fresh_q) and np.array_equal(v, fresh_v)
    q[:] = 99.0
    again = cls(scene, subset=np.array([0, 7]))
    assert len(calls) == 1 and (again.h, again.substeps) == (first.h, first.substeps)
    assert np.array_equal(again.start(scene, np.array([0, 7]))[0], fresh_q[[0, 7]])
    monkeypatch.setattr(plan, "PLANNED_BYTES", fresh_q.nbytes)  # q and v together no longer fit
    bigger = scene.replace(video={"width": 192, "height": 108})
    cls(bigger)
    cls(bigger)
    assert len(calls) == 3
