"""What limits the simulation kernels on a CPU: the sin/cos calls. Three forms of the same rigid RK4 step.

    .venv/bin/python benchmarks/sim_trig.py [--n 100000] [--precision f64]

- libm x6: render/rigid.py's force as written: sin/cos of d, 2d, θ1 and θ1 - 2θ2, each a call into libm
  (Taichi's CPU JIT targets generic x86-64 and emits scalar calls; 24 per RK4 step).
- libm x4: sin/cos of θ1 and θ2 only, the rest by angle-addition identities (same physics, fewer calls).
- poly sincos: the x4 form with an inline polynomial sin/cos (Cody-Waite reduction to [-π/4, π/4], Taylor to
  degree 13/14): no calls at all; agrees with libm to round-off in f64.

It prints pendulum-substeps per second for each and the largest difference from the libm x6 result after
2000 steps. This is an experiment for benchmarks/README.md, not the shipped kernel.
"""
import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import render  # noqa: E402,F401  (quiet Taichi start-up)
import taichi as ti  # noqa: E402

M1 = M2 = L1 = L2 = 1.0
G = 9.8


@ti.func
def rhs(s1, c1, sd, cd, s12, v):
    """θ1'', θ2'' from the sines and cosines they need (render/rigid.py's equations)."""
    den = 2.0 * M1 + M2 - M2 * (1.0 - 2.0 * sd * sd)  # cos 2d = 1 - 2 sin² d
    a1 = (-G * (2.0 * M1 + M2) * s1 - M2 * G * s12
          - 2.0 * sd * M2 * (v[1] * v[1] * L2 + v[0] * v[0] * L1 * cd)) / (L1 * den)
    a2 = 2.0 * sd * (v[0] * v[0] * L1 * (M1 + M2) + G * (M1 + M2) * c1 + v[1] * v[1] * L2 * M2 * cd) / (L2 * den)
    return ti.Vector([a1, a2])


@ti.func
def accel_x6(q, v):
    d = q[0] - q[1]
    sd, cd = ti.sin(d), ti.cos(d)
    den = 2.0 * M1 + M2 - M2 * ti.cos(2.0 * d)
    a1 = (-G * (2.0 * M1 + M2) * ti.sin(q[0]) - M2 * G * ti.sin(q[0] - 2.0 * q[1])
          - 2.0 * sd * M2 * (v[1] * v[1] * L2 + v[0] * v[0] * L1 * cd)) / (L1 * den)
    a2 = 2.0 * sd * (v[0] * v[0] * L1 * (M1 + M2) + G * (M1 + M2) * ti.cos(q[0]) + v[1] * v[1] * L2 * M2 * cd)
    return ti.Vector([a1, a2 / (L2 * den)])


@ti.func
def from_angles(s1, c1, s2, c2, v):
    sd, cd = s1 * c2 - c1 * s2, c1 * c2 + s1 * s2
    return rhs(s1, c1, sd, cd, sd * c2 - cd * s2, v)  # sin(θ1 - 2θ2) = sin(d - θ2)


@ti.func
def accel_x4(q, v):
    return from_angles(ti.sin(q[0]), ti.cos(q[0]), ti.sin(q[1]), ti.cos(q[1]), v)


@ti.func
def sincos(x):
    j = ti.round(x * (2.0 / math.pi))
    r = (x - j * 1.5707963267341256) - j * 6.077100506506192e-11  # π/2 in two parts (Cody-Waite)
    r2 = r * r
    s = r * (1.0 + r2 * (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880 + r2 * (
        -1.0 / 39916800 + r2 / 6227020800.0))))))
    c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 + r2 * (
        1.0 / 479001600 - r2 / 87178291200.0))))))
    k = ti.cast(j, ti.i32) & 3
    sn, cs = s, c
    if k == 1:
        sn, cs = c, -s
    elif k == 2:
        sn, cs = -s, -c
    elif k == 3:
        sn, cs = -c, s
    return sn, cs


@ti.func
def accel_poly(q, v):
    s1, c1 = sincos(q[0])
    s2, c2 = sincos(q[1])
    return from_angles(s1, c1, s2, c2, v)


def kernel(accel, q, v, h):
    @ti.func
    def rk4(x, w):
        a1 = accel(x, w)
        a2 = accel(x + 0.5 * h * w, w + 0.5 * h * a1)
        a3 = accel(x + 0.5 * h * (w + 0.5 * h * a1), w + 0.5 * h * a2)
        a4 = accel(x + h * (w + 0.5 * h * a2), w + h * a3)
        w2, w3, w4 = w + 0.5 * h * a1, w + 0.5 * h * a2, w + h * a3
        return x + h / 6.0 * (w + 2.0 * w2 + 2.0 * w3 + w4), w + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)

    @ti.kernel
    def advance(k: ti.i32):
        for i in q:
            x, w = q[i], v[i]
            for _ in range(k):
                x, w = rk4(x, w)
            q[i], v[i] = x, w
    return advance


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--precision", choices=("f32", "f64"), default="f64")
    args = ap.parse_args(argv)
    real = ti.f64 if args.precision == "f64" else ti.f32
    ti.init(arch=ti.cpu, default_fp=real, log_level=ti.ERROR)
    q, v = ti.Vector.field(2, real, args.n), ti.Vector.field(2, real, args.n)
    start = np.stack([np.linspace(-3, 3, args.n), np.linspace(3, -3, args.n)], 1)
    results = {}
    for name, accel in (("libm x6", accel_x6), ("libm x4", accel_x4), ("poly sincos", accel_poly)):
        q.from_numpy(start.astype(np.float64 if args.precision == "f64" else np.float32))
        v.fill(0)
        advance = kernel(accel, q, v, 1e-3)
        advance(1)
        best = math.inf
        for _ in range(3):
            t = time.perf_counter()
            advance(17)
            ti.sync()
            best = min(best, time.perf_counter() - t)
        advance(2000 - 1 - 3 * 17)
        results[name] = q.to_numpy().astype(np.float64)
        diff = np.abs(results[name] - results["libm x6"]).max()
        print(f"{args.precision} {name:12s} {args.n * 17 / best / 1e6:6.1f} M pendulum-substeps/s, "
              f"max |Δθ| vs libm x6 after 2000 steps {diff:.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
