"""Where a parallel loop stops paying: a system's advance and energy kernels run serially or on the thread pool.

    .venv/bin/python benchmarks/serial_loops.py [--system rigid] [--precision f64] [--substeps 17] [--rounds 5]

For each fan size N, the median over rounds of the µs per launch (synchronised, 200 launches a round) of the
advance kernel (`substeps` RK4 steps of every pendulum) and the energy kernel, with their loop on the launching
thread (serial) and on Taichi's thread pool (parallel); the two variants alternate in each round.
render/physics/runtime.py's SERIAL_WORK (pendulum-steps below which a loop runs serially) rests on this.
Each variant gives the same bits: only which thread steps a pendulum changes.
"""
import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import taichi as ti  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.physics.stepper import Run  # noqa: E402

PRESETS = {"rigid": "rigid_chaos", "elastic": "elastic_fan", "triple": "triple_chaos"}


def per_launch(fn, launches: int = 200) -> float:
    ti.sync()
    t = time.perf_counter()
    for _ in range(launches):
        fn()
    ti.sync()
    return (time.perf_counter() - t) / launches * 1e6


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--system", choices=sorted(PRESETS), default="rigid")
    ap.add_argument("--precision", choices=("f32", "f64"), default="f64")
    ap.add_argument("--substeps", type=int, default=17, help="steps per advance (rigid_chaos: 17)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--sizes", type=int, nargs="+", default=[16, 64, 100, 256, 1000, 4000, 16000])
    args = ap.parse_args(argv)
    print(f"{args.system} {args.precision}, {args.substeps} substeps, µs per launch (median of {args.rounds}):")
    print("N | pendulum-steps | advance serial | advance parallel | energy serial | energy parallel")
    for n in args.sizes:
        scene = load(PRESETS[args.system], [f"pendulums.count={n}", f"integrator.precision={args.precision}",
                                            'effects=["energy"]'])
        sim = Run(scene, "cpu").sim
        sim.measure_energy(first=True)
        kinds = {(k, serial): fn for serial in (True, False) for k, fn in (
            ("advance", lambda s=serial: sim.advance(args.substeps, sim.h, s)),
            ("energy", lambda s=serial: sim.energies(0, s)))}
        times = {key: [] for key in kinds}
        for fn in kinds.values():
            fn()  # compiles
        for _ in range(args.rounds):
            for key, fn in kinds.items():
                times[key].append(per_launch(fn))
        med = {key: statistics.median(v) for key, v in times.items()}
        print(f"{n} | {n * args.substeps} | {med['advance', True]:.0f} | {med['advance', False]:.0f} | "
              f"{med['energy', True]:.0f} | {med['energy', False]:.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
