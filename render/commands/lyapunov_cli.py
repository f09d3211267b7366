"""`pendulum lyapunov PRESET [--set ...] [--pendulums I,J,...] [--out DIR]`: the Lyapunov spectrum of chosen
pendulums (render/trust/lyapunov.py), printed, and written to OUT/NAME/lyapunov.json with lyapunov.png, the chart
of the running estimates. OUT/NAME/ is the preset as written; with --set it is OUT/NAME__<short hash>/, as
for `render`."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import SceneError
from ..config import budget
from ..config.options import (add_budget, add_common, budgeted, check_out_folder, output_name, progress_wanted,
                              out_path, thread_count)

FILES = ("lyapunov.png", "lyapunov.json")  # what it writes into OUT/NAME/

EPILOG = """examples:
  pendulum lyapunov classic
  pendulum lyapunov classic --set video.duration=200 --set video.fps=20
  pendulum lyapunov damped_heavy --pendulums 0,15,29
  pendulum lyapunov triple_classic --set integrator.dt=5e-4

The spectrum (1/s) is measured over the preset's video.duration in f64 with its integrator: 2D tangent
vectors per pendulum in canonical (q, p) ride along the state through the exact tangent map of the
numerical flow (Taichi forward-mode AD of one frame of the integrator) and are re-orthonormalised by QR
every frame (Benettin). Each exponent is printed with its error: 2 standard errors by batch means of the
per-frame log growth rates over the run's last half, plus how far the running average moved over it (the
start's 1/t bias). Checks: the sum of the exponents is -D*c at any duration (c = pendulums.damping, D the
coordinates; 0 undamped), and each pair λ_i + λ_(2D+1-i) tends to -c. λ1 predicts how long a render stays
true: ln(tolerance / e0) / λ1 from the error e0 after the first frame, printed beside the faithful time the
certificate measures. Default pendulums: the certificate's, thinned to 8."""


def indices(text: str) -> list[int]:
    """An argparse type: comma-separated pendulum indices."""
    parts = [p.strip() for p in text.split(",")]
    if not parts or not all(p.isascii() and p.isdigit() and len(p) <= 18 for p in parts):
        raise argparse.ArgumentTypeError(f"must be pendulum indices separated by commas (e.g. 0,3,7), "
                                         f"got {text[:40]!r}")
    return [int(p) for p in parts]


def add_parser(sub):
    p = sub.add_parser("lyapunov", help="the Lyapunov spectrum of chosen pendulums (OUT/NAME/lyapunov.json)",
                       formatter_class=argparse.RawDescriptionHelpFormatter, epilog=EPILOG,
                       description="Measure the full Lyapunov spectrum (2D exponents: 4 for a double pendulum, 6 "
                                   "for the triple, 8 for the elastic one) of chosen pendulums of PRESET; print "
                                   "each with its error and checks, and write lyapunov.json and lyapunov.png "
                                   "into OUT/NAME/ (OUT/NAME__<hash>/ with --set, OUT/compare/NAME/ for a "
                                   "comparison's preset).")
    p.add_argument("preset", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    add_common(p)
    add_budget(p)
    p.add_argument("--pendulums", type=indices, metavar="I,J,...",
                   help="which pendulums, by index in the fan (default: the certificate's, at most 8)")
    p.add_argument("--out", type=out_path, default=Path("out"), help="output root (default: out)")
    p.add_argument("--threads", type=thread_count, default=None, help="CPU threads for Taichi (default: all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    from . import charts
    from ..trust import lyapunov
    from ..video.atomic import together, write_atomic
    from ..config.scene import load

    scene = budgeted(output_name(load(args.preset, args.overrides), bool(args.overrides)), args)
    pendulums = lyapunov.chosen(scene, args.pendulums)
    lyapunov.check(scene, pendulums)
    est = lyapunov.seconds(scene, pendulums)
    if est > budget.limit_s(scene):  # refused before it starts, as a render over its budget is
        limit = budget.duration(budget.limit_s(scene))
        raise SceneError(f"{scene.source}: video.duration: the spectrum is estimated at {budget.duration(est)} "
                         f"({scene.frames} frames), over the run-time budget of {limit}; use a shorter "
                         f"video.duration or a lower video.fps, or {budget.raise_by(est)}")
    check_out_folder(scene, args.out, FILES)  # a file, a symlink or a folder where these go: before the work
    out_dir = scene.out_dir(args.out)
    doc, run_ = lyapunov.measure(scene, pendulums, args.arch, args.threads, progress_wanted(args))
    png, js = (out_dir / f for f in FILES)
    with together(out_dir):  # the chart only with its numbers
        charts.lyapunov_chart(png, run_["t"], run_["running"], [int(i) for i in pendulums], scene.name,
                              doc["pendulums"][0]["checks"]["expected_sum"])
        write_atomic(js, json.dumps(doc, indent=2) + "\n")
    for row in doc["pendulums"]:
        print(line(row))
    print(f"{scene.name}: {len(pendulums)} pendulum(s), {doc['pendulums'][0]['duration_s']:g} s, "
          f"{doc['method']['integrator']} dt={doc['method']['dt']:.3g} s -> {out_dir}/lyapunov.json")
    return 0


def line(row: dict) -> str:
    """One pendulum's spectrum, its checks and what λ1 predicts."""
    lam = ", ".join(f"{x:+.4f} ± {e:.4f}" for x, e in zip(row["exponents"], row["errors"]))
    c, f = row["checks"], row["faithfulness"]
    pairs = ", ".join(f"{s:+.2e} ± {e:.1e}" for s, e in zip(c["pair_sums"], c["pair_errors"]))
    pred = "—" if f["predicted_horizon_s"] is None else f"{f['predicted_horizon_s']:.2f} s"
    until = f"{f['faithful_until_s']:.2f} s" + (" (the end)" if f["faithful_through_the_end"] else "")
    return (f"pendulum {row['pendulum']}: λ = {lam} 1/s | sum {c['sum']:+.3e} (expected {c['expected_sum']:+g}) | "
            f"pairs {pairs} (tending to {c['expected_pair_sum']:+g}) | λ1 predicts faithful for {pred}, the "
            f"certificate measures {until}")
