"""The up-front budget: what a valid scene will cost, estimated before any work and refused (SceneError,
exit 2) when it is beyond a limit. Each refusal quotes the estimate and the limit. Refuse, don't attempt:
a run that cannot finish should not start, take hours, and then fail or freeze.

Three estimates, each against a limit stated as a share of what this machine has or of the time allowed:
- time: the seconds of every part of the run (render/config/estimate.py: simulation, the certificate's shadow,
  the --quality pilots, drawing and encoding, from this machine's rates) ≤ the budget: the scene's `budget`
  key or --budget, DEFAULT_LIMIT_S otherwise. A run of several scenes (`render A B`, `batch`, a
  comparison's panels) is held to the sum. Runs estimated over ANNOUNCE_S say so before they start;
- memory: the state fields, the canvas and the frames a run holds at once: frames queued for ffmpeg, and
  every GIF frame, kept until its palette is known at the end; `simulate` keeps every frame's
  state until it writes the file. Limit: MEMORY_FRACTION of the machine's physical memory;
- output: bytes written (MP4 and GIF and a map's NAME.npz, or simulate's .npz). Limit: DISK_FRACTION of the free space where they go.
Counts are Python ints (64-bit and beyond, never a wrapped 32-bit counter); the substeps per frame must fit
the advance kernel's i32, which integrators.check_substeps refuses when the System settles its step.

check() runs before any work (the CLI, compare and batch call check_run() for all their scenes before the
first render). It plans the step the System settles on ("auto" depends on the physics) without building a
Taichi field or kernel; the System checks its substeps again when it is built.
"""
from __future__ import annotations

import functools
import json
import math
import os
import re
import shutil
import sys
from pathlib import Path

from ..video import audio
from ..video.pipe import QUEUE_FRAMES
from ..video.mp4 import AUDIO_KBPS
from ..errors import SceneError
from ..physics.integrators import AUTO_DT, check_substeps
from ..physics.keys import BUDGET_MAX

DEFAULT_LIMIT_S = 3600.0  # "about one hour" (DESIGN.md, round 3); a scene's `budget` key or --budget raises it
ANNOUNCE_S = 60.0  # a run estimated longer prints its estimate before it starts
MEMORY_FRACTION = 0.8  # of physical memory: beyond it the machine swaps or the kernel kills the run
DISK_FRACTION = 0.9  # of the free space: the rest is left for the system and the temporary files beside
FALLBACK_MEMORY = 8 << 30  # where the physical memory cannot be read
# Output sizes per pixel of each frame, about twice the largest measured here (fractal: MP4 0.027,
# GIF 0.53 bytes per pixel; the swinging presets compress 10 to 30 times better), so the estimate errs high.
MP4_BYTES_PER_PIXEL = 0.05
GIF_BYTES_PER_PIXEL = 1.0
NPZ_BYTES_PER_START = 48  # a map's data, uncompressed: 16 for the start, up to 24 for the angles, the masks
GIF_BUFFER_BYTES_PER_PIXEL = 3  # the render keeps each GIF frame (RGB) until its palette is known (palette.py)


def check(scene, system, out: Path | None, simulate: bool = False):
    """Refuse `scene` if its memory, output or time exceed the limits; return its time estimate. `system` is
    its class (registry.get: for the size of its state); `out` is where the output goes (a folder, or the .npz's
    folder; its bench/rates.json gives this machine's rates), None when nothing is written (the API's
    simulate without a file)."""
    from . import estimate as estimates  # the planners (trust/, physics/): loaded only when a scene is checked

    src = scene.source
    need, key, detail = memory(scene, system, simulate)
    limit, total = memory_limit()
    if need > limit:
        raise SceneError(f"{src}: {key}: needs about {size(need)} of memory ({detail}), limit {size(limit)} "
                         f"({MEMORY_FRACTION:.0%} of this machine's {size(total)})")
    need, key, detail = output(scene, system, simulate)
    where = existing(Path(out)) if out is not None else None
    free = shutil.disk_usage(where).free if where is not None else math.inf
    if need > DISK_FRACTION * free:
        raise SceneError(f"{src}: {key}: the output needs about {size(need)} of disk ({detail}), more than "
                         f"{DISK_FRACTION:.0%} of the {size(free)} free in {where}")
    for variant in scene.variants() if scene.compare else [scene]:
        # A pinned dt gives its substeps before any planning: a subnormal one gives fps·dt = 0 once Taichi has
        # started (its CPU runtime sets the FPU's denormal flags for the whole process), or 1/(fps·dt) = inf.
        dt = variant.integrator.dt
        if dt != "auto":
            per_frame = variant.video.fps * dt
            ratio = 1.0 / per_frame if per_frame > 0 else math.inf
            if not math.isfinite(ratio):
                # no number: once Taichi has started, the FPU flushes subnormals, formatting's arithmetic too
                raise SceneError(f"{variant.source}: integrator.dt: too small to step by (subnormal): a frame of "
                                 f"1/{variant.video.fps} s would take infinitely many; use a larger integrator.dt")
            substeps = max(1, math.ceil(ratio - 1e-9))
            check_substeps(variant, substeps, 1.0 / (variant.video.fps * substeps))
    rates, source = estimates.load_rates(out)
    est = _estimate(scene, json.dumps(rates, sort_keys=True), source, simulate)
    if est.total > limit_s(scene):
        raise SceneError(refusal(scene, est, limit_s(scene)))
    return est


