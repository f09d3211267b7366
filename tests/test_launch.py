"""render/physics/launch.py: a prepared launch runs the kernel Taichi would run, with the same arguments and the
same result, and every launch it does not cover goes through Taichi."""
import numpy as np
import pytest
import taichi as ti
from taichi.lang import kernel_impl

from render.physics import launch, runtime


@pytest.fixture(autouse=True, scope="module")
def taichi():
    runtime.init("cpu", "f64")


@ti.data_oriented
class Kernels(runtime.Launcher):
    def __init__(self):
        self.total = ti.field(ti.f64, ())
        self.x = ti.field(ti.f64, 4, needs_dual=True)
        self.y = ti.field(ti.f64, 4, needs_dual=True)

    @ti.kernel
    def add(self, a: ti.types.ndarray(dtype=ti.u8, ndim=3), k: ti.i32, s: ti.f32):
        """Each byte of `a` plus k, into `a`; the total plus s."""
        for i, j, c in ti.ndrange(a.shape[0], a.shape[1], a.shape[2]):
            a[i, j, c] = ti.cast(a[i, j, c] + k, ti.u8)
        self.total[None] += s

    @ti.kernel
    def scaled(self, a: ti.types.ndarray(dtype=ti.f64, ndim=1), twice: ti.template()) -> ti.f64:
        """The sum of `a`, doubled if `twice` (a compile-time choice: two compiled kernels)."""
        out = 0.0
        for i in range(a.shape[0]):
            f = 2.0 if ti.static(twice) else 1.0
            out += f * a[i]
        return out

    @ti.kernel
    def count(self, n: ti.u32) -> ti.i32:
        return ti.cast(n, ti.i32) - 7

    @ti.kernel
    def square(self):
        for i in self.x:
            self.y[i] = self.x[i] * self.x[i]


@pytest.fixture
def taichi_calls(monkeypatch):
    """How many launches went through Taichi's Kernel.__call__."""
    calls = []
    stock = kernel_impl.Kernel.__call__

    def counted(self, *args, **kwargs):
        calls.append(self.func.__name__)
        return stock(self, *args, **kwargs)
    monkeypatch.setattr(kernel_impl.Kernel, "__call__", counted)
    return calls


def test_a_prepared_launch_gives_what_taichi_gives(taichi_calls):
    k = Kernels()
    a = np.arange(24, dtype=np.uint8).reshape(2, 4, 3)
    for n in range(5):
        k.launch("add", a, n, 0.5)
    assert taichi_calls == ["add"]  # the first launch only
    assert isinstance(launch.launches(k).prepared["add"], launch.Prepared)
    np.testing.assert_array_equal(a, np.arange(24).reshape(2, 4, 3) + 10)  # 0 + 1 + 2 + 3 + 4
    assert k.total[None] == 2.5
    b = np.linspace(0.0, 1.0, 11)
    assert [k.launch("scaled", b, False) for _ in range(3)] == [pytest.approx(5.5)] * 3
    assert [k.launch("count", 3) for _ in range(3)] == [-4] * 3
    assert taichi_calls == ["add", "scaled", "count"]


def test_other_kinds_of_arguments_go_through_taichi(taichi_calls):
    k = Kernels()
    b = np.linspace(0.0, 1.0, 11)
    assert k.launch("scaled", b, False) == pytest.approx(5.5)
    assert k.launch("scaled", b, True) == pytest.approx(11.0)  # another template value: its own kernel
    assert k.launch("scaled", b, True) == pytest.approx(11.0)  # now prepared
    assert taichi_calls == ["scaled", "scaled"]
    with pytest.raises(ValueError, match="Non contiguous"):  # Taichi's own error, not a launch on a copy
        k.launch("scaled", b[::2], True)
    with pytest.raises(ValueError, match="required array has dtype=f64"):  # another dtype: Taichi's own error
        k.launch("scaled", b.astype(np.float32), True)
    assert len(taichi_calls) == 4
    assert k.launch("count", 9) == 2
    assert k.launch("count", 9) == 2
    with pytest.raises(Exception, match="cannot be converted"):  # not an integer: refused, not truncated
        k.launch("count", 2.5)


def test_a_launch_under_forward_mode_goes_through_taichi():
    """Inside ti.ad.FwdMode Taichi launches the kernel's forward-mode version: the prepared primal would leave
    the duals alone."""
    k = Kernels()
    k.x.from_numpy(np.array([1.0, 2.0, 3.0, 4.0]))
    k.launch("square")
    k.launch("square")
    with ti.ad.FwdMode(loss=k.y, param=k.x, seed=[1.0, 0.0, 0.0, 0.0]):
        k.launch("square")
    assert k.y.dual.to_numpy().tolist() == [2.0, 0.0, 0.0, 0.0]  # d(x0²)/dx0 = 2 x0, the others 0
    k.x.from_numpy(np.array([5.0, 6.0, 7.0, 8.0]))
    k.x.dual.fill(1.0)
    k.launch("square")  # after the block, the plain kernel again: the forward one would add 2 x to y's duals
    k.launch("square")
    assert k.y.to_numpy().tolist() == [25.0, 36.0, 49.0, 64.0]
    assert k.y.dual.to_numpy().tolist() == [2.0, 0.0, 0.0, 0.0]


@ti.kernel
def weighted(twice: ti.template(), a: ti.types.ndarray(dtype=ti.f64, ndim=2), big: ti.u32, h: ti.f64) -> ti.f64:
    """A kernel of no object, a template before the arguments the launch sets: sum(a) * h (doubled), and `big`
    read back whole."""
    out = 0.0
    for i, j in ti.ndrange(a.shape[0], a.shape[1]):
        out += a[i, j] * h * (2.0 if ti.static(twice) else 1.0)
    return out + ti.cast(big >> 31, ti.f64)


def test_a_kernel_of_no_object_with_a_template_first(taichi_calls):
    ready = launch.Launches()
    run = lambda *args: ready.launch("weighted", lambda: weighted, args)  # noqa: E731
    assert run(True, np.ones((2, 3)), 1 << 31, 0.5) == 7.0  # 6 * 0.5 * 2 + 1
    assert run(True, np.ones((4, 1)), np.uint32(5), np.float64(0.25)) == 2.0  # another shape, numpy scalars
    assert run(True, np.full((1, 1), 3.0), 0xFFFFFFFF, 1) == 7.0  # 3 * 1 * 2 + 1
    assert run(False, np.ones((2, 2)), 0, 1.0) == 4.0  # the other template value: Taichi's, then prepared
    assert run(False, np.ones((2, 2)), 0, 1.0) == 4.0
    assert taichi_calls == ["weighted", "weighted"]


def test_a_new_runtime_is_never_launched_from_an_old_preparation():
    k = Kernels()
    a = np.zeros((1, 1, 3), np.uint8)
    k.launch("add", a, 1, 0.0)
    k.launch("add", a, 1, 0.0)
    ready = launch.launches(k).prepared["add"]
    assert ready.fits((a, 1, 0.0))
    runtime.forget()
    runtime.init("cpu", "f64")
    assert not ready.fits((a, 1, 0.0))
    k2 = Kernels()
    k2.launch("add", a, 1, 0.0)
    k2.launch("add", a, 1, 0.0)
    assert a.tolist() == [[[4, 4, 4]]]
