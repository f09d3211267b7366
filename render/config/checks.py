"""Checking one value of a preset, and wording the one line that refuses it.

The typed checks (a finite number in a range, an integer, one of a few strings, a list of them, bounded text)
and the merge of a preset's tables with the schema's defaults, each raising SceneError as `FILE: KEY: why`;
and the helpers those lines are worded with (a range, a close match, a clipped value, a type). Kept apart
from validate.py, which says what each section accepts, so that module reads as the rules alone; catalog.py
and options.py word their own refusals with the same helpers.
"""
from __future__ import annotations

import difflib
import math
import re

from ..physics import keys, registry
from ..errors import SceneError
from .limits import REQUIRED, SYSTEMS


class Checker:
    """The checks every section uses; validate.Validator adds the sections."""

    def __init__(self, src: str, given: dict):
        self.src = src
        self.given = given  # the keys as written, before defaults

    def fail(self, key: str, msg: str):
        raise SceneError(f"{self.src}: {key}: {msg}")

    def merge(self, raw: dict, schema: dict, prefix: str) -> dict:
        out = {}
        for k, val in raw.items():
            key = prefix + k
            if k not in schema:
                owners = [n for n in SYSTEMS if prefix == "pendulums." and k in registry.get(n).preset_keys()]
                if owners:
                    self.fail(key, f"is not a key of this system (it belongs to system {' and '.join(owners)})")
                near = hint(k, list(schema), prefix) or elsewhere(k, schema, prefix)
                self.fail(show_key(key), "unknown key" + near)
            if isinstance(schema[k], dict):
                if not isinstance(val, dict):
                    self.fail(key, f"must be a table, got {tname(val)}")
                out[k] = self.merge(val, schema[k], key + ".")
            else:
                out[k] = val
        for k, default in schema.items():
            if k in out:
                continue
            if default is REQUIRED:
                self.fail(prefix + k, "missing (this key is required)")
            out[k] = self.merge({}, default, prefix + k + ".") if isinstance(default, dict) else default
        return out

    # typed getters ------------------------------------------------
    def real(self, d, sec, key, lo=-math.inf, hi=math.inf, lo_open=False):
        val, name = d[sec][key], f"{sec}.{key}"
        if isinstance(val, bool) or not isinstance(val, (int, float)):
            self.fail(name, f"must be a number, got {tname(val)}")
        try:
            val = float(val)
        except OverflowError:  # a TOML integer of hundreds of digits
            self.fail(name, f"must be finite, got an integer of {len(str(abs(val)))} digits")
        if not math.isfinite(val):
            self.fail(name, f"must be finite, got {val}")
        if val < lo or (lo_open and val == lo) or val > hi:
            self.fail(name, f"must be {describe_range(lo, hi, lo_open)}, got {val:g}")
        return val

    def integer(self, d, sec, key, lo, hi):
        val, name = d[sec][key], f"{sec}.{key}"
        if isinstance(val, bool) or not isinstance(val, int):
            self.fail(name, f"must be an integer, got {tname(val)}")
        if not lo <= val <= hi:
            self.fail(name, f"must be between {lo} and {hi}, got {clip(str(val))}")
        return val

    def choice(self, val, name, options):
        if not isinstance(val, str):
            self.fail(name, f"must be a string, got {tname(val)}")
        if val not in options:
            self.fail(name, f"unknown value {clip(repr(val))}{hint(val, list(options))}; choose from "
                      f"{', '.join(options)}")
        return val

    def reals(self, d, sec, key, n, lo=-math.inf, hi=math.inf, lo_open=False):
        val, name = d[sec][key], f"{sec}.{key}"
        if not isinstance(val, list) or len(val) != n:
            self.fail(name, f"must be a list of {_COUNT.get(n, n)} numbers, got {clip(repr(val))}")
        sub = {sec: {f"{key}[{i}]": x for i, x in enumerate(val)}}
        return tuple(self.real(sub, sec, f"{key}[{i}]", lo, hi, lo_open) for i in range(n))

    def declared(self, d, sec, key, spec):
        """A value of a key a system declared (render/physics/keys.py)."""
        if isinstance(spec, keys.Reals):
            return self.reals(d, sec, key, len(spec.default), spec.lo, spec.hi, spec.lo_open)
        return self.real(d, sec, key, spec.lo, spec.hi, spec.lo_open)

    def strings(self, val, name, options):
        if not isinstance(val, list) or not val:
            self.fail(name, f"must be a non-empty list of strings, got {clip(repr(val))}")
        out = tuple(self.choice(x, name, options) for x in val)
        if len(set(out)) != len(out):
            self.fail(name, f"lists an entry twice: {list(out)}")
        return out

    def text(self, val, name, limit):
        if not isinstance(val, str):
            self.fail(name, f"must be a string, got {tname(val)}")
        if len(val) > limit:
            self.fail(name, f"is longer than the limit of {limit} characters ({len(val)})")
        return val


_COUNT = {1: "one", 2: "two", 3: "three", 4: "four"}


def describe_range(lo: float, hi: float, lo_open: bool) -> str:
    """How an accepted range reads in a message: '> 0 and <= 1', '>= 0', '> 0 and within [1e-06, 1e+06]'.

    A range whose floor is above zero is a physically positive quantity, so it leads with '> 0'."""
    upper = f" and <= {hi:g}" if hi < math.inf else ""
    if lo == 0:
        return (">" if lo_open else ">=") + " 0" + upper
    if lo > 0:
        return f"> 0 and within [{lo:g}, {hi:g}]"
    if lo > -math.inf:
        return f"within [{lo:g}, {hi:g}]"
    return f"<= {hi:g}" if hi < math.inf else "a number"


def hint(word: str, options: list[str], prefix: str = "") -> str:
    close = difflib.get_close_matches(word, options, n=1)
    return f" (did you mean '{prefix}{close[0]}'?)" if close else ""


def elsewhere(word: str, schema: dict, prefix: str) -> str:
    """A hint for a key close to none of its own section's: a key of another system's pendulums (`stiffnes` in
    a rigid preset), or of a section below this one (`count` at the top, for pendulums.count)."""
    owners = {}
    if prefix == "pendulums.":
        for name in SYSTEMS:
            for key in registry.get(name).preset_keys():
                owners.setdefault(key, []).append(name)
    close = difflib.get_close_matches(word, list(owners), n=1)
    if close:
        return f" (did you mean '{prefix}{close[0]}', a key of system {' and '.join(owners[close[0]])}?)"
    below = {key: f"{prefix}{sec}.{key}" for sec, sub in schema.items() if isinstance(sub, dict) for key in sub}
    close = difflib.get_close_matches(word, list(below), n=1)
    return f" (did you mean '{below[close[0]]}'?)" if close else ""


def clip(text: str, limit: int = 80) -> str:
    """A user's value as shown in a one-line message: long values are cut, not printed whole."""
    return text if len(text) <= limit else text[:limit - 3] + "..."


def show_key(key: str) -> str:
    """A key as written (TOML quoted keys may hold anything), quoted where it is not a plain dotted name."""
    return key if re.fullmatch(r"[\w.\-]*", key) else clip(repr(key))


def tname(val) -> str:
    return {bool: "a boolean", str: "a string", list: "a list", dict: "a table", int: "an integer",
            float: "a number"}.get(type(val), type(val).__name__) + (
        f" {clip(repr(val))}" if not isinstance(val, dict) else "")
