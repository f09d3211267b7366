"""The bench's numba peer: optional (null keys and one line without it) and, where installed, the same physics."""
import numpy as np
import pytest

from render.commands.bench import peers
from render.physics import reference
from render.config.scene import load


def bench_scene(preset, n=50):
    return load(preset, [f"pendulums.count={n}", 'integrator.method="rk4"', "integrator.dt=1e-3",
                         'effects=["bobs"]'])


def rows(numba):
    return [{"system": s, "precision": p, "n": 10**5, "taichi": 2e7, "numpy": 2e6, "numba": numba}
            for s in ("rigid", "elastic") for p in ("f32", "f64")]


def test_without_numba_the_peer_is_skipped_with_one_line_and_its_keys_are_null(monkeypatch, capsys):
    monkeypatch.setattr(peers, "numba", None)
    monkeypatch.setattr(peers, "_said", [])
    scene = bench_scene("rigid_chaos")
    q, v = (a.T.copy() for a in reference.initial_state(scene))
    never = lambda *a: pytest.fail("nothing to time")  # noqa: E731
    assert peers.numba_timer(scene, q, v, 1e-3, 50, 0.1, never) is None
    assert peers.numba_timer(scene, q, v, 1e-3, 50, 0.1, never) is None
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"bench: {peers.MISSING}"] and "pip install -e '.[bench]'" in err[0]
    keys = peers.throughput_keys(rows(None), render_s=10.0, video_s=20.0)
    assert keys["sim_speedup_vs_numba_1e5"] is None and keys["elastic_speedup_vs_numba_1e5"] is None
    assert keys["elastic_speedup_vs_numpy_1e5"] == pytest.approx(10.0)
    assert keys["rigid_f64_steps_per_s_1e5"] == 2e7 and keys["render_over_realtime"] == 0.5
    assert peers.throughput_keys(rows(1e7), 10.0, 20.0)["sim_speedup_vs_numba_1e5"] == pytest.approx(2.0)


@pytest.mark.parametrize("preset", ["rigid_chaos", "elastic_fan"])
def test_numba_peer_integrates_the_reference_equations(preset):
    pytest.importorskip("numba")
    scene = bench_scene(preset)
    q0, v0 = reference.initial_state(scene)
    q, v = q0.copy(), v0.copy()
    peers.numba_rk4(scene, np.dtype(np.float64))(q, v, 100, 1e-3)
    qr, vr = q0.T.copy(), v0.T.copy()
    for _ in range(100):
        qr, vr = reference.rk4_step(scene, qr, vr, 1e-3)
    assert np.abs(q - qr.T).max() < 1e-10 and np.abs(v - vr.T).max() < 1e-8
    assert np.abs(q - q0).max() > 1e-3  # it moved
