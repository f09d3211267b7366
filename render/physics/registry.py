"""The systems: every module in render/physics/systems/ that defines SYSTEM (a System subclass) is one.

Adding a system is adding a module there; nothing else names it. Everything that depends on the kind of
pendulum (the scene loader, simulate, accuracy, bench, quality, the canvas) asks this registry.
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
    """The System subclass registered under `name` (KeyError if none)."""
    return _all()[name]


def classes() -> list:
    return list(_all().values())
