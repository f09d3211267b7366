"""What the loop vectoriser's width buys: render/physics/vector_width.py's choice, measured.

    python benchmarks/vector_width.py [--widths 0 8 16 32] [--rounds 3] [--renders]

For each width (0: LLVM's own), in its own processes, since LLVM parses its options once per process: the
rigid RK4 advance at N = 1e5 (steps/s, f64 and f32), the peak kernel of render/commands/bench/peak.py (GFLOPS), the
time of the first launch of each (compiling, from an empty offline cache) and a hash of the state after 500
steps from the same start, equal at every width when the arithmetic is. With --renders, also the wall time
of two short renders (rigid_chaos 5 s and the flip map fractal_flip 2 s, MP4 + GIF, certificate included),
drawn at the same width. Rounds interleave the widths; each figure is the median over rounds, with its range.
Each width has its own offline cache in a temporary folder: the first round compiles, the others find it.
"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def child(prec: str):
    """One process at the width PENDULUM_VECTOR_WIDTH says: a JSON line of its figures."""
    import taichi as ti
    from render.commands.bench import peak, peers
    from render.config.scene import load
    from render.physics import vector_width
    from render.physics.stepper import Run

    scene = load("rigid_chaos", ["pendulums.count=100000", 'integrator.method="rk4"', "integrator.dt=1e-3",
                                 f'integrator.precision="{prec}"', 'effects=["bobs"]'])
    sim = Run(scene, "cpu").sim
    kern = f"{sim.NAME}_advance"
    t = time.perf_counter()
    sim.launch(kern, 1)
    ti.sync()
    compile_s = time.perf_counter() - t
    sim.launch(kern, 499)
    ti.sync()
    state = hashlib.sha1(sim.q.to_numpy().tobytes() + sim.v.to_numpy().tobytes()).hexdigest()[:12]
    p = peak.Peak()
    t = time.perf_counter()
    p.run(1)
    peak_compile_s = time.perf_counter() - t
    rates = peers.interleave({"sim": peers.timer(lambda k: (sim.launch(kern, k), ti.sync()), 100000, 1.0),
                              "peak": p.timer(1.0)}, 1)
    print(json.dumps({"width": vector_width.apply(), "steps_per_s": rates["sim"][0], "peak_flops": rates["peak"][0],
                      "compile_s": compile_s, "peak_compile_s": peak_compile_s, "state": state}))


def render_s(env: dict, out: str, preset: str, seconds: float) -> float:
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "render", "render", preset, "--set", f"video.duration={seconds}",
                    "--out", out, "--no-progress"], env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--widths", type=int, nargs="+", default=[0, 8, 16, 32])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--renders", action="store_true", help="time two short renders at each width too")
    ap.add_argument("--child", choices=["f32", "f64"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args.child)
    seen: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for w in args.widths:
                env = dict(os.environ, PENDULUM_VECTOR_WIDTH=str(w), TI_SKIP_VERSION_CHECK="ON",
                           TI_OFFLINE_CACHE_FILE_PATH=os.path.join(tmp, f"cache{w}"))
                for prec in ("f64", "f32"):
                    line = subprocess.run([sys.executable, __file__, "--child", prec], env=env, check=True,
                                          capture_output=True, text=True).stdout.strip().splitlines()[-1]
                    got = json.loads(line)
                    row = seen.setdefault((w, prec), {"width": got["width"], "state": got["state"], "runs": []})
                    if r == 0:
                        row["compile_s"], row["peak_compile_s"] = got["compile_s"], got["peak_compile_s"]
                    row["runs"].append((got["steps_per_s"], got["peak_flops"]))
                if args.renders:
                    for preset, seconds in (("rigid_chaos", 5), ("fractal_flip", 2)):
                        s = render_s(env, os.path.join(tmp, f"out{w}"), preset, seconds)
                        seen.setdefault((w, preset), {"runs": []})["runs"].append(s)
    med = lambda xs: f"{statistics.median(xs):.4g} ({min(xs):.4g}-{max(xs):.4g})"
    load = os.getloadavg()[0]
    print(f"{args.rounds} rounds, load average {load:.2f} at the end")
    print("| width asked (set) | precision | rigid RK4 steps/s, N = 1e5 | peak GFLOPS | first launch s (advance, "
          "peak) | state after 500 steps |")
    print("|---|---|---|---|---|---|")
    for (w, prec), row in seen.items():
        if prec in ("f32", "f64"):
            sim = [a / 1e6 for a, _ in row["runs"]]
            pk = [b / 1e9 for _, b in row["runs"]]
            print(f"| {w} ({row['width']}) | {prec} | {med(sim)}M | {med(pk)} | {row['compile_s']:.2f}, "
                  f"{row['peak_compile_s']:.2f} | {row['state']} |")
    if args.renders:
        print("\n| width asked | render | wall s |\n|---|---|---|")
        for (w, what), row in seen.items():
            if what not in ("f32", "f64"):
                print(f"| {w} | {what} | {med(row['runs'])} |")


if __name__ == "__main__":
    main()
