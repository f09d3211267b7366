"""The GIF's frames mapped to its palette (render/video/dither.py), timed on a preset's own GIF frames.

    .venv/bin/python benchmarks/gif_map.py [PRESET] [--rounds 3]

The preset's GIF frames are drawn once as a render draws them (gif_palette.py's gif_frames) and their palette
made by the render's own ffmpeg arguments (palette.stats_args, fed every palette_step-th frame). Then, each
round: Mapper.map over all the frames in the render's batches, over as many all-black frames (the cost of a
pixel that takes the fast path), and dither.write, the mapping with ffmpeg writing the GIF beside it (what a
render waits for after the palette). Prints each round's seconds, and a digest of the indices, which must not
change when the kernel does.
"""
import argparse
import hashlib
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import imageio_ffmpeg
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from gif_palette import gif_frames  # noqa: E402
from render.video import dither, gif, palette  # noqa: E402


def colours_of(scene, frames: list[np.ndarray]) -> np.ndarray:
    h, w = frames[0].shape[:2]
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
           "-s", f"{w}x{h}", "-r", str(gif.rate(scene.video)), "-i", "-", "-an", *palette.stats_args()]
    sampled = np.stack(frames[::palette.palette_step(scene.video)])
    return palette.read(subprocess.run(cmd, input=sampled.tobytes(), capture_output=True, check=True).stdout)


def mapped(mapper, frames: list[np.ndarray]) -> tuple[float, str]:
    digest = hashlib.sha256()
    t = time.perf_counter()
    for k in range(0, len(frames), dither.BATCH):
        digest.update(mapper.map(np.stack(frames[k:k + dither.BATCH])).tobytes())
    return time.perf_counter() - t, digest.hexdigest()[:16]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    scene, frames = gif_frames(args.preset)
    colours = colours_of(scene, frames)
    mapper, black = dither.Mapper(colours), [np.zeros_like(f) for f in frames]
    h, w = frames[0].shape[:2]
    print(f"{args.preset}: {len(frames)} GIF frames of {w}x{h}, {len(colours)} colours")
    with tempfile.TemporaryDirectory() as tmp, open(Path(tmp) / "log", "wb") as log:
        for r in range(args.rounds):
            own, digest = mapped(mapper, frames)
            dark, _ = mapped(mapper, black)
            t = time.perf_counter()
            dither.write(frames, colours, (w, h), gif.rate(scene.video), Path(tmp) / "x.gif", log)
            print(f"round {r + 1}: map {own:.3f} s, all black {dark:.3f} s, write {time.perf_counter() - t:.3f} s; "
                  f"indices {digest}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
