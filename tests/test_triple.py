"""The triple pendulum against the independent N-link chain of render.physics.reference (scipy DOP853), its energy,
and the limit of a vanishing third mass, where its first two links are the double pendulum."""
import math

import numpy as np
import pytest
import taichi as ti

from conftest import make_scene, run_cli
from render.physics import reference
from render.physics.stepper import Run

PEND = {"theta1": 2.0, "theta2": -0.5, "theta3": 2.8, "omega1": 0.3, "omega2": -1.0, "omega3": 0.7,
        "spread": 0.4, "lengths": [1.0, 0.7, 0.5], "masses": [1.5, 0.8, 1.2], "gravity": 9.81}


def triple(count=5, duration=1.0, fps=20, method="rk4", dt=1e-3, **pend):
    return make_scene("triple", count, effects=["energy"], pendulums={**PEND, **pend},
                      integrator={"method": method, "dt": dt}, video={"fps": fps, "duration": duration})


def run(scene):
    runner = Run(scene)
    for _ in runner.frames():
        pass
    return runner.sim


@ti.kernel
def force_and_energy(sim: ti.template(), acc: ti.types.ndarray(), e: ti.types.ndarray()):
    for i in range(sim.n):
        a = sim.force(sim.q[i], sim.v[i])
        for k in ti.static(range(sim.D)):
            acc[i, k] = a[k]
        e[i] = sim.energy(sim.q[i], sim.v[i])


def at_random_states(scene, seed: int):
    """(q, v, the kernel's accelerations, its energies) at random states of `scene`'s pendulums."""
    sim, n = Run(scene).sim, scene.pendulums.count
    rng = np.random.default_rng(seed)
    q, v = rng.uniform(-np.pi, np.pi, (n, 3)), rng.normal(0, 2.0, (n, 3))
    sim.q.from_numpy(q)
    sim.v.from_numpy(v)
    acc, e = np.zeros((n, 3)), np.zeros(n)
    force_and_energy(sim, acc, e)
    return q, v, acc, e


