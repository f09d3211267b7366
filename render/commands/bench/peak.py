"""The machine's peak floating-point rate, as Taichi compiles arithmetic here, and the rigid RK4 kernel's share.

    rate = peak.Peak().timer(min_s)      # after runtime.init(arch, precision); rate() -> flop/s of one run

The kernel is many independent chains a <- a·b + c, parallel over a field of groups. Each group holds
CHAINS accumulators for each of its LANES pendulum-like columns in a local matrix; the loop over the columns
is the one LLVM's loop vectoriser runs (as in System.advance), and each column takes UNROLL steps of every
chain per visit, so CHAINS · UNROLL products and sums per load and store of the matrix. CHAINS independent
vectors are enough to keep the multiply and add pipes busy through their latency (12 x 8 was the fastest
of the shapes tried on an AVX2 machine here: 8 to 24 chains, 4 to 16 steps; where a forced width takes more
lanes, fewer chains in as many registers). The accumulators are written
to a field, so nothing can be optimised away, and a run's result is a fixed function of its arguments
(tests/test_peak.py: bit for bit the same recurrence in numpy). Checked in the generated assembly: the
steps are vmulpd and vaddpd on ymm registers, no FMA (zmm where render/physics/vector_width.py sets 16 or 32
lanes, as it does for the RK4 kernel timed against this one).

runtime.init runs Taichi with fast_math off, under which LLVM may not fuse a·b + c into an FMA: each step is
a multiply and an add (2 flops, as an FMA counts them), the same instructions the rigid kernel is made of.
On AMD Zen (the machines here), whose two multiply and two add pipes issue together, that is the same flop
rate as FMAs; on a CPU that runs both on its FMA ports it is half the FMA peak.
"""

import taichi as ti

from . import peers
from ...physics import runtime, vector_width

CHAINS, UNROLL = 12, 8
LANES = {"f64": 16, "f32": 32}  # 4 AVX2 registers of lanes either way, or a forced width's (as System.chunk)
GROUPS = 1024  # parallel items: many per core even on a large machine, so a busy core delays only its share
# (spread by runtime.SPREAD: in Taichi's blocks of 512 iterations they were two tasks, two threads at most)
B, C = 0.999, 0.001  # a -> c / (1 - b) = 1 from any start: no overflow, no subnormal, at any iteration count

# Flops of one RK4 step of one rigid double pendulum (RigidKernels.accel, render/physics/sincos.py, steps.rk4), each
# add, subtract, multiply and divide counted once; products of the scene's constants are folded in Python
# before Taichi sees them (m1, m2, l1, l2, g), and identical subexpressions (w1·w1·l1, w2·w2·l2, 2·sd) once,
# as LLVM computes them; 0.5·h and h/6 are hoisted out of the step loop. Negations, selects and the |x|
# guard are not counted.
#   sincos_f64: reduction 12 (j, r0, w, r1, tail, r, rr), z and z·r 2, sin 16 (ps 8), cos 20 (pc 11) = 50
#   sincos_f32: reduction 5 (j, r: in f64), z 1, the tails 11 (in f32), sin 2 and cos 4 (in f64) = 23
#   accel beyond its two sincos: sd, cd 6, den 4, a1 18, a2 9 = 37
#   rk4: 4 accel; the stages q + (h/2)·v ... 3 x 8 = 24; the combination 2 coordinates x 7 for q and v = 28
# f64: 4·(2·50 + 37) + 24 + 28 = 600; f32: 4·(2·23 + 37) + 52 = 384 (88 of them in f64, half the f32 rate).
# A product by a length or m2 of exactly 1 is dropped by LLVM (x·1 = x in IEEE arithmetic too): l1 and l2
# are in 2 products per evaluation each (l·den, w·w·l), m2 in 3 (m2·sd, 2·sd·m2, ...·l2·m2·cd).
# tests/test_peak.py counts the arithmetic in the compiled loop's LLVM IR against rigid_rk4_flops.
RIGID_RK4_FLOPS = {"f64": 600, "f32": 384}


def rigid_rk4_flops(precision: str, lengths, masses) -> int:
    """Flops of one RK4 step of one rigid double pendulum as compiled for these constants."""
    (l1, l2), m2 = lengths, masses[1]
    return RIGID_RK4_FLOPS[precision] - 4 * (2 * (l1 == 1.0) + 2 * (l2 == 1.0) + 3 * (m2 == 1.0))


@ti.data_oriented
class Peak:
    def __init__(self, groups: int = GROUPS):
        self.precision = "f64" if runtime.real() == ti.f64 else "f32"
        self.lanes, self.groups = vector_width.lanes(LANES[self.precision]), groups
        # as many registers of accumulators at a forced width as at 16 f64 lanes: 12 chains of 32 f64 lanes are
        # 48 zmm registers, more than there are, and ran at 86 GFLOPS against 265 at 16 lanes; 6 chains at 267
        # (2-core AMD EPYC, python benchmarks/vector_width.py --widths 16 32)
        self.count = max(1, CHAINS * LANES[self.precision] // self.lanes)
        self.out = runtime.field("peak.accumulators", runtime.real(), (groups, self.count, self.lanes))

    def flops(self, iters: int) -> float:
        return 2.0 * self.groups * self.count * self.lanes * UNROLL * iters

    @ti.kernel
    def chains(self, iters: ti.i32, b: float, c: float):
        """iters x UNROLL steps of a <- a·b + c on every accumulator; a starts at start(g, k, lane)."""
        L = ti.static(self.lanes)
        S = ti.static(runtime.SPREAD)
        for t in range(self.groups * S):  # spread over the threads as the advance kernel is (runtime.SPREAD)
            if t % S == 0:
                g = t // S
                A = ti.Matrix.zero(float, self.count, L)
                for lane in range(L):
                    for k in ti.static(range(self.count)):
                        A[k, lane] = self.start(g, k, lane)
                for _ in range(iters):
                    for lane in range(L):  # the loop LLVM vectorises
                        a = A[:, lane]
                        for _u in ti.static(range(UNROLL)):
                            a = a * b + c
                        A[:, lane] = a
                for lane in range(L):
                    for k in ti.static(range(self.count)):
                        self.out[g, k, lane] = A[k, lane]

    @ti.func
    def start(self, g, k, lane):
        """(flat index + 1) / (count + 1), in (0, 1): every chain starts elsewhere (exact in f32 too: < 2^24)."""
        i = (g * self.count + k) * self.lanes + lane
        return (ti.cast(i, float) + 1.0) * (1.0 / (self.groups * self.count * self.lanes + 1))

    def run(self, iters: int, b: float = B, c: float = C):
        self.chains(iters, b, c)
        ti.sync()

    def timer(self, min_s: float):
        """rate(): flop/s of one run of at least min_s (its iteration count found here; the first run compiles)."""
        return peers.timer(self.run, self.flops(1), min_s)
