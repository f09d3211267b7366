"""What a comparison may vary: the rule behind [compare] vary (render/config/validate.py) and `pendulum compare --vary`.

A comparison (render/draw/split.py) runs every variant from the same initial states into one split-screen video,
pendulum i of each panel measured against pendulum i of the finest variant. So it may vary what changes the
motion: the integrator, the --quality level that chooses one, and the physics under [pendulums]. It may not
vary the one video they share, the drawing, the names, the watchdogs (they do not change the motion), nor the
initial states (the panels would no longer show the same pendulums).
"""
from __future__ import annotations

import re

VARY_INTEGRATOR = ("method", "dt", "precision")
INITIAL_STATE = ("count", "layout", "spread", "gap")  # and each link's theta_k, omega_k (keys.chain)
VARIANTS = (2, 4)  # panels: side by side, or 2x2
PANEL_MIN = 16  # pixels a panel keeps on each side (the smallest video)
VARYING = "a comparison varies integrator.method, dt or precision, quality, or the physics under [pendulums]"


class Twice(ValueError):
    """A table names one dotted key twice: quoted and dotted (`"integrator.dt"` and `integrator.dt`), or
    quoted and as a sub-table ([compare.vary.integrator] dt). TOML sees two keys; one would silently win."""

    def __init__(self, key: str):
        super().__init__(key)
        self.key = key


def dotted(table: dict, prefix: str = "") -> dict:
    """A nested table as {dotted key: value}: TOML's `integrator.dt = ...` and `"integrator.dt" = ...` alike.
    Raises Twice when both name the same key."""
    out = {}
    for k, v in table.items():
        for key, val in (dotted(v, f"{prefix}{k}.") if isinstance(v, dict) else {prefix + k: v}).items():
            if key in out:
                raise Twice(key)
            out[key] = val
    return out


def vary_refusal(key: str) -> str | None:
    """Why a comparison cannot vary `key` (a dotted key of the scene), or None when it may."""
    section, _, leaf = key.rpartition(".")
    if key == "quality" or (section == "integrator" and leaf in VARY_INTEGRATOR):
        return None
    if section == "pendulums":
        if leaf in INITIAL_STATE or re.fullmatch(r"(theta|omega)\d+", leaf):
            return ("every panel starts from the same initial states, pendulum i compared with pendulum i "
                    "(`pendulum batch --sweep` renders different starts apart)")
        return None
    if section == "video":
        return "the panels share one video (its size, rate, length and formats)"
    if section == "integrator":
        return "it does not change the motion (a watchdog or certificate setting, the same for every panel)"
    return "it is the same for every panel (the scene's name, description, system and drawing)"


def frozen(value):
    """Lists to tuples, so a scene holding them stays hashable."""
    return tuple(frozen(v) for v in value) if isinstance(value, list) else value


def plain(value) -> bool:
    """A value a comparison can hold: what TOML and --vary give for a key's value (no tables, no dates)."""
    return isinstance(value, (bool, int, float, str)) or (isinstance(value, list) and all(map(plain, value)))
