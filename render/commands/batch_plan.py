"""Which scenes `pendulum batch` renders, and their folder names: preset names, paths and globs expanded,
`--sweep KEY=a,b,c` lists parsed into variants, and each output's scene loaded and named (plan).

Apart from batch.py because it is planning, not running: it loads and validates every scene in the parent
before any worker starts, and `compare --vary` (api.with_vary) parses its lists and checks its keys here too
without importing the batch's executors.
"""
from __future__ import annotations

import difflib
import fnmatch
import glob
import itertools
import json
import re
from pathlib import Path

from ..errors import SceneError
from ..config.options import output_name
from ..config.scene import SCHEMA, list_presets, load, parse_override, preset_path


def expand_refs(refs: list[str]) -> list[str]:
    """Names, paths and globs -> preset refs, in order, without repeats; a glob matching nothing is bad input."""
    if not refs:
        return [str(p) for p in list_presets()]
    out = []
    for ref in refs:
        if not any(c in ref for c in "*?["):
            preset_path(ref)  # a missing preset is a bad command line (exit 2), not a failed render
            out.append(ref)
        elif "/" in ref or ref.endswith(".toml"):
            matches = sorted(glob.glob(ref)) or _no_match(ref)
            for match in matches:  # each must be a preset file, as a path given outright must: a FIFO is none
                preset_path(match)
            out += matches
        else:
            out += [str(p) for p in list_presets() if fnmatch.fnmatchcase(p.stem, ref)] or _no_match(ref)
    return list(dict.fromkeys(out))


def _no_match(ref):  # an expression, so `matches or _no_match(ref)` reads as one line
    raise SceneError(f"{ref}: matches no preset (see 'pendulum presets')")


def check_key(key: str, what: str):
    """An override key must exist in the preset schema; checked once here instead of failing every preset."""
    node = SCHEMA
    for i, part in enumerate(key.split(".")):
        if not isinstance(node, dict) or part not in node:
            close = difflib.get_close_matches(part, list(node) if isinstance(node, dict) else [], n=1)
            hint = f" (did you mean '{'.'.join(key.split('.')[:i] + close)}'?)" if close else ""
            raise SceneError(f"{what} {key}: unknown key{hint}")
        node = node[part]
    if isinstance(node, dict):
        raise SceneError(f"{what} {key}: is a section; give a key inside it")


def parse_sweeps(items: list[str], what: str = "--sweep",
                 distinct: bool = True) -> list[tuple[str, list[tuple[str, str]]]]:
    """['k=a,b'] -> [('k', [(raw 'a', name text 'a'), ...])]; `what` names the option in errors (`compare`
    parses its --vary lists here too). distinct: a value listed twice is refused, as a crossed sweep would make
    that variant twice; paired --vary lists repeat values in a grid (rk2,rk2,rk4,rk4 beside f32,f64,f32,f64),
    and a comparison refuses only panels that are the same as a whole."""
    sweeps = []
    for item in items:
        key, sep, values = item.partition("=")
        key = key.strip()
        if not sep or not values.strip():
            raise SceneError(f"{what} {item!r}: expected KEY=V1,V2,...")
        if key == "name":
            raise SceneError(f"{what} name: variants are named after the swept values")
        check_key(key, what)
        vals = []
        for raw in _split_top(values, what):
            _, value = parse_override(f"{key}={raw}", what)
            vals.append((raw, _sanitize(_text(value))))
        if distinct and len({t for _, t in vals}) != len(vals):
            raise SceneError(f"{what} {key}: lists a value twice")
        sweeps.append((key, vals))
    return sweeps


def _split_top(text: str, what: str = "--sweep") -> list[str]:
    parts = [v.strip() for v in re.split(r",(?![^\[]*\])", text)]  # commas inside [...] do not split
    if not all(parts):
        raise SceneError(f"{what}: empty value in {text!r}")
    return parts


def _text(value) -> str:
    """Canonical text of a parsed value, so 1e-5 and 0.00001 name the same variant."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, list):
        return ",".join(_text(v) for v in value)
    return repr(value) if isinstance(value, float) else str(value)


def _sanitize(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", text)


def variant_name(base: str, assignment: tuple[tuple[str, str], ...]) -> str:
    """rigid_chaos + (('pendulums.spread', '1e-05'),) -> 'rigid_chaos__pendulums.spread_1e-05'."""
    return "__".join([base] + [f"{k}_{t}" for k, t in assignment])


def plan(refs, overrides, sweeps, quality=None) -> list[dict]:
    """One job per output: {'name', 'scene'} or, when the preset is bad, {'name', 'error'}.

    As with `render`, OUT/NAME/ is only ever the preset as written: with --set or --quality a render is
    NAME__<short hash> (options.output_name), a sweep's NAME__KEY_VALUE__<short hash>."""
    for item in overrides:
        check_key(".".join(parse_override(item)[0]), "--set")
    overridden = bool(overrides or quality)
    jobs = []
    for ref in refs:
        try:
            base = load(ref, overrides, quality)
        except SceneError as e:
            jobs.append({"name": Path(ref).stem, "error": str(e)})
            continue
        if not sweeps:
            base = output_name(base, overridden)
            jobs.append({"name": base.name, "scene": base})
            continue
        for combo in itertools.product(*[[(k, raw, t) for raw, t in vals] for k, vals in sweeps]):
            name = variant_name(base.name, tuple((k, t) for k, _, t in combo))
            sets = [*overrides, *(f"{k}={raw}" for k, raw, _ in combo), f"name={json.dumps(name)}"]
            try:
                scene = output_name(load(ref, sets, quality), overridden)
                jobs.append({"name": scene.name, "scene": scene})
            except SceneError as e:
                jobs.append({"name": name, "error": str(e)})
    seen = {}
    for job in jobs:
        if job["name"] in seen and "scene" in job:
            raise SceneError(f"{seen[job['name']]} and {job['scene'].source} both render to {job['name']}/")
        seen[job["name"]] = job["scene"].source if "scene" in job else job["name"]
    return jobs