def test_accelerations_and_energy_match_the_chain_reference_at_random_states():
    scene = triple(64)
    q, v, acc, e = at_random_states(scene, 11)
    p = reference.params(scene)
    np.testing.assert_allclose(acc, reference.chain_accel(q, v, p), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(e, reference.chain_energy(q, v, p), rtol=1e-12, atol=1e-10)


def lagrangian_accel(q, v, masses, lengths, g):
    """The chain's accelerations from nothing but its Lagrangian over the bobs' Cartesian positions, every
    derivative numerical: independent of the mass matrix μ_ij l_i l_j cos(θ_i − θ_j) that both the kernel and
    reference.py are written from. T = ½ Σ m_k |ẋ_k|² (bob velocities as the complex-step derivative of the
    positions along v, exact to round-off), V = g Σ m_k y_k; M_ij = ∂²T/∂v_i∂v_j (T is quadratic in v: by
    polarisation), and M q̈ = ∂(T − V)/∂q − (d/dt along v of M) v, by central differences."""
    d, eps = len(q), 1e-5
    m, ls = np.asarray(masses), np.asarray(lengths)

    def positions(q):
        return np.cumsum(ls * np.sin(q)), -np.cumsum(ls * np.cos(q))

    def kinetic(q, v):
        x, y = positions(q + 1e-30j * v)
        return 0.5 * np.sum(m * ((x.imag / 1e-30) ** 2 + (y.imag / 1e-30) ** 2))

    def potential(q):
        return g * np.sum(m * positions(q)[1])

    def mass(q):
        e = np.eye(d)
        return np.array([[kinetic(q, e[i] + e[j]) - kinetic(q, e[i]) - kinetic(q, e[j]) for j in range(d)]
                         for i in range(d)])

    def grad(f):
        return np.array([(f(q + eps * e) - f(q - eps * e)) / (2 * eps) for e in np.eye(d)])

    force = grad(lambda x: kinetic(x, v) - potential(x))
    rate = (mass(q + eps * v) - mass(q - eps * v)) @ v / (2 * eps)  # d(M)/dt v, moving along v
    return np.linalg.solve(mass(q), force - rate)


def test_accelerations_match_a_lagrangian_of_the_bobs_positions():
    """Apart from reference.py: the kernel's accelerations at random states against the Lagrangian of the
    bobs' positions, differentiated numerically: within 1e-7 (measured 7.6e-9, the differences' own error, at
    accelerations up to 51 rad/s²; the masses swapped are 1.8 off)."""
    q, v, acc, _ = at_random_states(triple(16), 5)
    want = np.array([lagrangian_accel(qi, vi, PEND["masses"], PEND["lengths"], PEND["gravity"])
                     for qi, vi in zip(q, v)])
    np.testing.assert_allclose(acc, want, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("damping", [0.0, 0.7])
@pytest.mark.parametrize("method, tol", [("rk4", 2e-7), ("implicit_midpoint", 1e-3)])
def test_trajectories_match_dop853(method, tol, damping):
    scene = triple(method=method, damping=damping)
    sim = run(scene)
    q_ref, v_ref = reference.solve(scene, reference.initial_state(scene), sim.t, rtol=1e-12, atol=1e-12)
    err = np.abs(sim.q.to_numpy() - q_ref).max()
    assert err < tol, err
    assert np.abs(sim.v.to_numpy() - v_ref).max() < 100 * tol


def test_rk4_order_is_four():
    scene = triple(1, 1.0, fps=10, dt=4e-3)
    ref = reference.solve(scene, reference.initial_state(scene), 0.9)[0]  # the last of 10 frames
    errs = [np.abs(run(triple(1, 1.0, fps=10, dt=dt)).q.to_numpy() - ref).max() for dt in (4e-3, 2e-3, 1e-3)]
    slope = np.polyfit(np.log([4e-3, 2e-3, 1e-3]), np.log(errs), 1)[0]
    assert abs(slope - 4) < 0.3, (errs, slope)


def energy_errors(scene):
    """Max relative energy error over the pendulums, per frame."""
    runner, out = Run(scene), []
    sim = runner.sim
    for _ in runner.frames():
        out.append(np.max(np.abs(sim.e.to_numpy() - sim.e0.to_numpy()) / sim.escale.to_numpy()))
    return np.array(out)


def test_energy_is_conserved():
    """RK4 at dt 1e-3 over 20 s of chaotic triples: relative energy error below 1e-6. The implicit midpoint
    (symplectic in (θ, p)) keeps its larger, second-order error bounded: no growth from the first third of
    the run to the last."""
    assert energy_errors(triple(4, 20.0, fps=10)).max() < 1e-6
    err = energy_errors(triple(4, 30.0, fps=10, method="implicit_midpoint"))
    third = len(err) // 3
    assert err.max() < 1e-3 and err[-third:].max() < 2.0 * err[:third].max(), (err[:third].max(), err[-third:].max())


def test_a_vanishing_third_mass_leaves_the_double_pendulum():
    """m3 → 0: links 1 and 2 follow the rigid double pendulum with the same masses and lengths. (The step is
    "auto": energy alone would let a 1e-6 kg bob spin ~1e5 rad/s, so the sound step limit is small.)"""
    tri = run(triple(3, 2.0, dt="auto", masses=[1.5, 0.8, 1e-6]))
    dbl = run(make_scene("rigid", 3, effects=["energy"], integrator={"method": "rk4", "dt": 1e-3},
                         video={"fps": 20, "duration": 2.0},
                         pendulums={k: v for k, v in PEND.items() if not k.endswith("3") and k not in (
                             "lengths", "masses")} | {"lengths": [1.0, 0.7], "masses": [1.5, 0.8],
                                                      "spread": 0.0}))
    th = tri.q.to_numpy()
    assert np.abs(th[:, :2] - dbl.q.to_numpy()[:1]).max() < 1e-5  # the double fan has spread 0: one motion
    assert np.isfinite(th).all()


def test_simulate_writes_three_angles(tmp_path):
    out = tmp_path / "t.npz"
    r = run_cli("simulate", "triple_classic", "--out", out, "--set", "video.duration=1", "--no-progress")
    assert r.returncode == 0, r.stderr
    data = np.load(out)
    frames = 60  # 1 s at 60 fps, t = 0 included
    assert data["theta"].shape == (frames, 1, 3) and data["omega"].shape == (frames, 1, 3)
    assert data["energy"].shape == (frames, 1)
    np.testing.assert_allclose(data["theta"][0, 0], [math.pi / 2, 3 * math.pi / 4, math.pi], atol=1e-15)
