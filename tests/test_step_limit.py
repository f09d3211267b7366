"""The step limit is sound for the methods that gain energy on a chain's (θ, ω): symplectic Euler and RK2 at
0.95 of their stated limit run a whole video from random rigid and triple starts without blowing up or
tripping the energy watchdog; and the watchdog tells a blow-up, energy gained and energy lost apart."""
import math

import numpy as np
import pytest

from conftest import make_scene, run_cli
from render.physics import integrators, registry
from render.physics.stepper import Run
from render.errors import SimulationError

STARTS = 20
DURATION = 5.0


def random_starts(seed=22):
    """Rigid and triple chains, masses to 1:10, lengths to 1:5; half undamped, half damped by up to 50 1/s."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(STARTS):
        system, links = ("rigid", 2) if k % 2 else ("triple", 3)
        pend = {"masses": [1.0, *10.0 ** rng.uniform(-1, 1, links - 1)],
                "lengths": [1.0, *5.0 ** rng.uniform(-1, 1, links - 1)],
                "damping": 0.0 if k % 4 < 2 else float(rng.uniform(0, 50)), "spread": 0.0}
        for i in range(1, links + 1):
            pend[f"theta{i}"], pend[f"omega{i}"] = float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(-3, 3))
        out.append((system, pend))
    return out


def stated_limit(scene) -> float:
    plan = registry.get(scene.system)(scene)
    q0, v0 = plan.initial_state()
    return integrators.step_limit(scene, plan.omega_max(q0, v0), plan.energy_limit(q0, v0, scene.integrator.method))


def run(scene):
    """The scene through the System's advance and the watchdog, as a render steps it."""
    runner = Run(scene)
    for _ in runner.frames():
        pass
    return runner.sim


@pytest.mark.slow  # 40 scenes, each compiles its kernels: about a minute per method
@pytest.mark.parametrize("method", ["symplectic_euler", "rk2"])
def test_095_of_the_stated_limit_runs_clean_from_random_chains(method):
    for system, pend in random_starts():
        base = make_scene(system, 1, pendulums=pend, integrator={"method": method},
                          video={"fps": 2, "duration": DURATION}, effects=["energy"])
        scene = base.replace(integrator={"dt": 0.95 * stated_limit(base)})
        sim = run(scene)  # raises on a blow-up or energy drift beyond max_drift (0.05)
        assert np.isfinite(sim.q.to_numpy()).all() and sim.drift[None] <= 0.05, (system, pend)


@pytest.mark.parametrize("stiffness, damping", [(2e3, 0.0), (1e5, 0.0), (2e3, 5.0)])
def test_rk2_on_springs_at_095_of_its_stated_limit_runs_clean(stiffness, damping):
    """Symplectic Euler is symplectic on the springs' Cartesian coordinates (no energy limit); RK2 is not."""
    pend = {"theta1": 2.0, "theta2": 2.6, "spread": 0.3, "stiffness": stiffness, "damping": damping}
    base = make_scene("elastic", 4, pendulums=pend, integrator={"method": "rk2"},
                      video={"fps": 5, "duration": DURATION}, effects=["energy"])
    limit = stated_limit(base)
    plan = registry.get("elastic")(base)
    assert limit < integrators.stability_limit(base, plan.omega_max(*plan.initial_state()))  # the energy binds
    assert plan.energy_limit(*plan.initial_state(), "symplectic_euler") == math.inf
    sim = run(base.replace(integrator={"dt": 0.95 * limit}))
    assert np.isfinite(sim.q.to_numpy()).all() and sim.drift[None] <= 0.05


