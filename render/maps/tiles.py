"""One map in tiles: bands of its plot's rows, each integrated for the whole video by a task of its own (a Dask
worker's: render/video/tiled.py submits them and encodes what comes back), and the frames put together again.

A band is a Map (render/maps/fractal.py, ftle.py) over some rows of the plot: its system holds only the band's
pendulums (stepper.Run's subset, which keeps the whole scene's step), its trust mask is the band's rows of the
whole map's (the certificate ran once, on the client, and comes with the task), and it colours its rows where
they sit in the frame, hatch included. Every pixel is integrated on its own (a divergence pixel with its twin),
so a band's pixels are the whole map's, bit for bit. The FTLE map's barrier curve reads each pixel's four
neighbours: its bands integrate HALO rows more on each side and return only their own.

What a band returns per frame: its rows of the plot; the top band the whole frame around them too (axes,
legend, clock, drawn by the map's own code as a local render draws them). Each frame is XORed with the band's
previous one and zlib-compressed: a settled pixel then costs next to nothing, so the client can hold a whole
video's bands.
"""
from __future__ import annotations

import threading
import time
import zlib

import numpy as np

from ..errors import SimulationError
from ..physics import grid, runtime
from ..physics.stepper import Run

HALO = 1  # rows of the neighbouring bands an FTLE band integrates too: its barrier curve's 4-neighbours
_LOCK = threading.Lock()  # one Taichi runtime per process: a worker's threads take turns


def map_class(scene):
    """The Map that colours `scene`'s pixels."""
    if scene.fractal == "lyapunov":
        from .ftle import FtleMap  # it carries each pixel's tangent vectors through the frame
        return FtleMap
    from .fractal import Map
    return Map


def bands(height: int, n: int) -> list[range]:
    """The plot's `height` rows in n bands (at most one a row), as even as can be, top first."""
    n = max(1, min(n, height))
    edges = [height * i // n for i in range(n + 1)]
    return [range(a, b) for a, b in zip(edges, edges[1:])]


def render_band(scene, rows: range, cert, arch: str = "cpu", threads: int | None = None) -> dict:
    """The task: `rows` of scene's map integrated and drawn for every frame of the video.

    Returns `scene_hash` (the client checks it: a band of another scene is never put into this one), `rows`,
    `frames` (per frame the compressed XOR delta, see the module's docstring) of an array of `shape`, `arrays`
    (the map's arrays() of the band's own rows at the end), `t` (the clock at the end), `arch`, `kernels`,
    `fields` and `timings` (simulate, draw, compress: seconds). The watchdog's SimulationError comes back as
    `error`, not raised: it would fail the same way again, and Dask reruns what raises."""
    try:
        return _band(scene, rows, cert, arch, threads)
    except SimulationError as e:
        return {"scene_hash": scene.hash(), "rows": (rows.start, rows.stop), "error": str(e)}


def _band(scene, rows: range, cert, arch: str, threads: int | None) -> dict:
    lay = grid.plot(scene)
    halo = HALO if scene.fractal == "lyapunov" else 0
    span = range(max(rows.start - halo, 0), min(rows.stop + halo, lay.h))
    per_row = scene.pendulums.count // lay.h  # pendulums are pixel after pixel, row-major (grid.grid_state)
    timings = {"simulate": 0.0, "draw": 0.0, "compress": 0.0}
    with _LOCK:
        run = Run(scene, arch, threads, subset=np.arange(span.start * per_row, span.stop * per_row))
        canvas = map_class(scene)(scene, run.sim, cert, rows=span)
        frame, last, out = canvas.new_frame(), None, []
        y, x = slice(lay.y0 + rows.start, lay.y0 + rows.stop), slice(lay.x0, lay.x0 + lay.w)
        for _ in run.frames(advance=canvas.advance, timings=timings):
            t = time.perf_counter()
            canvas.draw(frame)
            part = (frame if rows.start == 0 else frame[y, x]).copy()  # a copy: the next draw overwrites frame
            t1 = time.perf_counter()
            out.append(zlib.compress((part if last is None else part ^ last).tobytes(), 1))
            last = part
            timings["draw"] += t1 - t
            timings["compress"] += time.perf_counter() - t1
        return {"scene_hash": scene.hash(), "rows": (rows.start, rows.stop), "frames": out, "shape": last.shape,
                "arrays": {k: inner(v, rows, span) for k, v in canvas.arrays().items()}, "t": run.sim.t,
                "arch": run.arch, "kernels": list(runtime.launched), "fields": dict(runtime.allocated), "timings": timings}


def inner(a: np.ndarray, rows: range, span: range) -> np.ndarray:
    """The band's own `rows` of an array over the `span` it integrated (per pixel or per point, row-major: a
    row's pixels, or their samples, are adjacent)."""
    per_row = len(a) // len(span)
    return a[(rows.start - span.start) * per_row:(rows.stop - span.start) * per_row]


class Assembly:
    """The frames of a map from its bands' results (render_band's, top band first), one after the other."""

    def __init__(self, scene, results: list[dict]):
        self.scene, self.results = scene, results
        lay = grid.plot(scene)
        self.x = slice(lay.x0, lay.x0 + lay.w)
        self.y = [slice(lay.y0 + r["rows"][0], lay.y0 + r["rows"][1]) for r in results]
        self.last = [None] * len(results)

    def frame(self, f: int, out: np.ndarray | None = None) -> np.ndarray:
        """Frame f (after frame f - 1: each band's frame is a delta on its previous one)."""
        for i, r in enumerate(self.results):
            part = np.frombuffer(zlib.decompress(r["frames"][f]), np.uint8).reshape(r["shape"])
            self.last[i] = part if f == 0 else part ^ self.last[i]
        if out is None:
            out = np.empty_like(self.last[0])
        np.copyto(out, self.last[0])  # the top band: the whole frame
        for i in range(1, len(self.results)):
            out[self.y[i], self.x] = self.last[i]
        return out

    def arrays(self) -> dict:
        """The bands' per-pixel arrays joined: the whole plot's, row-major, as one map's arrays() would be."""
        return {k: np.concatenate([r["arrays"][k] for r in self.results]) for k in self.results[0]["arrays"]}

    def result(self) -> dict:
        """What the map's result() would give of the whole plot, for its data (render/maps/data.py)."""
        return map_class(self.scene).result_of(self.scene, self.arrays(), self.results[0]["t"])

    def summary(self) -> dict:
        """What the map's summary() would say of the whole plot, for metadata.json."""
        return map_class(self.scene).summarise(self.scene, self.arrays(), self.results[0]["t"])
