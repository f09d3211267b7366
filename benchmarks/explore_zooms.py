"""What zooming costs in `pendulum show MAP`'s explorer: a box dragged over the map and `b` back out, many
times, with no window (render/commands/explore.py's Explorer, as the window drives it). Prints each zoom's and
back's seconds and the process's resident memory, to see whether it levels off.

    python benchmarks/explore_zooms.py [PRESET] [--size 640x360] [--zooms 60] [--every 10]
"""
import argparse
import tempfile
import time

from render.commands.explore import Explorer
from render.config.scene import load


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", nargs="?", default="fractal_flip", help="a map preset (default: fractal_flip)")
    ap.add_argument("--size", default="640x360", help="the map's video size, WxH (default: 640x360)")
    ap.add_argument("--zooms", type=int, default=60, help="zooms, each followed by a back (default: 60)")
    ap.add_argument("--every", type=int, default=10, help="print every this many zooms (default: 10)")
    args = ap.parse_args()
    w, h = (int(x) for x in args.size.split("x"))
    scene = load(args.preset, [f"video.width={w}", f"video.height={h}", "video.fps=10", "video.duration=0.5"])
    with tempfile.TemporaryDirectory() as out:
        ex = Explorer(scene, "cpu", None, out, log=lambda line: None)
        print(f"{args.preset} at {args.size}, {ex.scene.integrator.precision}: opened, {rss_mb():.0f} MB resident")
        x, y = ex.lay.x0, ex.lay.y0
        for k in range(args.zooms):
            t = time.perf_counter()
            ex.mouse("press", (x + 10, y + 10))
            ex.mouse("release", (x + 40, y + 40))
            zoom, t = time.perf_counter() - t, time.perf_counter()
            ex.key("b")
            if k % args.every == 0 or k == args.zooms - 1:
                print(f"zoom {k}: {zoom:.2f} s, back {time.perf_counter() - t:.2f} s, {rss_mb():.0f} MB resident")


if __name__ == "__main__":
    main()
