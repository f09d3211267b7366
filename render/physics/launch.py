"""Launching a kernel again without Taichi's per-call Python: a prepared launch.

At every launch Taichi 1.7.4's Kernel.__call__ works out from the arguments which compiled kernel they select
(its template mapper), sets each argument through a chain of type tests, and looks the compiled kernel up in
its cache. That Python is most of what a small kernel costs. Median µs a launch, through Taichi and prepared:
no argument 21.8 and 0.9; an array and two scalars (as draw_frame and hud_draw take) 48.3 and 5.9; four arrays
and a scalar (the MP4's conversion) 75.1 and 12.5; a returned value (the HUD's spread) 35.1 and 4.7
(`python benchmarks/launch_cost.py`, 5 rounds of 3000, 2-core Xeon, AVX-512, 2026-12-07). A render launches
about ten kernels a frame, on the thread that also feeds the encoders.

A prepared launch, made after a first launch through Taichi (which compiles or loads the kernel), holds that
compiled kernel and how to set each of its arguments. A later launch whose arguments are of the same kinds
(scalars of the annotated types, C-contiguous numpy arrays of the same dtype and number of dimensions, the same
template values) sets them straight into a launch context: the compiled kernel Taichi's mapper would pick is
the same one, since it keys on exactly those kinds. Anything else goes through Taichi as before: a kernel whose
arguments this does not cover (fields or objects as templates, Taichi's own ndarrays, structs), every launch
after Taichi is initialised again, and a launch under Taichi's autodiff (a FwdMode or a Tape), where Taichi runs
the kernel's forward or validating version: none is prepared then (tests/test_launch.py). The compiled kernel is
looked up once, where Taichi looks it up in its cache at every launch by the compile settings of the moment;
only render/physics/tangent.py changes one (force_scalarize_matrix), around a launch of its own under FwdMode.
"""
from __future__ import annotations

import numpy as np
from taichi.lang import impl
from taichi.lang.enums import AutodiffMode
from taichi.lang.util import cook_dtype
from taichi.types import ndarray_type, primitive_types
from taichi.types.annotations import template
from taichi.types.utils import is_signed

_SCALARS = (bool, int, float)  # the template values a prepared launch keeps


