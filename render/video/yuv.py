"""RGB frames to the MP4's yuv420p, in a Taichi kernel, before the pipe.

x264 codes yuv420p. Handed rgb24, ffmpeg converted every frame itself (swscale, before x264's threads) and read
twice the bytes through the pipe. On the 2-core Xeon (AVX-512), rigid_chaos's 1200 frames at 720p from a file
took ffmpeg 13.8-14.1 s of user CPU from rgb24 and 11.4-11.7 s from yuv420p, the same x264 settings
(`python benchmarks/yuv_pipe.py`, two rounds, 2026-12-04). Whole renders of rigid_chaos took 14.5 and 15.0 s
against 15.7 and 15.9 s before (`pendulum render rigid_chaos`, wall time, alternating). The kernel below takes
a median 0.97 ms a frame (10th-90th percentile 0.75-1.13 ms), 1.16 s for the 1200; before its groups were
staged on the stack, 1.50 ms and 1.65 s, the same bytes (the same script, one round each, 2026-12-06).

The conversion is ffmpeg's default one for untagged RGB, BT.601 at limited range (Y 16..235, Cb and Cr
16..240), in integer fixed point so that every CPU gives the same bytes. Y is swscale's within a level; chroma
is the mean of each 2×2 block, where swscale filters wider, so at a sharp coloured edge a chroma sample differs
by up to 18 levels. The decoded MP4 is as close to the frames as before (27.42 dB against 27.39 from rgb24,
rigid_chaos: `python benchmarks/mp4_psnr.py`).
"""
import numpy as np
import taichi as ti

from ..physics import launch, runtime, vector_width

SHIFT = 16  # coefficients are BT.601's times 2**SHIFT, rounded
Y = (16829, 33039, 6416)  # 0.256788, 0.504129, 0.097906: 219/255 of the luma weights 0.299, 0.587, 0.114
CB = (-9714, -19070, 28784)  # each chroma row sums to 0: grey has no chroma
CR = (28784, -24103, -4681)
BLACK_Y, BLACK_C = 0x10101010, 0x8080  # four Y bytes of 16, two chroma bytes of 128: what black converts to


def size(w: int, h: int) -> int:
    """Bytes of one yuv420p frame of w×h (both even)."""
    return w * h * 3 // 2


def fits(w: int, h: int) -> bool:
    """Whether convert() takes frames of w×h: rows of RGB in whole 4-byte words, and whole 2×2 blocks."""
    return w % 4 == 0 and h % 2 == 0


@ti.func
def _byte(word, k: ti.template()):
    """Byte k of a word as read from memory: x86 is little-endian, so byte 0 is the lowest."""
    return ti.cast((word >> (8 * k)) & 0xFF, ti.i32)


@ti.func
def _round(v, shift: ti.template()):
    return (v + (1 << (shift - 1))) >> shift  # >> floors: adding half first rounds to nearest


# Groups converted at a time: 16 words of 32 bits, one AVX-512 register (two AVX2 ones), or as many as a forced
# width takes (render/physics/vector_width.py's lanes()). Taichi's CPU threads
# take a parallel loop in blocks of at least 512 iterations (render/physics/runtime.py), so the loop is over
# runs of groups, not rows: 720p is 360 rows of 20 runs.
LANES = 16
# On two CPUs or fewer the loop runs on the launching thread: the conversion is bound by memory, and the thread
# pool's wake-up cost CPU time that x264 needs on the other core. rigid_chaos's second 10 s of 720p frames,
# from memory: 1.79 ms wall and 2.60 ms CPU a frame on two threads, 1.75 ms and 1.75 ms serial (2-core Xeon,
# 2026-12-06, medians of 3 rounds, the kernel before its groups were staged).
SERIAL_THREADS = 2


def serial() -> bool:
    """Whether a frame's conversion, or its shrink (render/video/downscale.py), runs on the launching thread
    (SERIAL_THREADS); on CUDA a loop is never serialised (that would be one GPU thread)."""
    cfg = ti.lang.impl.current_cfg()
    return cfg.arch != ti.cuda and cfg.cpu_max_num_threads <= SERIAL_THREADS


