"""Scene -> simulation -> canvas -> encoders: one render, and the draw-free `simulate`."""
from __future__ import annotations

import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

from . import audio
from ..trust import certify, faithful, quality
from ..physics import grid, runtime
from ..physics.stepper import Run
from .atomic import digest, discard, naming, output_dir, replacing, signals_held, temp_beside
from .files import read_regular
from .metadata import integrator_meta, metadata, run_meta

OUTPUTS = ("mp4", "gif", "png", "npz")  # the kinds of file a render writes beside metadata.json (superseded())
META_MAX_BYTES = 1 << 20  # an earlier render's metadata.json is a few kB


def prepare(scene, arch: str, threads: int | None):
    """Before the first frame: the integrator a --quality level calls for, and its faithfulness certificate,
    which refuses (SimulationError) a run that would be untrue for most of the video. Nothing is written yet."""
    t = time.perf_counter()
    scene, chosen = quality.choose(scene, arch, threads)
    t_quality = time.perf_counter() - t
    # A map certifies the lattice its trust mask is read from (render/physics/grid.py), not 128 pixels in row order.
    cert = certify.certify(scene, arch, threads, grid.trust_indices(scene) if scene.fractal else None)
    timings = {"quality": t_quality, "certify": cert.cost_s} if scene.quality else {"certify": cert.cost_s}
    if scene.has("lyapunov"):  # before the render's own Run starts its precision: the spectrum runs in f64
        from ..trust import lyapunov
        t = time.perf_counter()
        cert = dataclasses.replace(cert, lyapunov=lyapunov.for_certificate(scene, cert, arch, threads))
        timings["lyapunov"] = time.perf_counter() - t
    return scene, chosen, cert, timings


def progress_bar(total: int, desc: str, enabled: bool):
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit="frame", file=sys.stderr, disable=not enabled, leave=False,
                dynamic_ncols=True)


class Source:
    """The frames of a scene, one at a time, after prepare(): what `render` encodes and `show` plays.

    next_frame() returns the frame at index + 1 (frame 0 is t = 0), watchdog checked; reset() rewinds to
    t = 0 in place, so the same frames follow again (Taichi fields are never freed: none are made anew).
    """

    def __init__(self, scene, arch: str = "cpu", threads: int | None = None):
        self.scene, self.chosen, self.cert, before = prepare(scene, arch, threads)
        self.run = Run(self.scene, arch, threads)
        self.arch, self.sim = self.run.arch, self.run.sim
        if self.scene.fractal:
            from ..maps.tiles import map_class
            self.canvas = map_class(self.scene)(self.scene, self.sim, self.cert)  # it advances the pixels too
        else:
            from ..draw.canvas import Canvas
            from ..draw.hud import Info
            self.canvas = Canvas(self.scene, self.sim, Info.of(self.scene, self.sim.h, self.cert))
        self.name, self.frames = self.scene.name, self.scene.frames
        self.timings = {**before, "simulate": 0.0, "draw": 0.0}
        self.reset(rewind=False)

    def reset(self, rewind: bool = True):
        if rewind:
            self.sim.restart()
            self.canvas.restart()
        self._steps = self.run.frames(advance=getattr(self.canvas, "advance", None),  # a map's own advance
                                      timings=self.timings)  # frame 0 measures the energy afresh
        self.index = -1

    def next_frame(self, out: np.ndarray | None = None) -> np.ndarray:
        """The next frame as H×W×3 uint8, written into `out` if given (else a new array)."""
        self.index = next(self._steps)
        t = time.perf_counter()
        frame = self.canvas.draw(out, self.index / self.scene.video.fps)
        self.timings["draw"] += time.perf_counter() - t
        return frame

    def lit_tiles(self) -> tuple[np.ndarray, int] | None:
        """Which tiles of the frame drawn last may hold anything but black, where its canvas knows
        (render/draw/compose.py); the MP4's conversion reads no other (render/video/yuv.py). None for a map."""
        lit = getattr(self.canvas, "lit_tiles", None)
        return lit() if lit is not None else None

    def skip_frame(self):
        """On to the next frame without drawing it (the watchdog still checks it): for a render whose outputs
        are all drawn by canvases of their own (a GIF alone)."""
        self.index = next(self._steps)

    def run_meta(self) -> dict:
        """What metadata.json says of the simulation (metadata())."""
        return run_meta(self.scene, self.sim, self.cert, self.chosen)


