"""A comparison's frames: its variants side by side (2) or 2x2 (3 or 4) under one shared clock, each panel
drawn by the render's own canvas at the panel's size, labelled with the variant, its cost, its error
against the finest and until when its own certificate holds it faithful.

Two passes, because Taichi holds one precision per process (render/physics/runtime.py) and variants may differ in it:

1. each variant is simulated to the end in its own runtime exactly as `render` simulates it (--quality,
   the certificate, the watchdogs: pipeline.record), keeping its state at every frame time, and timed;
2. one runtime then draws each panel from those states with a Canvas of the panel's size (Replay, a frame
   source like pipeline.Source), and every label in one kernel launch of the bundled font. A label owns a band
   across its panel's top (label_band), and the panel's canvas frames its pendulums' whole reach below it.

Here are the panels' geometry (layout, the shared clock's band), the finest, the two passes and the metadata; the
labels' words, colours and fonts are render/draw/split_text.py's.

The finest variant is the one its certificate trusts longest (median, then first pendulum's faithful time);
ties go to f64, the higher order, the smaller step, then the order given. It is only the best of those shown,
not the truth: every panel, the finest too, says until when its own certificate (its own shadow run) holds it
faithful, and its HUD clock turns amber and red at that certificate's times. A panel's error at a frame is the
largest deviation of any of its pendulums from the same pendulum of the finest variant (System.deviation:
rad on any angle, the difference wrapped to (−π, π] first, since angles a turn apart draw the same picture;
springs, a fraction of the total rest length), shown live; it parts from the finest at the first frame where
that error exceeds its integrator.tolerance. The cost is its force evaluations per simulated second (a pendulum's),
as run; the wall time its simulation took per simulated second in pass 1, when nothing else of the render runs, is
in the metadata (cost_s_per_simulated_s), not in the frames. The step is said once, as run (System.h, which fits
whole steps into a frame, not the dt asked for).

Frames are deterministic at any thread count (recorded states, the canvas's order-free compositing, serial
text).
"""
from __future__ import annotations

import json
import time

import numpy as np

from ..physics import integrators, registry
from ..physics.stepper import Run
from ..trust import faithful
from .font import text_height
from .hud_text import faces, step
from .split_text import (COLOURS, INTEGRATOR, LABEL_SHARE, error_text, fit, label_band, label_face,
                         preset_name, shown, turned, value_text)

GAP = 2  # px of grey at least between panels
DIVIDER = 72  # its grey level


def cost(run: dict, fps: int) -> int:
    """Force evaluations per simulated second of each pendulum, as run: what a panel's label says it costs. The
    wall time its simulation took (metadata's cost_s_per_simulated_s) differs from run to run, and drawn into the
    frames it made them differ too."""
    integ = run["integrator"]
    return integrators.METHOD[integ["method"]].evals * integ["substeps"] * fps


def clock_face(height: int) -> tuple[str, int]:
    """The shared clock's font (size, scale): the HUD's big face for a frame `height` pixels high."""
    return faces(height)[1]


def band(height: int) -> int:
    """The height of the shared clock's band across the top, the grey line under it included (even)."""
    size, scale = clock_face(height)
    return (text_height("t", scale, size) + 2 * pad(height) + GAP + 1) // 2 * 2


def pad(height: int) -> int:
    """The margin above and below the shared clock."""
    return max(2, round(0.008 * height))


