"""Presets: load a TOML file, apply overrides, validate into a frozen Scene.

Every problem is raised as SceneError with one line naming the file and the dotted key, so the CLI can
print it and exit 2 before anything is written.
"""
from __future__ import annotations

import dataclasses
import difflib
import hashlib
import json
import math
import re
import tomllib
from pathlib import Path

from . import grid, keys, registry
from .errors import SceneError
from .quality import LEVELS, check_level

PRESET_DIR = Path(__file__).resolve().parent.parent / "presets"

SYSTEMS = registry.names()
METHODS = {name: registry.get(name).METHODS for name in SYSTEMS}
PRECISIONS = ("f32", "f64")
FORMATS = ("mp4", "gif", "png")  # png: the last frame as a still
LAYOUTS = ("fan", "grid")
FRACTALS = ("angles", "flip_time", "divergence")  # how a map (effects = ["fractal"]) colours its pixels
# What a scene can call for. Drawn effects need a canvas; the rest change the simulation or bookkeeping.
EFFECTS = ("rods", "springs", "bobs", "trails", "damping", "energy", "fractal")
LINK_EFFECTS = {"rods": "rod", "springs": "spring"}  # effect -> the kind of link (System.LINKS) it draws
MAX_PENDULUMS = 4_000_000  # ~0.5 GB of f64 state and work fields; beyond that a 24 GB machine struggles
MAX_PIXELS = 3840 * 2160


REQUIRED = object()  # schema default for keys a preset must state: the scene is ambiguous without them


# Keys under [pendulums] that every system has; each system adds its own (System.preset_keys()).
# `gap` (the angle between neighbours) is another way to give the fan: it resolves to spread = gap·count.
FAN_KEYS = {"gap": "spread", "spread": "gap"}
# A grid derives its count from the frame (render/grid.py): one pendulum per pixel of the plot.
COMMON_PENDULUM_KEYS = {"count": None, "layout": "fan", "spread": 1e-4, "gap": None, "gravity": 9.8,
                        "damping": 0.0}


def pendulum_keys(system: str | None) -> dict:
    """Key -> default under [pendulums] for one system, or for any system (the union) when None."""
    out = dict(COMMON_PENDULUM_KEYS)
    for name in (SYSTEMS if system is None else (system,)):
        for key, spec in registry.get(name).preset_keys().items():
            out.setdefault(key, list(spec.default) if isinstance(spec, keys.Reals) else spec.default)
    return out


# The schema: section -> key -> default. A default of None means "derived" (see _derive).
SCHEMA: dict[str, object] = {
    "name": "scene",
    "description": "",
    "system": REQUIRED,
    "effects": None,
    "quality": None,  # a level of render/quality.py: the integrator is then chosen by pilot runs
    "fractal": None,  # a map's colouring (FRACTALS); "angles" when effects list "fractal" and this is not given
    "pendulums": pendulum_keys(None),
    "integrator": {
        "method": "rk4", "dt": "auto", "precision": "f64",
        "allow_unstable": False, "max_drift": None, "tolerance": 1e-3, "min_faithful": 0.1,
    },
    "video": {
        "width": 1280, "height": 720, "fps": 60, "duration": 20.0, "formats": ["mp4", "gif"],
        "trail_seconds": 1.0, "gif_width": 352, "gif_fps": 20,
    },
    "map": {  # fractal maps only
        "epsilon": 1e-6,  # rad: how far a divergence map's twin starts from its pixel, on the last link
        "threshold": 0.1,  # a pair has diverged when its distance in (θ, ω) passes this
        "trust_stride": 16,  # pixels between the lattice points the trust mask is certified on
    },
}


class Pendulums(dict):
    """The validated [pendulums] table: its keys depend on the system, read as attributes (p.count)."""

    def __getattr__(self, key):
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def __hash__(self):
        return hash(tuple(sorted(self.items())))

    def _readonly(self, *args, **kwargs):
        raise TypeError("a scene's pendulums are read-only; use Scene.replace")

    __setitem__ = __delitem__ = __setattr__ = update = pop = clear = setdefault = _readonly

    def __reduce__(self):  # pickling (batch workers) must not go through __setitem__
        return Pendulums, (dict(self),)


