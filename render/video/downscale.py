"""A frame shrunk by its area average, in exact integers: the GIF's frame of a map, and of any frame without a
GIF canvas of its own (render/video/gif.py).

Each output pixel is the mean of the area of the frame it covers, a partly covered pixel weighted by its share
(what ffmpeg's flags=area does). Along a line of n pixels shrunk to m, in units of 1/m of a source pixel,
source pixel i spans [i·m, (i + 1)·m) and output pixel r spans [r·n, (r + 1)·n): every share is a whole
number, and an output pixel's shares sum to n. So the sums are exact (at most 255·H·W) and no order of
adding them can change a byte: the same bytes at any thread count, on any CPU. A byte is the exact mean
rounded to nearest, a half up.

Two Taichi kernels, rows then columns. The rows pass reads the frame in words of 4 bytes (a row that is not
whole words is padded: reading bytes took it 2.4 ms of a 720p frame, words 1.5 ms, timed by a script not
kept). fractal_flip's 720p frames shrink to 352×198 in 3.1-3.2 ms of CPU each, where numpy, with floats for the
cut pixels, took 8.5-8.7 ms (random bytes: 12-14 ms); a 20 s map's GIF is 400 of them (`python
benchmarks/shrink_time.py`, this and the numpy version alternating, 2 rounds each; 2-core Xeon, AVX-512,
2026-12-06).
"""
import functools

import numpy as np
import taichi as ti

from ..physics import runtime, vector_width
from .yuv import serial

LANES = 16  # words of a row summed at a time: one AVX-512 register of 32-bit lanes (two AVX2 ones), or a forced
# width's (render/physics/vector_width.py's lanes())


@functools.lru_cache(maxsize=16)
def shares(n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(first, share): output pixel r of a line of n pixels shrunk to m covers source pixels first[r] + k, each by
    the whole number share[r, k] (a pixel past the line's end has share 0, and is read as its last)."""
    if not 0 < m <= n:
        raise ValueError(f"a line of {n} pixels cannot be shrunk to {m}")
    r = np.arange(m)[:, None]
    first = r * n // m
    i = first + np.arange(-(-n // m) + 1)
    share = np.clip(np.minimum((i + 1) * m, (r + 1) * n) - np.maximum(i * m, r * n), 0, None)
    return first[:, 0].astype(np.int32), np.ascontiguousarray(share[:, share.any(axis=0)], np.int32)


@ti.kernel
def _rows(frame: ti.types.ndarray(dtype=ti.u32, ndim=1), rows: ti.types.ndarray(dtype=ti.i32, ndim=1),
          first: ti.types.ndarray(dtype=ti.i32, ndim=1), share: ti.types.ndarray(dtype=ti.i32, ndim=2),
          n: ti.i32, span: ti.i32, serial: ti.template()):
    """Each output row's sums of the frame's n rows it covers, by their shares, a byte at a time: `span` words
    a row. LANES words are read into an array on the stack and summed there, in the loop that touches no
    array argument (the one LLVM vectorises, as in render/video/yuv.py)."""
    L = ti.static(vector_width.lanes(LANES))
    runs = (span + L - 1) // L
    ti.loop_config(serialize=serial)
    for t in range(first.shape[0] * runs):
        r, x0 = t // runs, (t % runs) * L
        last = ti.min(L, span - x0) - 1
        acc = ti.Matrix.zero(ti.i32, 4, L)
        for k in range(share.shape[1]):
            s = share[r, k]
            base = ti.min(first[r] + k, n - 1) * span + x0
            v = ti.Vector.zero(ti.u32, L)
            for p in range(L):
                v[p] = frame[base + ti.min(p, last)]
            for p in range(L):  # the loop LLVM vectorises
                for b in ti.static(range(4)):  # x86 is little-endian: byte 0 of a word is its lowest
                    acc[b, p] += s * ti.cast((v[p] >> (8 * b)) & 0xFF, ti.i32)
        for p in range(last + 1):
            for b in ti.static(range(4)):
                rows[4 * (r * span + x0 + p) + b] = acc[b, p]


@ti.kernel
def _columns(rows: ti.types.ndarray(dtype=ti.i32, ndim=1), out: ti.types.ndarray(dtype=ti.u8, ndim=1),
             first: ti.types.ndarray(dtype=ti.i32, ndim=1), share: ti.types.ndarray(dtype=ti.i32, ndim=2),
             n: ti.i32, stride: ti.i32, h: ti.i32, area: ti.f64, serial: ti.template()):
    """Each output pixel: the sum of its row's sums (`stride` bytes a row) over the n columns it covers, by their
    shares, divided by the whole area (H·W units) and rounded. In f64: every sum is a whole number below 2^53,
    so exact, and a quotient that is not whole is at least 1/(2·area) from the nearest whole number, far more
    than its rounding error, so its floor is exact."""
    m = first.shape[0]
    ti.loop_config(serialize=serial)
    for r, c in ti.ndrange(h, m):
        acc = ti.Vector.zero(ti.f64, 3)
        for k in range(share.shape[1]):
            at = r * stride + ti.min(first[c] + k, n - 1) * 3
            s = ti.cast(share[c, k], ti.f64)
            for ch in ti.static(range(3)):
                acc[ch] += s * ti.cast(rows[at + ch], ti.f64)
        for ch in ti.static(range(3)):
            out[(r * m + c) * 3 + ch] = ti.cast(ti.floor((2.0 * acc[ch] + area) / (2.0 * area)), ti.u8)


def shrink(frame: np.ndarray, w: int, h: int) -> np.ndarray:
    """An H×W×3 uint8 frame area-averaged down to h×w (see the module's docstring), a new array; a copy if it
    is that size already, since the GIF keeps what this gives past the frame, which a render draws the next
    frame into (a GIF of the video's size and rate was every frame the last one). Taichi must run: a Run
    starts it (render/physics/stepper.py)."""
    H, W = frame.shape[:2]
    if (H, W) == (h, w):
        return frame.copy()
    if runtime.generation() == 0:
        raise RuntimeError("downscale.shrink: Taichi is not running (a Run starts it)")
    fy, sy = shares(H, h)
    fx, sx = shares(W, w)
    span = W * 3
    words = np.ascontiguousarray(frame).reshape(H, span)
    if span % 4:
        words = np.concatenate([words, np.zeros((H, -span % 4), np.uint8)], axis=1)
    stride = words.shape[1]
    # On two CPUs or fewer on the launching thread, as yuv.convert: the encoders hold the other core, and the
    # thread pool's wake-up cost more CPU than it saved (2.5 ms wall and 3.6 ms CPU a frame on two threads, by the
    # script not kept above; on the launching thread 2.9 ms of both)
    one = serial()
    rows = np.empty(h * stride, np.int32)
    _rows(words.reshape(-1).view(np.uint32), rows, fy, sy, H, stride // 4, one)
    out = np.empty((h, w, 3), np.uint8)
    _columns(rows, out.reshape(-1), fx, sx, W, stride, h, float(H * W), one)
    return out
