"""How long a preset's certificate takes once its kernels are compiled (render/trust/certify.py).

    .venv/bin/python benchmarks/certificate_time.py [PRESET] [--rounds 3] [--set KEY=VALUE]...

The first certify() in a process compiles or loads its kernels; each round after it clears the certificate's
in-process memo and certifies again, printing the wall time. To compare with an older commit, run it from a
worktree of that commit (`git worktree add /tmp/old COMMIT`, then `PYTHONPATH=/tmp/old` before this command).
"""
import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
if not os.environ.get("PYTHONPATH"):  # else the worktree named there is the one measured
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.config.scene import load  # noqa: E402
from render.trust import certify  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    scene = load(args.preset, args.overrides)
    certify.certify(scene)
    times = []
    for _ in range(args.rounds):
        certify._MEMO.clear()
        t = time.perf_counter()
        certify.certify(scene)
        times.append(time.perf_counter() - t)
    print(f"{args.preset} ({Path(certify.__file__).parent.parent}): certificate "
          + ", ".join(f"{s:.3f}" for s in times) + " s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
