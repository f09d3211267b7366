"""What x264's speed presets trade: CPU, bytes and PSNR, each encoding a render's own frames with the render's
own arguments (render/video/mp4.py's args: its threads and regions of interest), only the preset and crf swapped.

    .venv/bin/python benchmarks/x264_presets.py [PRESET] [--x264 veryfast:32 superfast:33 ...] [--rounds 2]
                                                [--out DIR] [--set KEY=VALUE]...

Draws the preset's frames (pipeline.Source, as `pendulum render` draws them) and converts them as a render does
(render/video/yuv.py) into a raw yuv420p file in DIR (default out/x264_presets). Then ffmpeg encodes an MP4 from
it for each PRESET:CRF in turn, --rounds times over (the settings interleaved, so a load that comes and goes
falls on all of them), and prints each encode's wall time and ffmpeg's user CPU, and once per setting the MP4's
bytes and its PSNR against the raw frames (ffmpeg's psnr filter: the mean over Y, Cb and Cr, and Y alone). The
raw file (1.7 GB for rigid_chaos) and the MP4s are deleted at the end.
"""
import argparse
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import imageio_ffmpeg  # noqa: E402

from render.video import mp4 as mp4_settings, yuv  # noqa: E402
from yuv_pipe import planar_source  # noqa: E402  (this script's folder is on the path)

SETTING = re.compile(r"(ultrafast|superfast|veryfast|faster|fast|medium):(\d{1,2})")


def x264_args(video, preset: str, crf: str) -> list[str]:
    """The render's MP4 arguments with x264's preset and crf swapped."""
    args = mp4_settings.args(video)
    args[args.index("-preset") + 1], args[args.index("-crf") + 1] = preset, crf
    return args


def raw_args(raw: Path, video) -> list[str]:
    return ["-f", "rawvideo", "-pix_fmt", "yuv420p", "-s", f"{video.width}x{video.height}", "-r", str(video.fps),
            "-i", str(raw)]


def encode(raw: Path, video, preset: str, crf: str, mp4: Path) -> tuple[float, float]:
    """(wall s, ffmpeg's user CPU s) for one MP4 from the raw file."""
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-y", "-loglevel", "error", *raw_args(raw, video),
           "-an", *x264_args(video, preset, crf), str(mp4)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    t = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def psnr(raw: Path, video, mp4: Path) -> tuple[float, float]:
    """(mean PSNR over the planes, Y's) of the decoded MP4 against the raw frames, dB."""
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", *raw_args(raw, video), "-i", str(mp4),
           "-lavfi", "[1:v][0:v]psnr", "-f", "null", "-"]
    log = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    line = [s for s in log.splitlines() if "PSNR y:" in s][-1]
    return float(re.search(r"average:([\d.]+)", line)[1]), float(re.search(r"PSNR y:([\d.]+)", line)[1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--x264", nargs="+", default=["veryfast:32", "superfast:32", "superfast:33", "superfast:34"],
                    metavar="PRESET:CRF", help="x264 settings to compare (default: %(default)s)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("out/x264_presets"))
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    settings = [SETTING.fullmatch(s) for s in args.x264]
    if not all(settings) or args.rounds < 1:
        bad = [s for s, m in zip(args.x264, settings) if not m]
        print(f"--x264 takes PRESET:CRF, e.g. superfast:33 (not {' '.join(bad)}); --rounds at least 1",
              file=sys.stderr)
        return 2
    src = planar_source(args.preset, args.overrides)
    if src is None:
        return 2
    v = src.scene.video
    args.out.mkdir(parents=True, exist_ok=True)
    raw = args.out / "frames.yuv"
    mp4s = {m[0]: args.out / f"{m[1]}_{m[2]}.mp4" for m in settings}
    try:
        with open(raw, "wb") as planar:
            for _ in range(src.frames):
                planar.write(yuv.convert(src.next_frame()).data)
        print(f"{args.preset}: {src.frames} frames of {v.width}x{v.height}, x264 "
              f"{' '.join(mp4_settings.x264_threads()) or 'on its own threads'}")
        for r in range(args.rounds):
            for m in settings:
                wall, cpu = encode(raw, v, m[1], m[2], mp4s[m[0]])
                print(f"round {r + 1}, {m[0]}: {wall:.2f} s wall, {cpu:.2f} s user CPU")
        for m in settings:
            mean, luma = psnr(raw, v, mp4s[m[0]])
            print(f"{m[0]}: {mp4s[m[0]].stat().st_size / 1e6:.2f} MB, PSNR {mean:.2f} dB (Y {luma:.2f})")
    finally:
        for p in (raw, *mp4s.values()):
            p.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
