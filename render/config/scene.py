"""Presets: load a TOML file, apply overrides, validate into a frozen Scene.

Every problem is raised as SceneError with one line naming the file and the dotted key, so the CLI can
print it and exit 2 before anything is written. Which values are accepted is render/config/validate.py.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import tomllib
from pathlib import Path

from ..physics import keys, registry
from ..video.files import Refused, read_regular
from .catalog import PRESET_DIR, PRESET_MAX_BYTES, list_presets, preset_path  # noqa: F401 - where presets are found
from ..errors import SceneError
from ..trust.levels import check_level
from .checks import clip, hint
from .limits import FAN_ONLY, MAP_AXES, MAP_DEFAULTS, REQUIRED, SYSTEMS
from .validate import Validator

# Keys under [pendulums] that every system has; each system adds its own (System.preset_keys()).
# `gap` (the angle between neighbours) is another way to give the fan: it resolves to spread = gap·count.
FAN_KEYS = {"gap": "spread", "spread": "gap"}
# A grid derives its count from the frame (render/physics/grid.py): one pendulum per pixel of the plot.
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
    "quality": None,  # a level of render/trust/quality.py: the integrator is then chosen by pilot runs
    "budget": None,  # seconds (or "2h") a run may be estimated to take, beyond budget.DEFAULT_LIMIT_S
    "fractal": None,  # a map's colouring (limits.FRACTALS); "angles" when effects list "fractal" and this is not given
    "compare": None,  # a comparison: [compare] vary = { KEY = [V1, V2, ...] } (validate.py, split.py)
    "pendulums": pendulum_keys(None),
    "integrator": {
        "method": "rk4", "dt": "auto", "precision": "f64", "trig": "inline",
        "allow_unstable": False, "max_drift": None, "tolerance": 1e-3, "min_faithful": 0.1,
    },
    "video": {
        "width": 1280, "height": 720, "fps": 60, "duration": 20.0, "formats": ["mp4", "gif"],
        "trail_seconds": 1.0, "gif_width": 352, "gif_fps": 20, "palette": "fan",
    },
    "map": {**MAP_DEFAULTS, **MAP_AXES},  # fractal maps only
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
    trig: str  # "inline": render/physics/sincos.py (vectorises); "libm": the C library's, bit for bit as the seed ran
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
    palette: str = "fan"


@dataclasses.dataclass(frozen=True)
class MapSpec:
    epsilon: float
    threshold: float
    trust_stride: int
    samples: int = 1  # sub-pixel starts per pixel
    x: str = "theta1"  # the axes' quantities and spans (render/physics/grid.py)
    y: str = "theta2"
    x_range: tuple[float, float] = tuple(MAP_AXES["x_range"])
    y_range: tuple[float, float] = tuple(MAP_AXES["y_range"])


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
    compare: tuple | None = None  # ((dotted key, (value per panel, ...)), ...): a split-screen comparison
    budget: float | None = None  # seconds; how long the run may take, not what it makes: not hashed
    source: str = dataclasses.field(default="", compare=False)
    # How it was made from its preset, as given: "quality=LEVEL", then each --set, then the API's keyword values,
    # each a --set argument. Not part of the scene (not hashed): metadata.json's "overrides".
    overrides: tuple[str, ...] = dataclasses.field(default=(), compare=False)

    @property
    def frames(self) -> int:
        """Frames including the initial state at t=0."""
        return int(round(self.video.fps * self.video.duration))

    def has(self, effect: str) -> bool:
        return effect in self.effects

    @property
    def model(self) -> str:
        """The independent model of this scene's system in render/physics/reference.py."""
        return registry.get(self.system).REFERENCE

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.pop("source")
        d.pop("overrides")
        if self.fractal is None:  # a fan has no map (its [map] is the defaults): it hashes as before maps
            d.pop("fractal")
            d.pop("map")
        if self.budget is None:
            d.pop("budget")
        if self.compare is None:
            d.pop("compare")  # a scene without a comparison hashes as it did before there were any
        else:
            d["compare"] = {"vary": {key: values for key, values in self.compare}}
        return json.loads(json.dumps(d))  # tuples to lists: the same dict metadata.json reads back as

    def hash(self) -> str:
        d = self.to_dict()
        d.pop("budget", None)  # the same frames under any budget: the same folder, up to date in `batch`
        if d["integrator"]["trig"] == "inline":  # the default of a key added later: scenes keep their hash
            del d["integrator"]["trig"]
        for key, default in MAP_AXES.items():  # so are a map's default axes
            if "map" in d and d["map"][key] == default:
                del d["map"][key]
        if d.get("map", {}).get("samples") == 1:
            del d["map"]["samples"]
        blob = json.dumps(d, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()[:16]

    def out_dir(self, root: Path) -> Path:
        """Where the scene renders: ROOT/NAME/, a comparison ROOT/compare/NAME/."""
        return Path(root) / ("compare" if self.compare else "") / self.name

    def variants(self) -> list["Scene"]:
        """A comparison's panels: this scene without its [compare] table, with value i of every varied key in
        variant i; each validated as a preset is, its errors naming the variant."""
        base = self.to_dict()
        base.pop("compare", None)
        out = []
        for i in range(len(self.compare[0][1])):
            d = json.loads(json.dumps(base))
            for key, values in self.compare:
                *sections, leaf = key.split(".")
                node = d
                for part in sections:
                    node = node[part]
                node[leaf] = json.loads(json.dumps(values[i]))
                if key == "pendulums.damping":  # the validator adds the effect where damping > 0
                    d["effects"] = [e for e in d["effects"] if e != "damping"]
            label = ", ".join(f"{key}={json.dumps(values[i])}" for key, values in self.compare)
            out.append(from_dict(d, f"{self.source} (compare variant {i + 1}: {label})"))
        return out

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
        return dataclasses.replace(from_dict(d, self.source), overrides=self.overrides)


# ---------------------------------------------------------------- loading


def load(ref: str, overrides: list[str] | tuple[str, ...] = (), quality: str | None = None,
         values: dict | None = None) -> Scene:
    """The preset `ref` with `--set` overrides ("a.b=TOML") and then `values` (dotted key -> Python value,
    the API's keyword overrides) applied, validated."""
    path = preset_path(ref)
    src = _display(path)
    try:
        raw = tomllib.loads(read_regular(path, PRESET_MAX_BYTES).decode())  # never blocks, never reads past the cap
    except Refused as e:  # over the cap, or no longer a regular file since preset_path looked
        raise SceneError(f"{src}: {e}") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{src}: malformed TOML: {e}") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise SceneError(f"{src}: malformed TOML: nested too deeply") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(f"{src}: cannot read: {e}") from None
    raw.setdefault("name", path.stem)
    if quality is not None:
        check_level(quality, src)
        raw["quality"] = quality
    for item in overrides:
        _apply_override(raw, *parse_override(item, src), src)
    for key, value in (values or {}).items():
        _apply_override(raw, key.split("."), value, src, how="")
    given = ([f"quality={quality}"] if quality is not None else []) + list(overrides)
    given += [f"{key}={json.dumps(value)}" for key, value in (values or {}).items()]  # JSON's scalars are TOML's
    _quality_or_integrator(raw.get("quality"), overrides, values, src)
    return dataclasses.replace(from_dict(raw, src), overrides=tuple(given))


def _quality_or_integrator(level, overrides, values: dict | None, src: str) -> None:
    """A quality level beside integrator.method, .dt or .precision given by --set (or the API's values): the
    level's choice had replaced them silently. The preset's own [integrator] is what a level overrides."""
    keys = [item.split("=", 1)[0].strip() for item in overrides]
    for key, value in (values or {}).items():
        keys += [f"{key}.{k}" for k in value] if isinstance(value, dict) else [key]
    for key in keys if level is not None else ():
        if key in ("integrator.method", "integrator.dt", "integrator.precision"):  # what the pilots choose
            raise SceneError(f"{src}: --set {key}: quality {level!r} chooses the integrator's method, dt and "
                             f"precision; give the quality level or the {key}, not both")


def parse_override(item: str, src: str = "--set") -> tuple[list[str], object]:
    """'a.b=value' -> (['a','b'], value); the value is TOML, or a bare word taken as a string."""
    if "=" not in item:
        raise SceneError(f"{src}: --set {clip(repr(item))}: expected KEY=VALUE")
    key, text = item.split("=", 1)
    key = key.strip()
    if not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*", key):
        raise SceneError(f"{src}: --set {clip(repr(item))}: malformed key {clip(repr(key))}")
    text = text.strip()
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, RecursionError):
        if re.fullmatch(r"[A-Za-z_][\w\-]*", text):
            value = text
        else:
            raise SceneError(f"{src}: --set {key}: cannot parse value {clip(repr(text))}") from None
    return key.split("."), value


