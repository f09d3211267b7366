"""Put measured figures into README.md: generated tables between markers, generated images in benchmarks/figures/.

    .venv/bin/python benchmarks/readme_figures.py [--out out]

`make figures` runs the commands that measure them first (see the Makefile). A README block

    <!-- generated: accuracy/quality.md -->
    ...
    <!-- end generated -->

is replaced by the file out/accuracy/quality.md as the last run wrote it, so no figure in the README is copied
by hand. Images listed in IMAGES are copied from out/ into benchmarks/figures/, which the README links.
"""
import argparse
import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "benchmarks" / "figures"
IMAGES = {  # out/<source> -> benchmarks/figures/<name>
    "accuracy/work_precision_rigid_chaos.png": "work_precision_rigid_chaos.png",
    "accuracy/faithful_rigid_chaos.png": "faithful_rigid_chaos.png",
    "figures/hud_rigid_chaos.png": "hud_rigid_chaos.png",  # benchmarks/frame.py: one frame, as render draws it
    "figures/glow_rainbow_1000.png": "glow_rainbow_1000.png",
    "figures/poincare_shell.png": "poincare_shell.png",
    "fractal_flip_readme/fractal_flip_readme.png": "fractal_flip.png",
    "figures/compare_precision.png": "compare_precision.png",  # benchmarks/compare_still.py
}
BLOCK = re.compile(r"(<!-- generated: (?P<src>[^ ]+) -->\n)(?P<body>.*?)(<!-- end generated -->)", re.S)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "out", help="where the commands wrote (default: out)")
    args = ap.parse_args()
    readme = (ROOT / "README.md").read_text()
    missing = []

    def fill(m):
        src = args.out / m["src"]
        if not src.is_file():
            missing.append(str(src))
            return m.group(0)
        return m.group(1) + src.read_text().rstrip() + "\n" + m.group(4)

    (ROOT / "README.md").write_text(BLOCK.sub(fill, readme))
    FIGURES.mkdir(parents=True, exist_ok=True)
    for src, name in IMAGES.items():
        if (args.out / src).is_file():
            shutil.copyfile(args.out / src, FIGURES / name)
        else:
            missing.append(str(args.out / src))
    if missing:
        print("not found (run the commands in `make figures` first):", *missing, sep="\n  ", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
