"""render/peak.py: the peak-rate kernel computes exactly its chains (nothing skipped, nothing fused), so the
flops it claims are the ones it does."""
import numpy as np
import pytest

from render import peak, runtime


@pytest.mark.parametrize("prec", ["f64", "f32"])
def test_peak_kernel_computes_every_chain_exactly(prec):
    runtime.init("cpu", prec)
    p = peak.Peak()
    iters = 3
    p.run(iters)
    got = p.out.to_numpy()
    assert got.shape == (peak.GROUPS, peak.CHAINS, peak.LANES[prec])
    dt = np.float64 if prec == "f64" else np.float32
    a0 = (np.arange(got.size).reshape(got.shape).astype(dt) + dt(1)) * dt(1.0 / (got.size + 1))
    a = a0.copy()
    for _ in range(iters * peak.UNROLL):  # the same recurrence in numpy: separate multiply and add, as Taichi's
        a = a * dt(peak.B) + dt(peak.C)
    np.testing.assert_array_equal(got, a)  # bit for bit: every step of every chain was done, none fused
    n = iters * peak.UNROLL  # and the closed form of a <- a·b + c
    closed = a0.astype(np.float64) * peak.B ** n + peak.C * (1 - peak.B ** n) / (1 - peak.B)
    assert np.abs(got - closed).max() < (1e-15 if prec == "f64" else 1e-6)
    assert len(np.unique(got)) == got.size  # every chain its own
    assert p.flops(iters) == 2 * got.size * n


def test_peak_timer_gives_a_rate_from_runs_of_at_least_min_s():
    runtime.init("cpu", "f64")
    rate = peak.Peak().timer(0.01)
    r = rate()
    assert np.isfinite(r) and r > 0

