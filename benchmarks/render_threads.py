"""Where a whole render's main thread spends its time: each stage of pipeline.render's frame loop timed in wall
time and in this thread's CPU time, so that waiting (on x264's pipe, or for a core x264 holds) shows apart
from work.

    .venv/bin/python benchmarks/render_threads.py [PRESET] [--set KEY=VALUE]...

Renders PRESET (default rigid_chaos) into a temporary folder as `pendulum render` does, with a timer around
Source.next_frame (simulate and draw the video's frame, its HUD included), gif.Frames.frame (the GIF's own
frame), Hud.draw (within both), yuv.convert (the MP4's yuv420p), the rest of Encoder.write (handing frames
to the pipes: its wall time beyond its CPU time is waiting on an encoder) and Encoder.close (after the last
frame). The stages nest: the frames' figures include the HUD's, write's the conversion's. Kernels compiled
on a first run are in the first run's figures.
"""
import argparse
import collections
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.config.scene import load  # noqa: E402
from render.draw.hud import Hud  # noqa: E402
from render.video import encode, gif, pipeline, yuv  # noqa: E402

STAGES = [(pipeline.Source, "next_frame", "video frame (simulate + draw + HUD)"),
          (gif.Frames, "frame", "GIF frame"),
          (Hud, "draw", "HUD (the video's and the GIF's frames)"),
          (yuv, "convert", "yuv420p conversion"),
          (encode.Encoder, "write", "Encoder.write (conversion included)"),
          (encode.Encoder, "close", "Encoder.close")]


def timed(fn, totals):
    def wrapper(*args, **kwargs):
        wall, cpu = time.perf_counter(), time.thread_time()
        try:
            return fn(*args, **kwargs)
        finally:
            totals[0] += time.perf_counter() - wall
            totals[1] += time.thread_time() - cpu
            totals[2] += 1
    return wrapper


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    scene = load(args.preset, args.overrides)
    stats = collections.defaultdict(lambda: [0.0, 0.0, 0])
    for owner, name, label in STAGES:
        setattr(owner, name, timed(getattr(owner, name), stats[label]))
    with tempfile.TemporaryDirectory(prefix="render-threads-") as tmp:
        wall, cpu = time.perf_counter(), time.process_time()
        meta = pipeline.render(scene, Path(tmp))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f"{args.preset}: pipeline.render {wall:.2f} s wall, {cpu:.2f} s CPU of this process (all its threads)")
    print(f"timings_s: {meta['timings_s']}")
    print("| stage | calls | wall s | main thread CPU s | wall ms a call |\n|---|---:|---:|---:|---:|")
    for _, _, label in STAGES:
        w, c, n = stats[label]
        print(f"| {label} | {n} | {w:.2f} | {c:.2f} | {1e3 * w / max(n, 1):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