def check_run(scenes: list, out: Path | None, simulate: bool = False, say: bool = True) -> str | None:
    """check() every scene, then hold their sum to the run's limit (the largest of theirs). Returns the estimate's
    line when it is over ANNOUNCE_S (else None), said on stderr here unless `say` is False: then by the caller,
    once nothing else can refuse the run (`show`, after its display)."""
    ests = [check(s, _system(s), out, simulate) for s in scenes]
    total, limit = sum(e.total for e in ests), max(limit_s(s) for s in scenes)
    if len(scenes) > 1 and total > limit:
        names = ", ".join(s.name for s in scenes[:3]) + (", ..." if len(scenes) > 3 else "")
        raise SceneError(f"{len(scenes)} renders ({names}): estimated {duration(total)} together "
                         f"({breakdown(ests)}), over the run-time budget of {duration(limit)}; render fewer at once, "
                         f"or {raise_by(total)}")
    if total <= ANNOUNCE_S:
        return None
    what = scenes[0].name if len(scenes) == 1 else f"{len(scenes)} renders"
    line = f"pendulum: {what}: estimated {duration(total)} ({breakdown(ests)}), within the budget of {duration(limit)}"
    if say:
        print(line, file=sys.stderr, flush=True)
    return line


@functools.lru_cache(maxsize=64)
def _estimate(scene, rates: str, source: str, simulate: bool):
    """estimate.estimate, once per scene and rates: a render is checked by the CLI, then by the API."""
    from . import estimate as estimates
    return estimates.estimate(scene, json.loads(rates), source, simulate)


def _system(scene):
    from ..physics import registry
    return registry.get(scene.system)


def limit_s(scene) -> float:
    return scene.budget if scene.budget is not None else DEFAULT_LIMIT_S


def refusal(scene, est, limit: float) -> str:
    """One line: the keys that drive the estimate, the estimate by part, the limit, and how to get under it."""
    steps = (f"{num(est.steps)} steps ({est.frames} frames x {est.substeps} substeps of {est.h:.3g} s x "
             f"{est.pendulums} pendulum{'s' * (est.pendulums != 1)}{f' x {est.panels} panels' * bool(est.panels)})")
    over = (f"{f'{est.panels} panels ' * bool(est.panels)}estimated {duration(est.total)} ({breakdown([est])}), "
            f"over the run-time budget of {duration(limit)}")
    src, dt = scene.source, scene.integrator.dt
    usual = max(1, math.ceil(1.0 / (scene.video.fps * AUTO_DT)))  # the same scene at dt = 1e-3
    at_usual = est.total - est.physics * (1 - usual / est.substeps) if est.substeps > usual else math.inf
    if est.physics + est.pendulums_s < est.total - est.physics - est.pendulums_s:
        keys, why = "video.width, video.height, video.duration", over
        fix = "use a smaller or shorter video, or a lower video.fps"
    elif est.physics < est.pendulums_s:  # drawing (or writing) the pendulums, frame after frame
        keys, why = "pendulums.count, video.duration", over
        fix = "use fewer pendulums, a shorter video or a lower video.fps"
    elif dt == "auto" and at_usual <= limit and not scene.compare:
        keys, fix = "integrator.dt", "use softer springs or heavier bobs, or fewer pendulums"
        why = (f"\"auto\" needs steps of {est.h:.3g} s for this scene's fastest rate, and {steps} are {over}; "
               f"stiff springs, or light bobs under heavy ones or on tiny links, are the usual cause")
    elif dt != "auto" and at_usual <= limit:
        keys, why, fix = "integrator.dt", f"dt too small: {steps} are {over}", "use a larger integrator.dt"
    else:
        keys, why = "pendulums.count, video.duration", f"{steps} are {over}"
        fix = "use fewer pendulums, a shorter video or a lower video.fps"
    return f"{src}: {keys}: {why}; {fix}, or {raise_by(est.total)}"


def raise_by(total: float) -> str:
    """How to allow `total` seconds, or that no budget does."""
    if total > BUDGET_MAX:
        return f"no budget allows it (at most {duration(BUDGET_MAX)})"
    wanted = min(BUDGET_MAX, math.ceil(total / 3600) * 3600 if total > 3000 else math.ceil(total / 600) * 600)
    text = f"{wanted // 3600:.0f}h" if wanted >= 3600 else f"{wanted // 60:.0f}min"
    return f"raise the budget: --budget {text} (or budget = \"{text}\" in the preset)"


def breakdown(ests: list) -> str:
    """'start 10 s, simulate 40 s, certificate 1 min 5 s, draw+encode 2 min; built-in rates'."""
    parts = {}
    for e in ests:
        for k, s in e.parts.items():
            parts[k] = parts.get(k, 0.0) + s
    sources = sorted({e.rates for e in ests})
    return ", ".join(f"{k} {duration(s)}" for k, s in parts.items() if s >= 0.5) + "; " + ", ".join(sources)


