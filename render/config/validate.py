"""Validation of a preset's values: every key typed and within its physical range, or one SceneError line.

Kept apart from the loader (scene.py) so each reads as one idea: scene.py says what a preset is and how it
is read; this module says which values each section accepts and why. The choices and ranges are
render/config/limits.py (systems declare theirs in render/physics/keys.py), the typed checks of one value
render/config/checks.py; what a valid scene *costs* is render/config/budget.py.

Validator.build returns plain, validated sections; scene.from_dict turns them into the frozen Scene.
"""
from __future__ import annotations

import json
import re
from types import SimpleNamespace  # the validated [map] read as grid.py reads a MapSpec

from ..physics import grid, keys, registry
from ..trust.levels import LEVELS
from .checks import Checker, clip, hint, show_key, tname
from .limits import (AXIS_MAX, DAMPING_MAX, DESCRIPTION_MAX, EFFECTS, F32_SIZE_MAX, F32_SIZE_MIN, FORMATS, FRACTALS,
                     GRAVITY_MAX, LAYOUTS, LINK_EFFECTS, MAP_AXES, MAP_DEFAULTS, MAX_MAP_PENDULUMS, MAX_PENDULUMS,
                     MAX_PIXELS, METHODS, NAME_MAX, NAME_PATTERN, PALETTES, POINCARE_MIN, PRECISIONS, RESERVED_NAMES,
                     SAMPLES, SPREAD_MAX, SYSTEMS, TRIGS)
from .vary import PANEL_MIN, VARIANTS, VARYING, Twice, dotted, frozen, plain, vary_refusal


