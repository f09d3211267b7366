"""sin and cos together, inline and branchless, for the hot loops: no libm call, so LLVM can vectorise them.

    s, c = sincos(x)          # x a scalar or a ti.Vector of the runtime's float type

Taichi's CPU backend calls scalar libm for ti.sin / ti.cos: a call in the loop stops LLVM's loop vectoriser,
and those calls were 93 % of the rigid kernel's time. These are plain arithmetic and ti.select instead.

Method: j = round(x·2/π), r = x − j·π/2 with π/2 split Cody-Waite style (P1 has 33 significant bits, so
j·P1 is exact for |j| < 2^20, |x| < 1.6e6), then sin and cos of r ∈ [−π/4, π/4] by fdlibm's minimax
polynomials (__kernel_sin / __kernel_cos, degree 13 / 14) in f64, Cephes' sinf / cosf (degree 7 / 8) in
f32 (their tails in f32, the leading terms in f64); the quadrant j mod 4 swaps and negates with ti.select.
`sincos` picks the form at compile time from the runtime's float type:
  f64 -> sincos_f64: fdlibm's double-double reduction (π/2 to 119 bits) and kernels that take its tail;
  f32 -> sincos_f32: the reduction and the leading terms in f64.

Both need IEEE arithmetic: Taichi's fast_math gives every float op LLVM's `reassoc nsz` flags, and LLVM may
then fold the compensation terms away (x − j·P1 − j·P2 becomes x − j·(P1 + P2)). Whether it does depends on
the CPU it compiles for: a fast_math-proof variant (the later parts multiplied by copies of j re-made from
the integer quadrant) held on AVX2 but was 2.3e8 ulp off near k·π/2 on AVX-512 (most likely its code
generator proved the copies equal to j; AVX-512 code could not be inspected on the AVX2 machines here).
So runtime.init starts Taichi with fast_math=False, and `sincos` refuses to compile under fast_math.
(Rigid RK4 at N = 1e5, fast_math off against on, interleaved on a loaded 2-core AVX2 machine: 4.8M against
5.0-5.4M steps/s in f64, 8.8M against 8.5-9.1M in f32, within the noise; the advance loop still vectorises.
`pendulum bench` reports the steps/s.) A reduction in f32 alone (π/2 in
8 + 8 + 24 bits) was 30 % faster in the f32 kernel but up to 1e7 ulp wrong: not used. Cephes' polynomials
wholly in f32 give 1.57 ulp, but an f32 flip map then parted from DOP853 where its trust mask vouched for it
(tests/test_fractal.py): the f32 form here is as close to libm's sinf as the f64 leading terms make it.

Measured error (ulp of the exact result; f64 and f32 against numpy's long double), tests/test_sincos.py, in
the scalar, the lane and the chunked-loop forms alike: sincos_f64 0.76 ulp, sincos_f32 0.76 ulp, on 3.6e5
arguments (uniform to |x| <= 1e5, log-spread from 1e-8, and the floats nearest k·π/2). The test holds f64
to 1 ulp and f32 to 1 ulp. Beyond |x| = 1.6e6 the reduction degrades slowly; |x| > 1e9 (where the i32
quadrant would overflow), NaN and ±inf give NaN. Subnormal inputs are flushed to 0 by Taichi's CPU runtime,
so sin(1e-310) = 0.
"""
import math

import taichi as ti

TWO_OVER_PI = 2.0 / math.pi
# π/2 split (fdlibm e_rem_pio2.c): P1 = pio2_1 (33 bits), P1T = pio2_1t (the rest), P2 = pio2_2 (the next
# 33 bits), P2T = pio2_2t.
P1 = 1.57079632673412561417e+00
P1T = 6.07710050650619224932e-11
P2 = 6.07710050630396597660e-11
P2T = 2.02226624879595063154e-21

# fdlibm k_sin.c / k_cos.c: |polynomial error| < 2^-58 on [−π/4, π/4]
S1, S2, S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
S4, S5, S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
C1, C2, C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
C4, C5, C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11

