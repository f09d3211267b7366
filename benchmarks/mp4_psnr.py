"""How close a rendered MP4 decodes to the frames it was made from: PSNR over the whole frame and over the two
columns beside the pendulums' circle (the HUD's, which get x264's finer quantiser: render/video/mp4.py's roi).

    .venv/bin/python benchmarks/mp4_psnr.py PRESET --mp4 out/PRESET/PRESET.mp4 [--every K] [--set KEY=VALUE]...

The frames are drawn afresh (pipeline.Source, as `pendulum render` draws them), so pass the same --set as the
render. Prints the mean PSNR over every K-th frame (default 1) and the worst frame, in dB.
"""
import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import imageio.v3 as iio  # noqa: E402
import numpy as np  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.video import mp4, pipeline  # noqa: E402


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = float(((a.astype(np.float64) - b) ** 2).mean())
    return 10 * np.log10(255.0 ** 2 / max(mse, 1e-12))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset")
    ap.add_argument("--mp4", type=Path, required=True)
    ap.add_argument("--every", type=int, default=1)
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    src = pipeline.Source(load(args.preset, args.overrides))
    v = src.scene.video
    side = int((v.width - 2 * mp4.REACH * v.height) / 2)  # the columns roi() quantises finer
    whole, hud = [], []
    for f, decoded in enumerate(iio.imiter(args.mp4, plugin="FFMPEG")):
        frame = src.next_frame()
        if f % args.every == 0:
            whole.append(psnr(decoded, frame))
            if side > 0:
                hud.append(psnr(np.concatenate([decoded[:, :side], decoded[:, -side:]], 1),
                                np.concatenate([frame[:, :side], frame[:, -side:]], 1)))
    print(f"{args.mp4}: {len(whole)} frames, whole frame {np.mean(whole):.2f} dB (worst {min(whole):.2f})"
          + (f", HUD columns {np.mean(hud):.2f} dB (worst {min(hud):.2f})" if hud else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
