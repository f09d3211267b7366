"""Scene -> simulation -> canvas -> encoders: one render, and the draw-free `simulate`."""
from __future__ import annotations

import json
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from . import certify, quality, registry, runtime
from .atomic import digest, replacing, write_atomic
from .system import DEFAULT_MAX_DRIFT
from .version import __version__


def make_system(scene, subset=None):
    """The scene's system, built by the class the registry holds for it."""
    return registry.get(scene.system)(scene, subset)


def prepare(scene, arch: str, threads: int | None):
    """Before the first frame: the integrator a --quality level calls for, and its faithfulness certificate,
    which refuses (SimulationError) a run that would be untrue for most of the video. Nothing is written yet."""
    t = time.perf_counter()
    scene, chosen = quality.choose(scene, arch, threads)
    t_quality = time.perf_counter() - t
    cert = certify.certify(scene, arch, threads)
    timings = {"quality": t_quality, "certify": cert.cost_s} if scene.quality else {"certify": cert.cost_s}
    return scene, chosen, cert, timings


def progress_bar(total: int, desc: str, enabled: bool):
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit="frame", file=sys.stderr, disable=not enabled, leave=False,
                dynamic_ncols=True)


def frames(scene, sim, timings: dict):
    """Yield each frame index with the simulation at that frame's time (frame 0 is t=0), watchdog checked."""
    max_drift = scene.integrator.max_drift or DEFAULT_MAX_DRIFT
    for f in range(scene.frames):
        t = time.perf_counter()
        if f:
            sim.advance_frame()
        if scene.has("energy"):
            sim.measure_energy(first=f == 0)
        sim.check(f, max_drift)
        timings["simulate"] += time.perf_counter() - t
        yield f


@contextmanager
def output_dir(path: Path):
    """Create the directory; if it was new and the block fails, remove it again when empty."""
    existed = path.exists()
    path.mkdir(parents=True, exist_ok=True)
    try:
        yield path
    except BaseException:
        if not existed:
            try:
                path.rmdir()
            except OSError:
                pass
        raise


class Source:
    """The frames of a scene, one at a time, after prepare(): what `render` encodes and `show` plays.

    next_frame() returns the frame at index + 1 (frame 0 is t = 0), watchdog checked; reset() rewinds to
    t = 0 in place, so the same frames follow again (Taichi fields are never freed: none are made anew).
    """

    def __init__(self, scene, arch: str = "cpu", threads: int | None = None):
        from .canvas import Canvas

        self.scene, self.chosen, self.cert, before = prepare(scene, arch, threads)
        self.arch = runtime.init(arch, self.scene.integrator.precision, threads)
        self.sim = make_system(self.scene)
        self.canvas = Canvas(self.scene, self.sim)
        self.name, self.frames = self.scene.name, self.scene.frames
        self.timings = {**before, "simulate": 0.0, "draw": 0.0}
        self.reset(rewind=False)

    def reset(self, rewind: bool = True):
        if rewind:
            self.sim.restart()
            self.canvas.restart()
        self._steps = frames(self.scene, self.sim, self.timings)  # frame 0 measures the energy afresh
        self.index = -1

    def next_frame(self, out: np.ndarray | None = None) -> np.ndarray:
        """The next frame as H×W×3 uint8, written into `out` if given (else a new array)."""
        self.index = next(self._steps)
        t = time.perf_counter()
        frame = self.canvas.draw(out)
        self.timings["draw"] += time.perf_counter() - t
        return frame


