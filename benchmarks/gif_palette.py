"""What the GIF's palette cut (render/video/palette.py: PALETTE_BITS) saves and costs, on a preset's own GIF frames.

    .venv/bin/python benchmarks/gif_palette.py [PRESET] [--bits 8 7 6] [--rate 50]

The preset's GIF frames are drawn once, as a render draws them (render/video/gif.py), and kept in memory. Then,
for each number of bits, they are fed to the render's Encoder at `rate` frames per second, about as fast as a
render hands them over, and its close() is timed: the seconds ffmpeg still needs after the last frame, which
the render waits for. Each GIF is decoded and compared with the raw frames (PSNR, whole frame and the HUD
clock's corner). 8 bits is no cut. The rounds are interleaved (8, 7, 6, 8, 7, 6, ...) and the median kept.
"""
import argparse
import dataclasses
import statistics
import sys
import tempfile
import time
from pathlib import Path

import imageio.v3 as iio
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from render.config.scene import load  # noqa: E402
from render.video import encode, gif, palette, pipeline  # noqa: E402

CORNER = (slice(0, 17), slice(0, 90))  # the clock's line at the GIF's size (render/draw/hud_text.py)


def gif_frames(name: str) -> tuple[object, list[np.ndarray]]:
    scene = load(name, ['video.formats=["gif"]'])
    src = pipeline.Source(scene)
    small = gif.Frames(src, scene.video, src.timings)
    kept = []
    for f in range(scene.frames):
        src.skip_frame()
        g = small.frame(f, None)
        kept += [g] * small.repeats[f] if g is not None else []
    return scene, kept


def tail(scene, frames, bits: int, rate: float, out: Path) -> float:
    """Seconds the render's Encoder spends in close() (the GIF's palette and mapping after the last frame), fed
    `rate` frames per second. Its video is the GIF's own size and rate, so each frame is one GIF frame."""
    palette.PALETTE_BITS = bits
    h, w = frames[0].shape[:2]
    video = dataclasses.replace(scene.video, width=w, height=h, gif_width=w, fps=gif.rate(scene.video),
                                formats=("gif",))
    enc = encode.Encoder(out, f"{bits}", video, len(frames))
    start = time.perf_counter()
    for k, f in enumerate(frames):
        enc.write(f)
        time.sleep(max(0.0, start + (k + 1) / rate - time.perf_counter()))
    t = time.perf_counter()
    enc.close()
    return time.perf_counter() - t


def distinct(frames: np.ndarray, mask: int, centre: int) -> int:
    """How many colours the frames hold once cut (mask 0xFF, centre 0: uncut)."""
    c = ((frames & mask) | centre).reshape(-1, 3).astype(np.uint32)
    return len(np.unique((c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]))


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    return float(10 * np.log10(255.0 ** 2 / np.mean((a.astype(np.float64) - b) ** 2)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--bits", type=int, nargs="+", default=[8, 7, 6])
    ap.add_argument("--rate", type=float, default=50.0, help="frames per second fed to ffmpeg (default 50)")
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args(argv)
    scene, frames = gif_frames(args.preset)
    raw = np.stack(frames)
    colours = {b: distinct(raw, *palette.palette_cut(b)) for b in args.bits}
    waits = {b: [] for b in args.bits}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            for b in args.bits:
                waits[b].append(tail(scene, frames, b, args.rate, Path(tmp)))
        print(f"{args.preset}: {len(frames)} GIF frames of {raw.shape[2]}x{raw.shape[1]}, fed at {args.rate:g}/s")
        print("| bits | distinct colours | wait after the last frame, s (rounds) | MB | PSNR dB | clock corner dB |")
        print("|---:|---:|---|---:|---:|---:|")
        for b in args.bits:
            back = iio.imread(Path(tmp) / f"{b}.gif")[..., :3]
            mb = (Path(tmp) / f"{b}.gif").stat().st_size / 1e6
            rounds = ", ".join(f"{w:.2f}" for w in waits[b])
            print(f"| {b} | {colours[b]:,} | {statistics.median(waits[b]):.2f} ({rounds}) | {mb:.2f} | "
                  f"{psnr(back, raw):.2f} | {psnr(back[(slice(None), *CORNER)], raw[(slice(None), *CORNER)]):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
