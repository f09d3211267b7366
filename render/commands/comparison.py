"""`pendulum compare PRESET --vary KEY=V1,V2[,...] [--vary ...] [--set ...]`: one split-screen video of 2 to 4
variants of a preset, from the same initial states, into OUT/compare/NAME/.

The variants become the scene's [compare] table, so `pendulum compare` and `pendulum render` of a preset that
carries one make the same video (render/draw/split.py draws it). Several --vary are paired, not crossed: each
lists one value per panel, so one panel can change two keys at once (a method with its own step, for equal
cost); a 2x2 grid of two keys is four paired values each. The --vary lists are parsed as `batch --sweep`
parses its lists.

OUT/compare/NAME/ is the comparison as the preset states it: the preset's own [compare], or for a preset
without one the --vary given. Anything else (--set, --quality, or --vary replacing a preset's own [compare])
renders to OUT/compare/NAME__<short hash>/ unless --name names the folder, as `render` does.
"""
from __future__ import annotations

import argparse

from . import api
from ..config import budget
from ..config.options import add_render_options, budgeted, output_name, progress_wanted

EXAMPLES = """examples:
  pendulum compare rigid_chaos --vary integrator.precision=f32,f64
  pendulum compare rigid_chaos --vary integrator.method=symplectic_euler,rk2,rk4 --vary integrator.dt=2.5e-4,5e-4,1e-3 \\
    --set integrator.allow_unstable=true --set integrator.min_faithful=0
      # symplectic Euler's drift, shown on purpose: past its energy limit, and faithful for 0.63 s only
  pendulum compare elastic_fan --vary pendulums.stiffness=2e3,2e4 --set video.duration=8
  pendulum compare compare_methods            # a preset's own [compare] table

One shared clock across the top. Each panel is labelled with its variant, its integrator as run, its
cost (force evaluations per simulated second of a pendulum, as run; the wall time its simulation took is
in metadata.json, not in the frames, which stay the same bytes), its error: the largest difference of any
of its pendulums from the same pendulum of the finest variant (Δθ in rad, wrapped to at most π; springs: Δx
as a fraction of the total length), live, and when it parts from it by more than integrator.tolerance; and
until when its own certificate holds it faithful, the finest too: its clock turns amber then, and red once
half its pendulums are not. metadata.json records every variant's integrator, timings, certificate and
divergence time."""


def add_parser(sub):
    c = sub.add_parser("compare", help="one split-screen video of 2 to 4 variants of a preset (OUT/compare/NAME/)",
                       formatter_class=argparse.RawDescriptionHelpFormatter, epilog=EXAMPLES,
                       description="Simulate each variant of PRESET from the same initial states and encode them "
                                   "side by side (2) or 2x2 (3-4) as one MP4 and GIF, with a metadata.json, into "
                                   "OUT/compare/NAME/.")
    c.add_argument("preset", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    c.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2[,...]",
                   help="one value per panel (2 to 4) of a physics or integrator key: integrator.method, "
                        "integrator.dt, integrator.precision, quality, or under [pendulums] (lengths, masses, "
                        "gravity, damping, stiffness); repeat to vary keys together, paired value by value "
                        "(default: the preset's own [compare] table)")
    add_render_options(c)
    c.set_defaults(func=run)


def run(args) -> int:
    """As `pendulum render` runs (cli.cmd_render): the scene named for its folder, then the API's refusals
    and render, so the command and render.compare refuse alike."""
    given = api.load(args.preset, *args.overrides, quality=args.quality)
    scene = api.with_vary(given, args.vary)
    # A --vary replacing the preset's own comparison is an override like --set: OUT/compare/NAME/ keeps the
    # comparison the preset states.
    overridden = bool(args.overrides or args.quality or (given.compare and scene.compare != given.compare))
    scene = budgeted(output_name(scene, overridden, args.name), args)
    api.check_render([scene], args.out)
    budget.check_run([scene], args.out)  # the estimate, when over a minute: every panel's parts, summed
    print(api.render(scene, args.out, arch=args.arch, progress=progress_wanted(args), threads=args.threads).line())
    return 0