@dataclasses.dataclass(frozen=True)
class Integrator:
    method: str
    dt: "float | str"
    precision: str
    allow_unstable: bool
    max_drift: float | None
    tolerance: float  # faithfulness: rad on any angle, or a fraction of the total length for positions
    min_faithful: float  # the median pendulum must stay faithful this fraction of the duration


@dataclasses.dataclass(frozen=True)
class Video:
    width: int
    height: int
    fps: int
    duration: float
    formats: tuple[str, ...]
    trail_seconds: float
    gif_width: int
    gif_fps: int


@dataclasses.dataclass(frozen=True)
class MapSpec:
    epsilon: float
    threshold: float
    trust_stride: int


@dataclasses.dataclass(frozen=True)
class Scene:
    name: str
    description: str
    system: str
    effects: tuple[str, ...]
    pendulums: Pendulums
    integrator: Integrator
    video: Video
    quality: str | None = None
    fractal: str | None = None  # a map's colouring, None for a fan
    map: MapSpec | None = None
    source: str = dataclasses.field(default="", compare=False)

    @property
    def frames(self) -> int:
        """Frames including the initial state at t=0."""
        return int(round(self.video.fps * self.video.duration))

    def has(self, effect: str) -> bool:
        return effect in self.effects

    @property
    def model(self) -> str:
        """The independent model of this scene's system in render/reference.py."""
        return registry.get(self.system).REFERENCE

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.pop("source")
        return json.loads(json.dumps(d))  # tuples to lists: the same dict metadata.json reads back as

    def hash(self) -> str:
        blob = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()[:16]

    def replace(self, **sections) -> "Scene":
        """A copy with whole sections or fields swapped, e.g. replace(integrator={...})."""
        d = self.to_dict()
        if d["pendulums"]["layout"] == "grid" and "count" not in sections.get("pendulums", {}):
            del d["pendulums"]["count"]  # derived again from the (new) frame
        for k, v in sections.items():
            if isinstance(v, dict):
                d[k].update(v)
            else:
                d[k] = v
        return from_dict(d, self.source)


# ---------------------------------------------------------------- loading


def preset_path(ref: str) -> Path:
    """A preset name from presets/ or a path to a .toml file."""
    p = Path(ref)
    if p.suffix == ".toml" or "/" in ref:
        if not p.is_file():
            raise SceneError(f"{ref}: preset file not found")
        return p
    cand = PRESET_DIR / f"{ref}.toml"
    if not cand.is_file():
        names = [q.stem for q in PRESET_DIR.glob("*.toml")]
        raise SceneError(f"{ref}: no such preset{_hint(ref, names)} (see 'pendulum presets')")
    return cand


def list_presets() -> list[Path]:
    return sorted(PRESET_DIR.glob("*.toml"))


def load(ref: str, overrides: list[str] | tuple[str, ...] = (), quality: str | None = None) -> Scene:
    path = preset_path(ref)
    src = _display(path)
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{src}: malformed TOML: {e}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(f"{src}: cannot read: {e}") from None
    raw.setdefault("name", path.stem)
    if quality is not None:
        check_level(quality, src)
        raw["quality"] = quality
    for item in overrides:
        _apply_override(raw, item, src)
    return from_dict(raw, src)


def parse_override(item: str, src: str = "--set") -> tuple[list[str], object]:
    """'a.b=value' -> (['a','b'], value); the value is TOML, or a bare word taken as a string."""
    if "=" not in item:
        raise SceneError(f"{src}: --set {item!r}: expected KEY=VALUE")
    key, text = item.split("=", 1)
    key = key.strip()
    if not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*", key):
        raise SceneError(f"{src}: --set {item!r}: malformed key {key!r}")
    text = text.strip()
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if re.fullmatch(r"[A-Za-z_][\w\-]*", text):
            value = text
        else:
            raise SceneError(f"{src}: --set {key}: cannot parse value {text!r}") from None
    return key.split("."), value


