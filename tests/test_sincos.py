"""render/physics/sincos.py against numpy's long-double sin/cos (the exact value, for f64 and f32 ulps), and the chunked
advance kernel that uses it: bit-identical at 1 and 2 threads and whatever a pendulum's place in its group."""
import numpy as np
import pytest
import taichi as ti

from conftest import make_scene
from render.physics import runtime
from render.physics.stepper import Run
from render.physics.sincos import sincos

LANES = 8
PI_LONG = np.longdouble("3.14159265358979323846264338327950288")


@ti.kernel
def eval_scalar(x: ti.types.ndarray(), s: ti.types.ndarray(), c: ti.types.ndarray()):
    for i in range(x.shape[0]):
        s[i], c[i] = sincos(x[i])


@ti.kernel
def eval_lanes(x: ti.types.ndarray(), s: ti.types.ndarray(), c: ti.types.ndarray()):
    """The same on ti.Vector lanes, as the systems call it on a row of a lane matrix."""
    for g in range(x.shape[0] // LANES):
        sv, cv = sincos(ti.Vector([x[g * LANES + k] for k in ti.static(range(LANES))]))
        for k in ti.static(range(LANES)):
            s[g * LANES + k], c[g * LANES + k] = sv[k], cv[k]


@ti.kernel
def eval_chunked(x: ti.types.ndarray(), s: ti.types.ndarray(), c: ti.types.ndarray()):
    """The same in System.advance's form: a runtime loop over the columns of a local matrix, which LLVM's
    loop vectoriser widens, each column a 1-lane vector."""
    for g in range(x.shape[0] // LANES):
        X, S, C = ti.Matrix.zero(float, 1, LANES), ti.Matrix.zero(float, 1, LANES), ti.Matrix.zero(float, 1, LANES)
        for k in range(LANES):
            X[0, k] = x[g * LANES + k]
        for k in range(LANES):
            S[:, k], C[:, k] = sincos(X[:, k])
        for k in range(LANES):
            s[g * LANES + k], c[g * LANES + k] = S[0, k], C[0, k]


def arguments(dtype) -> np.ndarray:
    """A wide spread: uniform to 1e5 and within ±π, log-spread from 1e-8, the floats nearest k·π/2 (±2 ulp,
    where sin or cos nearly vanishes), and ±0; no subnormals."""
    rng = np.random.default_rng(17)
    n = 100_000
    k = np.arange(0, 40_000, 7).astype(np.longdouble)
    near = [(PI_LONG / 2 * k).astype(dtype)]
    for _ in range(2):
        near = [np.nextafter(near[0], -np.inf)] + near + [np.nextafter(near[-1], np.inf)]
    near = np.concatenate(near).astype(np.float64)
    parts = [rng.uniform(-1e5, 1e5, n), rng.uniform(-np.pi, np.pi, n),
             rng.choice([-1.0, 1.0], n) * 10 ** rng.uniform(-8, 5, n), near, -near, [0.0, -0.0]]
    x = np.concatenate([np.asarray(p, dtype=np.float64) for p in parts]).astype(dtype)
    return x[(x == 0) | (np.abs(x) >= np.finfo(dtype).tiny)]  # the runtime flushes subnormal inputs to 0


def ulp_error(got: np.ndarray, exact: np.ndarray, dtype) -> np.ndarray:
    """|got − exact| in units of the spacing of `dtype` at the exact value (0 where the exact value is 0:
    those are checked for equality; Taichi's runtime flushes subnormals, numpy's spacing(0) included)."""
    zero = exact == 0
    spacing = np.spacing(np.abs(np.where(zero, 1, exact).astype(dtype))).astype(np.longdouble)
    return np.where(zero, 0.0, np.asarray(np.abs(got.astype(np.longdouble) - exact) / spacing, dtype=np.float64))


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_sincos_is_within_1_ulp_of_the_exact_value_in_every_form(precision):
    """Every form the kernels use (scalar: the maps; lanes and chunked: the advance loops) on any CPU: the
    runtime's IEEE arithmetic (fast_math off) is what keeps the reduction exact whatever the code generator."""
    runtime.init("cpu", precision)  # the project's settings, so the form the kernels use
    assert not ti.lang.impl.current_cfg().fast_math
    dtype = np.float64 if precision == "f64" else np.float32
    bound = 1.0  # measured: 0.76 (f64) and 0.76 (f32) ulp, the same bits in every form
    x = arguments(dtype)
    x = x[: len(x) // LANES * LANES]
    exact = x.astype(np.longdouble)
    exact_s, exact_c = np.sin(exact), np.cos(exact)  # 64-bit significands: exact at f64's 53 bits
    forms = []
    for kernel in (eval_scalar, eval_lanes, eval_chunked):
        s, c = np.empty_like(x), np.empty_like(x)
        kernel(x, s, c)
        forms.append(s.tobytes() + c.tobytes())
        es, ec = ulp_error(s, exact_s, dtype), ulp_error(c, exact_c, dtype)
        assert es.max() <= bound, (precision, kernel.__name__, x[es.argmax()], es.max())
        assert ec.max() <= bound, (precision, kernel.__name__, x[ec.argmax()], ec.max())
        # where the answer is exact it is given exactly
        zero = x == 0
        assert (s[zero] == 0).all() and (c[zero] == 1).all()
    assert forms[0] == forms[1] == forms[2]  # IEEE arithmetic: no form's code generation can change a bit


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_sincos_gives_nan_where_it_cannot_be_right(precision):
    runtime.init("cpu", precision)
    dtype = np.float64 if precision == "f64" else np.float32
    x = np.array([np.inf, -np.inf, np.nan, 2e9, -3e10, 1e30, 1e9, 0.5] * 1, dtype=dtype)
    s, c = np.empty_like(x), np.empty_like(x)
    eval_scalar(x, s, c)
    assert np.isnan(s[:6]).all() and np.isnan(c[:6]).all()
    assert np.isfinite(s[6:]).all() and np.isfinite(c[6:]).all()


def advanced(system, method, precision, q0, v0, threads, frames=3):
    """State after `frames` frames from (q0, v0), one pendulum per row, at the given thread count."""
    scene = make_scene(system, len(q0), integrator={"method": method, "dt": 2e-3, "precision": precision},
                       video={"fps": 10, "duration": 1.0})
    run = Run(scene, "cpu", threads)
    sim = run.sim
    sim.load(q0, v0)
    for _ in run.frames(frames + 1):
        pass
    return sim.q.to_numpy(), sim.v.to_numpy()


@pytest.mark.parametrize("system,method,precision", [("rigid", "rk4", "f64"), ("rigid", "rk4", "f32"),
                                                     ("elastic", "rk4", "f64"), ("triple", "rk4", "f64"),
                                                     ("rigid", "implicit_midpoint", "f64")])
def test_chunked_advance_is_bit_identical_at_1_and_2_threads_and_any_n(system, method, precision, monkeypatch):
    """N = 101 is no multiple of any group size, so the last group is padded; the first 37 pendulums run
    alone give the same bits as in the company of the others, wherever their group ends. So little work runs
    on the launching thread (runtime.SERIAL_WORK): here it goes to the pool, or two threads would be one."""
    from render.physics import runtime
    monkeypatch.setattr(runtime, "SERIAL_WORK", 0)
    d = {"rigid": 2, "elastic": 4, "triple": 3}[system]
    rng = np.random.default_rng(3)
    if system == "elastic":
        th = rng.uniform(-2, 2, (101, 2))
        x1, y1 = np.sin(th[:, 0]), -np.cos(th[:, 0])
        q0 = np.stack([x1, y1, x1 + np.sin(th[:, 1]), y1 - np.cos(th[:, 1])], 1)
    else:
        q0 = rng.uniform(-3, 3, (101, d))
    v0 = rng.normal(0, 1, (101, d))
    one = advanced(system, method, precision, q0, v0, threads=1)
    two = advanced(system, method, precision, q0, v0, threads=2)
    for a, b in zip(one, two):
        assert a.tobytes() == b.tobytes()
    alone = advanced(system, method, precision, q0[:37], v0[:37], threads=2)
    for a, b in zip(alone, two):
        assert a.tobytes() == b[:37].tobytes()
    assert np.isfinite(two[0]).all() and not np.array_equal(two[0], q0.astype(two[0].dtype))
