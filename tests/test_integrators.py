"""The integrators against an independent DOP853 reference: convergence order, accuracy, energy, symplecticity.

Each run starts Taichi in the precision it needs (render/physics/stepper.py: one runtime per process, re-initialised).
"""
import math

import numpy as np
import pytest

from render.commands import accuracy
from render.physics import integrators, reference, registry
from render.physics.stepper import Run
from render.config.limits import METHODS

THEORY = {"symplectic_euler": 1, "verlet": 2, "rk2": 2, "implicit_midpoint": 2, "rk4": 4, "yoshida4": 4}
# In the asymptotic regime for every method, and above the reference's ~1e-12 error even for rk4.
LADDER = (4e-3, 2e-3, 1e-3)
CASES = [(s, m) for s in ("rigid", "elastic") for m in METHODS[s]]


@pytest.fixture(scope="module")
def refs():
    """Reference state at each case's horizon (rigid: classic at 2 s; elastic: elastic_fan at 1 s)."""
    out = {}
    for system, (preset, horizon) in accuracy.CASES.items():
        sc = accuracy.case_scene(system, "rk4", "f64", 1e-3, horizon)
        out[system] = reference.solve(sc, reference.initial_state(sc), horizon)
    return out


def test_the_method_table_states_what_the_methods_are():
    """One row per method (integrators.METHOD): its order the theoretical one the convergence tests check against
    DOP853, a distinct chart colour each, and an oscillator gain for each method that gains energy on springs
    (stability.oscillator_limit reads it there)."""
    table = integrators.METHOD
    assert {m: row.order for m, row in table.items()} == THEORY
    assert len({row.color for row in table.values()}) == len(table)
    assert all(row.stability > 0 and row.evals >= 1 for row in table.values())
    assert all((row.oscillator_gain is not None) == ("springs" in row.energy_gain) for row in table.values())


def traj_error(system, method, precision, dt, ref):
    horizon = accuracy.CASES[system][1]
    q, _, _ = accuracy.advance(accuracy.case_scene(system, method, precision, dt, horizon), round(horizon * 10))
    return float(np.abs(q - ref[0]).max())


def test_reference_agrees_with_itself_and_with_taichi_start(refs):
    """The reference is converged (tightening rtol changes little) and starts where the Taichi systems start."""
    sc = accuracy.case_scene("rigid", "rk4", "f64", 1e-3, 2.0)
    loose = reference.solve(sc, reference.initial_state(sc), 2.0, rtol=1e-11, atol=1e-11)[0]
    assert np.abs(loose - refs["rigid"][0]).max() < 1e-9
    for system in ("rigid", "elastic"):
        sc = accuracy.case_scene(system, "rk4", "f64", 1e-3, 1.0)
        sim = Run(sc).sim
        q0, v0 = reference.initial_state(sc)
        np.testing.assert_allclose(sim.q.to_numpy(), q0, rtol=0, atol=1e-15)
        np.testing.assert_allclose(sim.v.to_numpy(), v0, rtol=0, atol=1e-15)


@pytest.mark.parametrize("system,method", CASES)
def test_observed_order_matches_theory(system, method, refs):
    errs = [traj_error(system, method, "f64", dt, refs[system]) for dt in LADDER]
    slope = np.polyfit(np.log(LADDER), np.log(errs), 1)[0]
    assert abs(slope - THEORY[method]) <= 0.3, f"{system} {method}: errors {errs}, observed order {slope:.2f}"


def test_rk4_f64_matches_reference_on_classic(refs):
    """classic (θ1 = 120°, θ2 = −10°): RK4 at dt = 1e-3 in f64 is within 1e-8 rad of DOP853 at t = 2 s."""
    sc = accuracy.case_scene("rigid", "rk4", "f64", 1e-3, 2.0)
    assert sc.pendulums.theta1 == pytest.approx(math.radians(120))
    assert sc.pendulums.theta2 == pytest.approx(math.radians(-10))
    err = traj_error("rigid", "rk4", "f64", 1e-3, refs["rigid"])
    assert err < 1e-8


@pytest.mark.parametrize("system,method", CASES)
def test_f32_is_f32_and_as_good_as_its_round_off(system, method, refs):
    """In f32 every method tracks its f64 error down to f32 round-off; rk4 is visibly limited by it."""
    e32 = traj_error(system, method, "f32", 1e-3, refs[system])
    e64 = traj_error(system, method, "f64", 1e-3, refs[system])
    assert e32 <= 1.2 * e64 + 1e-4
    if method == "rk4":  # f64 arithmetic behind an "f32" label would give ~e64 here
        assert e32 > 10 * e64


def energy_error(system, method, steps=100_000, dt=1e-3):
    """Relative energy error per frame (0.1 s), worst pendulum, over `steps` steps in f64."""
    sc = accuracy.case_scene(system, method, "f64", dt, steps * dt)
    _, _, series = accuracy.advance(sc, 1, round(steps * dt * accuracy.FPS) - 1)
    return series[1:]