def record(scene, arch: str = "cpu", threads: int | None = None) -> dict:
    """A scene simulated to the end without drawing, as `render` simulates it (prepare(), the watchdog): a
    comparison's variant, each in its own precision before the panels are drawn (render/draw/split.py).

    Returns the scene as run, `chosen`, `cert`, `timings`, `q` (frames, N, D) float64 at every frame time,
    `cost` (wall seconds of simulation per simulated second, steady: from the second advance on, since the
    first one compiles or loads the kernel), and what metadata reports of the run: `integrator`, `energy`,
    `kernels`, `fields`."""
    scene, chosen, cert, timings = prepare(scene, arch, threads)
    run = Run(scene, arch, threads)
    sim = run.sim
    timings["simulate"] = 0.0
    q = np.empty((scene.frames, sim.n, sim.D))
    warm = 0.0
    for f in run.frames(timings=timings):
        sim.read_out("q_into", q, f)  # one launch, not to_numpy()'s new array (render/physics/recording.py)
        if f == 1:
            warm = timings["simulate"]
    steady = scene.frames - 2
    cost = (timings["simulate"] - warm) * scene.video.fps / steady if steady > 0 else timings["simulate"] / \
        scene.video.duration
    return {**run_meta(scene, sim, cert, chosen), "scene": scene, "timings": timings, "q": q, "cost": cost,
            "fields": dict(runtime.allocated)}


def open_source(scene, arch: str = "cpu", threads: int | None = None, cluster=None, bands: int | None = None):
    """What `render` encodes and `show` plays: the scene's Source, a comparison's split screen, or with a Dask
    `cluster` (a Client) a map's frames made in `bands` tiles there (render/video/tiled.py)."""
    if cluster is not None:
        from .tiled import TiledSource
        src = TiledSource(prepare(scene, arch, threads), cluster, bands, arch, threads)
        src.run_meta = lambda: run_meta(src.scene, src.sim, src.cert, src.chosen)  # a Source's, of its plan
        return src
    if not scene.compare:
        return Source(scene, arch, threads)
    from ..draw.split import SplitScreen
    return SplitScreen(scene, lambda variant: record(variant, arch, threads), arch, threads)


def map_data(src, out_dir: Path) -> list[tuple[Path, Path]]:
    """A map's NAME.npz (render/maps/data.py), its pixels' data at the last frame, written into a temporary
    beside the video: [(temporary, final)], for render() to publish with the rest. Nothing for a fan."""
    if not src.scene.fractal:
        return []
    from ..maps import data
    path = out_dir / f"{src.name}.npz"
    tmp = temp_beside(path, suffix=".npz")  # savez wants the .npz
    try:
        with naming(path):
            np.savez_compressed(tmp, **data.arrays(src.scene, src.canvas))
    except BaseException:
        discard(tmp)
        raise
    return [(tmp, path)]


def superseded(out_dir: Path, name: str, now: dict) -> list[Path]:
    """The files an earlier render into this folder listed in its metadata.json and this one does not write (a
    GIF, after `formats` dropped it): removed once the new metadata is published, so that the folder holds one
    render. Only its own kind of file, NAME.<format or npz>, a regular file; an unreadable old metadata.json names
    nothing."""
    try:
        old = json.loads(read_regular(out_dir / "metadata.json", META_MAX_BYTES, follow=False)).get("outputs")
    except (OSError, ValueError, AttributeError):  # none, not ours to read (Refused is a ValueError), not a table
        return []
    ours = {f"{name}.{ext}" for ext in OUTPUTS}
    return [out_dir / f for f in (old if isinstance(old, dict) else ()) if f in ours and f not in now
            and (out_dir / f).is_file() and not (out_dir / f).is_symlink()]


