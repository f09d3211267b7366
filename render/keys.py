"""Preset keys a system declares: a default and the range in which a value is accepted.

The scene loader validates values against these; a system module only declares them, so systems need not
import the loader.
"""
from __future__ import annotations

import dataclasses
import math


@dataclasses.dataclass(frozen=True)
class Real:
    """A finite number in [lo, hi] (or (lo, hi] with lo_open)."""
    default: float
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False


@dataclasses.dataclass(frozen=True)
class Reals:
    """A list of exactly len(default) numbers, each within the same range."""
    default: tuple[float, ...]
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False


def chain(links: int, extra: dict | None = None) -> dict:
    """The keys of a chain of `links` links: angles and rates of each link, and its lengths and masses."""
    keys = {}
    for k in range(1, links + 1):
        keys[f"theta{k}"] = Real(math.pi)
    for k in range(1, links + 1):
        keys[f"omega{k}"] = Real(0.0)
    keys["lengths"] = Reals((1.0,) * links, 0.0, 1e6, lo_open=True)
    keys["masses"] = Reals((1.0,) * links, 0.0, 1e6, lo_open=True)
    return {**keys, **(extra or {})}
