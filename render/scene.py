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

PRESET_DIR = Path(__file__).resolve().parent.parent / "presets"

SYSTEMS = ("rigid", "elastic")
METHODS = {
    "rigid": ("symplectic_euler", "rk4", "implicit_midpoint"),
    "elastic": ("symplectic_euler", "rk4", "verlet", "yoshida4"),
}
PRECISIONS = ("f32", "f64")
FORMATS = ("mp4", "gif")
LAYOUTS = ("fan", "grid")
# What a scene can call for. Drawn effects need a canvas; the rest change the simulation or bookkeeping.
EFFECTS = ("rods", "springs", "bobs", "trails", "damping", "energy", "fractal")
DEFAULT_EFFECTS = {
    "rigid": ("rods", "bobs", "trails", "energy"),
    "elastic": ("springs", "bobs", "trails", "energy"),
}
MAX_PENDULUMS = 4_000_000  # ~0.5 GB of f64 state and work fields; beyond that a 24 GB machine struggles
MAX_PIXELS = 3840 * 2160


class SceneError(ValueError):
    """Bad input: one line, naming the file and the key."""


REQUIRED = object()  # schema default for keys a preset must state: the scene is ambiguous without them


# The schema: section -> key -> default. A default of None means "derived" (see _derive).
SCHEMA: dict[str, object] = {
    "name": "scene",
    "description": "",
    "system": REQUIRED,
    "effects": None,
    "pendulums": {
        "count": REQUIRED, "layout": "fan",
        "theta1": math.pi, "theta2": math.pi, "omega1": 0.0, "omega2": 0.0, "spread": 1e-4,
        "lengths": [1.0, 1.0], "masses": [1.0, 1.0], "gravity": 9.8, "stiffness": 2e3, "damping": 0.0,
    },
    "integrator": {
        "method": "rk4", "dt": "auto", "precision": "f64",
        "allow_unstable": False, "max_drift": None,
    },
    "video": {
        "width": 1280, "height": 720, "fps": 60, "duration": 20.0, "formats": ["mp4", "gif"],
        "trail_seconds": 1.0, "gif_width": 352, "gif_fps": 20,
    },
}


@dataclasses.dataclass(frozen=True)
class Pendulums:
    count: int
    layout: str
    theta1: float
    theta2: float
    omega1: float
    omega2: float
    spread: float
    lengths: tuple[float, float]
    masses: tuple[float, float]
    gravity: float
    stiffness: float
    damping: float


@dataclasses.dataclass(frozen=True)
class Integrator:
    method: str
    dt: "float | str"
    precision: str
    allow_unstable: bool
    max_drift: float | None


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
class Scene:
    name: str
    description: str
    system: str
    effects: tuple[str, ...]
    pendulums: Pendulums
    integrator: Integrator
    video: Video
    source: str = dataclasses.field(default="", compare=False)

    @property
    def frames(self) -> int:
        """Frames including the initial state at t=0."""
        return int(round(self.video.fps * self.video.duration))

    def has(self, effect: str) -> bool:
        return effect in self.effects

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
    if quality is not None and raw.get("system") in SYSTEMS:  # otherwise validation names the bad system
        from .quality import integrator_for
        raw.setdefault("integrator", {})
        if not isinstance(raw["integrator"], dict):
            raise SceneError(f"{src}: integrator: must be a table")
        raw["integrator"].update(integrator_for(quality, raw.get("system"), src))
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


def _sections(schema) -> list[str]:
    return [k for k, v in schema.items() if isinstance(v, dict)] if isinstance(schema, dict) else []


# ---------------------------------------------------------------- validation


def from_dict(raw: dict, src: str = "<scene>") -> Scene:
    v = _Validator(src)
    merged = v.merge(raw, SCHEMA, "")
    return v.build(merged)


class _Validator:
    def __init__(self, src: str):
        self.src = src

    def fail(self, key: str, msg: str):
        raise SceneError(f"{self.src}: {key}: {msg}")

    def merge(self, raw: dict, schema: dict, prefix: str) -> dict:
        out = {}
        for k, val in raw.items():
            key = prefix + k
            if k not in schema:
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

    def pair(self, d, sec, key):
        val, name = d[sec][key], f"{sec}.{key}"
        if not isinstance(val, list) or len(val) != 2:
            self.fail(name, f"must be a list of two numbers, got {val!r}")
        sub = {sec: {f"{key}[{i}]": x for i, x in enumerate(val)}}
        return tuple(self.real(sub, sec, f"{key}[{i}]", 0.0, 1e6, lo_open=True) for i in range(2))

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
        pend = self.pendulums(d, system, video)
        integ = self.integrator(d, system)
        effects = self.effects(d, system, pend)
        return Scene(name, d["description"], system, effects, pend, integ, video, source=self.src)

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

    def pendulums(self, d, system, video) -> Pendulums:
        layout = self.choice(d["pendulums"]["layout"], "pendulums.layout", LAYOUTS)
        count = self.integer(d, "pendulums", "count", 1, MAX_PENDULUMS)
        if layout == "grid" and count != video.width * video.height:
            self.fail("pendulums.count", f"a grid layout has one pendulum per pixel: "
                      f"{video.width}x{video.height} = {video.width * video.height}, got {count}")
        vals = {k: self.real(d, "pendulums", k) for k in ("theta1", "theta2", "omega1", "omega2", "spread")}
        lengths, masses = self.pair(d, "pendulums", "lengths"), self.pair(d, "pendulums", "masses")
        g = self.real(d, "pendulums", "gravity", 0.0, 1e4)
        k = self.real(d, "pendulums", "stiffness", 0.0, 1e12, lo_open=True)
        damp = self.real(d, "pendulums", "damping", 0.0, 1e3)
        return Pendulums(count, layout, vals["theta1"], vals["theta2"], vals["omega1"], vals["omega2"],
                         vals["spread"], lengths, masses, g, k, damp)

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
        return Integrator(method, dt, prec, allow, drift)

    def effects(self, d, system, pend) -> tuple[str, ...]:
        given = d["effects"]
        eff = list(DEFAULT_EFFECTS[system] if given is None else self.strings(given, "effects", EFFECTS))
        if pend.damping > 0 and "damping" not in eff:
            eff.append("damping")  # a damped scene always simulates its damping
        if "damping" in eff and pend.damping == 0:
            self.fail("effects", "lists 'damping' but pendulums.damping is 0")
        if "springs" in eff and system != "elastic":
            self.fail("effects", "'springs' needs system = \"elastic\" (a rigid pendulum has rods)")
        if "fractal" in eff:
            if pend.layout != "grid":
                self.fail("effects", "'fractal' colours one pendulum per pixel and needs pendulums.layout = \"grid\"")
            clash = [e for e in eff if e in ("rods", "springs", "bobs", "trails")]
            if clash:
                self.fail("effects", f"'fractal' fills every pixel; it cannot be combined with {clash}")
        elif pend.layout == "grid":
            self.fail("pendulums.layout", "a grid of pendulums is drawn with effects = [\"fractal\"]")
        return tuple(e for e in EFFECTS if e in eff)  # canonical order: same scene, same hash


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
