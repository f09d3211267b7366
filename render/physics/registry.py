"""The systems: every module in render/physics/systems/ that defines SYSTEM (a Plan subclass) is one, and the
module of the same name in render/physics/kernels/ is its Taichi side (KERNELS).

Adding a system is adding those two modules; nothing else names it. Everything that depends on the kind of
pendulum (the scene loader, simulate, accuracy, bench, quality, the canvas) asks this registry. get() gives the
declaration and the plan, which import no Taichi (listing presets, validating and refusing a scene start none);
kernels() the Taichi class, which only stepper.Run builds with fields.
"""
from __future__ import annotations

import functools
import importlib
import pkgutil

from . import systems


@functools.cache
def _all() -> dict:
    found = {}
    for info in sorted(pkgutil.iter_modules(systems.__path__), key=lambda m: m.name):
        cls = getattr(importlib.import_module(f"{systems.__name__}.{info.name}"), "SYSTEM", None)
        if cls is not None:
            found[cls.SYSTEM] = cls
    return found


def names() -> tuple[str, ...]:
    """Registered system names, in a stable order."""
    return tuple(_all())


def get(name: str):
    """The Plan subclass registered under `name` (KeyError if none): its declaration, and its plan when built."""
    return _all()[name]


def kernels(name: str):
    """The Taichi class of system `name`: its module in render/physics/kernels/ (imported now, with Taichi)."""
    module = get(name).__module__.rsplit(".", 1)[1]
    return importlib.import_module(f"{__package__}.kernels.{module}").KERNELS
