"""The FTLE map (fractal = "lyapunov"): σ_t against DOP853 on independently written variational equations
at trusted pixels, its s_max against numpy's SVD, the barrier's curve, determinism at 1 and 2 threads, and
bad input."""
import json

import imageio.v3 as iio
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import run_cli
from render.draw import axes
from render.maps import fractal, ftle
from render.physics import grid, reference
from render.video import pipeline
from render.config.scene import load


def run_map(scene, threads=None):
    src = pipeline.Source(scene, threads=threads)
    frames = [src.next_frame().copy() for _ in range(scene.frames)]
    return src.canvas, src.sim, frames


def small(n=24, seconds=4.0, *sets):
    return load("fractal_lyapunov", [f"video.width={n}", f"video.height={n}", f"video.duration={seconds}",
                                     "video.fps=30", "integrator.min_faithful=0", *sets])


def variational_sigma(scene, q0, v0, t_end):
    """σ_t = ln s_max(DΦ(t)) / t at t_end from each start, in (θ1, θ2, ω1, ω2), by DOP853 on the state and
    its variational equations δ' = J·δ (Φ(0) = I), J from central differences of render/physics/reference.py's
    independent chain model (the mass-matrix form, not the Taichi system's closed form)."""
    n, d = q0.shape
    eps = 1e-6

    def accel(q, v):
        return reference.accel(scene, q, v)

    def rhs(_, y):
        y = y.reshape(n, 2 * d + (2 * d) ** 2)
        q, v, phi = y[:, :d], y[:, d:2 * d], y[:, 2 * d:].reshape(n, 2 * d, 2 * d)
        jac = np.zeros((n, 2 * d, 2 * d))
        jac[:, :d, d:] = np.eye(d)
        for k in range(2 * d):  # column k of ∂a/∂(q, v)
            dq, dv = np.zeros_like(q), np.zeros_like(v)
            (dq if k < d else dv)[:, k % d] = eps
            jac[:, d:, k] = (accel(q + dq, v + dv) - accel(q - dq, v - dv)) / (2 * eps)
        return np.concatenate([v, accel(q, v), (jac @ phi).reshape(n, -1)], axis=1).ravel()

    y0 = np.concatenate([q0, v0, np.tile(np.eye(2 * d).ravel(), (n, 1))], axis=1).ravel()
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-11, atol=1e-11)
    assert sol.success
    phi = sol.y[:, -1].reshape(n, -1)[:, 2 * d:].reshape(n, 2 * d, 2 * d)
    return np.log(np.linalg.svd(phi, compute_uv=False)[:, 0]) / t_end


@pytest.mark.slow
def test_sigma_matches_dop853_variational_equations_at_50_trusted_pixels():
    scene = small(24, 4.0, "map.trust_stride=4")
    mp, sim, _ = run_map(scene)
    t_end = (scene.frames - 1) / scene.video.fps
    assert sim.t == pytest.approx(t_end)
    sigma = mp.sigma.to_numpy().astype(np.float64)
    trusted = np.flatnonzero(mp.until.to_numpy() >= np.float32(t_end))
    assert len(trusted) >= 50, len(trusted)
    pick = trusted[np.linspace(0, len(trusted) - 1, 50).round().astype(int)]
    q0, v0 = sim.initial_state()
    ref = variational_sigma(scene, q0[pick], v0[pick], t_end)
    rel = np.abs(sigma[pick] - ref) / np.abs(ref)
    assert rel.max() < 0.02, (rel.max(), pick[rel.argmax()], sigma[pick][rel.argmax()], ref[rel.argmax()])
    assert ref.max() > 1.0 and ref.min() < 0.8  # the picks span chaotic and regular starts, not one kind
    # the drawn s_max (MᵀM squared in the kernel) is the SVD's
    m, log_scale = mp.tangents()
    exact = (log_scale + np.log(np.linalg.svd(m, compute_uv=False)[:, 0])) / sim.t
    assert np.abs(exact - sigma).max() < 1e-4


