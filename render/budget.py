"""The up-front budget: what a valid scene will cost, estimated before any work and refused (SceneError,
exit 2) when it is beyond a limit. Each refusal quotes the estimate and the limit. Refuse, don't attempt:
a run that cannot finish should not start, take hours, and then fail or freeze.

Three estimates, all in Python ints (64-bit and beyond, never a wrapped 32-bit counter):
- steps = frames × substeps × pendulums ≤ STEP_LIMIT, and substeps per frame ≤ SUBSTEP_LIMIT (the advance
  kernel counts them in an i32: beyond it the count wrapped to 0 and the video froze);
- memory: the state fields, the canvas and the frames a run holds at once: frames queued for ffmpeg, and
  every GIF frame, which ffmpeg keeps until the palette is known at the end; `simulate` keeps every frame's
  state until it writes the file. Limit: MEMORY_FRACTION of the machine's physical memory;
- output: bytes written (MP4 and GIF, or the .npz). Limit: the free space where they go.

check() runs before any work (the CLI and batch call it for every scene before the first render); the
System calls check_steps() again once the stable step is known, since "auto" depends on the physics.
"""
from __future__ import annotations

import math
import os
import re
import shutil
from pathlib import Path

from .encode import QUEUE_FRAMES
from .errors import SceneError
from .integrators import AUTO_DT

# 1e11 pendulum-steps is about two hours of simulation on a 2-core CPU (13 M rigid RK4 steps/s at N = 1e5,
# README "Performance") and still above every shipped use: the full fractal preset takes 1.1e9, `bench`
# builds rigid_chaos with 1e6 pendulums (2e10).
STEP_LIMIT = 10 ** 11
SUBSTEP_LIMIT = 2 ** 31 - 1  # System.advance takes the substeps per frame as a Taichi i32
MEMORY_FRACTION = 0.8  # of physical memory: beyond it the machine swaps or the kernel kills the run
FALLBACK_MEMORY = 8 << 30  # where the physical memory cannot be read
# Output sizes per pixel of each frame, about twice the largest measured here (fractal: MP4 0.027,
# GIF 0.53 bytes per pixel; the swinging presets compress 10 to 30 times better), so the estimate errs high.
MP4_BYTES_PER_PIXEL = 0.05
GIF_BYTES_PER_PIXEL = 1.0
GIF_BUFFER_BYTES_PER_PIXEL = 4  # ffmpeg holds each scaled GIF frame as RGB32 until palettegen has seen all


def check(scene, system, out: Path | None, simulate: bool = False) -> None:
    """Refuse `scene` if its steps, memory or output exceed the limits. `system` is its System class (for
    the size of its state); `out` is where the output goes (a folder, or the .npz's folder), None when
    nothing is written (the API's simulate without a file)."""
    src = scene.source
    need, key, detail = memory(scene, system, simulate)
    limit, total = memory_limit()
    if need > limit:
        raise SceneError(f"{src}: {key}: needs about {size(need)} of memory ({detail}), limit {size(limit)} "
                         f"({MEMORY_FRACTION:.0%} of this machine's {size(total)})")
    need, key, detail = output(scene, system, simulate)
    where = existing(Path(out)) if out is not None else None
    free = shutil.disk_usage(where).free if where is not None else math.inf
    if need > free:
        raise SceneError(f"{src}: {key}: the output needs about {size(need)} of disk ({detail}), "
                         f"{size(free)} free in {where}")
    # A pinned dt gives its substeps now; "auto" at least those of AUTO_DT (stiffness only adds more), as
    # integrators.timestep rounds them. The System checks again with the step it settles on.
    dt = AUTO_DT if scene.integrator.dt == "auto" else scene.integrator.dt
    # A subnormal dt gives fps·dt = 0 once Taichi has started (its CPU runtime sets the FPU's denormal
    # flags for the whole process), or 1/(fps·dt) = inf before: either way, more substeps than anything holds.
    per_frame = scene.video.fps * dt
    ratio = 1.0 / per_frame if per_frame > 0 else math.inf
    substeps = max(1, math.ceil(ratio - 1e-9)) if math.isfinite(ratio) else 2 ** 64
    check_steps(scene, substeps, 1.0 / (scene.video.fps * substeps))
    for variant in scene.variants() if scene.compare else ():  # each panel at its own step
        check(variant, system, out, simulate)


def check_steps(scene, substeps: int, h: float) -> None:
    """Refuse a scene whose frames × substeps × pendulums exceed STEP_LIMIT (or whose substeps per frame
    overflow the kernel's counter), naming what made it so."""
    frames, n = scene.frames, scene.pendulums.count
    steps = frames * substeps * n
    if steps <= STEP_LIMIT and substeps <= SUBSTEP_LIMIT:
        return
    dt = scene.integrator.dt
    what = (f"{num(steps)} steps ({frames} frames x {substeps} substeps of {h:.3g} s x {n} "
            f"pendulum{'s' * (n != 1)}) exceed the step budget of {num(STEP_LIMIT)}")
    if steps <= STEP_LIMIT:
        what = f"{substeps} substeps per frame exceed the step counter's limit of {SUBSTEP_LIMIT}"
    usual = frames * max(1, math.ceil(1.0 / (scene.video.fps * AUTO_DT))) * n  # the same scene at dt = 1e-3
    if dt == "auto" and usual <= STEP_LIMIT:
        raise SceneError(f"{scene.source}: integrator.dt: \"auto\" needs steps of {h:.3g} s for this scene's "
                         f"fastest rate, and {what}; stiff springs, or light bobs under heavy ones or on tiny "
                         f"links, are the usual cause")
    if dt != "auto" and (usual <= STEP_LIMIT or substeps > SUBSTEP_LIMIT):
        raise SceneError(f"{scene.source}: integrator.dt: dt too small: {what}; use a larger integrator.dt")
    raise SceneError(f"{scene.source}: pendulums.count, video.duration: {what}; use fewer pendulums, "
                     f"a shorter video or a lower video.fps")


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
    # A comparison keeps every variant's state at every frame until its panels are drawn (render/split.py).
    kept = len(scene.compare[0][1]) * scene.frames * n * d * 8 if scene.compare else 0
    terms = {"pendulums.count": state, "video.width, video.height": canvas + queued,
             "video.gif_width, video.duration": gif, "pendulums.count, video.duration": kept}
    return sum(terms.values()), max(terms, key=terms.get), (
        f"state {size(state)}, canvas and queued frames {size(canvas + queued)}, "
        f"GIF frames held by ffmpeg {size(gif)}" + (f", the variants' states at every frame {size(kept)}"
                                                   if kept else ""))


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
    return sum(sizes.values()), "video.duration", ", ".join(f"{k} {size(b)}" for k, b in sizes.items())


def gif_frames(scene) -> int:
    """Frames of the GIF: ffmpeg's fps filter resamples to min(gif_fps, fps) (see encode.gif_args)."""
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
    """A count for a message: 2.45e11, or every digit where rounding would make it read as the limit."""
    if x < 1e6:
        return str(x)
    short = re.sub(r"e\+0*", "e", f"{x:.3g}")  # 3.79e+08 -> 3.79e8
    return short if float(short) != STEP_LIMIT or x == STEP_LIMIT else f"{x:,}"


def size(b: int) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if b >= scale:
            return f"{b / scale:.3g} {unit}"
    return f"{b / 1e3:.3g} kB"
