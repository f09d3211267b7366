"""render/physics/dual.py: the forward-mode duals a step is traced with give the step's own values to the bit and
its derivatives (against central differences of the plain step, and of each operator against its closed form)."""
import numpy as np
import pytest
import taichi as ti

from render.config.scene import load
from render.physics import dual, registry, runtime, steps

EPS = 1e-6  # central differences in f64: truncation ~ EPS² · |f'''|, round-off ~ 1e-16 / EPS


def plain_and_dual(name, sets, x0, substeps, h):
    """Per start: the plain step's end (n, 2D), the Dual's end, and its tangents (n, 2D, 2D), column k the image of
    unit vector k, all from the scene's own system, integrator and sin/cos."""
    scene = load(name, sets)
    runtime.init("cpu", "f64")
    sim = registry.kernels(scene.system)(scene, allocate=False)
    n, D = x0.shape[0], sim.D
    K = 2 * D
    x = ti.Vector.field(K, ti.f64, shape=n)
    plain, value = ti.Vector.field(K, ti.f64, shape=n), ti.Vector.field(K, ti.f64, shape=n)
    tan = ti.Vector.field(K, ti.f64, shape=(n, K))
    x.from_numpy(x0)

    @ti.kernel
    def run(s: ti.template()):
        for i in range(n):
            q = ti.Matrix.cols([ti.Vector([x[i][c] for c in ti.static(range(D))])])
            v = ti.Matrix.cols([ti.Vector([x[i][D + c] for c in ti.static(range(D))])])
            qd = dual.Dual(q, [ti.Matrix.cols([ti.Vector.unit(K, k, ti.f64)[0:D]]) for k in ti.static(range(K))])
            vd = dual.Dual(v, [ti.Matrix.cols([ti.Vector.unit(K, k, ti.f64)[D:K]]) for k in ti.static(range(K))])
            for _ in range(substeps):
                q, v = steps.step(s, q, v, h)
                qd, vd = steps.step(s, qd, vd, h)
            plain[i] = ti.Vector([q[c, 0] for c in ti.static(range(D))] + [v[c, 0] for c in ti.static(range(D))])
            value[i] = ti.Vector([qd.v[c, 0] for c in ti.static(range(D))] + [vd.v[c, 0] for c in ti.static(range(D))])
            for k in ti.static(range(K)):
                tan[i, k] = ti.Vector([qd.d[k][c, 0] for c in ti.static(range(D))]
                                      + [vd.d[k][c, 0] for c in ti.static(range(D))])

    run(sim)
    return plain.to_numpy(), value.to_numpy(), tan.to_numpy().transpose(0, 2, 1)


@pytest.mark.parametrize("name,sets", [("fractal_lyapunov", []), ("triple_chaos", []),
                                       ("fractal_lyapunov", ["effects=[\"fractal\",\"damping\"]",
                                                             "pendulums.damping=0.3"])])
def test_a_dual_step_is_the_plain_step_and_its_derivative(name, sets):
    rng = np.random.default_rng(7)
    D = 3 if name.startswith("triple") else 2
    x0 = np.concatenate([rng.uniform(-3, 3, (64, D)), rng.uniform(-4, 4, (64, D))], axis=1)
    substeps, h = 17, 1.0 / 30 / 17
    n, K = len(x0), 2 * D
    shifted = [x0 + sign * EPS * np.eye(K)[k] for k in range(K) for sign in (1, -1)]
    plain, value, tan = plain_and_dual(name, sets, np.concatenate([x0, *shifted]), substeps, h)
    assert plain.tobytes() == value.tobytes()  # the same operations: the same bits
    ends = plain[n:].reshape(K, 2, n, K)  # [k, up/down, start, coordinate]
    fd = ((ends[:, 0] - ends[:, 1]) / (2 * EPS)).transpose(1, 2, 0)  # [start, coordinate, k]
    tan = tan[:n]
    err = np.abs(tan - fd) / (1.0 + np.abs(fd))
    assert err.max() < 1e-7, err.max()
    assert np.abs(tan).max() > 1.0  # the frame stretches some direction: not a trivial identity


@ti.func
def libm(v):
    return ti.sin(v), ti.cos(v)


def test_each_operation_of_a_dual_has_its_derivative():
    runtime.init("cpu", "f64")
    xs = np.linspace(0.3, 2.9, 11)
    n = len(xs)
    x = ti.field(ti.f64, shape=n)
    out = ti.Vector.field(2, ti.f64, shape=(n, 8))
    x.from_numpy(xs)

    @ti.func
    def both(i, j, f):
        out[i, j] = ti.Vector([f.v, f.d[0]])

    @ti.kernel
    def run():
        for i in range(n):
            a = dual.Dual(x[i], [1.0])
            both(i, 0, 2.0 - a)
            both(i, 1, a * a - 3.0 * a)
            both(i, 2, 1.5 / a)
            both(i, 3, a / (1.0 + a * a))
            both(i, 4, -a + a)
            b = a * 1.0
            b += a
            b *= a  # 2a²
            b -= 0.5
            b /= a  # 2a − 0.5/a
            both(i, 5, b)
            s, c = dual.sincos(a, libm)
            both(i, 6, s * c)
            w = dual.Dual(ti.Vector([x[i]]), [ti.Vector([1.0])])  # a lane vector, as a force's rows are
            both(i, 7, dual.rows([w, 2.0 * w])[1, 0])

    run()
    got = out.to_numpy()
    want = [(2 - xs, -np.ones_like(xs)), (xs * xs - 3 * xs, 2 * xs - 3), (1.5 / xs, -1.5 / xs ** 2),
            (xs / (1 + xs ** 2), (1 - xs ** 2) / (1 + xs ** 2) ** 2), (0 * xs, 0 * xs),
            (2 * xs - 0.5 / xs, 2 + 0.5 / xs ** 2), (np.sin(xs) * np.cos(xs), np.cos(2 * xs)), (2 * xs, 2 + 0 * xs)]
    for j, (value, slope) in enumerate(want):
        np.testing.assert_allclose(got[:, j, 0], value, rtol=1e-14, atol=1e-15, err_msg=f"value {j}")
        np.testing.assert_allclose(got[:, j, 1], slope, rtol=1e-13, atol=1e-14, err_msg=f"derivative {j}")