@pytest.mark.parametrize("method", ["verlet", "yoshida4"])
@pytest.mark.parametrize("damping", [50.0, 1000.0])
def test_damped_springs_run_clean_up_to_095_of_the_stated_limit(method, damping):
    """Damping c adds to the rate the limit is stated over, so a heavily damped scene is offered h·c up to the
    method's 2 or 1.573. Yoshida's middle step, of negative length, once met a pole in its damping factor (the
    trapezoidal one, at h·c = 1.175) and grew it for h·c in about (1.13, 1.21); the damping split off with a
    Padé factor has none. Run at 0.95 of the limit and, below it, at h·c = 1.17."""
    pend = {"theta1": 2.0, "theta2": 2.6, "spread": 0.3, "stiffness": 2e3, "damping": damping}
    base = make_scene("elastic", 4, pendulums=pend, integrator={"method": method},
                      video={"fps": 5, "duration": 2.0}, effects=["energy"])
    limit = stated_limit(base)
    for h in (0.95 * limit, 1.17 / damping):
        if h < limit:
            sim = run(base.replace(integrator={"dt": h}))  # the watchdog: no blow-up, no energy gained
            assert np.isfinite(sim.q.to_numpy()).all() and sim.drift[None] <= 0.05, h


def test_the_energy_limit_is_measured_the_same_every_time():
    from render.physics import stability
    system, pend = random_starts()[0]
    scene = make_scene(system, 1, pendulums=pend, integrator={"method": "symplectic_euler"},
                       video={"fps": 2, "duration": DURATION})
    first = stated_limit(scene)
    stability._memo.clear()
    assert stated_limit(scene) == first
    longer = scene.replace(video={"duration": 4 * DURATION})  # the drift grows with the duration, at most in
    assert first / 4 <= stated_limit(longer) < first  # proportion: first order, at most a quarter of the step


def test_a_pinned_dt_beyond_the_energy_limit_is_refused(tmp_path):
    r = run_cli("render", "classic", "--set", "integrator.method=symplectic_euler", "--set", "integrator.dt=0.01",
                "--set", "video.width=64", "--set", "video.height=48", "--out", tmp_path, "--no-progress")
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip().splitlines()
    assert len(line) == 1 and "energy limit" in line[0] and "integrator.max_drift" in line[0] and "dt <" in line[0]
    assert not any(tmp_path.rglob("*"))


def test_a_blow_up_is_reported_as_one_not_as_unfaithful(tmp_path):
    """Far beyond the limit (the check bypassed), the run is stopped as a blow-up, naming when and which
    pendulum, even with the faithfulness watchdog on: it is not merely untrue."""
    r = run_cli("render", "classic", "--set", "integrator.method=symplectic_euler", "--set", "integrator.dt=0.2",
                "--set", "video.fps=5", "--set", "integrator.allow_unstable=true", "--set", "video.width=64",
                "--set", "video.height=48", "--out", tmp_path, "--no-progress")
    assert r.returncode == 1, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "blew up at t=" in lines[0] and "(pendulum " in lines[0], r.stderr
    assert "use a smaller integrator.dt" in lines[0] and "faithful" not in lines[0]
    assert not any(tmp_path.rglob("*"))


def watchdog_error(method, dt, max_drift, **pend):
    scene = make_scene("rigid", 1, pendulums={"theta1": 2.0, "theta2": 2.6, **pend},
                       video={"fps": 10, "duration": 10.0}, effects=["energy"],
                       integrator={"method": method, "dt": dt, "allow_unstable": True, "max_drift": max_drift})
    with pytest.raises(SimulationError) as err:
        run(scene)
    return str(err.value)


def test_the_watchdog_tells_energy_gained_from_energy_lost():
    gained = watchdog_error("symplectic_euler", 0.01, 1e-2)  # symplectic Euler pumps energy into (θ, ω)
    assert "(gained)" in gained and "relative energy drift +" in gained and "integrator.max_drift" in gained
    lost = watchdog_error("rk4", 0.05, 1e-2)  # RK4 near its limit damps every oscillation
    assert "(lost)" in lost and "relative energy drift -" in lost, lost


def test_energy_off_by_orders_of_magnitude_is_a_blow_up():
    msg = watchdog_error("symplectic_euler", 0.05, 150.0)  # the watchdog let it run on until it was past 100x
    assert "blew up at t=" in msg and "(pendulum 0: energy up " in msg and "use a smaller integrator.dt" in msg, msg
