"""render/commands/bench/peak.py: the peak-rate kernel computes exactly its chains (nothing skipped, nothing fused), so the
flops it claims are the ones it does."""
import numpy as np
import pytest

from render.commands.bench import peak
from render.physics import runtime


@pytest.mark.parametrize("prec", ["f64", "f32"])
def test_peak_kernel_computes_every_chain_exactly(prec):
    runtime.init("cpu", prec)
    p = peak.Peak()
    iters = 3
    p.run(iters)
    got = p.out.to_numpy()
    assert got.shape == (peak.GROUPS, p.count, p.lanes)
    assert p.count * p.lanes == peak.CHAINS * peak.LANES[prec]  # as many accumulators at any forced width
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



COUNT_IR = r"""
import json, pathlib, sys
import taichi as ti
from render.physics import registry
from render.config.scene import load
out = {}
for prec, sets in json.loads(sys.argv[1]):
    ti.init(arch=ti.cpu, default_fp=ti.f64 if prec == "f64" else ti.f32, fast_math=False, offline_cache=False,
            print_kernel_llvm_ir_optimized=True, log_level=ti.ERROR)  # runtime.init's settings, and the IR
    before = set(pathlib.Path().glob("*.ll"))
    scene = load("rigid_chaos", ["pendulums.count=64", 'integrator.method="rk4"', f'integrator.precision="{prec}"',
                                 'effects=["bobs"]'] + sets)
    sim = registry.kernels(scene.system)(scene)  # not a Run: it would restart the IR-printing ti.init above
    sim.advance(1, sim.h, False)
    ti.sync()
    ir = max(set(pathlib.Path().glob("*.ll")) - before, key=lambda p: p.stat().st_size).read_text()
    body = ir[ir.index("\nvector.body:"):]
    body = body[:body.index("\n\n")]  # the vectorised loop over a group's columns: one substep, W columns
    out[f"{prec} {sets}"] = sum(body.count(f"= {op} ") for op in ("fadd", "fsub", "fmul", "fdiv"))
print(json.dumps(out))
"""


def test_rigid_flop_count_is_the_arithmetic_of_the_compiled_step(tmp_path):
    """Each vector instruction of the vectorised RK4 loop does one flop per pendulum: their count is the flops of
    one pendulum's step, as rigid_rk4_flops says, with unit constants (rigid_chaos) and without."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    other = ["pendulums.lengths=[1.2, 0.8]", "pendulums.masses=[1.5, 0.7]"]
    cases = [(p, s) for p in ("f64", "f32") for s in ([], other)]
    root = Path(__file__).resolve().parent.parent
    r = subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(root)!r})\n" + COUNT_IR,
                        json.dumps(cases)], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout.strip().splitlines()[-1])
    want = {f"{p} {s}": peak.rigid_rk4_flops(p, *(((1.2, 0.8), (1.5, 0.7)) if s else ((1.0, 1.0), (1.0, 1.0))))
            for p, s in cases}
    assert got == want
    assert want == {"f64 []": 572, f"f64 {other}": 600, "f32 []": 356, f"f32 {other}": 384}