def _apply_override(raw: dict, item: str, src: str) -> None:
    parts, value = parse_override(item, src)
    node, schema = raw, SCHEMA
    for i, part in enumerate(parts[:-1]):
        if not isinstance(schema, dict) or not isinstance(schema.get(part), dict):
            raise SceneError(f"{src}: --set {'.'.join(parts[:i + 1])}: not a section"
                             f"{_hint(part, _sections(schema))}")
        schema = schema[part]
        node = node.setdefault(part, {})
        if not isinstance(node, dict):
            raise SceneError(f"{src}: {'.'.join(parts[:i + 1])}: must be a table")
    node[parts[-1]] = value
    if parts[:-1] == ["pendulums"] and parts[-1] in FAN_KEYS:  # --set of one form of the fan replaces the other
        node.pop(FAN_KEYS[parts[-1]], None)


def _sections(schema) -> list[str]:
    return [k for k, v in schema.items() if isinstance(v, dict)] if isinstance(schema, dict) else []


# ---------------------------------------------------------------- validation


def from_dict(raw: dict, src: str = "<scene>") -> Scene:
    v = _Validator(src, raw)
    system = raw.get("system")
    known = isinstance(system, str) and system in SYSTEMS  # else build() names the bad value
    schema = {**SCHEMA, "pendulums": pendulum_keys(system)} if known else SCHEMA
    merged = v.merge(raw, schema, "")
    return v.build(merged)


