"""A comparison's frames: its variants side by side (2) or 2x2 (3 or 4), each panel drawn by the render's own
canvas at the panel's size, labelled with the variant, its measured cost and its error against the finest.

Two passes, because Taichi holds one precision per process (render/physics/runtime.py) and variants may differ in it:

1. each variant is simulated to the end in its own runtime exactly as `render` simulates it (--quality,
   the certificate, the watchdogs: pipeline.record), keeping its state at every frame time, and timed;
2. one runtime then draws each panel from those states with a Canvas of the panel's size (Replay, a frame
   source like pipeline.Source), and every label in one kernel launch of the bundled font.

The finest variant is the one its certificate trusts longest (median, then first pendulum's faithful time);
ties go to f64, the higher order, the smaller step, then the order given. A panel's error at a frame is the
largest deviation of any of its pendulums from the same pendulum of the finest variant (System.deviation:
rad on any angle; springs, a fraction of the total rest length), shown live; it parts from the finest at the
first frame where that error exceeds its integrator.tolerance. The cost is the wall time its simulation took
per simulated second in pass 1, when nothing else of the render runs.

Frames are deterministic at any thread count (recorded states, the canvas's order-free compositing, serial
text) except the cost figures, which are measured; tests that compare bytes replace `cost`.
"""
from __future__ import annotations

import json
import time

import numpy as np

from ..physics import integrators, registry, runtime

GAP = 2  # px of grey at least between panels
DIVIDER = 72  # its grey level
LARGE = 300  # panels at least this tall get the 10x20 font, smaller ones 6x13
LABEL_SHARE = 0.4  # of a panel's height its label may cover (from the top)
COLOURS = {"title": (1.0, 1.0, 1.0), "detail": (0.7, 0.7, 0.7), "close": (0.45, 0.95, 0.5),
           "parted": (1.0, 0.55, 0.2), "finest": (0.55, 0.75, 1.0)}


def cost(run: dict) -> float:
    """Wall seconds of simulation per simulated second, as measured in pass 1 (pipeline.record)."""
    return run["cost"]


def shown(lines: list, room: int) -> list:
    """The label's lines that fit in `room` lines, in their order: the integrator's line goes first, then
    the cost; the variant and its error always stay."""
    drop = [1, 2][:max(0, len(lines) - room)]
    return [line for k, line in enumerate(lines) if k not in drop]


