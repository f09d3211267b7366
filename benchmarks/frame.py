"""One frame of a preset as a PNG: the frame `pendulum render` would encode at that time (pipeline.Source,
the certificate included), for the README's figures.

    .venv/bin/python benchmarks/frame.py PRESET --at SECONDS [--size 640x360] [--colours 256] [--set KEY=VALUE]...
                                         --out FILE.png

The video keeps its duration (the HUD's time axis and the certificate are the whole video's); only the
frames up to --at are simulated and drawn. The PNG is saved with a palette of --colours colours (Pillow's
octree; 0 keeps every colour), which keeps a README figure near 50 KB instead of 180 KB.
"""
import argparse
import io
import os
import sys
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from PIL import Image  # noqa: E402

from render.video import pipeline  # noqa: E402
from render.video.atomic import write_atomic  # noqa: E402
from render.config.scene import load  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset")
    ap.add_argument("--at", type=float, required=True, help="simulated time of the frame, in seconds")
    ap.add_argument("--size", default="640x360", help="WIDTHxHEIGHT (default 640x360)")
    ap.add_argument("--colours", type=int, default=256, help="palette size of the PNG, 0: all (default 256)")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    w, h = args.size.split("x")
    src = pipeline.Source(load(args.preset, [f"video.width={w}", f"video.height={h}", *args.overrides]))
    index = min(round(args.at * src.scene.video.fps), src.frames - 1)
    frame = None
    for _ in range(index + 1):
        frame = src.next_frame()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    image = Image.fromarray(frame)
    if args.colours:
        image = image.quantize(args.colours, method=Image.Quantize.FASTOCTREE)
    buf = io.BytesIO()
    image.save(buf, "PNG", optimize=True)
    write_atomic(args.out, buf.getvalue())
    print(f"{args.out}: {src.name} at t = {index / src.scene.video.fps:g} s, {args.out.stat().st_size} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