class _Validator:
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
                self.fail(key, "unknown key" + _hint(k, list(schema), prefix))
            if isinstance(schema[k], dict):
                if not isinstance(val, dict):
                    self.fail(key, f"must be a table, got {_tname(val)}")
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
            self.fail(name, f"must be a number, got {_tname(val)}")
        val = float(val)
        if not math.isfinite(val):
            self.fail(name, f"must be finite, got {val}")
        if val < lo or (lo_open and val == lo) or val > hi:
            rng = f"{'>' if lo_open else '>='} {lo:g}" + (f" and <= {hi:g}" if hi < math.inf else "")
            self.fail(name, f"must be {rng}, got {val:g}")
        return val

    def integer(self, d, sec, key, lo, hi):
        val, name = d[sec][key], f"{sec}.{key}"
        if isinstance(val, bool) or not isinstance(val, int):
            self.fail(name, f"must be an integer, got {_tname(val)}")
        if not lo <= val <= hi:
            self.fail(name, f"must be between {lo} and {hi}, got {val}")
        return val

    def choice(self, val, name, options):
        if not isinstance(val, str):
            self.fail(name, f"must be a string, got {_tname(val)}")
        if val not in options:
            self.fail(name, f"unknown value {val!r}{_hint(val, list(options))}; choose from {', '.join(options)}")
        return val

    def reals(self, d, sec, key, n, lo=-math.inf, hi=math.inf, lo_open=False):
        val, name = d[sec][key], f"{sec}.{key}"
        if not isinstance(val, list) or len(val) != n:
            self.fail(name, f"must be a list of {_COUNT.get(n, n)} numbers, got {val!r}")
        sub = {sec: {f"{key}[{i}]": x for i, x in enumerate(val)}}
        return tuple(self.real(sub, sec, f"{key}[{i}]", lo, hi, lo_open) for i in range(n))

    def declared(self, d, sec, key, spec):
        """A value of a key a system declared (render/keys.py)."""
        if isinstance(spec, keys.Reals):
            return self.reals(d, sec, key, len(spec.default), spec.lo, spec.hi, spec.lo_open)
        return self.real(d, sec, key, spec.lo, spec.hi, spec.lo_open)

    def strings(self, val, name, options):
        if not isinstance(val, list) or not val:
            self.fail(name, f"must be a non-empty list of strings, got {val!r}")
        out = tuple(self.choice(x, name, options) for x in val)
        if len(set(out)) != len(out):
            self.fail(name, f"lists an entry twice: {list(out)}")
        return out

    def build(self, d: dict) -> Scene:
        name = d["name"]
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*", name):
            self.fail("name", f"must be a file-name-safe string, got {name!r}")
        if not isinstance(d["description"], str):
            self.fail("description", f"must be a string, got {_tname(d['description'])}")
        system = self.choice(d["system"], "system", SYSTEMS)
        video = self.video(d)
        fractal = self.fractal(d, system)
        pend = self.pendulums(d, system, video, fractal)
        integ = self.integrator(d, system)
        effects = self.effects(d, system, pend, fractal)
        if "fractal" in effects and fractal is None:
            fractal = "angles"
        mp = self.map(d, fractal)
        quality = d["quality"]
        if quality is not None:
            check_level(self.choice(quality, "quality", LEVELS), self.src)
        return Scene(name, d["description"], system, effects, pend, integ, video, quality, fractal, mp,
                     source=self.src)

    def fractal(self, d, system) -> str | None:
        val = d["fractal"]
        if val is None:
            return None
        self.choice(val, "fractal", FRACTALS)
        if not registry.get(system).ANGLES:
            self.fail("fractal", f"{val!r} colours pixels by link angles, and this system's state is not angles "
                      f"(systems with angles: {', '.join(n for n in SYSTEMS if registry.get(n).ANGLES)})")
        return val

    def map(self, d, fractal) -> MapSpec:
        given = self.given.get("map") or {}
        changed = [k for k, val in given.items() if val != SCHEMA["map"].get(k)]  # (a fan's own dict round trips)
        if fractal is None and changed:
            self.fail(f"map.{changed[0]}", "only a fractal map (effects = [\"fractal\"]) has this key")
        eps = self.real(d, "map", "epsilon", 0.0, 1.0, lo_open=True)
        thr = self.real(d, "map", "threshold", 0.0, 1e3, lo_open=True)
        if fractal == "divergence" and thr <= eps:
            self.fail("map.threshold", f"must exceed map.epsilon ({eps:g}): a pair starts that far apart")
        return MapSpec(eps, thr, self.integer(d, "map", "trust_stride", 1, 4096))

    def video(self, d) -> Video:
        w = self.integer(d, "video", "width", 16, 7680)
        h = self.integer(d, "video", "height", 16, 4320)
        for key, val in (("width", w), ("height", h)):
            if val % 2:
                self.fail(f"video.{key}", f"must be even (H.264 with yuv420p), got {val}")
        if w * h > MAX_PIXELS:
            self.fail("video.width", f"{w}x{h} is larger than 4K ({MAX_PIXELS} pixels)")
        fps = self.integer(d, "video", "fps", 1, 240)
        dur = self.real(d, "video", "duration", 0.0, 3600.0, lo_open=True)
        if round(fps * dur) < 1:
            self.fail("video.duration", f"gives no frames at {fps} fps")
        formats = self.strings(d["video"]["formats"], "video.formats", FORMATS)
        trail = self.real(d, "video", "trail_seconds", 0.0, 60.0, lo_open=True)
        gw = self.integer(d, "video", "gif_width", 16, 1920)
        if gw % 2:
            self.fail("video.gif_width", f"must be even, got {gw}")
        gfps = self.integer(d, "video", "gif_fps", 1, 50)
        return Video(w, h, fps, dur, formats, trail, gw, gfps)

    def pendulums(self, d, system, video, fractal) -> Pendulums:
        layout = self.choice(d["pendulums"]["layout"], "pendulums.layout", LAYOUTS)
        if layout == "grid":
            want = grid.pendulums(video.width, video.height, fractal)
            if d["pendulums"]["count"] is None:
                d["pendulums"]["count"] = want
            lay = grid.layout(video.width, video.height)
            if d["pendulums"]["count"] != want:
                self.fail("pendulums.count", f"a grid has one pendulum per pixel of its {lay.w}x{lay.h} plot"
                          f"{' and a twin for each' if want != lay.pixels else ''} in a {video.width}x"
                          f"{video.height} frame: {want} (leave it out), got {d['pendulums']['count']!r}")
        elif d["pendulums"]["count"] is None:
            self.fail("pendulums.count", "missing (this key is required)")
        count = self.integer(d, "pendulums", "count", 1, MAX_PENDULUMS)
        out = {"count": count, "layout": layout}
        out.update({k: self.declared(d, "pendulums", k, spec)
                    for k, spec in registry.get(system).preset_keys().items()})
        out["spread"] = self.real(d, "pendulums", "spread")
        if d["pendulums"]["gap"] is not None:
            if "spread" in self.given.get("pendulums", {}):
                self.fail("pendulums.gap", "give either pendulums.gap (between neighbours) or pendulums.spread "
                          "(over the whole fan), not both")
            out["spread"] = self.real(d, "pendulums", "gap") * count
        out["gravity"] = self.real(d, "pendulums", "gravity", 0.0, 1e4)
        out["damping"] = self.real(d, "pendulums", "damping", 0.0, 1e3)
        return Pendulums(out)

    def integrator(self, d, system) -> Integrator:
        method = self.choice(d["integrator"]["method"], "integrator.method", METHODS[system])
        dt = d["integrator"]["dt"]
        if dt != "auto":
            if isinstance(dt, str):
                self.fail("integrator.dt", f"must be a number of seconds or \"auto\", got {dt!r}")
            dt = self.real(d, "integrator", "dt", 0.0, 1.0, lo_open=True)
        prec = self.choice(d["integrator"]["precision"], "integrator.precision", PRECISIONS)
        allow = d["integrator"]["allow_unstable"]
        if not isinstance(allow, bool):
            self.fail("integrator.allow_unstable", f"must be true or false, got {_tname(allow)}")
        drift = d["integrator"]["max_drift"]
        if drift is not None:
            drift = self.real(d, "integrator", "max_drift", 0.0, 1e6, lo_open=True)
        tol = self.real(d, "integrator", "tolerance", 0.0, 1.0, lo_open=True)
        least = self.real(d, "integrator", "min_faithful", 0.0, 1.0)
        return Integrator(method, dt, prec, allow, drift, tol, least)

    def effects(self, d, system, pend, fractal) -> tuple[str, ...]:
        given = d["effects"]
        cls = registry.get(system)
        if given is None and fractal is not None:
            given = ["fractal"]  # a colouring names a map
        eff = list(cls.DEFAULT_EFFECTS if given is None else self.strings(given, "effects", EFFECTS))
        if fractal is not None and "fractal" not in eff:
            self.fail("fractal", f"colours a map, and effects = {eff} draws none: use effects = [\"fractal\"]")
        if pend.damping > 0 and "damping" not in eff:
            eff.append("damping")  # a damped scene always simulates its damping
        if "damping" in eff and pend.damping == 0:
            self.fail("effects", "lists 'damping' but pendulums.damping is 0")
        for effect, link in LINK_EFFECTS.items():
            if effect in eff and link not in cls.LINKS:
                having = [n for n in SYSTEMS if link in registry.get(n).LINKS]
                self.fail("effects", f"'{effect}' draws {link}s, and this system has none: its links are "
                          f"{list(cls.LINKS)} (systems with {link}s: {', '.join(having)})")
        if "fractal" in eff:
            if not cls.ANGLES:
                self.fail("effects", "'fractal' colours pixels by link angles, and this system's state is not "
                          "angles (systems with angles: " + ", ".join(n for n in SYSTEMS if registry.get(n).ANGLES)
                          + ")")
            if pend.layout != "grid":
                self.fail("effects", "'fractal' colours one pendulum per pixel and needs pendulums.layout = \"grid\"")
            clash = [e for e in eff if e in ("rods", "springs", "bobs", "trails")]
            if clash:
                self.fail("effects", f"'fractal' fills every pixel; it cannot be combined with {clash}")
        elif pend.layout == "grid":
            self.fail("pendulums.layout", "a grid of pendulums is drawn with effects = [\"fractal\"]")
        return tuple(e for e in EFFECTS if e in eff)  # canonical order: same scene, same hash


_COUNT = {1: "one", 2: "two", 3: "three", 4: "four"}


def _hint(word: str, options: list[str], prefix: str = "") -> str:
    close = difflib.get_close_matches(word, options, n=1)
    return f" (did you mean '{prefix}{close[0]}'?)" if close else ""


def _tname(val) -> str:
    return {bool: "a boolean", str: "a string", list: "a list", dict: "a table", int: "an integer",
            float: "a number"}.get(type(val), type(val).__name__) + (f" {val!r}" if not isinstance(val, dict) else "")


def _display(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)
