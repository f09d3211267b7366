"""Where the bench's end-to-end render and its encode floor spend the machine's cores: the lower bound on their ratio.

    .venv/bin/python benchmarks/cpu_budget.py [--rounds 3] [--seconds 20]

Runs what `pendulum bench` times for end_to_end_over_encode_floor, as its e2e phase does
(render/commands/bench/e2e.py): rigid_chaos's frames recorded once, then its encode floor and its render (after a
one-frame warm-up render), alternating, once a round. For each it prints the wall time, this process's CPU time, its
ffmpeg children's CPU time (they are waited for inside the span), and the cores' idle time over the span (from
/proc/stat: the whole machine's, so run it on a quiet one). The floor's span is its Encoder's, from its creation
to the end of close(), as the bench times it; recording the floor's frames beforehand is not in it.

A render cannot take less wall time than its CPU time shared perfectly over the cores, so the last line divides
the median render's CPU time by the core count and by the median floor: the end_to_end_over_encode_floor that a
render could reach with every core busy from its first instant to its last, at the CPU cost it has now. What the
render leaves idle (its serial start, mostly) is the rest of the gap.
"""
import argparse
import os
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.commands.bench import e2e  # noqa: E402
from render.video import pipeline  # noqa: E402


def usage() -> tuple[float, float, float, float]:
    """(wall s, this process's CPU s, its waited-for children's CPU s, the machine's idle core-s so far)."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    with open("/proc/stat") as f:
        ticks = [int(v) for v in f.readline().split()[1:]]
    idle = (ticks[3] + ticks[4]) / os.sysconf("SC_CLK_TCK")  # idle and iowait
    return time.perf_counter(), me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime, idle


def spent(a, b) -> dict:
    wall, ours, ffmpeg, idle = (y - x for x, y in zip(a, b))
    return {"wall": wall, "ours": ours, "ffmpeg": ffmpeg, "idle": idle}


def floor(rec: dict, tmp: Path) -> dict:
    """One encode floor as the bench times it (e2e.encode_floor: from its Encoder's creation to the end of its
    close())."""
    start = usage()
    e2e.encode_floor(rec, tmp)
    return spent(start, usage())


def render(scene, tmp: Path) -> dict:
    start = usage()
    pipeline.render(scene, tmp / "timed")
    return spent(start, usage())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=20.0, help="rigid_chaos's duration (the bench's: 20)")
    args = ap.parse_args(argv)
    cfg = {"chaos_s": args.seconds}
    scene = e2e.chaos_scene(cfg)
    cores = os.cpu_count()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rec = e2e.record_frames(cfg, "cpu", tmp)
        pipeline.render(scene.replace(video={"duration": 1.0 / scene.video.fps}), tmp / "warm")
        rows = []
        for r in range(args.rounds):
            rows += [("floor", r, floor(rec, tmp)), ("render", r, render(scene, tmp))]
    print(f"rigid_chaos, {args.seconds:g} s; seconds of wall, of CPU (ours, ffmpeg's) and of idle cores ({cores}):")
    for name, r, s in rows:
        print(f"  {name:6s} round {r + 1}: wall {s['wall']:5.2f}  ours {s['ours']:5.2f}  ffmpeg {s['ffmpeg']:5.2f}  "
              f"total {s['ours'] + s['ffmpeg']:5.2f}  idle {s['idle']:5.2f}")
    med = {name: {k: statistics.median(s[k] for n, _, s in rows if n == name) for k in ("wall", "ours", "ffmpeg")}
           for name in ("floor", "render")}
    packed = (med["render"]["ours"] + med["render"]["ffmpeg"]) / cores
    print(f"medians: render {med['render']['wall']:.2f} s over floor {med['floor']['wall']:.2f} s = "
          f"{med['render']['wall'] / med['floor']['wall']:.3f}; the render's CPU on {cores} cores with none idle: "
          f"{packed:.2f} s, a ratio of {packed / med['floor']['wall']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