def render(scene, out_root: Path, arch: str = "cpu", progress: bool = False, threads: int | None = None,
           frame_hook=None, cluster=None, bands: int | None = None) -> dict:
    """Render scene into out_root/NAME/ (a comparison into out_root/compare/NAME/); returns the metadata it
    wrote. frame_hook(f, frame) sees raw frames. cluster, bands: a map in tiles on Dask (open_source)."""
    from .encode import Encoder
    from .gif import Frames

    t_start = time.perf_counter()
    src = open_source(scene, arch, threads, cluster, bands)  # may refuse (exit 2 or 1) before anything is written
    scene, timings = src.scene, src.timings
    timings["encode"] = 0.0
    voices = None
    if audio.heard(scene):  # the `audio` effect: the fan's angles at every frame make the MP4's track
        voices = audio.Voices(src.sim, scene.video.fps, scene.frames)
    with output_dir(scene.out_dir(out_root)) as out_dir:
        enc = Encoder(out_dir, scene.name, scene.video, scene.frames, planar=True)
        pending = []  # (temporary, final) of the files beside the videos
        try:  # from here on a failure or an interrupt removes the encoders' temporaries (enc.abort())
            small = Frames(src, scene.video, timings) if "gif" in scene.video.formats else None  # the GIF's own
            # A GIF alone with a canvas of its own needs no frame of the video's size: 720p frames drawn for
            # nothing were half of a GIF-only rigid_chaos render (28.4 s, 14.8 s without them).
            drawn = set(scene.video.formats) != {"gif"} or not small.alone or frame_hook is not None
            # One frame drawn over each time where nothing keeps it past write(): a new zeroed 720p array took
            # 0.5 ms a frame (allocator and page faults; rigid_chaos, cProfile), refilling one 0.1 ms.
            reuse, buf = not enc.queues_frames and frame_hook is None, None
            with progress_bar(scene.frames, scene.name, progress) as bar:
                for f in range(scene.frames):
                    # the frame, or None where nothing needs it; a new array where the encoder shares it
                    frame = src.next_frame(buf) if drawn else src.skip_frame()
                    if reuse:
                        buf = frame
                    if voices:
                        voices.record()
                    if frame_hook:
                        frame_hook(f, frame)
                    gif_frame = small.frame(f, frame) if small else None
                    t = time.perf_counter()
                    # the tiles it may have lit, from a fan's Source (not a comparison's or a cluster's), where
                    # no hook had the frame, which could have drawn on it
                    lit = src.lit_tiles() if drawn and frame_hook is None and isinstance(src, Source) else None
                    enc.write(frame, gif_frame, lit)  # blocks only when the encoder is behind
                    timings["encode"] += time.perf_counter() - t
                    bar.update()
            t = time.perf_counter()
            enc.close(voices.track() if voices else None, publish=False)  # the track is made and muxed here
            timings["encode"] += time.perf_counter() - t
            # Every file is finished in its temporary before any is published, metadata.json last: a failure
            # (a full disk) leaves none of them, not videos without their metadata.
            pending += map_data(src, out_dir)
            files = enc.done() + pending
            pending.append((temp_beside(out_dir / "metadata.json"), out_dir / "metadata.json"))
            timings["total"] = time.perf_counter() - t_start
            sizes = {final.name: tmp.stat().st_size for tmp, final in files}
            sha256 = {final.name: digest(tmp) for tmp, final in files}
            meta = metadata(scene, src.arch, src.run_meta(), timings, sizes, sha256)
            if scene.compare:
                meta["compare"] = src.compare_meta()
            if scene.fractal:
                meta["map"] = src.canvas.summary()
            if scene.has("poincare"):
                meta["poincare"] = src.canvas.section.summary()
            if voices:
                meta["audio"] = voices.summary()
            with naming(pending[-1][1]):
                pending[-1][0].write_text(json.dumps(meta, indent=2) + "\n")
            stale = superseded(out_dir, scene.name, sizes)
            with signals_held():  # an interrupt waits for the folder to hold one whole render, the new one
                enc.publish(*pending)  # all or none: never a new video beside an earlier run's metadata
                for path in stale:
                    path.unlink(missing_ok=True)
        except BaseException:
            enc.abort()
            for tmp, _ in pending:
                discard(tmp)
            raise
    return meta


def simulate(scene, out_file: Path | None, arch: str = "cpu", progress: bool = False) -> dict:
    """The state at every frame time (t, theta/omega or pos/vel, energy: docs/output-format.md), as float64
    arrays in the returned info's "arrays", and written to out_file (a .npz) unless that is None."""
    if not scene.has("energy"):
        scene = scene.replace(effects=[*scene.effects, "energy"])  # the file carries energy
    scene, chosen, cert, before = prepare(scene, arch, None)
    run = Run(scene, arch)
    sim = run.sim
    timings = {**before, "simulate": 0.0}
    rows: dict[str, list] = {"t": [], "energy": []}
    with progress_bar(scene.frames, scene.name, progress) as bar:
        for f in run.frames(timings=timings):
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
            "line": faithful.sentence(cert.to_dict(), scene.video.duration), "arrays": arrays}