def duration(s: float) -> str:
    """Seconds for a message: '42 s', '3 min 20 s', '2 h 5 min', '1.2e+04 h'."""
    if s < 59.5:
        return f"{s:.0f} s"
    if s < 3570:
        m, r = divmod(round(s), 60)
        return f"{m} min {r} s" if r else f"{m} min"
    if s < 100 * 3600:
        h, m = divmod(round(s / 60), 60)
        return f"{h} h {m} min" if m else f"{h} h"
    return f"{s / 3600:.3g} h"


def memory(scene, system, simulate: bool) -> tuple[int, str, str]:
    """(bytes, the keys that drive it, a breakdown) of what a run holds in memory at its peak."""
    p, v = scene.pendulums, scene.video
    n, d = p.count, system.D
    real = 8 if scene.integrator.precision == "f64" else 4
    state = n * (2 * d + 3) * real  # q, v, and the energy fields e, e0, scale
    if simulate:
        kept = scene.frames * n * (2 * d + 1) * (real + 8)  # per frame: state and energy, then a float64 copy
        return state + kept, "pendulums.count, video.duration", (
            f"{scene.frames} frames x {n} pendulums kept until the file is written")
    pixels = v.width * v.height
    canvas = pixels * 12 * (1 + scene.has("trails")) + n * 8 * (len(system.LINKS) + 1)
    queued = (QUEUE_FRAMES * len(v.formats) + 2) * pixels * 3
    gif = gif_frames(scene) * gif_pixels(scene) * GIF_BUFFER_BYTES_PER_PIXEL if "gif" in v.formats else 0
    # A comparison keeps every variant's state at every frame until its panels are drawn (render/draw/split.py).
    kept = len(scene.compare[0][1]) * scene.frames * n * d * 8 if scene.compare else 0
    sound = audio.peak_bytes(scene) if audio.heard(scene) else 0  # made as the frames come, levelled at the end
    terms = {"pendulums.count": state, "video.width, video.height": canvas + queued,
             "video.gif_width, video.duration": gif, "pendulums.count, video.duration": kept,
             "video.duration": sound}
    detail = (f"state {size(state)}, canvas and queued frames {size(canvas + queued)}, "
              f"GIF frames held for its palette {size(gif)}" + (
                  f", the variants' states at every frame {size(kept)}" if kept else ""))
    detail += f", the audio track being made {size(sound)}" if sound else ""
    return sum(terms.values()), max(terms, key=terms.get), detail


def output(scene, system, simulate: bool) -> tuple[int, str, str]:
    """(bytes, the keys that drive it, a breakdown) of what a run writes."""
    v = scene.video
    if simulate:
        per = scene.pendulums.count * (2 * system.D + 1) * 8  # savez_compressed: chaos barely compresses
        return scene.frames * (per + 8), "pendulums.count, video.duration", (
            f"{scene.frames} frames x {scene.pendulums.count} pendulums in float64")
    sizes = {}
    if "mp4" in v.formats:
        sizes["mp4"] = int(scene.frames * v.width * v.height * MP4_BYTES_PER_PIXEL)
    if "gif" in v.formats:
        sizes["gif"] = int(gif_frames(scene) * gif_pixels(scene) * GIF_BYTES_PER_PIXEL)
    if audio.heard(scene):  # the MP4's AAC track: its bit rate, with room to spare
        sizes["audio"] = int(2 * v.duration * AUDIO_KBPS * 125)
    if scene.fractal:  # NAME.npz (render/maps/data.py): per start, its (x, y), its value and two masks
        sizes["npz"] = scene.pendulums.count * NPZ_BYTES_PER_START
    return sum(sizes.values()), "video.duration", ", ".join(f"{k} {size(b)}" for k, b in sizes.items())


def gif_frames(scene) -> int:
    """Frames of the GIF: ffmpeg's fps filter resamples to min(gif_fps, fps) (see render/video/gif.py)."""
    v = scene.video
    return math.ceil(min(v.gif_fps, v.fps) * scene.frames / v.fps - 1e-9)


def gif_pixels(scene) -> int:
    """Pixels of one GIF frame: downscaled to gif_width, never upscaled, the height kept even."""
    v = scene.video
    w = min(v.gif_width, v.width)
    return w * max(2, round(v.height * w / v.width / 2) * 2)


def memory_limit() -> tuple[int, int]:
    """(limit, physical memory) in bytes."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        total = FALLBACK_MEMORY
    return int(total * MEMORY_FRACTION), total


def existing(path: Path) -> Path:
    """The nearest existing ancestor of `path` (itself if it exists): where its bytes will land."""
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def num(x: int) -> str:
    """A count for a message: 2.45e11, or every digit below a million."""
    return str(x) if x < 1e6 else re.sub(r"e\+0*", "e", f"{x:.3g}")  # 3.79e+08 -> 3.79e8


def size(b: int) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if b >= scale:
            return f"{b / scale:.3g} {unit}"
    return f"{b / 1e3:.3g} kB"
