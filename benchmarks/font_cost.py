"""Per-call cost of render/draw/font.py on a 1280×720 frame: microseconds per draw call, best of 5 rounds.

    python benchmarks/font_cost.py [--threads N]

Cases: the clock alone ("t = 12.34 s", 9 glyphs), a HUD in one draw_many call (clock, caption and
settings in 10x20, 8 tick labels in 6x13: 97 glyphs), and 300 glyphs at scale 2; each into the uint8 frame
and into a Vector.field(3, f32) like the canvas's layer. The host-side layout alone and an empty Taichi kernel are
timed too, for scale: most of a small call is Taichi's launch overhead (an ndarray argument costs more than
the kernel's work).
"""
import argparse
import os
import time

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")

import numpy as np  # noqa: E402
import taichi as ti  # noqa: E402

from render.physics import runtime  # noqa: E402


def best_us(fn, calls=200, rounds=5):
    fn()  # compile
    best = float("inf")
    for _ in range(rounds):
        t = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - t) / calls * 1e6)
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    runtime.init("cpu", "f64", args.threads)
    from render.draw.font import Font

    font = Font("10x20")
    frame = np.zeros((720, 1280, 3), np.uint8)
    layer = ti.Vector.field(3, ti.f32, (720, 1280))
    ticks = [(lab, 100 + 140 * i, 690, {"ha": "center", "colour": (0.7, 0.7, 0.7), "size": "6x13"})
             for i, lab in enumerate(["-π", "-3π/4", "-π/2", "-π/4", "0", "π/4", "π/2", "π"])]
    hud = [("t = 12.34 s", 20, 16), ("100 rigid pendulums, 1e-6 rad apart: one arm for 4 s, a spray by 8 s", 20, 44),
           ("rk4 dt=1e-3 f64", 1260, 16, {"ha": "right"})]
    many = [("0123456789" * 3, 10, 40 + 45 * i, {"scale": 2}) for i in range(10)]  # 300 glyphs of 20×40 px

    @ti.kernel
    def empty():
        pass

    rows = []
    rows.append(("empty Taichi kernel (launch overhead)", best_us(empty)))
    rows.append(("layout only: clock", best_us(lambda: font.layout("t = 12.34 s", 20, 16))))
    for label, target in (("uint8 frame", frame), ("f32 field", layer)):
        rows.append((f"clock, 9 glyphs -> {label}", best_us(lambda: font.draw(target, "t = 12.34 s", 20, 16))))
        rows.append((f"HUD: 3 lines (10x20) + 8 ticks (6x13), one draw_many -> {label}",
                     best_us(lambda: font.draw_many(target, hud + ticks))))
        static = np.concatenate([font.layout(*t[:3], **(t[3] if len(t) > 3 else {})) for t in hud[1:] + ticks])
        rows.append((f"HUD, static text laid out once, clock per frame -> {label}",
                     best_us(lambda: font.draw_glyphs(target, np.concatenate([font.layout("t = 12.34 s", 20, 16),
                                                                                static])))))
        rows.append((f"300 glyphs at scale 2 -> {label}", best_us(lambda: font.draw_many(target, many), calls=50)))
    n_hud = sum(len(font.layout(*h[:3], **(h[3] if len(h) > 3 else {}))) for h in hud + ticks)
    print(f"threads={args.threads or 'default'}; the HUD case draws {n_hud} glyphs")
    for name, us in rows:
        print(f"{us:9.1f} us  {name}")


if __name__ == "__main__":
    main()
