"""The Taichi physics against an independent formulation (render.physics.reference, scipy DOP853 at rtol 1e-12)."""
import numpy as np
import pytest
import taichi as ti

from conftest import make_scene
from render.physics import reference
from render.physics.stepper import Run

SYSTEMS = {
    "rigid": dict(pendulums={"theta1": 2.0, "theta2": -0.5, "omega1": 0.3, "omega2": -1.0, "spread": 0.4,
                             "lengths": [1.0, 0.7], "masses": [1.5, 0.8], "gravity": 9.81},
                  integrator={"method": "rk4", "dt": 1e-3}),
    "elastic": dict(pendulums={"theta1": 1.2, "theta2": 2.0, "omega1": 0.5, "spread": 0.3,
                               "lengths": [1.0, 0.8], "masses": [1.0, 2.0], "stiffness": 500.0},
                    integrator={"method": "rk4", "dt": 5e-4}),
}


@ti.kernel
def force_and_energy(sim: ti.template(), acc: ti.types.ndarray(), e: ti.types.ndarray()):
    for i in range(sim.n):
        a = sim.force(sim.q[i], sim.v[i])
        for k in ti.static(range(sim.D)):
            acc[i, k] = a[k]
        e[i] = sim.energy(sim.q[i], sim.v[i])


@pytest.mark.parametrize("system", SYSTEMS)
def test_accelerations_and_energy_at_random_states(system):
    scene = make_scene(system, 64, effects=["energy"], video={"fps": 10, "duration": 0.1}, **SYSTEMS[system])
    sim = Run(scene).sim
    rng = np.random.default_rng(7)
    d = sim.D
    scale = 1.0 if system == "rigid" else 0.6
    q = rng.uniform(-np.pi, np.pi, (sim.n, d)) if system == "rigid" else rng.normal(0, scale, (sim.n, d))
    v = rng.normal(0, 2.0, (sim.n, d))
    sim.q.from_numpy(q)
    sim.v.from_numpy(v)
    acc, e = np.zeros((sim.n, d)), np.zeros(sim.n)
    force_and_energy(sim, acc, e)
    np.testing.assert_allclose(acc, reference.accel(scene, q, v), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(e, reference.energy(scene, q, v), rtol=1e-12, atol=1e-10)


@pytest.mark.parametrize("system", SYSTEMS)
def test_short_trajectory_matches_dop853(system):
    scene = make_scene(system, 5, video={"fps": 20, "duration": 1.05}, **SYSTEMS[system])
    run = Run(scene)
    sim = run.sim
    q0, v0 = sim.q.to_numpy(), sim.v.to_numpy()
    np.testing.assert_allclose(np.stack([q0, v0]), np.stack(reference.initial_state(scene)), atol=1e-15)
    for _ in run.frames():
        pass
    q_ref, v_ref = reference.solve(scene, (q0, v0), sim.t, rtol=1e-12, atol=1e-12)
    assert sim.t == pytest.approx(1.0)
    np.testing.assert_allclose(sim.q.to_numpy(), q_ref, atol=1e-8)
    np.testing.assert_allclose(sim.v.to_numpy(), v_ref, atol=1e-7)


# Damped (0.7 1/s) runs against DOP853 after 1 s: each method's own path for the damping (the implicit midpoint's
# momentum rate, Verlet's closing kick) is checked, not only lane_force's. Bounds about 10x the errors measured.
DAMPED = {("rigid", "rk4"): 2e-10, ("rigid", "implicit_midpoint"): 3e-5, ("elastic", "rk4"): 2e-10,
          ("elastic", "verlet"): 2e-5, ("elastic", "yoshida4"): 2e-9}


@pytest.mark.parametrize("system, method", DAMPED, ids=[f"{s}-{m}" for s, m in DAMPED])
def test_damped_trajectory_matches_dop853(system, method):
    def damped(c):
        return make_scene(system, 5, video={"fps": 20, "duration": 1.05}, integrator={**sec["integrator"],
                                                                                      "method": method},
                          pendulums={**sec["pendulums"], "damping": c})

    sec = SYSTEMS[system]
    scene, free = damped(0.7), damped(0.0)
    assert "damping" in scene.effects
    run = Run(scene)
    sim = run.sim
    q0, v0 = sim.q.to_numpy(), sim.v.to_numpy()
    for _ in run.frames():
        pass
    q_ref, _ = reference.solve(scene, (q0, v0), sim.t, rtol=1e-12, atol=1e-12)
    q_free, _ = reference.solve(free, (q0, v0), sim.t, rtol=1e-12, atol=1e-12)
    assert np.abs(q_free - q_ref).max() > 1e-2  # the damping moves the state far more than the bound
    err = np.abs(sim.q.to_numpy() - q_ref).max()
    assert err < DAMPED[system, method], err


@pytest.mark.parametrize("method, order", [("verlet", 2), ("yoshida4", 4)])
def test_damping_keeps_the_symmetric_methods_order(method, order):
    """Verlet's closing kick takes the damping at the step's end, so Yoshida's composition of it stays fourth
    order; with the damping taken at mid-step velocities both were first order (yoshida4 2e-3 off at dt 1e-3)."""
    ladder, errs = (4e-3, 2e-3, 1e-3), []
    for dt in ladder:
        scene = make_scene("elastic", 3, video={"fps": 10, "duration": 1.0},
                           pendulums={**SYSTEMS["elastic"]["pendulums"], "damping": 0.7},
                           integrator={"method": method, "dt": dt})
        run = Run(scene)
        q0, v0 = run.sim.q.to_numpy(), run.sim.v.to_numpy()
        for _ in run.frames():
            pass
        q_ref, _ = reference.solve(scene, (q0, v0), run.sim.t, rtol=1e-13, atol=1e-13)
        errs.append(np.abs(run.sim.q.to_numpy() - q_ref).max())
    slope = np.polyfit(np.log(ladder), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.3, (errs, slope)


def test_rk4_f64_conserves_energy_on_classic_for_10_s():
    from render.config.scene import load
    scene = load("classic", ["video.duration=10.05", "video.fps=20"])
    assert scene.integrator.method == "rk4" and scene.integrator.precision == "f64"
    run = Run(scene)
    sim = run.sim
    worst = 0.0
    for _ in run.frames():
        worst = max(worst, abs(sim.e[0] - sim.e0[0]) / abs(sim.e0[0]))
    assert sim.t == pytest.approx(10.0)
    assert worst < 1e-6, worst
    assert sim.drift[None] == pytest.approx(worst, rel=1e-9)


def test_libm_trig_is_an_option_that_agrees_with_inline_on_a_regular_orbit():
    """integrator.trig = "libm" (the C library's sin/cos, whose last bits differ between CPUs) stays an option:
    on an orbit that is not chaotic (small swings, so last-bit differences do not grow), it and the inline
    sin/cos both match DOP853, and each other to round-off."""
    from render.config.scene import load
    ends = {}
    for trig in ("libm", "inline"):
        scene = load("classic", ["pendulums.theta1=0.3", "pendulums.theta2=0.2", "video.duration=5.05",
                                 "video.fps=20", f'integrator.trig="{trig}"'])
        run = Run(scene)
        sim = run.sim
        assert sim.libm == (trig == "libm")
        q0, v0 = sim.q.to_numpy(), sim.v.to_numpy()
        for _ in run.frames():
            pass
        q_ref, _ = reference.solve(scene, (q0, v0), sim.t, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(sim.q.to_numpy(), q_ref, atol=1e-9)
        ends[trig] = sim.q.to_numpy()
    np.testing.assert_allclose(ends["libm"], ends["inline"], rtol=0, atol=1e-12)