def test_the_barrier_curve_is_black_and_bounds_the_region_that_cannot_flip():
    scene = small(48, 0.2)
    mp, sim, frames = run_map(scene)
    q0, v0 = sim.initial_state()
    inside = (reference.energy(scene, q0, v0) < min(fractal.barriers((1.0, 1.0), (1.0, 1.0), 9.8))).reshape(48, 48)
    edge = mp.edge.to_numpy().reshape(48, 48).astype(bool)
    assert edge.sum() > 40 and (inside | ~edge).all()  # on the inner side only
    outside = np.pad(~inside, 1, constant_values=False)
    touches = outside[:-2, 1:-1] | outside[2:, 1:-1] | outside[1:-1, :-2] | outside[1:-1, 2:]
    assert (edge == (inside & touches)).all()
    assert (frames[-1][edge] == 0).all() and (frames[-1][~edge].sum(-1) > 0).all()  # black, and only there


def test_frames_are_byte_identical_at_1_and_2_threads_and_the_legend_is_in_1_per_s(tmp_path):
    scene = load("fractal_lyapunov", ["video.width=256", "video.height=144", "video.duration=0.5", "video.fps=10"])
    runs = []
    for threads in (1, 2):
        frames = []
        meta = pipeline.render(scene, tmp_path / str(threads), threads=threads,
                               frame_hook=lambda f, fr: frames.append(fr.copy()))
        runs.append((frames, meta))
    (a, meta), (b, _) = runs
    assert len(a) == scene.frames == 5 and all(x.tobytes() == y.tobytes() for x, y in zip(a, b))
    assert a[1].tobytes() != a[-1].tobytes()  # σ is live: it changes as t grows
    d = tmp_path / "1" / "fractal_lyapunov"
    assert iio.imread(d / "fractal_lyapunov.png").tobytes() == a[-1].tobytes()
    m = json.loads((d / "metadata.json").read_text())["map"]
    assert m["colouring"] == "lyapunov" and m["sigma_scale_per_s"] == [0.0, ftle.SIGMA_MAX]
    assert {"ftle_frame", "ftle_colour", "fractal_swatch"} <= set(meta["kernels"])
    decor = axes.decorate(scene, grid.layout(1280, 720), (0.0, ftle.SIGMA_MAX), "")  # at 720p: the bar's ticks
    labels = [t[0] for t in decor.texts]
    assert "σ [1/s]" in labels and {"0.2", "1", "1.8", "2"} <= set(labels) and "barrier" in " ".join(labels)
    assert axes.linear_ticks(0.0, 2.0, 5) == [0.0, 0.5, 1.0, 1.5, 2.0]


def test_the_map_steps_each_pixel_exactly_as_the_plain_advance_does():
    """The tangents ride beside the state as duals (render/physics/dual.py): the state is the plain advance's, to
    the bit, in the same vectorised group loop (so the certificate's trig is the map's)."""
    src = pipeline.Source(small(40, 1.0))
    mp, sim = src.canvas, src.sim
    q0, v0 = sim.q.to_numpy(), sim.v.to_numpy()
    for _ in range(4):
        mp.advance(sim.substeps, sim.h)
    mapped = sim.q.to_numpy().tobytes() + sim.v.to_numpy().tobytes()
    sim.q.from_numpy(q0)
    sim.v.from_numpy(v0)
    for _ in range(4):
        sim.advance_by(sim.substeps, sim.h)
    assert mapped == sim.q.to_numpy().tobytes() + sim.v.to_numpy().tobytes()
    assert np.abs(sim.q.to_numpy() - q0).max() > 0.01  # they moved


def test_an_integrator_without_a_tangent_map_exits_2_naming_the_key(tmp_path):
    r = run_cli("render", "fractal_lyapunov", "--out", tmp_path, "--set", "integrator.method=implicit_midpoint",
                "--set", "video.width=64", "--set", "video.height=36", "--set", "video.duration=0.1")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "fractal_lyapunov.toml" in r.stderr and "integrator.method" in r.stderr, r.stderr
    assert not list(tmp_path.iterdir())
