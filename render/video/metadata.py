"""What a render's metadata.json says (docs/output-format.md): the scene and the versions, the run (integrator as
run, energy, certificate, the --quality choice, kernels), the Taichi fields, the timings and the files. Apart from
render/video/pipeline.py, which runs the render: what is recorded of a run is one idea, running it another.
"""
import numpy as np

from ..physics import runtime
from .version import __version__


def integrator_meta(scene, sim) -> dict:
    return {"method": scene.integrator.method, "dt": sim.h, "dt_requested": scene.integrator.dt,
            "substeps": sim.substeps, "precision": scene.integrator.precision}


def run_meta(scene, sim, cert, chosen: dict) -> dict:
    """What metadata.json says of a run (metadata()): `integrator` (as run), `energy`, `cert`, `chosen` (the
    --quality choice) and the `kernels` launched so far."""
    return {"integrator": integrator_meta(scene, sim), "energy": energy_meta(scene, sim), "cert": cert,
            "chosen": chosen, "kernels": list(runtime.launched)}


def header(scene, arch: str) -> dict:
    """What every metadata.json opens with: the scene, the versions, the video."""
    import taichi as ti
    from .encode import ffmpeg_version

    v = scene.video
    return {
        "preset": scene.to_dict(),
        "preset_hash": scene.hash(),
        "source": scene.source,
        "overrides": list(scene.overrides),  # as given: --quality as "quality=LEVEL", then each --set
        "versions": {"package": __version__, "taichi": ".".join(map(str, ti.__version__)),
                     "numpy": np.__version__, "ffmpeg": ffmpeg_version()},
        "arch": arch,
        "frames": scene.frames, "fps": v.fps, "width": v.width, "height": v.height, "duration": v.duration,
    }


def energy_meta(scene, sim) -> dict | None:
    if not scene.has("energy"):
        return None
    return {"initial_total": float(sim.e0.to_numpy().sum()), "max_rel_drift": float(sim.drift[None])}


def metadata(scene, arch: str, run: dict, timings: dict, sizes: dict, sha256: dict) -> dict:
    """metadata.json (docs/output-format.md) of a render or a comparison: the header, what `run` says of the
    simulation (Source.run_meta(), or a comparison's SplitScreen.run_meta()), the Taichi fields of the whole
    render, the timings and the files. A comparison adds its own "compare" after it."""
    return {
        **header(scene, arch),
        "integrator": run["integrator"],
        "effects": list(scene.effects),
        "kernels": list(dict.fromkeys(run["kernels"] + list(runtime.launched))),  # a comparison's variants' first
        "field_bytes": sum(runtime.allocated.values()),  # a comparison's drawing pass; each variant's in "compare"
        "fields": dict(runtime.allocated),
        "energy": run["energy"],
        "faithfulness": run["cert"].to_dict(),
        "quality": run["chosen"],
        "timings_s": {k: round(val, 4) for k, val in timings.items()},
        "outputs": sizes,
        "outputs_sha256": sha256,  # file name -> sha256: `batch` re-renders a file changed in place
    }
