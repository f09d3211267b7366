"""Is the certificate ever later than the truth? Each pendulum's certified faithful time against the time its run
really strays past the tolerance, the truth being RK4 in 80-bit long double at about 2e-5 s on the reference's own
equations (render/physics/reference.long_double).

    .venv/bin/python benchmarks/certificate_truth.py [PRESET] [--dt DT ...] [--truth-dt H] [--set KEY=VALUE]...

Per dt (default: the preset's): how many pendulums are over-claimed, the worst by how much, the first and median
faithful times on both sides, and the mean claim over the truth. The truth is computed once (rigid_chaos: 100
pendulums over 20 s, 7 minutes). A fan's angles only (the rigid and triple chains). At an exact equilibrium even long
double rounds tiny steps' changes away (seed_rigid's first pendulum, upright: docs/from-the-talk.md); --truth-dt
takes a longer step for it.
"""
import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.config.scene import load  # noqa: E402
from render.physics import reference  # noqa: E402
from render.trust import certify  # noqa: E402

TRUTH_DT = 2e-5


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--dt", type=float, action="append", default=[])
    ap.add_argument("--truth-dt", type=float, default=TRUTH_DT, help=f"the truth's step (default {TRUTH_DT:g} s)")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    base = load(args.preset, args.overrides)
    n, fps, duration = base.pendulums.count, base.video.fps, base.video.duration
    indices = np.arange(n)
    t0 = time.perf_counter()
    truth = reference.long_double(base, indices, args.truth_dt, base.frames)
    print(f"{args.preset}: the long-double truth (RK4, {args.truth_dt:g} s) for {n} pendulums over {duration:g} s in "
          f"{time.perf_counter() - t0:.0f} s", flush=True)
    for dt in args.dt or [None]:
        scene = base if dt is None else base.replace(integrator={"dt": dt})
        scene = scene.replace(integrator={"min_faithful": 0.0})
        cert = certify.certify(scene, indices=indices)
        main_run, _ = certify.trajectory(scene, indices, "cpu")
        strayed = np.abs(main_run - truth).max(-1) > scene.integrator.tolerance
        true_until = np.where(strayed.any(0), (strayed.argmax(0) - 1) / fps, duration)
        over = cert.until_s - true_until
        i = scene.integrator
        print(f"{i.method} dt={i.dt} {i.precision}: over-claimed {(over > 1e-9).sum()} of {n}, the worst by "
              f"{max(over.max(), 0):.3f} s | first {cert.faithful_until_s:.3f} / {true_until.min():.3f} s, median "
              f"{cert.median_until_s:.3f} / {np.median(true_until):.3f} s (certificate / truth) | mean claim / "
              f"truth {np.mean(cert.until_s / true_until):.3f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
