"""How long a run will take, estimated before any work (no Taichi runtime, no kernel compiled): the seconds of
each part of it, from per-machine rates.

Parts: `start` (Taichi's start, the kernels' compiles, ffmpeg's start), `simulate` (the render's own run),
`certificate` (render/trust/certify.py: the certified pendulums, all of them up to its memory cap, run again at the render's settings and
by the shadow: RK4 in f64 at the same step, or at an eighth of an order-4 method's), `quality` (the pilot
runs of --quality, render/trust/quality.py), and `draw+encode` (per frame: a fixed cost, a cost per pixel, one per
drawn link, the HUD, an FTLE map's σ of every point; x264 per pixel of every frame, the GIF's ffmpeg of every
frame it keeps), or `write` for `simulate`'s .npz.
A comparison sums its panels (each variant simulated and certified, each panel drawn).

Everything errs long: a --quality run is costed at the most expensive setting the pilots could choose, and
the parts are added although encoding overlaps drawing.

The rates are OUT/bench/rates.json (written by `pendulum bench --out OUT/bench`) where it exists, figure by
figure, and the built-in RATES otherwise: nothing outside the output folder the user named is read.
"""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

from ..trust import certify, quality
from ..physics import grid, registry
from ..physics.integrators import METHOD
from ..physics.keys import DRAWN
from ..video.files import read_regular

RATES_FILE = Path("bench") / "rates.json"  # under the run's OUT
RATES_MAX_BYTES = 1 << 20  # the bench writes about 2 kB
# The FTLE map (render/maps/ftle.py) steps each point with its 2D tangent vectors beside it, as duals: its advance
# took 3.25 times the plain advance of the same points (fractal_lyapunov at 720p, 381,924 points, 17 RK4 substeps:
# 184.1 against 56.6 ms, medians of 5 alternating rounds, 2-core Xeon with AVX-512, 2026-12-06, a script not kept)
FTLE_COST = 3.25
# and its colours come from σ of each point's (2D)×(2D) MᵀM, squared ten times, every frame: 30 ms more than the
# angles map's drawing of the same 381,924 points (36.5 against 6.2 ms a 720p frame, `python benchmarks/map_frame.py
# fractal_lyapunov --seconds 0.2`, and fractal, 2-core Xeon, AVX-512, 2026-12-07), about the cost of 9 plain RK4
# steps of each point (the double pendulum's, 115 M steps/s there). Counted as such, so it follows the machine's
# measured rate, and another system's as the cube of its matrix's side in its own steps, which errs long: a
# triple pendulum's step is itself slower.
FTLE_SIGMA_STEPS = 9.0
# Measured on this project's 2-core AMD EPYC machine (/tmp scripts timing System.advance, Canvas.draw and
# the Encoder on their own, 2026-12-01) while other work kept its load average at about 4: a quiet machine
# is up to twice as fast (the bench report of 2026-11-23: 35.5 M rigid f64 steps/s at N = 1e5, 17 ms a
# 720p frame to draw with the HUD and 17 ms to encode as MP4 and GIF), so these err long.
RATES = {
    # RK4 pendulum-steps per second of the advance kernel at N = 1e4 (measured 2.5e7, 3.7e7, 7.6e7, 1.5e8,
    # 1.4e7, 2.1e7); other methods in proportion to their force evaluations per step (integrators.Method.evals).
    "steps_per_s": {"rigid_f64": 2.5e7, "rigid_f32": 3.5e7, "elastic_f64": 7.0e7, "elastic_f32": 1.4e8,
                    "triple_f64": 1.4e7, "triple_f32": 2.0e7},
    "frame_s": 3e-4,  # per simulated frame: a launch of 1 substep of 128 pendulums took 150-300 µs
    "fixed_s": 10.0,  # per render: a one-frame 720p render of rigid_chaos took 9.3 s of wall time
    "compile_s": 2.0,  # per kernel compiled anew (a quality pilot's method and precision): 0.6-2.0 s each
    "draw_frame_s": 2e-3,  # 640x360, 100 pendulums: 4.6 ms a frame
    "draw_pixel_s": 5e-9,  # 2560x1440, 100 pendulums: 34 ms a frame
    "draw_link_s": 17e-6,  # per drawn link (rod or spring, bob, trail) in a 720 px tall frame, ∝ its height:
    #                        10^4 pendulums drew in 187, 348 and 800 ms a frame at 360, 720 and 1440 px
    "hud_frame_s": 2e-3,  # the HUD, parallel since issue 27: 0.27-0.43 ms a 720p frame (`pendulum bench`'s
    #                       hud_ms_720p, 2026-12-06), 0.74-0.75 ms a call beside x264 in a render of rigid_chaos
    #                       (`python benchmarks/render_threads.py`, twice); 8 ms when it was serial
    "mp4_frame_s": 3e-3, "mp4_pixel_s": 25e-9,  # x264: 16, 26 and 170 ms a frame at 360, 720 and 1440 px
    "gif_frame_s": 2e-3, "gif_pixel_s": 8e-9,  # the GIF's ffmpeg, per frame piped to it: 6.5, 8.9 and 46 ms
    "npz_byte_s": 2e-8,  # savez_compressed: about 50 MB/s
}
REFERENCE_HEIGHT = 720  # px: draw_link_s is per link at this height