class Prepared:
    """How to launch one compiled kernel again: see the module's docstring. Make one with Prepared.of()."""

    def __init__(self, primal, full_args: tuple, skip: int):
        key = primal.ensure_compiled(*full_args)  # compiled by the launch before: a lookup
        self.t_kernel = primal.compiled_kernels[key]
        self.prog = impl.get_runtime().prog
        self.data = self.prog.compile_kernel(self.prog.config(), self.prog.get_device_caps(), self.t_kernel)
        self.n = len(full_args) - skip  # the arguments the caller passes (a class kernel's owner is not one)
        self.setters, self.arrays, self.templates = [], [], []
        slot = 0  # the launch context numbers the arguments that are not templates
        for i, (arg, v) in enumerate(zip(primal.arguments[skip:], full_args[skip:])):
            ann = arg.annotation
            if isinstance(ann, template):
                self.templates.append((i, v))
                continue
            if isinstance(ann, ndarray_type.NdarrayType):
                self.arrays.append((i, v.dtype, v.ndim))
                kind = "array"
            elif id(ann) in primitive_types.real_type_ids:
                kind = "float"
            else:
                kind = "int" if is_signed(cook_dtype(ann)) else "uint"
            self.setters.append((i, (slot,), kind))
            slot += 1
        self.ret = None
        if primal.return_type is not None:
            ret = primal.return_type[0]
            self.ret = "float" if ret in primitive_types.real_types else \
                "int" if is_signed(cook_dtype(ret)) else "uint"

    @classmethod
    def of(cls, kernel, args: tuple) -> Prepared | None:
        """A prepared launch of `kernel` (a @ti.kernel function, or one bound to its data-oriented owner) as
        just launched with `args`, or None where one would not launch it as Taichi does."""
        primal = getattr(kernel, "_primal", None)
        if primal is None:  # not a Taichi kernel: a method that launches one
            return None
        bound = getattr(kernel, "_kernel_owner", None)  # a data-oriented object's kernel, bound to it
        owner = () if bound is None or kernel._is_staticmethod else (bound,)
        full = owner + tuple(args)
        rt = impl.get_runtime()
        if len(full) != len(primal.arguments) or primal.has_print or not _covered(primal.return_type) or \
                primal.autodiff_mode != AutodiffMode.NONE or rt.fwd_mode_manager is not None or \
                rt.target_tape is not None:  # under autodiff Taichi launches another kernel, until it ends
            return None
        for k, (arg, v) in enumerate(zip(primal.arguments, full)):
            ann = arg.annotation
            if isinstance(ann, template):
                if not (k < len(owner) or type(v) in _SCALARS):
                    return None
            elif isinstance(ann, ndarray_type.NdarrayType):
                if type(v) is not np.ndarray or not v.flags.c_contiguous or \
                        id(ann.dtype) not in primitive_types.type_ids:
                    return None
            elif id(ann) not in primitive_types.type_ids:
                return None
        return cls(primal, full, len(owner))

    def fits(self, args: tuple) -> bool:
        """Whether `args` select this launch's compiled kernel, in the runtime it was compiled in."""
        rt = impl.get_runtime()
        if len(args) != self.n or rt.prog is not self.prog or rt.fwd_mode_manager is not None or \
                rt.target_tape is not None:
            return False
        for i, dtype, ndim in self.arrays:
            v = args[i]
            if type(v) is not np.ndarray or v.dtype != dtype or v.ndim != ndim or not v.flags.c_contiguous:
                return False
        for i, value in self.templates:
            if type(args[i]) is not type(value) or args[i] != value:
                return False
        for i, _, kind in self.setters:
            if kind == "float" and not isinstance(args[i], (float, int, np.floating, np.integer)) or \
                    kind in ("int", "uint") and not isinstance(args[i], (int, np.integer)):
                return False
        return True

    def __call__(self, args: tuple):
        ctx = self.t_kernel.make_launch_context()
        for i, slot, kind in self.setters:
            v = args[i]
            if kind == "array":
                ctx.set_arg_external_array_with_shape(slot, int(v.ctypes.data), v.nbytes, v.shape, 0)
            elif kind == "float":
                ctx.set_arg_float(slot, float(v))
            elif kind == "int":
                ctx.set_arg_int(slot, int(v))
            else:
                ctx.set_arg_uint(slot, int(v))
        self.prog.launch_kernel(self.data, ctx)
        if self.ret is None:
            return None
        impl.get_runtime().sync()  # as Taichi does before it reads a result
        if self.ret == "float":
            return ctx.get_struct_ret_float((0,))
        return ctx.get_struct_ret_int((0,)) if self.ret == "int" else ctx.get_struct_ret_uint((0,))


def _covered(ret) -> bool:
    """Whether a prepared launch reads this return type: none, or one scalar."""
    return ret is None or len(ret) == 1 and id(ret[0]) in primitive_types.type_ids


class Launches:
    """The prepared launches of one owner's kernels, by name. launch() goes through Taichi the first time, and
    whenever the arguments do not fit the launch prepared (then it prepares one for them); otherwise straight to
    the compiled kernel."""

    def __init__(self):
        self.prepared: dict = {}

    def launch(self, name, kernel_of, args: tuple):
        """kernel_of(): the kernel, asked for only when Taichi launches it."""
        ready = self.prepared.get(name)
        if ready is not None and ready.fits(args):
            return ready(args)
        kernel = kernel_of()
        out = kernel(*args)
        self.prepared[name] = Prepared.of(kernel, args)
        return out


def launches(owner) -> Launches:
    """The prepared launches of an object's kernels, kept in its own __dict__."""
    found = owner.__dict__.get("_launches")
    if found is None:
        found = owner.__dict__["_launches"] = Launches()
    return found


def call(owner, name: str, *args):
    """owner's kernel `name` launched with `args`, as prepared after its first launch."""
    return launches(owner).launch(name, lambda: getattr(owner, name), args)
