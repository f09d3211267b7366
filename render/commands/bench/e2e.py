"""The end-to-end render against its floor (`pendulum bench`'s e2e phase): rigid_chaos rendered as `render` does,
and the same frames, recorded beforehand, through the same encoders alone.

end_to_end_over_encode_floor is the render's wall time over the floor's; render_over_realtime the render's over
the video's length. The frames' simulate and draw fps come from the recording. Method: benchmarks/README.md.
"""
from __future__ import annotations

import statistics
import time

import numpy as np

CHAOS = "rigid_chaos"


def chaos_scene(cfg):
    from ...config.scene import load
    return load(CHAOS, [f"video.duration={cfg['chaos_s']}"])


def record_frames(cfg, arch, tmp) -> dict:
    """rigid_chaos's frames as a render makes them (pipeline.Source, and the GIF's own smaller frames from
    gif.Frames), written to raw files in tmp and memory-mapped for encode_floor(), with the fps of simulating and
    drawing them. Until 2026-12-04 the floor fed the GIF the video's frames, which the Encoder then area-averaged
    in numpy (3.1 s of this process's CPU beside the encoders on the 2-core Xeon): work no render does, so the
    floor was higher than the encoders alone."""
    from ...video import pipeline
    from ...video.gif import Frames

    src = pipeline.Source(chaos_scene(cfg), arch)
    scene, v = src.scene, src.scene.video
    small = Frames(src, v, {"draw": 0.0}) if "gif" in v.formats else None
    raw, raw_small, kept, draw, simulate = tmp / "frames.raw", tmp / "gif.raw", [], 0.0, 0.0
    with open(raw, "wb") as fh, open(raw_small, "wb") as fs:
        for f in range(scene.frames):
            if f == 2:  # frames 0 and 1 instantiate the kernels; time the steady state
                draw, simulate = 0.0, src.timings["simulate"]
            d0 = src.timings["draw"]
            frame = src.next_frame()
            draw += src.timings["draw"] - d0
            fh.write(memoryview(frame).cast("B"))
            gif_frame = small.frame(f, frame) if small else None
            if gif_frame is not None:
                kept.append(f)
                fs.write(memoryview(np.ascontiguousarray(gif_frame)).cast("B"))
    simulate = src.timings["simulate"] - simulate
    n = scene.frames - 2
    gif_frames = {}
    if kept:
        gif_frames = dict(zip(kept, np.memmap(raw_small, np.uint8, "r", shape=(len(kept), small.h, small.w, 3))))
    return {"scene": scene, "frames": np.memmap(raw, np.uint8, "r", shape=(scene.frames, v.height, v.width, 3)),
            "gif_frames": gif_frames, "files": (raw, raw_small),
            "draw_fps": n / draw, "sim_draw_fps": n / (draw + simulate)}


def encode_floor(rec: dict, tmp) -> float:
    """Wall seconds to encode record_frames()'s frames through the same Encoder a render uses, from its creation
    to the end of its close(): the floor an end-to-end render cannot beat."""
    from ...video.encode import Encoder

    scene, frames, gif_frames = rec["scene"], rec["frames"], rec["gif_frames"]
    (tmp / "floor").mkdir(exist_ok=True)
    t = time.perf_counter()
    enc = Encoder(tmp / "floor", scene.name, scene.video, scene.frames, planar=True)
    for f in range(scene.frames):
        enc.write(frames[f], gif_frames.get(f))
    enc.close()
    return time.perf_counter() - t


def timed_render(scene, arch, tmp, warm_scene=None) -> tuple[float, dict]:
    """Wall time of pipeline.render, after a warm-up render (Taichi init, kernel cache); and its metadata."""
    from ...video import pipeline
    if warm_scene is not None:
        pipeline.render(warm_scene, tmp / "warm", arch=arch)
    t = time.perf_counter()
    meta = pipeline.render(scene, tmp / "timed", arch=arch)
    return time.perf_counter() - t, meta


def phase_e2e(cfg, arch, tmp) -> dict:
    """rigid_chaos's encode floor and its end-to-end render, alternating, once a round (--repeat): the floor, then
    the render, the first after a one-frame warm-up render. Each ratio is round i's render over round i's floor,
    timed a few seconds apart. In phases of their own, minutes apart, the ratio moved with the hour: two
    consecutive bench runs read 1.099 and 1.194 (the floors 6.35 and 6.32 s, the renders 6.98 and 7.55 s; runs D
    and E, docs/performance.md). Returns the medians, each round's times, the median render's split, the fixed
    cost (a one-frame render after the rounds) and the fps of simulating and drawing the frames (record_frames)."""
    rec = record_frames(cfg, arch, tmp)
    scene = chaos_scene(cfg)
    one = scene.replace(video={"duration": 1.0 / scene.video.fps})
    floors, runs = [], []
    for r in range(cfg["rounds"]):
        floors.append(encode_floor(rec, tmp))
        runs.append(timed_render(scene, arch, tmp, one if r == 0 else None))
    for path in rec.pop("files"):
        path.unlink()
    walls, floor = [wall for wall, _ in runs], statistics.median(floors)
    _, meta = sorted(runs, key=lambda run: run[0])[(len(runs) - 1) // 2]  # the median's split (the lower of two)
    fixed, _ = timed_render(one, arch, tmp)  # what every render pays besides its frames
    return {"wall_s": statistics.median(walls), "rounds_s": walls, "frames": meta["frames"],
            "timings": meta["timings_s"], "fixed_s": fixed, "floor_s": floor, "floor_rounds_s": floors,
            "encode_fps": scene.frames / floor, "draw_fps": rec["draw_fps"], "sim_draw_fps": rec["sim_draw_fps"]}