@dataclasses.dataclass(frozen=True)
class Estimate:
    parts: dict  # part -> seconds
    steps: int  # pendulum-steps of the render's own simulation (every panel's)
    frames: int
    substeps: int  # per frame (a comparison: its finest panel's)
    h: float  # s (likewise)
    pendulums: int
    panels: int  # 0 unless a comparison
    rates: str  # where the rates came from
    # of draw+encode (or write), what grows with the pendulums: drawing their links (or writing their states);
    # the rest is per pixel and per frame
    pendulums_s: float = 0.0

    @property
    def total(self) -> float:
        return sum(self.parts.values())

    @property
    def physics(self) -> float:
        """The parts that scale with the steps."""
        return sum(self.parts.get(k, 0.0) for k in ("simulate", "certificate", "quality"))


def load_rates(out: Path | None) -> tuple[dict, str]:
    """The rates for a run under `out`, and where they came from: OUT/bench/rates.json's figures where each
    is a positive number, the built-in RATES for the rest (all of them when the file is absent or not a
    JSON table: a malformed file is ignored, never an error)."""
    rates = json.loads(json.dumps(RATES))
    path = Path(out) / RATES_FILE if out is not None else None
    # Inside OUT only: a symlink there (OUT/bench or the file) may lead out of it, and rates read from elsewhere
    # could lift the budget's refusal. Read as a preset is: a FIFO or /dev/zero must not hang the check.
    inside = path is not None and not path.parent.is_symlink()  # OUT/bench; the file is opened O_NOFOLLOW
    try:
        given = json.loads(read_regular(path, RATES_MAX_BYTES, follow=False)) if inside else None
    except (OSError, ValueError):  # absent, unreadable, not a regular file (Refused), not UTF-8 or not JSON
        given = None
    used = 0
    for key, default in RATES.items() if isinstance(given, dict) else ():
        mine, theirs = (rates[key], given.get(key)) if isinstance(default, dict) else (rates, given)
        names = default if isinstance(default, dict) else (key,)
        for name in names if isinstance(theirs, dict) else ():
            if _positive(theirs.get(name)):
                mine[name], used = float(theirs[name]), used + 1
    return rates, (f"rates from {path}" if used else "built-in rates")