def fit(text: str, width: int, cell: int) -> str:
    """Text cut to `width` pixels of `cell`-wide glyphs, so a label stays inside its panel."""
    room = max(width // cell, 1)
    return text if len(text) <= room else text[:room - 1] + "…"


def amount(x: float) -> str:
    """An error for a label: 3.1e-05 when small, 0.42 or 44 when large."""
    return "0" if x == 0 else f"{x:.1e}" if x < 0.1 else f"{x:.2g}" if x < 10 else f"{x:.0f}"


def layout(width: int, height: int, n: int) -> list[tuple[int, int, int, int]]:
    """(x, y, w, h) of each of n panels: side by side for 2, row by row in 2x2 for 3 or 4. Sizes are even (a
    panel is a valid video size) and leave at least GAP between panels."""
    rows = 1 if n == 2 else 2
    pw, ph = (width - GAP) // 2 // 2 * 2, (height - GAP * (rows - 1)) // rows // 2 * 2
    ys = (0,) if rows == 1 else (0, height - ph)
    return [((0, width - pw)[i % 2], ys[i // 2], pw, ph) for i in range(n)]


def finest(runs: list[dict]) -> int:
    """The index of the variant taken as the truth the others are measured against."""
    def rank(i):
        c, integ = runs[i]["cert"], runs[i]["integrator"]
        return (c.median_until_s, c.faithful_until_s, c.fraction_faithful, integ["precision"] == "f64",
                integrators.METHOD[integ["method"]].order, -integ["dt"], -i)
    return max(range(len(runs)), key=rank)


def value_text(v) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return json.dumps(v) if isinstance(v, (list, tuple, bool)) else str(v)


class Replay:
    """One variant's recorded states drawn at its panel's size by the canvas `render` draws with: a frame
    source with pipeline.Source's interface (name, frames, index, reset(), next_frame(out=None))."""

    def __init__(self, scene, q: np.ndarray):
        from .canvas import Canvas
        from .hud import Info

        self.scene, self.q = scene, q
        self.name, self.frames = scene.name, len(q)
        self.sim = registry.get(scene.system)(scene)
        self.canvas = Canvas(scene, self.sim, Info.of(scene, self.sim.h, panel=True))  # the HUD, if called for
        self.reset(rewind=False)

    def reset(self, rewind: bool = True):
        if rewind:
            self.canvas.restart()
        self.index = -1

    def next_frame(self, out: np.ndarray | None = None) -> np.ndarray:
        self.index += 1
        self.sim.q.from_numpy(self.q[self.index])
        return self.canvas.draw(out)


class SplitScreen:
    """The frames of a comparison (a scene with [compare]), with pipeline.Source's interface, so `render`
    encodes it and `show` plays it. record(variant scene) -> dict is pipeline.record."""

    def __init__(self, scene, record, arch: str = "cpu", threads: int | None = None):
        from .font import Font

        self.scene, self.name, self.frames = scene, scene.name, scene.frames
        variants = scene.variants()
        for v in variants:  # every variant's step, refused (a pinned dt beyond its limit) before any is run
            registry.get(v.system)(v, allocate=False)
        self.runs = [record(v) for v in variants]  # pass 1, each in its own precision
        self.ref = finest(self.runs)
        v = scene.video
        self.rects = layout(v.width, v.height, len(self.runs))
        self.arch = runtime.init(arch, "f64", threads)  # pass 2: f64 positions, drawn in f32 pixels as ever
        self.panels = [Replay(run["scene"].replace(video={"width": w, "height": h}), run["q"])
                       for run, (_, _, w, h) in zip(self.runs, self.rects)]
        self.buffers = [p.canvas.new_frame() for p in self.panels]
        ref_q = self.runs[self.ref]["q"]
        self.errors = [self.panels[self.ref].sim.deviation(run["q"], ref_q).max(-1) for run in self.runs]
        self.parted = [self.divergence(i) for i in range(len(self.runs))]
        self.costs = [cost(run) for run in self.runs]
        self.angles = registry.get(scene.system).ANGLES
        self.delta = "Δθ" if self.angles else "Δx/L"  # what the error measures: rad, or of the total length
        self.font = Font()
        self.size = "10x20" if self.rects[0][3] >= LARGE else "6x13"
        self.timings = {k: sum(run["timings"].get(k, 0.0) for run in self.runs)
                        for k in ("quality", "certify", "simulate") if any(k in run["timings"] for run in self.runs)}
        self.timings["draw"] = 0.0
        self.reset(rewind=False)

    def divergence(self, i: int) -> float | None:
        """When variant i first differs from the finest by more than its tolerance (None: never, or it is it)."""
        over = self.errors[i] > self.runs[i]["scene"].integrator.tolerance
        return float(np.argmax(over)) / self.scene.video.fps if i != self.ref and over.any() else None

    def reset(self, rewind: bool = True):
        for p in self.panels:
            p.reset(rewind)
        self.index = -1

    def next_frame(self, out: np.ndarray | None = None) -> np.ndarray:
        """The next frame as H×W×3 uint8, written into `out` if given (else a new array)."""
        t = time.perf_counter()
        v = self.scene.video
        frame = np.empty((v.height, v.width, 3), np.uint8) if out is None else out
        frame.fill(DIVIDER)  # what the panels leave uncovered is the grey between them
        if len(self.rects) == 3:
            x, y, w, h = layout(v.width, v.height, 4)[3]
            frame[y:y + h, x:x + w] = 0  # the free cell holds the legend
        for panel, buf, (x, y, w, h) in zip(self.panels, self.buffers, self.rects):
            frame[y:y + h, x:x + w] = panel.next_frame(buf)
        self.index += 1
        self.font.draw_many(frame, self.labels(self.index), blend="over")
        self.timings["draw"] += time.perf_counter() - t
        return frame

    # ------------------------------------------------------------ labels
    def label_lines(self, i: int, f: int) -> list[tuple[str, str]]:
        """(text, colour name) of panel i's label at frame f."""
        integ = self.runs[i]["integrator"]
        variant = ", ".join(f"{key.rsplit('.', 1)[-1]} = {value_text(vals[i])}" for key, vals in self.scene.compare)
        lines = [(variant, "title"),
                 (f"{integ['method']}, dt {1e3 * integ['dt']:.3g} ms, {integ['precision']}", "detail"),
                 (f"cost {1e3 * self.costs[i]:.3g} ms per simulated s", "detail")]
        if i == self.ref:
            return lines + [(f"finest: the reference for {self.delta}", "finest")]
        err = f"{self.delta} {amount(self.errors[i][f])}{' rad' if self.angles else ''}"
        parted = self.parted[i]
        if parted is not None and f / self.scene.video.fps >= parted:
            return lines + [(f"{err}, parted at {parted:.2f} s", "parted")]
        return lines + [(err, "close")]

    def labels(self, f: int) -> list[tuple]:
        """Every panel's label (and, with 3 variants, the legend in the free cell) as Font.draw_many items."""
        big = self.size == "10x20"
        pad, step, cell = (8, 21, 10) if big else (4, 13, 6)
        room = max(2, int(LABEL_SHARE * self.rects[0][3]) // step)  # a small panel keeps its pendulums in view
        cells = [(rect, shown(self.label_lines(i, f), room)) for i, rect in enumerate(self.rects)]
        if len(self.rects) == 3:
            cells.append((layout(self.scene.video.width, self.scene.video.height, 4)[3],
                          [(text, "detail") for text in self.legend()]))
        return [(fit(text, w - 2 * pad, cell), x + pad, y + pad // 2 + k * step,
                 {"colour": COLOURS[colour], "size": self.size})
                for (x, y, w, _), lines in cells for k, (text, colour) in enumerate(lines)]

    def legend(self) -> list[str]:
        tol, unit = self.scene.integrator.tolerance, " rad" if self.angles else ""
        return [self.scene.name, f"{self.scene.pendulums.count} pendulums, one start for all",
                "cost: simulation wall time", f"{self.delta}: the largest of any pendulum",
                "  from the finest variant's", f"parted: {self.delta} > {tol:g}{unit}"]

    # ------------------------------------------------------------ metadata
    def metadata(self, header: dict, timings: dict, sizes: dict, sha256: dict) -> dict:
        """metadata.json of a comparison: a render's fields for the finest variant, and every variant's."""
        ref = self.runs[self.ref]
        drifts = [run["energy"]["max_rel_drift"] for run in self.runs if run["energy"]]
        energy = {**ref["energy"], "max_rel_drift": max(drifts)} if ref["energy"] else None
        kernels = list(dict.fromkeys(k for run in self.runs for k in run["kernels"]))
        return {
            **header,
            "integrator": ref["integrator"],  # the finest variant's, as its faithfulness and quality below
            "effects": list(self.scene.effects),
            "kernels": list(dict.fromkeys(kernels + list(runtime.launched))),
            "field_bytes": sum(runtime.allocated.values()),  # the drawing pass; each variant's below
            "fields": dict(runtime.allocated),
            "energy": energy,
            "faithfulness": ref["cert"].to_dict(),
            "quality": ref["chosen"],
            "timings_s": {k: round(val, 4) for k, val in timings.items()},
            "outputs": sizes,
            "outputs_sha256": sha256,
            "compare": {
                "vary": {key: list(values) for key, values in json.loads(json.dumps(self.scene.compare))},
                "panels": [{"x": x, "y": y, "width": w, "height": h} for x, y, w, h in self.rects],
                "finest": self.ref,
                "finest_why": "the longest median faithful time of its certificate (then the first pendulum's; "
                              "ties: f64, higher order, smaller step, the order given)",
                "error": ("largest |Δθ| over the pendulums and angles, rad" if self.angles else
                          "largest distance of a bob over the pendulums, as a fraction of the total rest length")
                         + ", against the same pendulum of the finest variant at each frame",
                "variants": [self.variant_meta(i) for i in range(len(self.runs))],
            },
        }

    def variant_meta(self, i: int) -> dict:
        run = self.runs[i]
        return {
            "label": self.label_lines(i, 0)[0][0] + ("  (finest)" if i == self.ref else ""),
            "values": {key: values[i] for key, values in json.loads(json.dumps(self.scene.compare))},
            "preset_hash": run["scene"].hash(),
            "integrator": run["integrator"],
            "quality": run["chosen"],
            "faithfulness": run["cert"].to_dict(),
            "timings_s": {k: round(val, 4) for k, val in run["timings"].items()},
            "cost_s_per_simulated_s": round(self.costs[i], 6),
            "divergence_s": self.parted[i],
            "tolerance": run["scene"].integrator.tolerance,
            "max_error": float(self.errors[i].max()),
            "error_at_end": float(self.errors[i][-1]),
            "energy": run["energy"],
            "kernels": run["kernels"],
            "field_bytes": sum(run["fields"].values()),
        }
