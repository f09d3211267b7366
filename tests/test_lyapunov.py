"""`pendulum lyapunov`: the spectrum's exact identities (the sum of the exponents is −D·c at every duration), its
pairs and their reported error over a long run, λ1 against an independent reference (scipy DOP853 on
variational equations written here, on render/physics/reference.py's model), and the command's files and refusals."""
import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import run_cli
from render.trust import certify, lyapunov
from render.physics import reference
from render.config.scene import load


@pytest.fixture(scope="module")
def classic_200s():
    """classic over 200 s (frames of 0.1 s: QR every frame, as often as the command does at this fps)."""
    scene = load("classic", ["video.duration=200", "video.fps=10"])
    run = lyapunov.spectrum(scene, np.array([0]))
    return scene, run, lyapunov.summary(run, 0.0)[0]


def test_undamped_sum_is_zero_at_every_duration(classic_200s):
    """Volume is conserved in canonical (θ, p): the running sum stays within 1e-3·λ1 of 0 at every frame. What
    is left is the RK4 numerical flow's own volume defect: far below that (measured: |ln det| of one frame's
    tangent map ~1e-12, 1.7e-9 at the worst frame; the running sum within 5e-10 1/s of 0 at every frame)."""
    _, run, row = classic_200s
    lam1 = row["exponents"][0]
    sums = run["running"][:, 0].sum(-1)
    assert lam1 > 0.5  # classic is chaotic
    assert np.abs(sums).max() < 1e-3 * lam1
    assert np.abs(sums).max() < 1e-6 * lam1  # far below: the numerical flow is volume-preserving to ~1e-10
    assert abs(row["checks"]["sum"]) < 1e-3 * lam1 and row["checks"]["expected_sum"] == 0.0


def test_damped_sum_is_minus_d_times_c_at_every_duration():
    """damped_heavy: c = 0.15 1/s on both coordinates, so the exponents sum to −0.30 1/s at any duration,
    for every pendulum measured (the default ones: the certificate's, thinned)."""
    scene = load("damped_heavy", ["video.duration=4"])
    assert scene.pendulums.damping == 0.15
    indices = lyapunov.default_pendulums(scene)
    assert 2 <= len(indices) <= lyapunov.CAP and indices[0] == 0 and indices[-1] == scene.pendulums.count - 1
    run = lyapunov.spectrum(scene, indices)
    sums = run["running"].sum(-1)  # (frames, pendulums)
    assert np.abs(sums + 0.30).max() < 1e-3 * 0.30, np.abs(sums + 0.30).max()
    for row in lyapunov.summary(run, scene.pendulums.damping):
        assert row["checks"]["expected_sum"] == pytest.approx(-0.30)
        assert row["checks"]["expected_pair_sum"] == pytest.approx(-0.15)  # conformally symplectic: each pair −c
        assert abs(row["checks"]["sum_defect"]) < 1e-3 * 0.30
        assert row["exponents"] == sorted(row["exponents"], reverse=True)


def test_the_spectrum_is_the_same_at_one_and_two_threads():
    """Every tangent vector is its own kernel element (no reduction), the primal is thread-invariant, and QR
    runs in numpy: the running estimates agree to the bit."""
    scene = load("damped_heavy", ["video.duration=1"])
    indices = lyapunov.default_pendulums(scene)
    one = lyapunov.spectrum(scene, indices, threads=1)["running"]
    two = lyapunov.spectrum(scene, indices, threads=2)["running"]
    assert np.array_equal(one, two)


