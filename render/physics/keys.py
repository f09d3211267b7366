"""Preset keys a system declares: a default and the range in which a value is accepted.

The scene loader validates values against these; a system module only declares them, so systems need not
import the loader.
"""
from __future__ import annotations

import dataclasses
import math
import re


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
# render/config/validate.py); what a tiny or stiff scene costs in time is the run-time budget's to refuse
# (render/config/budget.py), not a range's.
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


# The run-time budget (top-level `budget`, or --budget): the longest a run may be estimated to take before it
# is refused (render/config/budget.py; the default is budget.DEFAULT_LIMIT_S). At least a second; at most two days,
# far below the week after which an unfinished render's partial files count as abandoned (render/video/atomic.py).
BUDGET_MIN, BUDGET_MAX = 1.0, 2 * 24 * 3600.0
DURATION_UNITS = {"s": 1, "sec": 1, "m": 60, "min": 60, "h": 3600, "hr": 3600, "d": 86400}
_DURATION = re.compile(r"\s*(\d+(?:\.\d*)?|\.\d+)\s*([a-z]+)\s*")


def seconds(value) -> float | None:
    """A duration in seconds: a number (seconds) or a text such as "90", "90 s", "20 min", "2h", "1h30m";
    None when it is neither (or not finite)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        try:
            value = float(value)
        except OverflowError:
            return None
        return value if math.isfinite(value) else None
    if not isinstance(value, str) or not value.strip() or len(value) > 40:
        return None
    text = value.strip().lower()
    try:
        return float(text) if math.isfinite(float(text)) else None
    except ValueError:
        pass
    total, at = 0.0, 0
    for m in _DURATION.finditer(text):
        if m.start() != at or m.group(2) not in DURATION_UNITS:
            return None
        total, at = total + float(m.group(1)) * DURATION_UNITS[m.group(2)], m.end()
    return total if at == len(text) else None


# The effects that draw the pendulums themselves (glow composes these): the canvas gives them the frame or half
# of it, and validation asks for one of them under glow.
DRAWN = ("rods", "springs", "bobs", "trails")  # effects that draw the pendulums (glow composes these)
