"""The `poincare` effect: crossings of θ1 = 0 (ω1 > 0) against scipy's event location on the independent model,
the shell start's energy, the poincare_shell preset the same bytes at 1 and 2 threads, and its refusals."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import run_cli
from render.video import pipeline
from render.physics import poincare, reference
from render.physics.stepper import Run
from render.errors import SceneError
from render.config.scene import load

SMALL = ["video.width=256", "video.height=144", "video.fps=10"]


def scene_of(*overrides):
    return load("poincare_shell", [*SMALL, *overrides])


def scipy_crossings(scene, q0, v0, t_end):
    """Per pendulum, (t, θ2, ω2) where θ1 ≡ 0 (mod 2π) is crossed upwards: DOP853 at rtol 1e-12 on
    render/physics/reference.py's equations, events at sin θ1 rising, kept where cos θ1 > 0 (θ1 ≡ π falling also
    makes sin θ1 rise)."""
    p = reference.params(scene)

    def rhs(t, y):
        return np.concatenate([y[2:], reference.chain_accel(y[None, :2], y[None, 2:], p)[0]])

    def section(t, y):
        return math.sin(y[0])
    section.direction = 1
    out = []
    for q, v in zip(q0, v0):
        sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([q, v]), method="DOP853", rtol=1e-12, atol=1e-12,
                        events=section)
        t, y = sol.t_events[0], sol.y_events[0]
        keep = (np.cos(y[:, 0]) > 0) & (t > 0)  # the shell's start, on the section, is no crossing
        out.append((t[keep], y[keep, 1], y[keep, 3]))
    return out


def test_crossings_agree_with_scipy_event_location_where_the_certificate_trusts():
    """Eight pendulums of the shell for 6 s: every crossing before the pendulum's faithful time is found,
    at the time, θ2 and ω2 scipy locates, within 1e-6 (the certificate's tolerance set to 1e-7 rad, so the
    trajectory's own error stays well below it where it trusts)."""
    duration = 6.0
    scene = scene_of("pendulums.count=8", f"video.duration={duration}", "video.fps=60",
                     "integrator.tolerance=1e-7", "integrator.min_faithful=0")
    scene, _, cert, _ = pipeline.prepare(scene, "cpu", None)
    run = Run(scene)
    sim = run.sim
    q0, v0 = sim.initial_state()
    assert (q0[:, 0] == 0).all() and (v0[:, 0] > 0).all()
    found = [[] for _ in range(sim.n)]
    for f in run.frames():
        if not f:
            continue
        i, t, th2, w2, lost = poincare.read(sim, sim.t - sim.substeps * sim.h)
        assert lost == 0
        for row in zip(i, t, th2, w2):
            found[row[0]].append(row[1:])
    t_end = (scene.frames - 1) / scene.video.fps
    truth = scipy_crossings(scene, q0, v0, t_end)
    until = dict(zip(cert.indices.tolist(), cert.until_s))
    assert len(until) == sim.n
    compared = 0
    for k in range(sim.n):
        mine = np.array(found[k]).reshape(-1, 3)
        t_ref, th_ref, w_ref = truth[k]
        trusted = t_ref < until[k] - 0.05  # a crossing within the last frames may fall either side of it
        assert len(mine) >= trusted.sum(), (k, len(mine), trusted.sum())
        for t, th2, w2 in zip(t_ref[trusted], th_ref[trusted], w_ref[trusted]):
            j = np.argmin(np.abs(mine[:, 0] - t))
            assert abs(mine[j, 0] - t) < 1e-6, (k, t, mine[j])
            assert abs(math.remainder(mine[j, 1] - th2, 2 * math.pi)) < 1e-6, (k, t, mine[j, 1], th2)
            assert abs(mine[j, 2] - w2) < 1e-6, (k, t, mine[j, 2], w2)
            compared += 1
        assert len(mine) == len(t_ref) or until[k] < duration  # the untrusted end aside, no extra crossing
    assert compared >= 20, compared  # the certificate trusts most of these pendulums' 6 s


def test_the_shell_starts_every_pendulum_on_the_section_with_the_presets_energy():
    """The start is built from the reference model's energy; the Taichi system's own energy agrees."""
    scene = scene_of("video.duration=0.1")
    sim = Run(scene).sim
    sim.measure_energy(first=True)
    p = scene.pendulums
    want = 0.5 * (p.masses[0] + p.masses[1]) * p.lengths[0] ** 2 * p.omega1 ** 2  # hanging start: all kinetic
    e = sim.e.to_numpy()
    assert np.abs(e - want).max() < 1e-12 * want
    q, v = sim.q.to_numpy(), sim.v.to_numpy()
    assert (q[:, 0] == 0).all() and (v[:, 0] > 0).all()
    assert len(np.unique(np.round(q[:, 1], 9) + 1j * np.round(v[:, 1], 9))) == sim.n  # every start its own


def frames_at(threads, tmp_path):
    frames = []
    meta = pipeline.render(scene_of("video.duration=3"), tmp_path / str(threads), threads=threads,
                           frame_hook=lambda f, fr: frames.append(fr.copy()))
    return meta, np.stack(frames)


def test_poincare_shell_is_the_same_bytes_at_1_and_2_threads_and_accumulates_points(tmp_path):
    meta1, one = frames_at(1, tmp_path)
    meta2, two = frames_at(2, tmp_path)
    assert one.tobytes() == two.tobytes()
    sec = meta1["poincare"]
    assert sec == meta2["poincare"] and sec["lost"] == 0
    assert sec["crossings"] > meta1["preset"]["pendulums"]["count"]  # 300 pendulums, ~1.5 turns each in 3 s
    panel = one[:, :, 128:]  # the section is the right half of the frame, beside the pendulums
    lit = (panel != panel[0]).any(-1).sum((1, 2))  # pixels the crossings lit since the first frame
    assert lit[-1] > 60 and (np.diff(lit) >= 0).all()  # points only accumulate


def test_the_section_needs_two_link_angles():
    with pytest.raises(SceneError, match="'poincare' draws the section"):
        load("elastic_fan", ['effects=["springs", "poincare"]'])
    with pytest.raises(SceneError, match="'poincare' draws the section"):
        load("triple_classic", ['effects=["rods", "poincare"]'])
    with pytest.raises(SceneError, match="'shell' starts pendulums"):
        load("elastic_fan", ['pendulums.layout="shell"'])
    with pytest.raises(SceneError, match="compare"):
        load("compare_methods", ['effects=["rods", "poincare"]'])


@pytest.mark.parametrize("size, effects, ok", [((64, 36), '["rods", "poincare"]', False),
                                                ((190, 96), '["rods", "poincare"]', False),
                                                ((192, 96), '["rods", "poincare"]', True),
                                                ((96, 94), '["poincare"]', False), ((96, 96), '["poincare"]', True)])
def test_the_section_panel_has_a_least_size_and_draws_from_there(size, effects, ok):
    """Below it the panel's labels fell outside the frame: an IndexError after the simulation (exit 1)."""
    sets = [f"video.width={size[0]}", f"video.height={size[1]}", "video.duration=0.05", f"effects={effects}"]
    if not ok:
        with pytest.raises(SceneError, match="'poincare' draws its section in a panel"):
            load("classic", sets)
        return
    src = pipeline.open_source(load("classic", sets))
    assert src.next_frame().shape == (size[1], size[0], 3)


def test_a_shell_at_rest_and_the_effect_on_springs_exit_2_with_one_line(tmp_path):
    springs = ["--set", 'system="elastic"', "--set", "pendulums.stiffness=1e3",
               "--set", 'effects=["springs", "poincare"]']
    for args, needle in ((["--set", "pendulums.omega1=0"], "pendulums.layout: \"shell\""), (springs, "'poincare'")):
        r = run_cli("render", "poincare_shell", "--out", tmp_path, "--no-progress", *args)
        assert r.returncode == 2, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert "poincare_shell" in r.stderr and needle in r.stderr, r.stderr
    assert not any(tmp_path.rglob("*"))
