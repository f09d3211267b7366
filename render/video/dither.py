"""The GIF's frames mapped to its palette (render/video/palette.py): ordered dither, then the nearest colour.

Each pixel gets the Bayer dither of its place added to every channel (clipped to 0..255), then the palette
entry nearest to it (squared RGB distance; the first such entry on a tie). The search is exact and short: the
colour cube is cut into CELLS^3 cells, and each cell lists, in palette order, only the entries that can be
nearest to some colour in it (an entry whose distance to the cell's box exceeds the least distance within
which some entry reaches all its corners never is). A black pixel, most of a frame, takes the index of the
dither's grey at its place, found once. Nothing depends on the order pixels are done in: the same bytes at
any thread count.

On rigid_chaos's 400 GIF frames (352x198, 47 colours) a cell lists 1.6 entries on average, and all 400 frames
are mapped in 0.42-0.47 s on two threads, the same indices as a search of the whole palette (0.65-0.9 s with a
cache of answers instead of the cells; 2-core Xeon, 2026-12-06). `python benchmarks/gif_palette.py` times the
GIF's tail after the last frame, which this is most of.
"""
import subprocess

import imageio_ffmpeg
import numpy as np
import taichi as ti

from ..physics import runtime
from . import palette
from .pipe import RESTORE_SIGNALS

BATCH = 16  # frames mapped in one launch: one wake-up of the thread pool for several
CELL_BITS = 3  # cells of 8 levels a side
CELLS = 256 >> CELL_BITS


@ti.kernel
def _map(frames: ti.types.ndarray(dtype=ti.u8, ndim=4), out: ti.types.ndarray(dtype=ti.u8, ndim=3),
         colours: ti.types.ndarray(dtype=ti.i32, ndim=2), bayer: ti.types.ndarray(dtype=ti.i32, ndim=1),
         black: ti.types.ndarray(dtype=ti.i32, ndim=1), starts: ti.types.ndarray(dtype=ti.i32, ndim=1),
         listed: ti.types.ndarray(dtype=ti.i32, ndim=1)):
    # rows in parallel, each walked along x: one loop over (f, y, x), its flat index divided back into three at
    # every pixel, took 0.22-0.31 s for rigid_chaos's 400 frames all black, this 0.06-0.10 s (benchmarks/gif_map.py)
    for f, y in ti.ndrange(out.shape[0], out.shape[1]):
        for x in range(out.shape[2]):
            at = (y & 7) * 8 + (x & 7)
            px = ti.Vector([ti.cast(frames[f, y, x, k], ti.i32) for k in ti.static(range(3))])
            index = black[at]
            if px.max() > 0:
                c = ti.min(ti.max(px + bayer[at], 0), 255)
                cell = ((c[0] >> CELL_BITS) * CELLS + (c[1] >> CELL_BITS)) * CELLS + (c[2] >> CELL_BITS)
                best = 1 << 30
                for j in range(starts[cell], starts[cell + 1]):  # in palette order: the first on a tie
                    i = listed[j]
                    e = c - ti.Vector([colours[i, 0], colours[i, 1], colours[i, 2]])
                    dist = e.dot(e)
                    if dist < best:
                        best, index = dist, i
            out[f, y, x] = ti.cast(index, ti.u8)


def candidates(colours: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(starts, listed): cell c's entries are listed[starts[c]:starts[c + 1]], those that can be nearest to
    some colour in it: within the least distance at which one entry reaches every corner of the cell."""
    lo = np.arange(CELLS)[:, None] << CELL_BITS
    hi = lo + (1 << CELL_BITS) - 1
    near, far = [], []
    for k in range(3):
        p = colours[None, :, k]
        near.append(np.maximum(np.maximum(lo - p, p - hi), 0) ** 2)  # (CELLS, K): to the cell's box
        far.append(np.maximum(np.abs(p - lo), np.abs(p - hi)) ** 2)  # to its farthest corner
    near = near[0][:, None, None] + near[1][None, :, None] + near[2][None, None, :]
    far = far[0][:, None, None] + far[1][None, :, None] + far[2][None, None, :]
    can = (near <= far.min(-1, keepdims=True)).reshape(CELLS ** 3, -1)
    cell, listed = np.nonzero(can)  # row-major: by cell, then in palette order
    starts = np.searchsorted(cell, np.arange(CELLS ** 3 + 1)).astype(np.int32)
    return starts, listed.astype(np.int32)


class Mapper:
    """Frames of one GIF to indices into `colours` ((K, 3) int32, 0 < K <= 256)."""

    def __init__(self, colours: np.ndarray):
        if not 0 < len(colours) <= 256:
            raise ValueError(f"a palette of {len(colours)} colours")
        if runtime.generation() == 0:
            raise RuntimeError("dither.Mapper: Taichi is not running (a Run starts it)")
        self.colours = np.ascontiguousarray(colours, np.int32)
        self.bayer = palette.dither()
        grey = np.clip(self.bayer, 0, 255)[:, None, None]  # black dithered, at each of the 64 places
        self.black = ((grey - self.colours[None]) ** 2).sum(-1).argmin(-1).astype(np.int32)
        self.starts, self.listed = candidates(self.colours)

    def map(self, frames: np.ndarray) -> np.ndarray:
        """The (N, H, W, 3) uint8 frames' palette indices, (N, H, W) uint8."""
        out = np.empty(frames.shape[:3], np.uint8)
        _map(np.ascontiguousarray(frames), out, self.colours, self.bayer, self.black, self.starts, self.listed)
        return out


def write(frames: list, colours: np.ndarray, size: tuple[int, int], rate: int, path, log):
    """The GIF of `frames` (H×W×3 uint8 each, size (W, H)) in `colours` at `path`: ffmpeg writes it from pal8
    frames (each frame's indices, then the palette) as they are mapped. Returns (ffmpeg's exit status, the
    BrokenPipeError if it died before taking them all); its log goes to `log`."""
    w, h = size
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo",
           "-pix_fmt", "pal8", "-s", f"{w}x{h}", "-r", str(rate), "-i", "-", "-loop", "0", "-f", "gif", path]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=log,
                            start_new_session=True, restore_signals=RESTORE_SIGNALS)
    error = None
    try:
        mapper, pal = Mapper(colours), palette.pal8(colours)
        try:
            for k in range(0, len(frames), BATCH):
                for index in mapper.map(np.stack(frames[k:k + BATCH])):
                    proc.stdin.write(memoryview(index).cast("B"))
                    proc.stdin.write(pal)
            proc.stdin.close()
        except BrokenPipeError as e:  # ffmpeg died: its exit status and log say why
            error = e
        return proc.wait(), error
    except BaseException:
        proc.kill()
        proc.wait()
        raise