def _positive(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and 0 < x < 1e15


def estimate(scene, rates: dict, source: str = "", simulate: bool = False) -> Estimate:
    """The seconds of each part of a run of `scene` (`simulate`: the draw-free .npz run). Plans the step the
    System settles on ("auto" included) without any Taichi field, so it refuses what the System refuses."""
    cls = registry.get(scene.system)
    variants = scene.variants() if scene.compare else [scene]
    panels = len(variants) if scene.compare else 0
    parts = {"start": rates["fixed_s"] * (1 + panels)}
    steps, finest = 0, (0, 0.0)
    for variant in variants:
        run, h, substeps = physics(variant, rates)
        for k, s in run.items():
            parts[k] = parts.get(k, 0.0) + s
        steps += scene.frames * substeps * variant.pendulums.count
        finest = max(finest, (substeps, h))
    if simulate:
        parts["write"] = grows = scene.frames * scene.pendulums.count * (2 * cls.D + 1) * 8 * rates["npz_byte_s"]
    else:
        per, links = picture_frame_s(scene, rates, panels)
        if scene.fractal == "lyapunov":  # a map's points are its pixels: σ grows with the video, not a count
            per += sigma_s(scene, rates)
        parts["draw+encode"], grows = scene.frames * per, scene.frames * links
    return Estimate(parts, steps, scene.frames, finest[0], finest[1], scene.pendulums.count, panels, source, grows)


def sigma_s(scene, rates: dict) -> float:
    """Seconds a frame of an FTLE map spends on σ of its points (FTLE_SIGMA_STEPS)."""
    side = (2 * registry.get(scene.system).D / 4) ** 3  # 1 for the double pendulum's 4×4
    rate = steps_per_s(rates, scene.system, scene.integrator.precision, "rk4")  # σ is worked out in that precision
    return scene.pendulums.count * FTLE_SIGMA_STEPS * side / rate


def physics(scene, rates: dict) -> tuple[dict, float, int]:
    """({simulate, certificate[, quality]} seconds, step, substeps per frame) of one (non-comparison) scene."""
    plan = registry.get(scene.system)(scene)  # the stable step; refuses an unstable dt
    parts, (h, substeps) = {}, (plan.h, plan.substeps)
    cands = quality.offered(scene, plan) if scene.quality else []
    if cands:  # (none: quality.choose refuses the scene)
        parts["quality"] = pilots_s(scene, cands, rates)
        worst = max(cands, key=lambda s: quality.cost(s, scene.video.fps))
        scene = scene.replace(integrator={**worst, "allow_unstable": False})
        h, substeps = pinned(scene, worst["dt"])
    i, n = scene.integrator, scene.pendulums.count
    parts["simulate"] = run_s(scene, rates, i.method, i.precision, substeps, n)
    if scene.fractal == "lyapunov":
        parts["simulate"] *= FTLE_COST
    certified = len(grid.trust_indices(scene)) if scene.fractal else len(certify.certified(scene))
    shadow = certify.shadow_scene(scene, h).integrator
    _, shadow_substeps = pinned(scene, shadow.dt)
    parts["certificate"] = (run_s(scene, rates, i.method, i.precision, substeps, certified)
                            + run_s(scene, rates, shadow.method, "f64", shadow_substeps, certified))
    if scene.has("lyapunov"):  # render/trust/lyapunov.py: up to CAP of those, each with 2D tangent vectors, every frame
        from ..trust.lyapunov import CAP, FRAME_S, TANGENT_COST
        carried = min(CAP, certified) * (1 + 2 * plan.D * TANGENT_COST)
        parts["lyapunov"] = run_s(scene, rates, i.method, "f64", substeps, carried) + scene.frames * FRAME_S
    return parts, h, substeps


def pinned(scene, dt: float) -> tuple[float, int]:
    """(h, substeps per frame) of a pinned step, as integrators.timestep rounds it."""
    substeps = max(1, math.ceil(1.0 / (scene.video.fps * dt) - 1e-9))
    return 1.0 / (scene.video.fps * substeps), substeps


def steps_per_s(rates: dict, system: str, precision: str, method: str) -> float:
    """Pendulum-steps per second of `method`: RK4's rate over the ratio of their force evaluations. A system
    with no rate of its own takes the slowest known."""
    table = rates["steps_per_s"]
    return table.get(f"{system}_{precision}", min(table.values())) * METHOD["rk4"].evals / METHOD[method].evals


def run_s(scene, rates: dict, method: str, precision: str, substeps: int, n: int, frames: int | None = None) -> float:
    """Seconds to run n pendulums `substeps` steps a frame through `frames` frames (default: all)."""
    frames = scene.frames if frames is None else frames
    return frames * (substeps * n / steps_per_s(rates, scene.system, precision, method) + rates["frame_s"])


def pilots_s(scene, cands: list[dict], rates: dict) -> float:
    """The pilot runs of quality.choose, at most: the fine reference, then per method and precision a bisection
    over its steps, each try at that ladder's costliest step, through the frames the target needs; and a
    kernel compiled for each."""
    if scene.quality == "reference":
        return 0.0  # the finest setting is taken without pilots
    n = min(scene.pendulums.count, quality.PILOT)
    frames = min(scene.frames, math.ceil(quality.TARGET[scene.quality] * scene.video.duration * scene.video.fps) + 2)
    _, ref = pinned(scene, min(s["dt"] for s in cands) / 2)
    total = run_s(scene, rates, "rk4", "f64", ref, n, frames) + rates["compile_s"]
    ladders = {}
    for s in cands:
        ladders.setdefault((s["method"], s["precision"]), []).append(s)
    for (method, precision), ladder in ladders.items():
        tries = math.ceil(math.log2(len(ladder) + 1))
        _, substeps = pinned(scene, min(s["dt"] for s in ladder))
        total += tries * run_s(scene, rates, method, precision, substeps, n, frames) + rates["compile_s"]
    return total


def picture_frame_s(scene, rates: dict, panels: int = 0) -> tuple[float, float]:
    """Seconds to draw and encode one frame, and of those what drawing the pendulums' links takes: the canvas
    (a fixed cost, per pixel, per drawn link at the panels' heights, the HUD), then x264 and the GIF's ffmpeg,
    each per pixel of the full frame."""
    from ..draw.split import layout

    v, cls = scene.video, registry.get(scene.system)
    pixels = v.width * v.height
    heights = [h for _, _, _, h in layout(v.width, v.height, panels)] if panels else [v.height]
    links = scene.pendulums.count * len(cls.LINKS) if any(scene.has(e) for e in DRAWN) else 0
    links_s = sum(links * rates["draw_link_s"] * h / REFERENCE_HEIGHT for h in heights)
    per = rates["draw_frame_s"] + pixels * rates["draw_pixel_s"] + rates["hud_frame_s"] * scene.has("hud") + links_s
    # x264 sees every frame; the GIF's ffmpeg only those it keeps (render/video/encode.py), min(gif_fps, fps) a second
    for fmt, share in (("mp4", 1.0), ("gif", min(v.gif_fps, v.fps) / v.fps)):
        if fmt in v.formats:
            per += share * (rates[f"{fmt}_frame_s"] + pixels * rates[f"{fmt}_pixel_s"])
    return per, links_s


def measured(res: dict, chaos) -> dict:
    """rates.json from `pendulum bench`'s phases (`res`, render/commands/bench/command.py): the RK4 rates at the largest N
    measured up to 1e5, the triple's scaled as the rigid system's (not benched); the drawing and encoding
    constants scaled so that the model gives the measured fps of `chaos` (the scene the e2e phase drew);
    the fixed cost of a one-frame render."""
    rates = json.loads(json.dumps(RATES))
    rows = [r for r in res["sim"]["rows"] if r["n"] <= 10 ** 5]
    for r in sorted(rows, key=lambda r: r["n"]):
        rates["steps_per_s"][f"{r['system']}_{r['precision']}"] = r["taichi"]
    for prec in ("f32", "f64"):
        rates["steps_per_s"][f"triple_{prec}"] = (RATES["steps_per_s"][f"triple_{prec}"] * rates["steps_per_s"]
                                                  [f"rigid_{prec}"] / RATES["steps_per_s"][f"rigid_{prec}"])
    draw_only = {**RATES, "mp4_frame_s": 0, "mp4_pixel_s": 0, "gif_frame_s": 0, "gif_pixel_s": 0}
    encode_only = {**RATES, "draw_frame_s": 0, "draw_pixel_s": 0, "draw_link_s": 0, "hud_frame_s": 0}
    for keys, fps, model in ((("draw_frame_s", "draw_pixel_s", "draw_link_s", "hud_frame_s"), res["e2e"]["draw_fps"],
                              draw_only),
                             (("mp4_frame_s", "mp4_pixel_s", "gif_frame_s", "gif_pixel_s"), res["e2e"]["encode_fps"],
                              encode_only)):
        scale = (1.0 / fps) / picture_frame_s(chaos, model)[0]
        for k in keys:
            rates[k] = RATES[k] * scale
    rates["fixed_s"] = res["e2e"]["fixed_s"]
    return rates