# Cephes sinf.c / cosf.c on [−π/4, π/4]
FS1, FS2, FS3 = -1.6666654611e-1, 8.3321608736e-3, -1.9515295891e-4
FC1, FC2, FC3 = 4.166664568298827e-2, -1.388731625493765e-3, 2.443315711809948e-5

XMAX = 1.0e9  # |x| beyond this gives NaN: the i32 quadrant would overflow near 3.4e9 into finite garbage


@ti.func
def _quadrant(k, s, c):
    """(sin, cos) of r + k·π/2 from s = sin r, c = cos r (k an i32): swap on odd k, negate by k mod 4."""
    swap = (k & 1) != 0
    a = ti.select(swap, c, s)
    b = ti.select(swap, s, c)
    return ti.select((k & 2) != 0, -a, a), ti.select(((k + 1) & 2) != 0, -b, b)


@ti.func
def _guard(x, s, c):
    """NaN for |x| > XMAX, NaN and ±inf, instead of a finite wrong value."""
    ok = ti.abs(x) <= XMAX
    return ti.select(ok, s, ti.math.nan), ti.select(ok, c, ti.math.nan)


@ti.func
def sincos_f64(x):
    """f64, fdlibm's way (< 1 ulp): a double-double r + rr (π/2 to 119 bits) and kernels that take the tail."""
    j = ti.round(x * TWO_OVER_PI)
    r0 = x - j * P1  # exact
    w = j * P2  # exact
    r1 = r0 - w
    tail = ((r0 - r1) - w) - j * P2T
    r = r1 + tail
    rr = (r1 - r) + tail
    z = r * r
    v = z * r
    ps = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))
    s = r - ((z * (0.5 * rr - v * ps) - rr) - v * S1)
    pc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))))
    hz = 0.5 * z
    wc = 1.0 - hz
    c = wc + (((1.0 - wc) - hz) + (z * pc - r * rr))
    sn, cs = _quadrant(ti.cast(j, ti.i32), s, c)
    return _guard(x, sn, cs)


@ti.func
def sincos_f32(x):
    """f32 result; x widened to f64 for the reduction (3 f64 ops), so r is right at any |x| < 1.6e6. The
    polynomials' tails run in f32 (8 lanes to a ymm register); sin = r + r·tail and cos = 1 − r²/2 + tail in
    f64, rounded once to f32, so their rounding errors shrink with the tails (a few % of the result)."""
    xd = ti.cast(x, ti.f64)
    j = ti.round(xd * ti.f64(TWO_OVER_PI))
    k = ti.cast(j, ti.i32)
    # j itself, not k converted back: the same value (|j| < 2^31 wherever _guard lets a result through), so the
    # same bits, and one conversion fewer a call: the rigid f32 RK4 kernel at N = 1e5 took 5-7 % more steps a
    # second (alternating, timed by a script not kept), and `pendulum bench`'s f32 peak fraction went from
    # 0.266-0.268 to 0.286-0.287 (AVX-512, docs/performance-log.md)
    r = (xd - j * ti.f64(P1)) - j * ti.f64(P1T)
    rf = ti.cast(r, ti.f32)
    zf = rf * rf
    ps = zf * (FS1 + zf * (FS2 + zf * FS3))  # the polynomials' tails in f32: their rounding is scaled down
    pc = zf * zf * (FC1 + zf * (FC2 + zf * FC3))
    s = ti.cast(r + r * ti.cast(ps, ti.f64), ti.f32)  # the leading terms in f64, rounded once
    c = ti.cast((1.0 - 0.5 * r * r) + ti.cast(pc, ti.f64), ti.f32)
    sn, cs = _quadrant(k, s, c)
    return _guard(x, sn, cs)


def _cfg():
    return ti.lang.impl.current_cfg()


@ti.func
def sincos(x):
    """(sin x, cos x), elementwise, in the runtime's float type. Branchless, no libm."""
    if ti.static(_cfg().fast_math):
        raise RuntimeError("render/physics/sincos.py needs Taichi started with fast_math=False (runtime.init does)")
    if ti.static(_cfg().default_fp == ti.f64):
        return sincos_f64(x)
    else:
        return sincos_f32(x)
