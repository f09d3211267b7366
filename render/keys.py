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


# Ranges of a chain's keys: where f64 (and f32) arithmetic on them stays meaningful. Angles wrap, so
# beyond ±1000 rad a value only loses resolution (f64 resolves ~1e-13 rad there, f32 ~1e-4). A link turning
# at 1e4 rad/s (1600 turns a second, 27 per 60 fps frame) is no longer a picture. Lengths (m) and masses
# (kg) within [1e-6, 1e6]: twelve decades, and the products the equations form (m·l²·ω², g·m·l, the
# triple's determinant ~ (m·l²)³) stay far inside f64's range (f32 drafts are held to [1e-3, 1e3] by
# render/validate.py); what a tiny or stiff scene costs in steps is the step budget's to refuse
# (render/budget.py), not a range's.
ANGLE_MAX = 1e3
RATE_MAX = 1e4
SIZE_MIN, SIZE_MAX = 1e-6, 1e6


def chain(links: int, extra: dict | None = None) -> dict:
    """The keys of a chain of `links` links: angles and rates of each link, and its lengths and masses."""
    keys = {}
    for k in range(1, links + 1):
        keys[f"theta{k}"] = Real(math.pi, -ANGLE_MAX, ANGLE_MAX)
    for k in range(1, links + 1):
        keys[f"omega{k}"] = Real(0.0, -RATE_MAX, RATE_MAX)
    keys["lengths"] = Reals((1.0,) * links, SIZE_MIN, SIZE_MAX)
    keys["masses"] = Reals((1.0,) * links, SIZE_MIN, SIZE_MAX)
    return {**keys, **(extra or {})}