def test_pairs_vanish_within_the_reported_error_and_the_error_is_honest(classic_200s):
    """Over 200 s the pairs λ1 + λ4 and λ2 + λ3 are within the error the command reports. Honest both ways:
    the errors reported at 100 s (from the run's first half only) cover where each exponent went by 200 s,
    and they are not vacuous (λ1 known to a fraction of itself)."""
    _, run, row = classic_200s
    sums, errors = row["checks"]["pair_sums"], row["checks"]["pair_errors"]
    assert len(sums) == 2
    for s, e in zip(sums, errors):
        assert abs(s) <= e, (sums, errors)
        assert e < 0.05
    half = run["rates"][:len(run["rates"]) // 2, 0]
    lam_half, err_half = half.mean(0), lyapunov.error(half)
    lam = run["rates"][:, 0].mean(0)
    assert np.all(np.abs(lam - lam_half) <= err_half), (lam, lam_half, err_half)
    assert row["errors"][0] < 0.3 * row["exponents"][0]


def variational_spectrum(scene, i: int, t: np.ndarray) -> np.ndarray:
    """Benettin's running spectrum (F, 2d) of pendulum i at the frame times t, from the canonical axes, as
    the package measures it but from independent parts: the 2d tangent vectors ride along by DOP853 on the
    variational equations of reference.py's model (its Jacobian by central differences of its force) in
    (q, v); at each frame they are taken into canonical (q, p), p = M(θ)ω for a chain and m·v for springs,
    re-orthonormalised by QR (ln |R_ii| summed), and taken back."""
    p = reference.params(scene)
    q, v = (a[i] for a in reference.initial_state(scene))
    d, eps = len(q), 1e-6
    steps = eps * np.eye(2 * d)

    def accel(q, v):  # rows of states (N, d) -> (N, d)
        return reference.accel(p, q, v)

    def momenta(q, v):
        if p.model == "chain":
            return np.einsum("nij,nj->ni", reference.chain_mass(q, p), v)
        return np.repeat(p.masses, 2) * v

    def jac(f, q, v):  # d f / d(q, v) at one state, (d, 2d), by central differences in one batched call
        plus = f(q + steps[:, :d], v + steps[:, d:])
        minus = f(q - steps[:, :d], v - steps[:, d:])
        return ((plus - minus) / (2 * eps)).T

    def rhs(_, y):  # the state and the tangent vectors (columns of a 2d x 2d matrix, in (δq, δv))
        q, v, tangents = y[:d], y[d:2 * d], y[2 * d:].reshape(2 * d, 2 * d)
        flow = np.block([[np.zeros((d, d)), np.eye(d)], [jac(accel, q, v)]])
        return np.concatenate([v, accel(q[None], v[None])[0], (flow @ tangents).ravel()])

    def canonical(q, v, tangents):  # (δq, δv) -> (δq, δp)
        return np.vstack([tangents[:d], jac(momenta, q, v) @ tangents])

    def velocities(q, v, basis):  # (δq, δp) -> (δq, δv)
        jp = jac(momenta, q, v)
        return np.vstack([basis[:d], np.linalg.solve(jp[:, d:], basis[d:] - jp[:, :d] @ basis[:d])])

    tangents, sums, out, t0 = velocities(q, v, np.eye(2 * d)), np.zeros(2 * d), [], 0.0
    for tf in t:
        sol = solve_ivp(rhs, (t0, tf), np.concatenate([q, v, tangents.ravel()]), method="DOP853",
                        rtol=1e-11, atol=1e-11)
        assert sol.success
        y = sol.y[:, -1]
        q, v = y[:d], y[d:2 * d]
        basis, r = np.linalg.qr(canonical(q, v, y[2 * d:].reshape(2 * d, 2 * d)))
        sums += np.log(np.abs(np.diagonal(r)))
        out.append(sums / tf)
        tangents, t0 = velocities(q, v, basis), tf
    return np.array(out)


CASES = {"classic": ("classic", [], 0), "triple_classic": ("triple_classic", ["video.duration=3"], 0),
         "elastic_fan": ("elastic_fan", ["video.duration=2", "integrator.method=rk4"], 4)}


@pytest.mark.parametrize("case", CASES)
def test_the_spectrum_agrees_with_an_independent_variational_reference(case):
    """Inside the certificate's faithful window, from the same initial tangent vectors, every running exponent
    of the package (tangent map of its integrator, by forward-mode AD) matches Benettin's on DOP853 and
    independent variational equations within 0.1 % of λ1 (the brief asks 2 %) at every frame past the first
    second: not λ1 alone, so two exponents swapped, or one lost, cannot pass on the sum and pairs."""
    preset, sets, i = CASES[case]
    scene = load(preset, ["video.duration=5", *sets])
    cert = certify.certify(scene.replace(integrator={"min_faithful": 0.0}), indices=np.array([i]))
    assert cert.until_s[0] >= scene.video.duration  # the whole run is faithful
    run = lyapunov.spectrum(scene, np.array([i]))
    t = run["t"]
    ours = run["running"][:, 0]  # (frames, 2D): each column the growth its QR step gives, as the reference's
    ref = variational_spectrum(scene, i, t)
    late = t >= 1.0
    # The brief asks for 2 %; measured, the largest difference in any column over λ1: 4.5e-9 (classic), 4.2e-8
    # (triple), 7.9e-5 (elastic_fan with rk4; with its preset's verlet at dt "auto" the numerical flow's own λ1
    # is 1.3 % off the exact flow's).
    assert np.abs(ours[late] - ref[late]).max() <= 1e-3 * np.abs(ref[-1, 0]), (ours[-1], ref[-1])
    row = lyapunov.summary(run, 0.0)[0]  # the whole spectrum of every system: 2D exponents summing to 0
    assert len(row["exponents"]) == {"rigid": 4, "triple": 6, "elastic": 8}[scene.system]
    assert abs(row["checks"]["sum"]) < 1e-3 * row["exponents"][0]


def test_the_command_writes_the_spectrum_and_its_chart(tmp_path):
    r = run_cli("lyapunov", "damped_heavy", "--pendulums", "0,29", "--set", "video.duration=3", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    (folder,) = tmp_path.iterdir()
    assert folder.name.startswith("damped_heavy__")  # --set: not the preset's own folder
    doc = json.loads((folder / "lyapunov.json").read_text())
    assert [row["pendulum"] for row in doc["pendulums"]] == [0, 29] and doc["unit"] == "1/s"
    for row in doc["pendulums"]:
        assert len(row["exponents"]) == len(row["errors"]) == 4
        assert row["exponents"] == sorted(row["exponents"], reverse=True)
        assert row["duration_s"] == pytest.approx(3.0, abs=0.02)
        assert row["checks"]["sum"] == pytest.approx(-0.30, abs=3e-4) and len(row["checks"]["pair_sums"]) == 2
        f = row["faithfulness"]
        assert f["faithful_until_s"] > 0 and f["tolerance"] == 1e-3 and f["initial_error"] > 0
        if row["exponents"][0] > 0:
            assert f["predicted_horizon_s"] > 0
    png = (folder / "lyapunov.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert r.stdout.count("pendulum ") >= 2 and "lyapunov.json" in r.stdout


@pytest.mark.parametrize("args, says", [
    (["classic", "--pendulums", "1"], "--pendulums 1: no such pendulum"),
    (["classic", "--pendulums", "0,x"], "must be pendulum indices"),
    (["damped_heavy", "--pendulums", "3,3"], "a pendulum named twice"),
    (["classic", "--set", "integrator.method=implicit_midpoint"], "integrator.method"),
    (["classic", "--set", "video.duration=0.1"], "video.duration"),
    # many frames of few substeps: under the step cap, but their launches take hours (5 ms a frame)
    (["classic", "--set", "video.duration=3000", "--set", "video.fps=240"], "over the run-time budget of 1 h"),
    (["classic", "--set", "video.duration=300", "--budget", "60"], "over the run-time budget of 1 min"),
])
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, args, says):
    r = run_cli("lyapunov", *args, "--out", tmp_path / "out")
    assert r.returncode == 2 and says in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    assert not (tmp_path / "out").exists()


def test_help_explains_the_command():
    r = run_cli("lyapunov", "--help")
    assert r.returncode == 0
    for word in ("Benettin", "lyapunov.json", "--pendulums", "canonical", "batch means"):
        assert word in r.stdout


def test_a_render_with_the_lyapunov_effect_puts_lambda1_beside_its_certificate(tmp_path):
    """effects += "lyapunov": metadata's faithfulness.lyapunov holds λ1 of the certified pendulums (thinned to
    CAP), the same λ1 `pendulum lyapunov` measures for them, and the horizon it predicts from the certificate's
    own first-frame error, beside the faithful time that certificate measured."""
    from render.video import pipeline
    small = ["video.width=128", "video.height=72", "video.fps=10", "video.duration=3", 'video.formats=["mp4"]',
             'effects=["rods", "bobs", "energy", "lyapunov"]']
    scene = load("rigid_chaos", small)
    meta = pipeline.render(scene, tmp_path)
    faith = meta["faithfulness"]
    got = faith["lyapunov"]
    picked = lyapunov.default_pendulums(scene)
    assert [row["pendulum"] for row in got["pendulums"]] == picked.tolist() and got["unit"] == "1/s"
    doc, _ = lyapunov.measure(scene, picked)  # the command's measurement of the same pendulums
    for row, ref in zip(got["pendulums"], doc["pendulums"]):
        assert row["lambda1"] == pytest.approx(ref["exponents"][0], rel=1e-12) and row["lambda1"] > 0
        assert row["initial_error"] == pytest.approx(ref["faithfulness"]["initial_error"], rel=1e-12)
        assert row["predicted_horizon_s"] == pytest.approx(np.log(1e-3 / row["initial_error"]) / row["lambda1"])
        assert row["faithful_until_s"] == ref["faithfulness"]["faithful_until_s"]  # each pendulum's own, alone or not
        assert faith["faithful_until_s"] <= row["faithful_until_s"]
    assert meta["timings_s"]["lyapunov"] > 0


def test_the_lyapunov_effect_is_refused_up_front_where_it_cannot_run(tmp_path):
    r = run_cli("render", "classic", "--set", 'effects=["rods", "bobs", "lyapunov"]', "--set",
                "integrator.method=implicit_midpoint", "--out", tmp_path / "out")
    assert r.returncode == 2 and "integrator.method" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()
    r = run_cli("render", "fractal_flip", "--set", 'effects=["fractal", "lyapunov"]', "--out", tmp_path / "out")
    assert r.returncode == 2 and "'lyapunov'" in r.stderr and not (tmp_path / "out").exists()
