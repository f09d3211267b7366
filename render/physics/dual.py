"""Forward-mode dual numbers for Taichi kernels: a value and K tangents, carried through a system's own force and
the scene's own integrator by Python's operators while Taichi traces the kernel.

    q = Dual(Q, [dQ_1, ..., dQ_K])      # in Taichi scope: each part a Taichi expression of the same shape
    q2, v2 = steps.step(sys, q, v, h)   # q2.v is the step; q2.d[k] its derivative along tangent k

Every operation a force is written with makes its value's code and, beside it, the chain rule's code for each
tangent (+, −, ×, ÷; sin and cos through System.sincos, whose derivative is the other one): the result is the
derivative of the numerical step to round-off, not a finite difference, and no physics is written here. Forces
made of other functions (ti.sqrt, ti.max...) are not covered: Taichi then refuses the Dual as an operand.

Why not Taichi's forward mode (ti.ad.FwdMode, render/physics/tangent.py). In Taichi 1.7.4 it cannot differentiate
the inline sin/cos of render/physics/sincos.py ("Not supported": its ti.round), so it runs a libm twin, which does not
vectorise; it needs scalarised matrices; and it carries one dual per loop element, so each of a point's K
tangent vectors repeats the whole primal. The FTLE map (render/maps/ftle.py) simulated a 720p frame in 2.13 s that
way (381,924 points, 17 RK4 substeps, K = 4); traced here, the primal once and its four tangents beside it, in
the group loop that System.advance_group vectorises, in 0.18 s (`python benchmarks/map_frame.py fractal_lyapunov
--seconds 0.2`, 2-core Xeon, AVX-512). On 2000 random states the tangents agreed with ti.ad.FwdMode's to 1.6e-16,
relative (a script not kept); tests/test_dual.py holds them to central differences.

Taichi's front end takes a Dual as it is: its arithmetic returns NotImplemented for one (patched below, so that
Python then asks the Dual), an object marked _data_oriented is passed into a ti.func without a copy, and
assigning to a Dual variable assigns its parts, each a local variable (so a Dual may change in a loop or a branch).
Those are Taichi 1.7.4's internals (impl.expr_init, impl.subscript, ops._binary_operation): pyproject.toml pins it,
and tests/test_dual.py fails if a later one behaves otherwise.
"""
import taichi as ti
from taichi.lang import impl, ops


def traced(fn):
    """A plain Python function that kernels call while Taichi traces them (its arguments may be Duals): marked so
    that the front end does not warn that it is not a ti.func."""
    fn._is_taichi_function = False
    return fn


class Dual:
    _data_oriented = True  # impl.expr_init passes such an object through as it is
    _is_taichi_function = False  # made in kernels: see traced()

    def __init__(self, v, d):
        self.v, self.d = impl.expr_init(v), [impl.expr_init(x) for x in d]

    def _assign(self, other):
        """`x = y` where x is a Dual variable: its parts take y's (in place, as any Taichi variable)."""
        self.v._assign(other.v)
        for a, b in zip(self.d, other.d):
            a._assign(b)
        return self

    def _augassign(self, other, op):
        return self._assign({"Add": self.__add__, "Sub": self.__sub__, "Mult": self.__mul__,
                             "Div": self.__truediv__}[op](other))

    def get_shape(self):
        return self.v.get_shape()

    def __getitem__(self, index):
        index = index if isinstance(index, tuple) else (index,)
        return Dual(impl.subscript(None, self.v, *index), [impl.subscript(None, x, *index) for x in self.d])

    def __neg__(self):
        return Dual(-self.v, [-x for x in self.d])

    def __add__(self, o):
        if isinstance(o, Dual):
            return Dual(self.v + o.v, [a + b for a, b in zip(self.d, o.d)])
        return Dual(self.v + o, self.d)

    __radd__ = __add__

    def __sub__(self, o):
        if isinstance(o, Dual):
            return Dual(self.v - o.v, [a - b for a, b in zip(self.d, o.d)])
        return Dual(self.v - o, self.d)

    def __rsub__(self, o):
        return Dual(o - self.v, [-x for x in self.d])

    def __mul__(self, o):
        if isinstance(o, Dual):
            return Dual(self.v * o.v, [a * o.v + self.v * b for a, b in zip(self.d, o.d)])
        return Dual(self.v * o, [x * o for x in self.d])

    __rmul__ = __mul__

    def __truediv__(self, o):
        if isinstance(o, Dual):
            q = impl.expr_init(self.v / o.v)
            return Dual(q, [(a - q * b) / o.v for a, b in zip(self.d, o.d)])
        return Dual(self.v / o, [x / o for x in self.d])

    def __rtruediv__(self, o):
        q = impl.expr_init(o / self.v)
        return Dual(q, [-q * x / self.v for x in self.d])


@traced
def is_dual(x) -> bool:
    return isinstance(x, Dual)


@traced
def sincos(x, primal):
    """(sin x, cos x) of a Dual, the values by primal(value) (the system's own sin and cos)."""
    s, c = primal(x.v)
    s, c = impl.expr_init(s), impl.expr_init(c)
    return Dual(s, [c * d for d in x.d]), Dual(c, [-s * d for d in x.d])


@traced
def rows(items):
    """ti.Matrix.rows of lane vectors, or of Duals (a Dual of matrices): what a force returns."""
    if not any(isinstance(i, Dual) for i in items):
        return ti.Matrix.rows(items)
    k = max(len(i.d) for i in items if isinstance(i, Dual))
    items = [i if isinstance(i, Dual) else Dual(i, [0.0 * i] * k) for i in items]
    return Dual(ti.Matrix.rows([i.v for i in items]), [ti.Matrix.rows([i.d[t] for i in items]) for t in range(k)])


def _defer_to_duals():
    """Taichi's binary operations turn any operand into an expression (and fail on a Dual); for a Dual they must
    return NotImplemented, so that Python calls the Dual's reflected operator. Nothing else changes."""
    binary = ops._binary_operation
    if getattr(binary, "defers_to_duals", False):
        return

    def operation(taichi_op, python_op, a, b):
        if isinstance(a, Dual) or isinstance(b, Dual):
            return NotImplemented
        return binary(taichi_op, python_op, a, b)

    operation.defers_to_duals = True
    ops._binary_operation = operation


_defer_to_duals()
