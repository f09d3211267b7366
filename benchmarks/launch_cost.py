"""What a kernel launch costs on the host, through Taichi and prepared (render/physics/launch.py).

    .venv/bin/python benchmarks/launch_cost.py [--launches N] [--rounds R]

Four kernels that do next to nothing, with the kinds of arguments a render's kernels take: none (the canvas's
bob_pixels), an array and two scalars (draw_frame and hud_draw take arrays), four arrays and a scalar (the MP4's
conversion, render/video/yuv.py), and one that returns a value (the HUD's spread). Each is launched N times in
a row, through Taichi's Kernel.__call__ and through its prepared launch, in alternating rounds; printed are the
µs a launch, the median of the rounds and their range.
"""
import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402
import taichi as ti  # noqa: E402

from render.physics import launch, runtime  # noqa: E402


@ti.data_oriented
class Small:
    def __init__(self):
        self.f = ti.field(ti.f64, 2)

    @ti.kernel
    def none(self):
        self.f[0] += 1.0

    @ti.kernel
    def array(self, a: ti.types.ndarray(dtype=ti.u8, ndim=3), k: ti.i32, s: ti.f32):
        self.f[0] += a[0, 0, 0] + k + s

    @ti.kernel
    def arrays(self, a: ti.types.ndarray(dtype=ti.u32, ndim=1), b: ti.types.ndarray(dtype=ti.u32, ndim=1),
               c: ti.types.ndarray(dtype=ti.u16, ndim=1), d: ti.types.ndarray(dtype=ti.u16, ndim=1), w: ti.i32):
        b[1] = a[0] + ti.cast(c[0] + d[0] + w, ti.u32)

    @ti.kernel
    def returns(self, k: ti.i32) -> ti.f64:
        self.f[1] += k
        return self.f[1]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--launches", type=int, default=3000)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args(argv)
    runtime.init("cpu", "f64")
    k = Small()
    frame, words, halves = np.zeros((720, 1280, 3), np.uint8), np.zeros(1000, np.uint32), np.zeros(1000, np.uint16)
    cases = {"no argument": ("none", ()), "an array, two scalars": ("array", (frame, 3, 1.5)),
             "four arrays, a scalar": ("arrays", (words, words, halves, halves, 5)),
             "a returned value": ("returns", (2,))}
    print(f"µs a launch, median of {args.rounds} rounds of {args.launches} (range):")
    for label, (name, a) in cases.items():
        kernel = getattr(k, name)
        kernel(*a)  # compiles
        ready = launch.Prepared.of(kernel, a)
        ways = {"Taichi": lambda: kernel(*a), "prepared": lambda: ready(a)}
        times = {way: [] for way in ways}
        for _ in range(args.rounds):
            for way, go in ways.items():
                ti.sync()
                t = time.perf_counter()
                for _ in range(args.launches):
                    go()
                ti.sync()
                times[way].append(1e6 * (time.perf_counter() - t) / args.launches)
        print(f"  {label:24s}" + "".join(
            f"  {way} {statistics.median(v):5.1f} ({min(v):.1f}-{max(v):.1f})" for way, v in times.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
