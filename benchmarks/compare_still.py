"""One frame of a comparison as a PNG, for the README (`make figures` runs it):

    .venv/bin/python benchmarks/compare_still.py [--preset compare_precision] [--at 7] [--out out]

draws PRESET's split screen at 640x360 (the preset's fps and scene) up to --at seconds, exactly as
`pendulum render` would draw it at that size, and writes that frame to OUT/figures/PRESET.png as a
256-colour PNG (line art on black loses nothing visible; RGB would be 3x the size).
"""
import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from PIL import Image  # noqa: E402  (here only, for the palette: renders never need Pillow)

from render.video import pipeline  # noqa: E402
from render.config.scene import load  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="compare_precision")
    ap.add_argument("--at", type=float, default=7.0, help="the frame's time in s (default: 7)")
    ap.add_argument("--out", type=Path, default=ROOT / "out")
    args = ap.parse_args()
    scene = load(args.preset, ["video.width=640", "video.height=360", f"video.duration={args.at + 0.5}"])
    src = pipeline.open_source(scene)
    target = round(args.at * scene.video.fps)
    for _ in range(target + 1):
        frame = src.next_frame()
    path = args.out / "figures" / f"{args.preset}.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(frame).quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(
        path, "PNG", optimize=True)
    print(f"{path}: frame {target} (t = {target / scene.video.fps:g} s), {path.stat().st_size / 1e3:.0f} kB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
