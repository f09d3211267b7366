"""The Python API: `load`, `render`, `simulate`, `compare` and `load_map`. The CLI is a thin layer over it.

Every check the command line makes before any work lives here, so a notebook gets the same refusals as a
shell: bad input raises SceneError (the CLI's exit 2) before anything is written, a failure while running
raises SimulationError or EncodeError (exit 1), the file system's errors are OSErrors naming the file.

    import render
    scene = render.load("classic", **{"video.duration": 2}, video={"width": 640, "height": 360})
    result = render.render(scene, out="out")      # a RenderResult: paths, metadata, certificate
    traj = render.simulate(scene)                 # a Trajectory: t, theta/omega or pos/vel, energy
    both = render.compare("rigid_chaos", vary={"integrator.precision": ["f32", "f64"]})  # a split screen
    pixels = render.load_map("out/fractal_flip")  # a map's NAME.npz: its pixels' flip times, mask, axes
"""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from ..config import budget, scene as scenes
from . import batch_plan
from ..video import pipeline
from ..physics import registry
from ..errors import SceneError
from ..config.options import (check_arch, check_npz, check_out, check_out_folder, check_threads, check_tiles,
                              usable_cores)
from ..config.checks import clip
from ..config.vary import VARIANTS, VARYING, vary_refusal
from .results import RenderResult, Trajectory


def load(preset: str | os.PathLike, /, *settings: str, quality: str | None = None, **overrides) -> scenes.Scene:
    """The frozen, validated Scene of a preset (a name on the preset search path, or a .toml file).

    Overrides are dotted keys, `load("classic", **{"video.duration": 2})`, or nested dicts,
    `load("classic", video={"duration": 2})`; `settings` are strings as `--set` takes them
    ("video.duration=2", the value in TOML). `quality` is a --quality level (draft, standard, high, reference).
    """
    for setting in settings:
        if not isinstance(setting, str):
            raise SceneError(f"load({preset!r}, {clip(repr(setting))}): settings are strings as --set takes them, "
                             f"'KEY=VALUE'; give other values as keywords, load(..., video={{'fps': 30}})")
    values = {}
    for key, value in overrides.items():
        _flatten(key, value, values)
    return scenes.load(os.fspath(preset), settings, quality, values)


def _flatten(key: str, value, out: dict) -> None:
    """video={"duration": 2} -> out["video.duration"] = 2; numpy scalars and arrays, tuples as plain TOML
    values (the validator checks types as TOML gives them)."""
    if not isinstance(key, str):
        raise SceneError(f"{clip(repr(key))}: not a key name (a key is a string, 'integrator.dt')")
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(f"{key}.{k}", v, out)
        return
    if key in out:  # {"video.fps": 30, "video": {"fps": 60}}: neither may silently win
        raise SceneError(f"{key}: given twice (once dotted, once in a nested dict); give it once")
    out[key] = _plain(value, key)


def _plain(value, key: str):
    if hasattr(value, "tolist") and callable(value.tolist):  # numpy scalar or array
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v, key) for v in value]
    if not isinstance(value, (bool, int, float, str)):  # what TOML holds; the validator judges the rest
        raise SceneError(f"{key}={clip(repr(value))}: must be a number, a string, a boolean or a list of them")
    return value


def check_flag(value, name: str) -> bool:
    """The API's progress=: a bool, as the CLI's --no-progress is one (a string "no" would be true)."""
    if not isinstance(value, bool):
        raise SceneError(f"{name}={clip(repr(value))}: must be True or False")
    return value


def _scene(scene) -> scenes.Scene:
    return scene if isinstance(scene, scenes.Scene) else load(scene)


def check_panels(scene) -> None:
    """Refuse a comparison whose panels, under the shared clock's band (render/draw/split.py's layout), would
    be smaller than a video may be: found only once every variant had been simulated, before."""
    from ..draw.split import layout
    from ..config.vary import PANEL_MIN
    v = scene.video
    rects = layout(v.width, v.height, len(scene.compare[0][1]))
    w, h = min(r[2] for r in rects), min(r[3] for r in rects)
    for key, size, side, way in (("width", v.width, w, "wide"), ("height", v.height, h, "high")):
        if side < PANEL_MIN:
            raise SceneError(f"{scene.source}: video.{key}: {size} px leaves panels {side} px {way} beside the "
                             f"shared clock; each needs at least {PANEL_MIN}: use a larger video")


def check_render(scene_list, out: Path, tiled: str | None = None, files: tuple[str, ...] | None = None) -> None:
    """Refuse (SceneError) before any work: an output that cannot be written (options.check_out_folder, with
    its `files`), a scene over the budget, or with `tiled` (the option asking for it) one that cannot be
    rendered in tiles. Every command that renders or plays a scene (render, batch, compare, show) asks this."""
    out = Path(out)
    for scene in scene_list:
        if scene.compare:
            check_panels(scene)
        if tiled:
            from ..video import tiled as tiling
            tiling.check(scene, tiled)
        check_out_folder(scene, out, files)
        if scene.has("lyapunov"):  # an integrator with no tangent map, too few frames for the error
            from ..trust import lyapunov
            lyapunov.check(scene, lyapunov.default_pendulums(scene))
        budget.check(scene, registry.get(scene.system), out)


