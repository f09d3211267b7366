"""A map's GIF frames shrunk (render/video/downscale.py), timed on the map's own 720p frames: wall and CPU time
per frame, as a render shrinks them (on the launching thread on two CPUs or fewer).

    .venv/bin/python benchmarks/shrink_time.py [PRESET] [--frames 60] [--rounds 5]

The preset's first frames are drawn once (the map's frames, its simulation included); each round then shrinks
them all to the GIF's size. Prints each round's median ms per frame, wall and CPU, and a digest of the bytes,
which must not change when the kernels do.
"""
import argparse
import hashlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from render.config.scene import load  # noqa: E402
from render.video import gif  # noqa: E402
from render.video.downscale import shrink  # noqa: E402
from render.video.pipeline import Source  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="fractal_flip")
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args(argv)
    scene = load(args.preset, ["video.width=1280", "video.height=720", f"video.duration={args.frames / 60}",
                               "video.fps=60"])
    src = Source(scene)
    frames = []
    for _ in range(src.frames):
        frames.append(src.next_frame(src.canvas.new_frame()).copy())
    w, h = gif.size(scene.video)
    shrink(frames[0], w, h)  # compiles
    print(f"{args.preset}: {len(frames)} frames of {scene.video.width}x{scene.video.height} to {w}x{h}")
    for r in range(args.rounds):
        wall, cpu, digest = [], [], hashlib.sha256()
        for f in frames:
            t, c = time.perf_counter(), time.process_time()
            small = shrink(f, w, h)
            wall.append(time.perf_counter() - t)
            cpu.append(time.process_time() - c)
            digest.update(small.tobytes())
        print(f"round {r + 1}: {1e3 * np.median(wall):.2f} ms wall, {1e3 * np.median(cpu):.2f} ms CPU a frame "
              f"(median); bytes {digest.hexdigest()[:16]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