class Validator(Checker):
    """The sections' rules, each written with Checker's typed checks."""

    def build(self, d: dict) -> dict:
        """The validated sections: name, description, system, effects, pendulums, integrator, video."""
        name = self.text(d["name"], "name", NAME_MAX)
        if not re.fullmatch(NAME_PATTERN, name):
            self.fail("name", f"must be a file-name-safe string (letters, digits, _ . -), got {clip(repr(name))}")
        if name in RESERVED_NAMES:
            self.fail("name", f"{name!r} is what OUT itself holds ({', '.join(RESERVED_NAMES)}): choose another")
        description = self.text(d["description"], "description", DESCRIPTION_MAX)
        system = self.choice(d["system"], "system", SYSTEMS)
        video = self.video(d)
        fractal = self.fractal(d, system)
        spec = self.map(d, fractal, system)
        pend = self.pendulums(d, system, video, fractal, spec)
        integ = self.integrator(d, system)
        if fractal is not None and grid.f64_reason(video["width"], video["height"], SimpleNamespace(**spec)):
            integ["precision"] = "f64"  # a zoom f32 cannot resolve: grid.f64_reason, said in the map's metadata
        if integ["precision"] == "f32":
            for key in ("lengths", "masses"):
                for i, x in enumerate(pend[key]):
                    if not F32_SIZE_MIN <= x <= F32_SIZE_MAX:
                        self.fail(f"pendulums.{key}[{i}]", f"{x:g} is beyond what f32 arithmetic holds here (within "
                                  f"[{F32_SIZE_MIN:g}, {F32_SIZE_MAX:g}]); use integrator.precision = \"f64\"")
        quality = d["quality"]
        if quality is not None:
            self.choice(quality, "quality", LEVELS)
        effects = self.effects(d, system, pend, fractal)
        if "fractal" in effects and fractal is None:
            fractal = "angles"
        if "lyapunov" in effects and (d.get("compare") is not None or fractal is not None):
            self.fail("effects", "'lyapunov' measures the certified pendulums of one fan beside the certificate; "
                      "for a comparison or a map, run `pendulum lyapunov` on the variant or pixel instead")
        if "poincare" in effects:  # its panel (render/draw/section.py): title, ticks and labels around a plot
            panel = video["width"] // 2 if any(e in keys.DRAWN for e in effects) else video["width"]
            if min(panel, video["height"]) < POINCARE_MIN:
                self.fail("effects", f"'poincare' draws its section in a panel of {panel}x{video['height']} px, "
                          f"and needs {POINCARE_MIN} px each way (video.width {2 * POINCARE_MIN} beside the pendulums)")
        if "poincare" in effects and d.get("compare") is not None:
            self.fail("compare", "a Poincaré section is drawn from crossings found as the pendulums are stepped, "
                      "which a comparison's panels do not record; render each variant with --set instead")
        return {"name": name, "description": description, "system": system, "quality": quality,
                "budget": self.budget(d),
                "effects": effects, "pendulums": pend, "integrator": integ, "video": video,
                "fractal": fractal, "map": spec, "compare": self.compare(d, pend, video, fractal)}

    def budget(self, d) -> float | None:
        """The run-time budget in seconds (render/config/budget.py), a number or a text such as "2h" or "90 min"."""
        val = d["budget"]
        if val is None:
            return None
        secs = keys.seconds(val)
        if secs is None:
            self.fail("budget", f"must be a number of seconds or a duration such as \"90 min\" or \"2h\", got "
                      f"{tname(val)}")
        if not keys.BUDGET_MIN <= secs <= keys.BUDGET_MAX:
            self.fail("budget", f"must be between {keys.BUDGET_MIN:g} s and {keys.BUDGET_MAX / 3600:g} h, got "
                      f"{secs:g} s")
        return secs

    def fractal(self, d, system) -> str | None:
        val = d["fractal"]
        if val is None:
            return None
        self.choice(val, "fractal", FRACTALS)
        if not registry.get(system).ANGLES:
            self.fail("fractal", f"{val!r} colours pixels by link angles, and this system's state is not angles "
                      f"(systems with angles: {', '.join(n for n in SYSTEMS if registry.get(n).ANGLES)})")
        return val

    def map(self, d, fractal, system) -> dict:
        given = self.given.get("map") or {}
        defaults = {**MAP_DEFAULTS, **MAP_AXES}
        changed = [k for k, val in given.items() if val != defaults.get(k)]  # (a fan's own dict round trips)
        if fractal is None and changed:
            self.fail(f"map.{changed[0]}", "only a fractal map (effects = [\"fractal\"]) has this key")
        eps = self.real(d, "map", "epsilon", 0.0, 1.0, lo_open=True)
        thr = self.real(d, "map", "threshold", 0.0, 1e3, lo_open=True)
        if fractal == "divergence" and thr <= eps:
            self.fail("map.threshold", f"must exceed map.epsilon ({eps:g}): a pair starts that far apart")
        out = {"epsilon": eps, "threshold": thr, "trust_stride": self.integer(d, "map", "trust_stride", 1, 4096),
               "samples": self.samples(d)}
        return {**out, **self.axes(d, system)}

    def samples(self, d) -> int:
        val = d["map"]["samples"]
        if isinstance(val, bool) or not isinstance(val, int) or val not in SAMPLES:
            self.fail("map.samples", f"must be 1, 4 or 9 (a pixel's centre, or a 2 x 2 or 3 x 3 split of it), "
                      f"got {clip(repr(val))}")
        return val

    def axes(self, d, system) -> dict:
        """[map] x, y (quantities, grid.quantities) and x_range, y_range ([lo, hi], lo < hi)."""
        offered = grid.quantities(len(registry.get(system).LINKS))
        out = {}
        for axis in ("x", "y"):
            val, name = d["map"][axis], f"map.{axis}"
            if val in grid.RATIOS:
                self.fail(name, f"{val!r} ({grid.RATIOS[val]}) would need a mass or length per pixel, and the "
                          f"systems' kernels take one per scene; choose from {', '.join(offered)}")
            out[axis] = self.choice(val, name, offered)
            lo, hi = self.reals(d, "map", f"{axis}_range", 2, -AXIS_MAX, AXIS_MAX)
            if not lo < hi:
                self.fail(f"map.{axis}_range", f"must be [lo, hi] with lo < hi, got [{lo:g}, {hi:g}]")
            if (hi - lo) < 1e-12 * max(abs(lo), abs(hi), 1.0):
                self.fail(f"map.{axis}_range", f"[{lo:.17g}, {hi:.17g}] is narrower than f64 resolves pixel steps "
                          f"in (1e-12 of the values)")
            out[f"{axis}_range"] = (lo, hi)
        if out["x"] == out["y"]:
            self.fail("map.y", f"is map.x's quantity too ({out['x']!r}): a map's axes are two different quantities")
        return out

    def video(self, d) -> dict:
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
        palette = self.choice(d["video"]["palette"], "video.palette", PALETTES)
        return {"width": w, "height": h, "fps": fps, "duration": dur, "formats": formats, "trail_seconds": trail,
                "gif_width": gw, "gif_fps": gfps, "palette": palette}

    def pendulums(self, d, system, video, fractal, spec) -> dict:
        layout = self.choice(d["pendulums"]["layout"], "pendulums.layout", LAYOUTS)
        if layout == "grid":
            want = grid.pendulums(video["width"], video["height"], fractal, SimpleNamespace(**spec))
            if d["pendulums"]["count"] is None:
                d["pendulums"]["count"] = want
            lay = grid.layout(video["width"], video["height"], SimpleNamespace(**spec))
            samples = spec["samples"]
            each = f"{samples} sub-pixel starts" if samples > 1 else "one pendulum"
            if d["pendulums"]["count"] != want:
                self.fail("pendulums.count", f"a grid has {each} per pixel of its {lay.w}x{lay.h} plot"
                          f"{' and a twin for each' if fractal == 'divergence' else ''} in a {video['width']}x"
                          f"{video['height']} frame: {want} (leave it out), got {d['pendulums']['count']!r}")
            if samples > 1 and want > MAX_PENDULUMS:
                self.fail("map.samples", f"{each} per pixel of a {lay.w}x{lay.h} plot make {want} pendulums, more "
                          f"than {MAX_PENDULUMS}; use fewer samples or a smaller video")
        elif d["pendulums"]["count"] is None:
            self.fail("pendulums.count", "missing (this key is required)")
        count = self.integer(d, "pendulums", "count", 1, MAX_MAP_PENDULUMS if layout == "grid" else MAX_PENDULUMS)
        out = {"count": count, "layout": layout}
        out.update({k: self.declared(d, "pendulums", k, spec)
                    for k, spec in registry.get(system).preset_keys().items()})
        out["spread"] = self.real(d, "pendulums", "spread", -SPREAD_MAX, SPREAD_MAX)
        if d["pendulums"]["gap"] is not None:
            if "spread" in self.given.get("pendulums", {}):
                self.fail("pendulums.gap", "give either pendulums.gap (between neighbours) or pendulums.spread "
                          "(over the whole fan), not both")
            gap = self.real(d, "pendulums", "gap", -SPREAD_MAX, SPREAD_MAX)
            if abs(gap * count) > SPREAD_MAX:
                self.fail("pendulums.gap", f"{gap:g} x {count} pendulums spreads the fan over {gap * count:g} rad; "
                          f"the spread must be within [-{SPREAD_MAX:g}, {SPREAD_MAX:g}]")
            out["spread"] = gap * count
        out["gravity"] = self.real(d, "pendulums", "gravity", 0.0, GRAVITY_MAX)
        out["damping"] = self.real(d, "pendulums", "damping", 0.0, DAMPING_MAX)
        return out

    def integrator(self, d, system) -> dict:
        method = self.choice(d["integrator"]["method"], "integrator.method", METHODS[system])
        dt = d["integrator"]["dt"]
        if dt != "auto":
            if isinstance(dt, str):
                self.fail("integrator.dt", f"must be a number of seconds or \"auto\", got {clip(repr(dt))}")
            dt = self.real(d, "integrator", "dt", 0.0, 1.0, lo_open=True)
        prec = self.choice(d["integrator"]["precision"], "integrator.precision", PRECISIONS)
        trig = self.choice(d["integrator"]["trig"], "integrator.trig", TRIGS)
        allow = d["integrator"]["allow_unstable"]
        if not isinstance(allow, bool):
            self.fail("integrator.allow_unstable", f"must be true or false, got {tname(allow)}")
        drift = d["integrator"]["max_drift"]
        if drift is not None:
            drift = self.real(d, "integrator", "max_drift", 0.0, 1e6, lo_open=True)
        tol = self.real(d, "integrator", "tolerance", 0.0, 1.0, lo_open=True)
        least = self.real(d, "integrator", "min_faithful", 0.0, 1.0)
        return {"method": method, "dt": dt, "precision": prec, "trig": trig, "allow_unstable": allow,
                "max_drift": drift, "tolerance": tol, "min_faithful": least}

    def effects(self, d, system, pend, fractal) -> tuple[str, ...]:
        given = d["effects"]
        cls = registry.get(system)
        if given is None and fractal is not None:
            given = ["fractal"]  # a colouring names a map
        eff = list(cls.DEFAULT_EFFECTS if given is None else self.strings(given, "effects", EFFECTS))
        if fractal is not None and "fractal" not in eff:
            self.fail("fractal", f"colours a map, and effects = {eff} draws none: use effects = [\"fractal\"]")
        if pend["damping"] > 0 and "damping" not in eff:
            eff.append("damping")  # a damped scene always simulates its damping
        if "damping" in eff and pend["damping"] == 0:
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
            if pend["layout"] != "grid":
                self.fail("effects", "'fractal' colours one pendulum per pixel and needs pendulums.layout = \"grid\"")
            clash = [e for e in eff if e in keys.DRAWN + ("hud", "glow", "poincare")]
            if clash:
                self.fail("effects", f"'fractal' fills every pixel; it cannot be combined with {clash}")
        elif pend["layout"] == "grid":
            self.fail("pendulums.layout", "a grid of pendulums is drawn with effects = [\"fractal\"]")
        section = [n for n in SYSTEMS if registry.get(n).ANGLES and len(registry.get(n).LINKS) == 2]
        if "poincare" in eff and system not in section:
            self.fail("effects", "'poincare' draws the section θ1 = 0 of a double pendulum's two angles as "
                      "(θ2, ω2) points, and this system has no such section (systems with two link angles: "
                      f"{', '.join(section)})")
        if pend["layout"] == "shell" and system not in section:
            self.fail("pendulums.layout", "'shell' starts pendulums on the section θ1 = 0 of a double pendulum's two "
                      f"angles, and this system has none (systems with two link angles: {', '.join(section)})")
        if "audio" in eff and not cls.ANGLES:
            self.fail("effects", "'audio' sings the link angles (left θ1, right θ2), and this system's state is "
                      "not angles (systems with angles: " + ", ".join(n for n in SYSTEMS if registry.get(n).ANGLES)
                      + ")")
        if "audio" in eff and "fractal" in eff:
            self.fail("effects", "'audio' sings the pendulums of a fan, and a map's are its pixels: it cannot be "
                      "combined with 'fractal'")
        if "glow" in eff and not any(e in eff for e in keys.DRAWN):
            self.fail("effects", f"'glow' adds up the light of what is drawn and nothing is: list one of {list(keys.DRAWN)}")
        return tuple(e for e in EFFECTS if e in eff)  # canonical order: same scene, same hash

    def compare(self, d, pend, video, fractal) -> tuple | None:
        """[compare] vary = { KEY = [V1, V2, ...], ... }: ((key, values), ...), the keys paired (value i of
        each makes panel i). Each value is validated when the variants are built (Scene.variants)."""
        table = d.get("compare")
        if table is None:
            return None
        if fractal is not None:
            self.fail("compare", "a fractal map fills its whole frame and cannot be split into panels; "
                      "render each variant with --set instead")
        if not isinstance(table, dict):
            self.fail("compare", f"must be a table, got {tname(table)}")
        for k in table:
            if k != "vary":
                self.fail(f"compare.{show_key(k)}", "unknown key" + hint(k, ["vary"], "compare."))
        if "vary" not in table:
            self.fail("compare.vary", "missing (this key is required)")
        if not isinstance(table["vary"], dict) or not table["vary"]:
            self.fail("compare.vary", f"must be a table of KEY = [V1, V2, ...], got {tname(table['vary'])}")
        known = sorted(dotted({k: v for k, v in d.items() if k != "compare"}))
        try:
            flat = dotted(table["vary"])
        except Twice as e:
            self.fail(f"compare.vary.{show_key(e.key)}", "given twice (quoted, and dotted or as a table); give it once")
        out = []
        for key, values in flat.items():
            name = f"compare.vary.{show_key(key)}"
            if key not in known:  # hinted among the keys a comparison may vary
                section, _, leaf = key.rpartition(".")
                owners = [n for n in SYSTEMS if section == "pendulums" and leaf in registry.get(n).preset_keys()]
                if owners:
                    self.fail(name, f"is not a key of this system (it belongs to system {' and '.join(owners)})")
                self.fail(name, "unknown key" + hint(key, [k for k in known if not vary_refusal(k)]))
            why = vary_refusal(key)
            if why:
                self.fail(name, f"cannot vary: {why}; {VARYING}")
            if d.get("quality") is not None and key.startswith("integrator."):  # every panel's would be replaced
                self.fail(name, f"quality {d['quality']!r} (--quality) chooses every panel's integrator, so the "
                          f"panels would not differ by it; vary quality itself, or leave --quality out")
            lo, hi = VARIANTS
            if not isinstance(values, list) or not lo <= len(values) <= hi:
                self.fail(name, f"must list {lo} to {hi} values (one per panel), got {clip(repr(values))}")
            if not all(plain(v) for v in values):
                self.fail(name, f"values are numbers, strings, booleans or lists of them (one value of {key} "
                          f"each), got {clip(repr(values))}")
            if out and len(values) != len(out[0][1]):
                self.fail(name, f"lists {len(values)} values and {out[0][0]} lists {len(out[0][1])}: varied keys "
                          f"are paired, one value per panel")
            out.append((key, frozen(values)))
        columns = list(zip(*(values for _, values in out)))
        if len(set(columns)) != len(columns):
            self.fail("compare.vary", f"two panels would be the same variant: {clip(json.dumps(columns))}")
        if pend["layout"] == "grid":
            self.fail("compare", "a grid (one pendulum per pixel) cannot be split into panels")
        rows = 1 if len(columns) == 2 else 2
        for key, size, parts in (("width", video["width"], 2), ("height", video["height"], rows)):
            if size // parts < PANEL_MIN:
                self.fail(f"video.{key}", f"{size} px split into {parts} panels leaves less than {PANEL_MIN} px each")
        return tuple(out)