@ti.kernel
def _convert(rgb: ti.types.ndarray(dtype=ti.u32, ndim=1), y4: ti.types.ndarray(dtype=ti.u32, ndim=1),
             cb2: ti.types.ndarray(dtype=ti.u16, ndim=1), cr2: ti.types.ndarray(dtype=ti.u16, ndim=1), w: ti.i32,
             lit: ti.types.ndarray(dtype=ti.i32, ndim=2), shift: ti.template(), serial: ti.template()):
    """Groups of 4×2 pixels: in each of its two rows 12 bytes of RGB are 3 words (the frame's rows are whole
    words since its width is a multiple of 4), out come a word of Y per row and two bytes each of Cb and Cr.
    LANES groups of a row at a time: their words are read into an array on the stack, converted there in a loop
    that touches no array argument (the one LLVM vectorises: a loop that stores through an ndarray stays
    scalar, as in render/draw/compose.py's fade_tile), and written back. Most of a frame is black, and a run
    of black groups is only read and written, and where `lit` says that all its tiles (2^shift pixels a side;
    shift 0: no tiles known) are black, only written. The arrays are flat: 2-D ndarray indexing made the same
    loop 5 times slower."""
    L = ti.static(vector_width.lanes(LANES))
    gw = w // 4
    rows = cb2.shape[0] // gw  # rows of groups: half the frame's height
    runs = (gw + L - 1) // L
    ti.loop_config(serialize=serial)
    for t in range(rows * runs):
        gy, g0 = t // runs, (t % runs) * L
        n = ti.min(L, gw - g0)
        top = 2 * gy * 3 * gw + 3 * g0  # the first group's first word in the top row; the bottom row 3 * gw on
        words = ti.Matrix.zero(ti.u32, 6, L)
        bright = ti.u32(0)
        dark = False
        if ti.static(shift):  # both rows of a group lie in one row of tiles, since tiles are an even size
            dark = True
            for tx in range((4 * g0) >> shift, ((4 * (g0 + n) - 1) >> shift) + 1):
                if lit[(2 * gy) >> shift, tx]:
                    dark = False
        if not dark:
            for p in range(n):
                for r, k in ti.static(ti.ndrange(2, 3)):
                    words[3 * r + k, p] = rgb[top + 3 * gw * r + 3 * p + k]
                    bright |= words[3 * r + k, p]
        luma = ti.Matrix.zero(ti.u32, 2, L)
        cb = ti.Vector.zero(ti.u32, L)
        cr = ti.Vector.zero(ti.u32, L)
        if bright == 0:
            for p in range(L):
                luma[0, p], luma[1, p], cb[p], cr[p] = ti.u32(BLACK_Y), ti.u32(BLACK_Y), ti.u32(BLACK_C), \
                    ti.u32(BLACK_C)
        else:
            for p in range(L):  # the loop LLVM vectorises
                sums = ti.Matrix.zero(ti.i32, 2, 3)  # channel sums of the group's left and right 2×2 blocks
                for r in ti.static(range(2)):
                    for q in ti.static(range(4)):
                        c = ti.Vector([_byte(words[3 * r + (3 * q + k) // 4, p], (3 * q + k) % 4)
                                       for k in ti.static(range(3))])
                        for k in ti.static(range(3)):
                            sums[q // 2, k] += c[k]
                        v = 16 + _round(Y[0] * c[0] + Y[1] * c[1] + Y[2] * c[2], SHIFT)
                        luma[r, p] |= ti.cast(v, ti.u32) << (8 * q)
                for b in ti.static(range(2)):  # a sum of 4 pixels: two more bits to shift away
                    u = 128 + _round(CB[0] * sums[b, 0] + CB[1] * sums[b, 1] + CB[2] * sums[b, 2], SHIFT + 2)
                    v = 128 + _round(CR[0] * sums[b, 0] + CR[1] * sums[b, 1] + CR[2] * sums[b, 2], SHIFT + 2)
                    cb[p] |= ti.cast(u, ti.u32) << (8 * b)
                    cr[p] |= ti.cast(v, ti.u32) << (8 * b)
        for p in range(n):
            ci = gy * gw + g0 + p
            y4[2 * gy * gw + g0 + p], y4[(2 * gy + 1) * gw + g0 + p] = luma[0, p], luma[1, p]
            cb2[ci], cr2[ci] = ti.cast(cb[p], ti.u16), ti.cast(cr[p], ti.u16)


_LAUNCHES = launch.Launches()  # convert()'s launches after the first, without Taichi's per-call Python
_NO_TILES = np.zeros((1, 1), np.int32)  # `lit` where no tiles are known: every group is read


def convert(frame: np.ndarray, lit: tuple[np.ndarray, int] | None = None) -> np.ndarray:
    """An H×W×3 uint8 RGB frame (fits()) as a new yuv420p frame: the Y plane, then Cb, then Cr. `lit`, (tiles,
    side) from the canvas that drew the frame (render/draw/compose.py's lit_tiles), says which side×side tiles
    may hold anything but black; the others are not read. rigid_chaos's 1200 frames, each read from memory
    (`python benchmarks/yuv_pipe.py --convert-only --evict 64`, twice; 2-core Xeon, AVX-512, 2026-12-07): median
    0.81-0.82 ms a frame reading every tile, 0.77-0.78 ms the lit ones; right after drawing (no --evict), the
    frame still in the cache, 0.56-0.57 and 0.55-0.56 ms. Taichi must run: a Run starts it
    (render/physics/stepper.py)."""
    if runtime.generation() == 0:
        raise RuntimeError("yuv.convert: Taichi is not running (a Run starts it)")
    h, w = frame.shape[:2]
    tiles, shift = _NO_TILES, 0
    if lit is not None:
        tiles, side = lit
        shift = side.bit_length() - 1
        if side < 2 or side != 1 << shift or tiles.shape != (-(-h // side), -(-w // side)):
            raise ValueError(f"yuv.convert: {tiles.shape} tiles of {side} pixels do not tile a {w}x{h} frame")
    out = np.empty(size(w, h), np.uint8)
    n, c = w * h, w * h // 4
    words = np.ascontiguousarray(frame).reshape(-1).view(np.uint32)
    _LAUNCHES.launch("convert", lambda: _convert, (words, out[:n].view(np.uint32), out[n:n + c].view(np.uint16),
                                                 out[n + c:].view(np.uint16), w, tiles, shift, serial()))
    return out