def bounded(series) -> tuple[float, float]:
    """(last third's max |error| / first third's, worst |linear trend over the run| / max |error|)."""
    a = np.abs(series).max(1)
    third = len(a) // 3
    t = np.arange(len(series))
    slope = np.polyfit(t, series, 1)[0]  # per pendulum
    trend = np.max(np.abs(slope) * len(t) / np.abs(series).max(0))
    return a[-third:].max() / a[:third].max(), trend


@pytest.mark.parametrize("system,method", [("elastic", "verlet"), ("elastic", "yoshida4"),
                                           ("rigid", "implicit_midpoint")])
def test_symplectic_energy_error_is_bounded_without_trend(system, method):
    growth, trend = bounded(energy_error(system, method))
    assert growth < 2.0 and trend < 0.5, f"growth {growth:.2f}, trend {trend:.2f}"


def test_energy_check_detects_rk4_drift():
    """The same check fails for RK4 (not symplectic): its energy error creeps steadily."""
    growth, trend = bounded(energy_error("elastic", "rk4"))
    assert growth > 2.0 and trend > 0.8


def one_step_jacobian(system, method, y, to_canon, from_canon, h=1e-2, eps=1e-5):
    """Jacobian of one Taichi step in canonical coordinates, by central differences over 2·dim pendulums."""
    dim = len(y)
    sc = accuracy.case_scene(system, method, "f64", h, 1.0).replace(pendulums={"count": 2 * dim})
    assert sc.pendulums.masses == (1.0, 1.0) and sc.pendulums.lengths == (1.0, 1.0)  # as the helpers assume
    sim = Run(sc).sim
    ys = np.array([y + s * eps * np.eye(dim)[k] for k in range(dim) for s in (1, -1)])
    q, v = from_canon(ys)
    sim.q.from_numpy(q)
    sim.v.from_numpy(v)
    sim.launch(f"{sim.NAME}_advance", 1)
    out = to_canon(sim.q.to_numpy(), sim.v.to_numpy())
    return ((out[0::2] - out[1::2]) / (2 * eps)).T


def symplectic_defect(jac):
    n = len(jac) // 2
    omega = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])
    return np.abs(jac.T @ omega @ jac - omega).max()


@pytest.mark.parametrize("method", ["symplectic_euler", "verlet", "yoshida4", "rk4"])
def test_elastic_step_is_symplectic(method):
    """With unit masses p = v, so the one-step map in (x, v) must preserve the canonical 2-form; rk4 must not."""
    y = np.array([0.9, -0.5, 1.6, -0.9, 0.3, 1.1, -0.8, 0.4])
    jac = one_step_jacobian("elastic", method, y, lambda q, v: np.hstack([q, v]), lambda ys: (ys[:, :4], ys[:, 4:]))
    defect = symplectic_defect(jac)  # finite differences leave ~3e-9; rk4 at h·ω_max = 0.7 gives ~1e-3
    assert (defect < 1e-7) == (method != "rk4"), defect


def rigid_momenta(q, v):
    """p = M(θ)·ω for unit lengths and masses."""
    c = np.cos(q[:, 0] - q[:, 1])
    return np.stack([2 * v[:, 0] + c * v[:, 1], c * v[:, 0] + v[:, 1]], 1)


def rigid_from_canon(ys):
    q, p = ys[:, :2], ys[:, 2:]
    c = np.cos(q[:, 0] - q[:, 1])
    det = 2 - c * c
    return q, np.stack([(p[:, 0] - c * p[:, 1]) / det, (2 * p[:, 1] - c * p[:, 0]) / det], 1)


# The implicit midpoint steps the rigid pendulum in canonical (θ, p = M(θ)ω) and must be symplectic. The seed's
# Euler (v += a·h; x += v·h) on (θ, ω) is not, since (θ, ω) are not canonical: its defect was 4.3e-3 at h = 1e-2.
@pytest.mark.parametrize("method, symplectic", [("implicit_midpoint", True), ("symplectic_euler", False)])
def test_rigid_step_symplecticity(method, symplectic):
    y = np.concatenate([[2.0, -0.3], rigid_momenta(np.array([[2.0, -0.3]]), np.array([[1.5, -2.0]]))[0]])
    jac = one_step_jacobian("rigid", method, y, lambda q, v: np.hstack([q, rigid_momenta(q, v)]), rigid_from_canon)
    defect = symplectic_defect(jac)
    assert (defect < 1e-7) if symplectic else (defect > 1e-4), defect


def test_every_quality_level_is_stable_on_every_preset():
    """The --quality table (chosen from the accuracy figures) must never trip the stability check."""
    from render.errors import SceneError
    from render.trust.quality import LEVELS
    from render.config.scene import list_presets, load

    for path in list_presets():
        for level in LEVELS:
            try:
                sc = load(str(path), quality=level)
            except SceneError as e:  # a comparison of integrators (compare_methods): the level would choose
                assert "chooses every panel's integrator" in str(e), e  # each panel's, so it is refused
                continue
            small = {"video": {"width": 16, "height": 16}} if sc.pendulums.layout == "grid" else {}
            sc = sc.replace(**small) if small else sc.replace(pendulums={"count": 1})  # a grid counts its pixels
            sim = registry.get(sc.system)(sc)  # raises SceneError beyond the method's stability limit
            assert sim.h <= (sc.integrator.dt if sc.integrator.dt != "auto" else 1e-3) + 1e-15
