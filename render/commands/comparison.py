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
import dataclasses
from pathlib import Path

from . import batch
from ..trust import faithful
from ..video import pipeline
from ..errors import SceneError
from ..config.options import add_render_options, budgeted, check_out_folder, output_name, progress_wanted
from ..config.scene import from_dict, load, parse_override
from ..config.vary import VARIANTS, VARYING, vary_refusal

EXAMPLES = """examples:
  pendulum compare rigid_chaos --vary integrator.precision=f32,f64
  pendulum compare rigid_chaos --vary integrator.method=symplectic_euler,rk2,rk4 --vary integrator.dt=2.5e-4,5e-4,1e-3
    --set integrator.allow_unstable=true   # symplectic Euler's drift, shown on purpose: past its energy limit
  pendulum compare elastic_fan --vary pendulums.stiffness=2e3,2e4 --set video.duration=8
  pendulum compare compare_methods            # a preset's own [compare] table

One shared clock across the top. Each panel is labelled with its variant, its integrator as run, its
cost (wall time of its simulation per simulated second, measured), its error: the largest difference of any
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


def with_vary(scene, items: list[str]):
    """The scene with --vary as its [compare] table (validated as a preset's is), or its own table."""
    if not items:
        if not scene.compare:
            raise SceneError(f"{scene.source}: compare: the preset has no [compare] table; give --vary KEY=V1,V2 "
                             f"(e.g. --vary integrator.precision=f32,f64)")
        return scene
    for item in items:  # which keys may vary, before their values are parsed
        key = item.partition("=")[0].strip()
        batch.check_key(key, "--vary")
        why = vary_refusal(key)
        if why:
            raise SceneError(f"--vary {key}: cannot vary: {why}; {VARYING}")
    vary = {}
    for key, vals in batch.parse_sweeps(items, "--vary"):
        if key in vary:
            raise SceneError(f"--vary {key}: given twice; list every value in one --vary")
        lo, hi = VARIANTS
        if not lo <= len(vals) <= hi:
            raise SceneError(f"--vary {key}: {len(vals)} value(s); a comparison has {lo} to {hi} panels, one value "
                             f"each")
        if vary and len(vals) != len(next(iter(vary.values()))):
            first = next(iter(vary))
            raise SceneError(f"--vary {key}: {len(vals)} values and {first} has {len(vary[first])}: --vary lists "
                             f"are paired, one value per panel")
        vary[key] = [parse_override(f"{key}={raw}", "--vary")[1] for raw, _ in vals]
    return with_table(scene, vary)


def with_table(scene, vary: dict):
    """The scene with [compare] vary = `vary` (dotted key -> one value per panel), validated as a preset's."""
    raw = scene.to_dict()
    raw["compare"] = {"vary": vary}
    return dataclasses.replace(from_dict(raw, scene.source), overrides=scene.overrides)


def run(args) -> int:
    from ..config import budget

    given = load(args.preset, args.overrides, args.quality)
    scene = with_vary(given, args.vary)
    # A --vary replacing the preset's own comparison is an override like --set: OUT/compare/NAME/ keeps the
    # comparison the preset states.
    overridden = bool(args.overrides or args.quality or (given.compare and scene.compare != given.compare))
    scene = output_name(scene, overridden, args.name)
    check_out_folder(scene, args.out)
    out_dir = scene.out_dir(args.out)
    budget.check_run([budgeted(scene, args)], args.out)  # every panel's parts, summed
    meta = pipeline.render(scene, args.out, arch=args.arch, progress=progress_wanted(args), threads=args.threads)
    print(summary(meta, out_dir))
    return 0


def summary(meta: dict, out_dir: Path) -> str:
    """The comparison's line: each variant's cost, divergence and certificate, and where it went."""
    parts = []
    for i, v in enumerate(meta["compare"]["variants"]):
        if i == meta["compare"]["finest"]:
            how = "finest"
        else:
            how = "never parts" if v["divergence_s"] is None else f"parts at {v['divergence_s']:.2f} s"
        until = faithful.until(v["faithfulness"]["faithful_until_s"], meta["duration"])
        parts.append(f"{v['label'].removesuffix('  (finest)')}: {1e3 * v['cost_s_per_simulated_s']:.3g} ms/s, {how}, "
                     f"faithful until {until}")
    t = meta["timings_s"]
    return (f"{meta['preset']['name']}: {len(parts)} panels, {meta['frames']} frames {meta['width']}x{meta['height']}"
            f"@{meta['fps']} | " + " | ".join(parts) + f" | total {t['total']:.2f}s -> {out_dir}/")