def layout(width: int, height: int, n: int) -> list[tuple[int, int, int, int]]:
    """(x, y, w, h) of each of n panels under the clock's band: side by side for 2, row by row in 2x2 for 3
    or 4. Sizes are even (a panel is a valid video size) and leave at least GAP between panels."""
    rows, top = 1 if n == 2 else 2, band(height)
    pw, ph = (width - GAP) // 2 // 2 * 2, (height - top - GAP * (rows - 1)) // rows // 2 * 2
    ys = (top,) if rows == 1 else (top, height - ph)
    return [((0, width - pw)[i % 2], ys[i // 2], pw, ph) for i in range(n)]


def finest(runs: list[dict]) -> int:
    """The index of the variant taken as the truth the others are measured against."""
    def rank(i):
        c, integ = runs[i]["cert"], runs[i]["integrator"]
        return (c.median_until_s, c.faithful_until_s, c.fraction_faithful, integ["precision"] == "f64",
                integrators.METHOD[integ["method"]].order, -integ["dt"], -i)
    return max(range(len(runs)), key=rank)


class Replay:
    """One variant's recorded states drawn at its panel's size by the canvas `render` draws with: a frame
    source with pipeline.Source's interface (name, frames, index, reset(), next_frame(out=None))."""

    def __init__(self, scene, q: np.ndarray, cert, arch: str = "cpu", threads: int | None = None,
                 keep_log: bool = False, keep_clear=()):
        from .canvas import Canvas
        from .hud import Info

        self.scene, self.q = scene, q
        self.name, self.frames = scene.name, len(q)
        # pass 2 draws every panel from f64 positions (in f32 pixels as ever), all panels in one runtime's log
        self.run = Run(scene, arch, threads, precision="f64", keep_log=keep_log)
        self.sim = self.run.sim
        # the HUD, if called for, with the variant's own certificate: its clock's colours and timeline ticks
        self.canvas = Canvas(scene, self.sim, Info.of(scene, self.sim.h, cert, panel=True), keep_clear)
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
            registry.get(v.system)(v)
        self.runs = [record(v) for v in variants]  # pass 1, each in its own precision
        self.ref = finest(self.runs)
        v = scene.video
        self.rects = layout(v.width, v.height, len(self.runs))
        # each panel's label owns a band across its top: the panel's canvas frames its pendulums below it
        self.panels = [Replay(run["scene"].replace(video={"width": w, "height": h}), run["q"], run["cert"], arch,
                              threads, keep_log=k > 0, keep_clear=[(0, 0, w - 1, label_band(scene, h) - 1)])
                       for k, (run, (_, _, w, h)) in enumerate(zip(self.runs, self.rects))]
        self.arch, self.threads = self.panels[0].run.arch, threads  # a second split screen (the GIF's) shares them
        self.buffers = [p.canvas.new_frame() for p in self.panels]
        self.angles = registry.get(scene.system).ANGLES
        ref_q, sim = self.runs[self.ref]["q"], self.panels[self.ref].sim
        self.errors = [sim.deviation(turned(run["q"] - ref_q), 0.0).max(-1) if self.angles else
                       sim.deviation(run["q"], ref_q).max(-1) for run in self.runs]
        self.parted = [self.divergence(i) for i in range(len(self.runs))]
        self.costs = [cost(run, scene.video.fps) for run in self.runs]
        self.delta = "Δθ" if self.angles else "Δx/L"  # what the error measures: rad, or of the total length
        self.font = Font()
        self.size = label_face(self.rects[0][3])[0]
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
        frame[:band(v.height) - GAP] = 0  # the shared clock's band
        if len(self.rects) == 3:
            x, y, w, h = layout(v.width, v.height, 4)[3]
            frame[y:y + h, x:x + w] = 0  # the free cell holds the legend
        for panel, buf, (x, y, w, h) in zip(self.panels, self.buffers, self.rects):
            frame[y:y + h, x:x + w] = panel.next_frame(buf)
        self.index += 1
        self.font.draw_many(frame, self.labels(self.index) + [self.clock(self.index)], blend="over")
        self.timings["draw"] += time.perf_counter() - t
        return frame

    # ------------------------------------------------------------ labels
    def label_lines(self, i: int, f: int) -> list[tuple[str, tuple]]:
        """(text, colour) of panel i's label at frame f: the variant, the integrator's settings the variant
        does not name (as run), the cost, the error (or that it is the finest), and until when it is faithful.
        An empty text is a line left out."""
        run, t = self.runs[i], f / self.scene.video.fps
        integ = run["integrator"]
        said = {"integrator.method": integ["method"], "integrator.dt": f"{step(integ['dt'])} s",
                "integrator.precision": integ["precision"]}
        variant = ", ".join(f"{key.rsplit('.', 1)[-1]} = {said[key] if key in said else value_text(vals[i])}"
                            for key, vals in self.scene.compare)
        rest = [f"dt = {said[key]}" if key == "integrator.dt" else said[key]
                for key in INTEGRATOR if key not in dict(self.scene.compare)]
        hud = self.panels[i].canvas.hud
        lines = [(variant, COLOURS["title"]), (", ".join(rest), COLOURS["detail"]),
                 (f"cost {self.costs[i]} force evaluations per simulated s", COLOURS["detail"])]
        parted = self.parted[i]
        if i == self.ref:
            lines.append((f"finest: the reference for {self.delta}", COLOURS["finest"]))
        else:
            err = error_text(self.delta, self.errors[i][f], self.angles)
            lines.append((f"{err}, parted at {parted:.2f} s", COLOURS["parted"]) if parted is not None and
                         t >= parted else (err, COLOURS["close"]))
        until = faithful.until(run["cert"].faithful_until_s, self.scene.video.duration)
        # as its clock: white while faithful, amber and red at its certificate's times (no HUD: grey)
        return lines + [(f"faithful to {until}", COLOURS["detail"] if hud is None else hud.clock_colour(t))]

    def labels(self, f: int) -> list[tuple]:
        """Every panel's label (and, with 3 variants, the legend in the free cell) as Font.draw_many items."""
        _, pad_, step_, cell = label_face(self.rects[0][3])
        room = max(2, int(LABEL_SHARE * self.rects[0][3]) // step_)  # a small panel keeps its pendulums in view
        cells = [(rect, shown(self.label_lines(i, f), room)) for i, rect in enumerate(self.rects)]
        if len(self.rects) == 3:
            cells.append((layout(self.scene.video.width, self.scene.video.height, 4)[3],
                          [(text, COLOURS["detail"]) for text in self.legend()]))
        return [(fit(text, w - 2 * pad_, cell), x + pad_, y + pad_ // 2 + k * step_,
                 {"colour": colour, "size": self.size})
                for (x, y, w, _), lines in cells for k, (text, colour) in enumerate(lines)]

    def clock(self, f: int) -> tuple:
        """The shared clock at frame f, big in the top centre band, as a Font.draw_many item. White: each
        panel's own clock (its HUD) says whether that panel is still faithful."""
        v = self.scene.video
        size, scale = clock_face(v.height)
        return (f"t = {f / v.fps:5.2f} s", v.width // 2, pad(v.height),
                {"colour": COLOURS["clock"], "size": size, "scale": scale, "ha": "center"})

    def legend(self) -> list[str]:
        tol, unit = self.scene.integrator.tolerance, " rad" if self.angles else ""
        return [preset_name(self.scene), f"{self.scene.pendulums.count} pendulums, one start for all",
                "cost: force evaluations", f"{self.delta}: the largest of any pendulum",
                "  from the finest variant's", f"parted: {self.delta} > {tol:g}{unit}",
                "clock amber: one not faithful", "clock red: half not faithful"]

    # ------------------------------------------------------------ metadata
    def run_meta(self) -> dict:
        """What metadata.json says of the simulation (render/video/metadata.py), as pipeline.record says it of one
        run: the finest variant's integrator, certificate and quality, the largest energy drift of any
        variant, every variant's kernels."""
        ref = self.runs[self.ref]
        drifts = [run["energy"]["max_rel_drift"] for run in self.runs if run["energy"]]
        energy = {**ref["energy"], "max_rel_drift": max(drifts)} if ref["energy"] else None
        return {**ref, "energy": energy, "kernels": list(dict.fromkeys(k for run in self.runs for k in run["kernels"]))}

    def compare_meta(self) -> dict:
        """metadata.json's "compare": the variants, the panels, which is the finest and every variant's own."""
        return {
            "vary": {key: list(values) for key, values in json.loads(json.dumps(self.scene.compare))},
            "panels": [{"x": x, "y": y, "width": w, "height": h} for x, y, w, h in self.rects],
            "finest": self.ref,
            "finest_why": "the longest median faithful time of its certificate (then the first pendulum's; "
                          "ties: f64, higher order, smaller step, the order given)",
            "error": ("largest |Δθ| over the pendulums and angles, wrapped to [0, π], rad" if self.angles else
                      "largest distance of a bob over the pendulums, as a fraction of the total rest length")
                     + ", against the same pendulum of the finest variant at each frame",
            "variants": [self.variant_meta(i) for i in range(len(self.runs))],
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
            "cost_s_per_simulated_s": round(run["cost"], 6),
            "force_evaluations_per_simulated_s": self.costs[i],
            "divergence_s": self.parted[i],
            "tolerance": run["scene"].integrator.tolerance,
            "max_error": float(self.errors[i].max()),
            "error_at_end": float(self.errors[i][-1]),
            "energy": run["energy"],
            "kernels": run["kernels"],
            "field_bytes": sum(run["fields"].values()),
        }