def render(scene, out: str | os.PathLike = "out", *, arch: str = "cpu", threads: int | None = None,
           progress: bool = False, scheduler: str | None = None, tiles: int | None = None) -> RenderResult:
    """Render a Scene (or a preset name) into OUT/NAME/: MP4 and GIF as the scene's formats say, and
    metadata.json. Returns the paths, the metadata and the faithfulness certificate.

    A map in tiles on Dask, the same bytes: `scheduler` (an address, as --scheduler takes it) and `tiles`
    bands (default: one per worker thread), or `tiles` alone: that many bands on a local cluster of as many
    worker processes (at most one a core), which share the cores."""
    from ..video import tiled

    scene = _scene(scene)
    arch, threads, out = check_arch(arch), check_threads(threads), check_out(out)
    progress = check_flag(progress, "progress")
    if scheduler is not None and not isinstance(scheduler, str):
        raise SceneError(f"scheduler={clip(repr(scheduler))}: must be an address string, as --scheduler takes it")
    address, tiles = tiled.scheduler_address(scheduler), check_tiles(tiles)
    how = "--scheduler" if address else "--tiles" if tiles else None
    check_render([scene], out, how)
    if not how:
        meta = pipeline.render(scene, out, arch=arch, progress=progress, threads=threads)
    else:
        cores = usable_cores()
        workers = None if address else min(tiles, cores)
        if workers and threads is None:
            threads = max(1, cores // workers)
        with tiled.cluster(address, workers) as client:
            meta = pipeline.render(scene, out, arch=arch, progress=progress, threads=threads, cluster=client,
                                   bands=tiles)
    return RenderResult(scene, scene.out_dir(out), meta)


def simulate(scene, out: str | os.PathLike | None = None, *, arch: str = "cpu",
             progress: bool = False) -> Trajectory:
    """Simulate a Scene (or a preset name) without drawing: the state at every frame time, as the .npz of
    `pendulum simulate` holds it. Nothing is written unless `out` names a .npz file."""
    scene, arch, progress = _scene(scene), check_arch(arch), check_flag(progress, "progress")
    out = check_out(out) if out is not None else None
    if out is not None:
        check_npz(out, scene.name)
    budget.check(scene, registry.get(scene.system), out.parent if out is not None else None, simulate=True)
    try:
        info = pipeline.simulate(scene, out, arch=arch, progress=progress)
    except OSError as e:  # e.g. a full disk while writing: numpy's error does not say which file
        if out is not None and e.filename is None and e.strerror:
            raise OSError(e.errno, e.strerror, str(out)) from e
        raise
    return Trajectory(scene, info.pop("arrays", {}), info, out)


def compare(scene, vary: dict | str | list[str] | None = None, out: str | os.PathLike = "out", *, arch: str = "cpu",
            threads: int | None = None, progress: bool = False) -> RenderResult:
    """The split-screen comparison `pendulum compare` renders: `vary` maps dotted keys to one value per panel
    (2 to 4), paired key by key, e.g. {"integrator.precision": ["f32", "f64"]}, or is what --vary takes,
    "integrator.precision=f32,f64", or a list of those; without it, the preset's own [compare] table.
    Writes OUT/compare/NAME/; the result's metadata has every variant under "compare"."""
    scene = _scene(scene)
    check_arch(arch)  # before the variants are built
    check_threads(threads)
    if isinstance(vary, str):
        vary = [vary]
    if isinstance(vary, dict) and not vary:
        raise SceneError("vary={}: give each key to vary with its values, {KEY: [V1, V2]}, or leave vary out for the "
                         "preset's own [compare] table")
    if isinstance(vary, dict):
        values = {}
        for key, val in vary.items():
            _flatten(key, val, values)
        scene = with_table(scene, values)
    elif isinstance(vary, (list, tuple)) and all(isinstance(v, str) for v in vary):  # [] as no --vary
        scene = with_vary(scene, list(vary))
    elif vary is not None:
        raise SceneError(f"vary={type(vary).__name__}: must be a dict {{KEY: [V1, V2]}}, a string 'KEY=V1,V2' as "
                         f"--vary takes it, or a list of such strings")
    elif not scene.compare:
        raise SceneError(f"{scene.source}: compare: the preset has no [compare] table; give vary={{KEY: [V1, V2]}}")
    return render(scene, out, arch=arch, threads=threads, progress=progress)


def with_vary(scene, items: list[str]):
    """The scene with --vary items ("KEY=V1,V2", as `pendulum compare` and compare(vary=) take them) as its
    [compare] table, validated as a preset's is; without any, its own table."""
    if not items:
        if not scene.compare:
            raise SceneError(f"{scene.source}: compare: the preset has no [compare] table; give --vary KEY=V1,V2 "
                             f"(e.g. --vary integrator.precision=f32,f64)")
        return scene
    for item in items:  # which keys may vary, before their values are parsed
        key = item.partition("=")[0].strip()
        batch_plan.check_key(key, "--vary")
        why = vary_refusal(key)
        if why:
            raise SceneError(f"--vary {key}: cannot vary: {why}; {VARYING}")
    vary = {}
    for key, vals in batch_plan.parse_sweeps(items, "--vary", distinct=False):
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
        vary[key] = [scenes.parse_override(f"{key}={raw}", "--vary")[1] for raw, _ in vals]
    return with_table(scene, vary)


def with_table(scene, vary: dict):
    """The scene with [compare] vary = `vary` (dotted key -> one value per panel), validated as a preset's."""
    raw = scene.to_dict()
    raw["compare"] = {"vary": vary}
    return dataclasses.replace(scenes.from_dict(raw, scene.source), overrides=scene.overrides)


def load_map(path: str | os.PathLike):
    """A map render's per-pixel data (a MapData, render/maps/data.py): its NAME.npz, or the render's folder
    OUT/NAME/ that holds it."""
    from ..maps import data
    return data.load(path)
