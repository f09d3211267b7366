"""Milliseconds of simulation and drawing per frame of a map preset at 720p, its first frames (every pixel
still pending), without encoding: what the map kernel costs, apart from the certificate and the encoders
(`pendulum bench` times whole renders: fractal_fps).

    python benchmarks/map_frame.py fractal_flip --seconds 3
"""
import argparse
import time

import numpy as np

from render.config.scene import load
from render.video.pipeline import Source


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", help="a map preset, e.g. fractal_flip or fractal_divergence")
    ap.add_argument("--seconds", type=float, default=3.0, help="video seconds rendered (default: 3)")
    args = ap.parse_args()
    scene = load(args.preset, ["video.width=1280", "video.height=720", f"video.duration={args.seconds}"])
    t0 = time.perf_counter()
    src = Source(scene)  # the certificate, the system and the map
    print(f"{args.preset}: {src.sim.n} pendulums, prepared in {time.perf_counter() - t0:.1f} s")
    out, per = src.canvas.new_frame(), []
    for _ in range(src.frames):
        s0, d0 = src.timings["simulate"], src.timings["draw"]
        src.next_frame(out)
        per.append((src.timings["simulate"] - s0, src.timings["draw"] - d0))
    ms = 1e3 * np.array(per[2:])  # frames 0 and 1 compile the kernels
    print(f"per frame: simulate {np.median(ms[:, 0]):.1f} ms (median; {ms[:, 0].min():.1f}-{ms[:, 0].max():.1f}), "
          f"draw {np.median(ms[:, 1]):.1f} ms, over {len(ms)} frames")


if __name__ == "__main__":
    main()