def _apply_override(raw: dict, parts: list[str], value, src: str, how: str = "--set ") -> None:
    node, schema = raw, SCHEMA
    for i, part in enumerate(parts[:-1]):
        if not isinstance(schema, dict) or not isinstance(schema.get(part), dict):
            raise SceneError(f"{src}: {how}{'.'.join(parts[:i + 1])}: not a section"
                             f"{hint(part, _sections(schema))}")
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
    """A validated Scene from a preset's table (render/config/validate.py checks every key)."""
    v = Validator(src, raw)
    system = raw.get("system")
    known = isinstance(system, str) and system in SYSTEMS  # else build() names the bad value
    schema = {**SCHEMA, "pendulums": pendulum_keys(system)} if known else SCHEMA
    d = v.build(v.merge(raw, schema, ""))
    for section, key in FAN_ONLY if d["fractal"] is not None else ():  # a map's pendulums are its pixels
        if raw.get(section, {}).get(key, schema[section][key]) != schema[section][key]:
            raise SceneError(f"{src}: {section}.{key}: applies to a fan, and does nothing in a map, whose "
                             f"pendulums are its pixels (map.x, map.y); leave it out")
    scene = Scene(d["name"], d["description"], d["system"], d["effects"], Pendulums(d["pendulums"]),
                  Integrator(**d["integrator"]), Video(**d["video"]), d["quality"], d["fractal"], MapSpec(**d["map"]),
                  d["compare"], d["budget"], source=src)
    if scene.compare:
        scene.variants()  # every variant's values are validated with the preset, before any work
    return scene


def _display(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)
