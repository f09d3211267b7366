"""pendulum: double-pendulum presets to MP4 and GIF, simulated and drawn with Taichi.

The Python API (render/commands/api.py, results in render/commands/results.py):

    import render
    scene = render.load("classic", **{"video.duration": 2})   # the frozen, validated Scene
    result = render.render(scene, out="out")                   # MP4, GIF, metadata.json, certificate
    traj = render.simulate(scene)                              # t, theta/omega or pos/vel, energy
    both = render.compare(scene, vary={"integrator.precision": ["f32", "f64"]})  # one split-screen video
    data = render.load_map("out/fractal_flip")                 # a map's per-pixel data (NAME.npz) as arrays

Errors are the typed exceptions of render/errors.py: SceneError (bad input), SimulationError, EncodeError.
"""
import os

from .video.version import __version__  # noqa: F401

# Before any module imports taichi: no network version check, no banner on stdout.
os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")

# Public names, imported on first use: `import render` stays cheap (Taichi, scipy and friends start only
# when a function needs them), which keeps `pendulum --help` and `pendulum presets` as fast as they were.
__all__ = ["load", "render", "simulate", "compare", "load_map", "MapData", "RenderResult", "Trajectory", "Scene",
           "SceneError", "SimulationError", "EncodeError"]


def __getattr__(name):
    if name in ("load", "render", "simulate", "compare", "load_map"):
        from .commands import api
        value = getattr(api, name)
    elif name in ("RenderResult", "Trajectory"):
        from .commands import results
        value = getattr(results, name)
    elif name == "MapData":
        from .maps.data import MapData as value
    elif name == "Scene":
        from .config.scene import Scene as value
    elif name in ("SceneError", "SimulationError", "EncodeError"):
        from . import errors
        value = getattr(errors, name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # looked up once
    return value


def __dir__():
    return sorted([*globals(), *__all__])
