"""Cost per frame of each effect, toggled one at a time on the same scene (simulate + draw, no encoding).

    .venv/bin/python benchmarks/effects.py [--frames 240] [--clock wall|cpu] [--out out/bench/effects.md]

Each row adds one effect to the row above and reports ms per frame at the preset's 1280x720, 60 fps, so the
difference between rows is what that effect costs. Times are medians of per-frame times after a warm-up
that pays for kernel compilation; each row is measured --repeat times, round-robin, keeping the fastest
median, since a 2-core machine is noisy at the 0.5 ms level. The noise of a row is the range of its totals
over the rounds; a difference between two rows no larger than the noise of either is shown as "±", not as
a number (with --repeat 1 there is no noise to tell, and every difference is shown). On a machine others are using, wall times
measure the load; `--clock cpu` runs Taichi on one thread and times each frame in CPU time of this process
(time.process_time), which time-sharing does not inflate: the cost of a frame, not how long it waited.

Glow is not a layer on top but the way a scene's lines are drawn (render/draw/glow.py: antialiased hairlines
whose light adds up, where the plain canvas scores every pixel of a band around a line and keeps the max),
so it enters a ladder with the rods it draws: glowing rods cost less than plain ones, and glow added last
read as a saving. Each ladder is its preset's own effects (rigid_chaos adds damping, which it lacks).

rainbow_1000 is measured from t = 8 s (simulated, not drawn, up to there), when its 1000 pendulums have
sprayed over the whole frame: its first seconds, one coherent line, cost far less to draw. The HUD is drawn
as `render` draws it, except that it has no certificate here (no ticks: two columns of pixels).
"""
import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.physics import runtime  # noqa: E402
from render.physics.stepper import Run  # noqa: E402
from render.draw.canvas import Canvas  # noqa: E402
from render.config.scene import load  # noqa: E402

LADDERS = {
    "rigid_chaos": [["energy"], ["bobs"], ["bobs", "rods"], ["bobs", "rods", "trails"],
                    ["bobs", "rods", "trails", "energy"], ["bobs", "rods", "trails", "energy", "damping"],
                    ["bobs", "rods", "trails", "energy", "damping", "hud"]],
    "elastic_fan": [["energy"], ["bobs"], ["bobs", "springs"], ["bobs", "springs", "trails"],
                    ["bobs", "springs", "trails", "energy"], ["bobs", "springs", "trails", "energy", "hud"]],
    "rainbow_1000": [["energy"], ["glow", "rods"], ["glow", "rods", "trails"], ["glow", "rods", "trails", "energy"],
                     ["glow", "rods", "trails", "energy", "hud"]],
}
START_S = {"rainbow_1000": 8.0}  # measure from here (see above)
WARMUP = 10


def measure(preset: str, effects: list[str], frames: int, cpu: bool = False) -> dict:
    start = round(START_S.get(preset, 0.0) * 60)
    sets = [f"effects={effects!r}".replace("'", '"'), f"video.duration={(start + frames + WARMUP) / 60}"]
    if "damping" in effects:
        sets.append("pendulums.damping=0.1")
    scene = load(preset, sets)
    run = Run(scene, "cpu", 1 if cpu else None)
    clock = time.process_time if cpu else time.perf_counter
    sim = run.sim
    drawn = any(e in scene.effects for e in ("bobs", "rods", "springs", "trails"))
    canvas = Canvas(scene, sim) if drawn else None
    sim_ms, draw_ms = [], []
    steps = run.frames(timings={"simulate": 0.0})
    while True:
        t = clock()
        f = next(steps, None)  # simulates the frame (and its energy and watchdog)
        if f is None:
            break
        simulated = clock() - t
        if f < start:  # simulated up to the start, not drawn
            continue
        sim_ms.append(simulated * 1e3)
        t = clock()
        if canvas:
            canvas.draw()
        draw_ms.append((clock() - t) * 1e3)
    sim_ms, draw_ms = sim_ms[WARMUP:], draw_ms[WARMUP:]
    return {"preset": preset, "effects": effects, "sim": statistics.median(sim_ms),
            "draw": statistics.median(draw_ms), "fields": sum(runtime.allocated.values()),
            "kernels": len(runtime.launched)}


def total(r: dict) -> float:
    return r["sim"] + r["draw"]


def best(runs: list[dict]) -> dict:
    """A row's fastest round, with its noise: the range of its totals over the rounds."""
    return {**min(runs, key=total), "noise": max(map(total, runs)) - min(map(total, runs))}


def added(r: dict, prev: dict | None) -> str:
    """What the row's last effect adds: blank for a scene's first row, "±" within the noise of either row."""
    if prev is None or prev["preset"] != r["preset"]:
        return ""
    d = total(r) - total(prev)
    return "±" if abs(d) <= max(r["noise"], prev["noise"]) else f"{d:+.2f}"


def table(rows: list[dict]) -> str:
    out = ["| scene | effects | simulate ms/frame | draw ms/frame | total ms/frame | added by the last effect | "
           "noise ms/frame | field MB | kernels |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    prev = None
    for r in rows:
        effects = ", ".join(r["effects"]) if r["effects"] != ["energy"] else "energy only (no drawing)"
        out.append(f"| {r['preset']} | {effects} | {r['sim']:.2f} | {r['draw']:.2f} | {total(r):.2f} | "
                   f"{added(r, prev)} | {r['noise']:.2f} | {r['fields'] / 1e6:.1f} | {r['kernels']} |")
        prev = r
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=240, help="timed frames per row (default 240)")
    ap.add_argument("--repeat", type=int, default=3, help="rounds over all rows (default 3)")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="wall: all threads, wall time; cpu: one Taichi thread, CPU time (see above)")
    ap.add_argument("--out", type=Path, help="also write the markdown table here")
    args = ap.parse_args(argv)
    configs = [(p, e) for p, ladder in LADDERS.items() for e in ladder]
    rounds = [[measure(p, e, args.frames, args.clock == "cpu") for p, e in configs] for _ in range(args.repeat)]
    rows = [best(list(runs)) for runs in zip(*rounds)]
    text = table(rows)
    print(text)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
