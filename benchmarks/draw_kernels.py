"""The canvas's rod, coil and bob kernels timed alone, at a given thread count: where a frame's drawing goes.

    .venv/bin/python benchmarks/draw_kernels.py PRESET [--threads T] [--seconds S] [--set KEY=VALUE]...

Simulates and draws the preset's first S seconds (default 10) as a render does, then, after each frame of the
second half, launches each primitive kernel once more on its own (synchronised) and prints the median ms of
each. Relaunching draws the same pixels again, which a max leaves as they were.
"""
import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import taichi as ti  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.draw.canvas import Canvas  # noqa: E402
from render.physics.stepper import Run  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset")
    ap.add_argument("--threads", type=int, default=None, help="CPU threads (default: all)")
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    scene = load(args.preset, [f"video.duration={args.seconds}", *args.overrides])
    run = Run(scene, "cpu", args.threads)
    canvas = Canvas(scene, run.sim)
    # not the trails: relaunched, stamp_trails would draw a dot where the bob is, not the frame's stretch of path
    kernels = [k for k, on in (("draw_rods", canvas.rods), ("draw_spring_coils", canvas.springs),
                               ("draw_bobs", canvas.bobs_on)) if on]
    frame, ms = canvas.new_frame(), {k: [] for k in kernels}
    for f in run.frames():
        canvas.draw(frame)
        if f >= scene.frames // 2:
            for name in kernels:
                ti.sync()
                t = time.perf_counter()
                canvas.launch(name)
                ti.sync()
                ms[name].append(1e3 * (time.perf_counter() - t))
    print(f"{scene.name}, {canvas.w}x{canvas.h}, {canvas.bands} band(s), frames {scene.frames // 2}.."
          f"{scene.frames - 1}: " + ", ".join(f"{k} {statistics.median(v):.3f} ms" for k, v in ms.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
