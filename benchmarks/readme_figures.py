"""Put measured figures into the docs: generated tables between markers, generated images in benchmarks/figures/.

    .venv/bin/python benchmarks/readme_figures.py [--out out]

`make figures` runs the commands that measure them first (see the Makefile). A block, in README.md or any
page docs/*.md,

    <!-- generated: accuracy/quality.md -->
    ...
    <!-- end generated -->

is replaced by the file out/accuracy/quality.md as the last run wrote it, so no figure in the docs is copied
by hand, and a block moved to another page is still filled there. Images listed in IMAGES are copied from
out/ into benchmarks/figures/, which the pages link by relative paths (../benchmarks/figures/ from docs/).
"""
import argparse
import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
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


def pages(root: Path = ROOT) -> list[Path]:
    """The pages that may hold generated blocks: README.md and docs/*.md."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md"))]


def splice(text: str, out: Path) -> tuple[str, list[str], list[str]]:
    """(text with each block's body replaced by out/<src>, the sources filled, the sources not found).
    A block whose source is missing keeps its old body."""
    filled, missing = [], []

    def fill(m):
        src = out / m["src"]
        if not src.is_file():
            missing.append(str(src))
            return m.group(0)
        filled.append(m["src"])
        return m.group(1) + src.read_text().rstrip() + "\n" + m.group(4)

    return BLOCK.sub(fill, text), filled, missing


def main(argv=None, root: Path = ROOT) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=root / "out", help="where the commands wrote (default: out)")
    args = ap.parse_args(argv)
    missing = []
    for page in pages(root):
        text = page.read_text()
        new, filled, lost = splice(text, args.out)
        missing += lost
        if new != text:
            page.write_text(new)
        for src in filled:
            print(f"{page.relative_to(root)}: {src}")
    figures = root / "benchmarks" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for src, name in IMAGES.items():
        if (args.out / src).is_file():
            shutil.copyfile(args.out / src, figures / name)
        else:
            missing.append(str(args.out / src))
    if missing:
        print("not found (run the commands in `make figures` first):", *missing, sep="\n  ", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
