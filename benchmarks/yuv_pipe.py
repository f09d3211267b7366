"""What converting a render's frames to yuv420p before the MP4's pipe (render/video/yuv.py) costs and saves.

    .venv/bin/python benchmarks/yuv_pipe.py [PRESET] [--rounds 2] [--out DIR] [--convert-only] [--set KEY=VALUE]...

Draws the preset's frames (pipeline.Source, as `pendulum render` draws them) into a raw rgb24 file in DIR
(default out/yuv_pipe), timing yuv.convert on each, as a render calls it (with the canvas's lit tiles, which
it does not read where they are dark) and without them, in alternating order, and checking that both give the
same bytes; writes the converted frames beside them. Then ffmpeg encodes the MP4 from each file with the
render's own x264 arguments (mp4.args), rgb24 and yuv420p alternating for --rounds rounds, and prints each
encode's wall time and ffmpeg's user CPU. The raw files (3.3 GB and 1.7 GB for rigid_chaos) and the MP4s are
deleted at the end. --convert-only times the conversion and writes no file; --evict MB writes that many MB of
another array before each conversion, so that it reads the frame from memory, not from the cache.
"""
import argparse
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import imageio_ffmpeg  # noqa: E402
import numpy as np  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.video import mp4 as mp4_settings, pipeline, yuv  # noqa: E402


def encode_file(raw: Path, pix_fmt: str, video, mp4: Path) -> tuple[float, float]:
    """(wall s, ffmpeg's user CPU s) for one MP4 from a raw file."""
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo",
           "-pix_fmt", pix_fmt, "-s", f"{video.width}x{video.height}", "-r", str(video.fps), "-i", str(raw),
           "-an", *mp4_settings.args(video), str(mp4)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    t = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def planar_source(preset: str, overrides: list[str]):
    """The preset's frames as `pendulum render` draws them (pipeline.Source), or None, with one line on stderr,
    where yuv.convert cannot take frames of its size. benchmarks/x264_presets.py draws its frames here too."""
    src = pipeline.Source(load(preset, overrides))
    v = src.scene.video
    if not yuv.fits(v.width, v.height):
        print(f"{v.width}x{v.height}: yuv.convert needs a width divisible by 4 and an even height", file=sys.stderr)
        return None
    return src


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("out/yuv_pipe"))
    ap.add_argument("--evict", type=int, default=0, metavar="MB", help="MB written before each conversion")
    ap.add_argument("--convert-only", action="store_true", help="time the conversion only: no files, no ffmpeg")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    src = planar_source(args.preset, args.overrides)
    if src is None:
        return 2
    v = src.scene.video
    args.out.mkdir(parents=True, exist_ok=True)
    raw = {"rgb24": args.out / "frames.rgb", "yuv420p": args.out / "frames.yuv"}
    ms = {"every tile": [], "the lit tiles": []}
    other = np.zeros(args.evict << 20, np.uint8)
    try:
        with open(os.devnull if args.convert_only else raw["rgb24"], "wb") as rgb, \
                open(os.devnull if args.convert_only else raw["yuv420p"], "wb") as planar:
            for f in range(src.frames):
                frame = src.next_frame()
                lit = src.lit_tiles()
                out = {}
                for name in sorted(ms, reverse=f % 2 == 1):  # alternating, so neither always finds it cached
                    other += 1
                    t = time.perf_counter()
                    out[name] = yuv.convert(frame, lit if name == "the lit tiles" else None)
                    if f >= 2:  # frames 0 and 1 instantiate the kernel
                        ms[name].append(1e3 * (time.perf_counter() - t))
                if not np.array_equal(out["every tile"], out["the lit tiles"]):
                    print(f"frame {f}: the conversion of the lit tiles differs from the whole one", file=sys.stderr)
                    return 1
                rgb.write(frame.data)
                planar.write(out["every tile"].data)
        for name, times in ms.items():
            q = np.percentile(times, [50, 10, 90])
            print(f"{args.preset}: {src.frames} frames of {v.width}x{v.height}; yuv.convert reading {name} "
                  f"{q[0]:.2f} ms a frame (median; 10th-90th percentile {q[1]:.2f}-{q[2]:.2f}), "
                  f"{sum(times) / 1e3:.2f} s in all")
        if args.convert_only:
            return 0
        mp4 = args.out / "out.mp4"
        for r in range(args.rounds):
            for fmt in ("rgb24", "yuv420p"):
                wall, cpu = encode_file(raw[fmt], fmt, v, mp4)
                print(f"round {r + 1}, ffmpeg from {fmt}: {wall:.2f} s wall, {cpu:.2f} s user CPU")
    finally:
        for p in (*raw.values(), args.out / "out.mp4"):
            p.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
