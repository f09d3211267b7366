"""Each kernel of a preset's frames timed alone, at a given thread count: where a frame's simulating and drawing go.

    .venv/bin/python benchmarks/draw_kernels.py PRESET [--threads T] [--seconds S] [--set KEY=VALUE]...

Simulates and draws the preset's first S seconds (default 10) as a render does (nothing encoded), once to
compile, then again with every kernel launch synchronised and timed (wall and this process's CPU time, both
threads together), and prints each kernel's ms per frame over the whole run, and the frame's total without
the synchronisation. The canvas draws and composes a frame in one kernel (render/draw/canvas.py's draw_frame),
so its primitives are not timed apart.
"""
import argparse
import collections
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import taichi as ti  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.draw.canvas import Canvas  # noqa: E402
from render.physics import runtime  # noqa: E402
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
    frame = canvas.new_frame()

    def frames():
        run.sim.restart()
        canvas.restart()
        t, c = time.perf_counter(), time.process_time()
        for _ in run.frames():
            canvas.draw(frame)
        return time.perf_counter() - t, time.process_time() - c

    frames()  # compiles
    wall, cpu = frames()
    spent = collections.defaultdict(lambda: [0.0, 0.0])
    launch = runtime.Launcher.launch

    def timed(self, name, *a):
        ti.sync()
        t, c = time.perf_counter(), time.process_time()
        result = launch(self, name, *a)
        ti.sync()
        spent[name][0] += time.perf_counter() - t
        spent[name][1] += time.process_time() - c
        return result

    runtime.Launcher.launch = timed
    frames()
    runtime.Launcher.launch = launch
    n = scene.frames
    print(f"{scene.name}, {canvas.w}x{canvas.h}, {canvas.bands} band(s), {n} frames; ms per frame, wall / CPU:")
    for name, (w, c) in sorted(spent.items(), key=lambda kv: -kv[1][0]):
        print(f"  {name:28s} {1e3 * w / n:7.3f} / {1e3 * c / n:7.3f}")
    print(f"  {'whole frame, unsynchronised':28s} {1e3 * wall / n:7.3f} / {1e3 * cpu / n:7.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