def render(scene, out_root: Path, arch: str = "cpu", progress: bool = False, threads: int | None = None,
           frame_hook=None) -> dict:
    """Render scene into out_root/NAME/; returns the metadata it wrote. frame_hook(f, frame) sees raw frames."""
    from .encode import Encoder

    t_start = time.perf_counter()
    src = Source(scene, arch, threads)  # may refuse (exit 2 or 1) before anything is written
    scene, timings = src.scene, src.timings
    timings["encode"] = 0.0
    with output_dir(Path(out_root) / scene.name) as out_dir:
        enc = Encoder(out_dir, scene.name, scene.video)
        try:
            with progress_bar(scene.frames, scene.name, progress) as bar:
                for f in range(scene.frames):
                    frame = src.next_frame()  # a new array: the encoder shares it, it does not copy
                    if frame_hook:
                        frame_hook(f, frame)
                    t = time.perf_counter()
                    enc.write(frame)  # blocks only when the encoder is behind
                    timings["encode"] += time.perf_counter() - t
                    bar.update()
            t = time.perf_counter()
            sizes = enc.close()
            timings["encode"] += time.perf_counter() - t
        except BaseException:
            enc.abort()
            raise
        timings["total"] = time.perf_counter() - t_start
        meta = metadata(scene, src.sim, src.arch, timings, sizes, src.cert, src.chosen,
                        {f: digest(out_dir / f) for f in sizes})
        write_atomic(out_dir / "metadata.json", (json.dumps(meta, indent=2) + "\n").encode())
    return meta


def simulate(scene, out_file: Path | None, arch: str = "cpu", progress: bool = False) -> dict:
    """The state at every frame time (DESIGN.md: t, theta/omega or pos/vel, energy), as float64 arrays in
    the returned info's "arrays", and written to out_file (a .npz) unless that is None."""
    if not scene.has("energy"):
        scene = scene.replace(effects=[*scene.effects, "energy"])  # the file carries energy
    scene, chosen, cert, before = prepare(scene, arch, None)
    runtime.init(arch, scene.integrator.precision)
    sim = make_system(scene)
    timings = {**before, "simulate": 0.0}
    rows: dict[str, list] = {"t": [], "energy": []}
    with progress_bar(scene.frames, scene.name, progress) as bar:
        for f in frames(scene, sim, timings):
            rows["t"].append(f / scene.video.fps)
            rows["energy"].append(sim.e.to_numpy())
            for k, v in sim.state().items():
                rows.setdefault(k, []).append(v)
            bar.update()
    arrays = {k: np.asarray(v, dtype=np.float64) for k, v in rows.items()}
    if out_file is not None:
        out_file = Path(out_file)
        with output_dir(out_file.parent), replacing(out_file, suffix=".npz") as tmp:  # savez wants the .npz
            np.savez_compressed(tmp, **arrays)
    return {"frames": scene.frames, "kernels": list(runtime.launched), "timings_s": timings,
            "integrator": integrator_meta(scene, sim), "faithfulness": cert.to_dict(), "quality": chosen,
            "line": cert.line(), "arrays": arrays}


def integrator_meta(scene, sim) -> dict:
    return {"method": scene.integrator.method, "dt": sim.h, "dt_requested": scene.integrator.dt,
            "substeps": sim.substeps, "precision": scene.integrator.precision}


def metadata(scene, sim, arch: str, timings: dict, sizes: dict, cert, chosen: dict,
             sha256: dict | None = None) -> dict:
    import taichi as ti
    from .encode import ffmpeg_version

    energy = None
    if scene.has("energy"):
        energy = {"initial_total": float(sim.e0.to_numpy().sum()), "max_rel_drift": float(sim.drift[None])}
    v = scene.video
    return {
        "preset": scene.to_dict(),
        "preset_hash": scene.hash(),
        "source": scene.source,
        "versions": {"package": __version__, "taichi": ".".join(map(str, ti.__version__)),
                     "numpy": np.__version__, "ffmpeg": ffmpeg_version()},
        "arch": arch,
        "frames": scene.frames, "fps": v.fps, "width": v.width, "height": v.height, "duration": v.duration,
        "integrator": integrator_meta(scene, sim),
        "effects": list(scene.effects),
        "kernels": list(runtime.launched),
        "field_bytes": sum(runtime.allocated.values()),
        "fields": dict(runtime.allocated),
        "energy": energy,
        "faithfulness": cert.to_dict(),
        "quality": chosen,
        "timings_s": {k: round(val, 4) for k, val in timings.items()},
        "outputs": sizes,
        "outputs_sha256": sha256 or {},  # file name -> sha256: `batch` re-renders a file changed in place
    }
