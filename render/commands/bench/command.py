"""`pendulum bench`: how close a render comes to the encoder's floor, simulation vs numpy, and the fractal.

Every phase runs in its own subprocess (a fresh Taichi runtime: render/commands/bench/process.py) while this
process samples the resident memory of that process tree (ffmpeg included), so all figures of one report come
from one run. Precision is fixed per Taichi init, so the simulation phase runs f32, then f64. Every ratio
against a peer (numpy, numba, matplotlib, the peak rate of render/commands/bench/peak.py) comes from --repeat
interleaved rounds (render/commands/bench/peers.py) and is reported with its spread over them. Method and findings:
benchmarks/README.md.
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ...config import estimate
from . import peers
from .e2e import CHAOS, chaos_scene, phase_e2e, timed_render
from .process import maxrss_mb, run_phase
from .sim import phase_sim
from .report import cpu_kind, fmt, load_text, markdown, summarise, targets_table, width_text
from ...video.atomic import together, write_atomic
from ...config.options import check_replaceable, check_writable, out_path, positive_int
from ...physics import vector_width

RAINBOW = "rainbow_1000"
FRACTALS = {"angles": "fractal", "flip_time": "fractal_flip", "divergence": "fractal_divergence",
            "lyapunov": "fractal_lyapunov"}  # colouring: preset (each measured at 720p: SIZE)
SIZE = ["video.width=1280", "video.height=720"]
# fractal_s: seconds of each map rendered (None: the preset's own). A flip map speeds up as pixels flip and
# stop, so it is timed over its whole 20 s. The divergence map (issue 27's other map target) is timed over its
# whole 10 s too: its fps counts the certificate, about 1.2 s at 720p whatever the length, which was a tenth
# of a 2 s map's wall (9.89 fps there, 2026-12-04) and is a fiftieth of the map a user renders. The others cost
# about the same every frame, so 2 s tell (the FTLE map 1 s: 30 frames at 720p, 8.3 s in all on 2026-12-07,
# docs/performance-log.md).
# rounds: interleaved rounds of every comparison with a peer, and how many times the end-to-end render and its
# encode floor are timed (--repeat); peer_s: seconds of rigid_chaos that both sides render and draw in the
# matplotlib phase (10 s: 600 frames); warm_maps: render a map's first frame before timing it (phase_fractal).
FULL = {"ladder": [100, 1000, 10**4, 10**5, 10**6], "chaos_s": 20.0, "min_s": 0.3, "rainbow_s": None, "peer_s": 10.0,
        "fractal_s": {"angles": 2.0, "flip_time": None, "divergence": None, "lyapunov": 1.0}, "rounds": 3,
        "warm_maps": True}
FILES = ("report.json", "report.md", "rates.json", "targets.md")  # what a run writes into --out
QUICK = {"ladder": [100, 10**5], "chaos_s": 2.0, "min_s": 0.1, "rainbow_s": 3.0, "peer_s": 1.0,
         "fractal_s": {"angles": 0.1, "flip_time": 0.1, "divergence": 0.1, "lyapunov": 0.1},  # smoke: a few frames
         "rounds": 2, "warm_maps": False}
MAX_ROUNDS = 20


def add_parser(sub):
    p = sub.add_parser("bench", help="performance report: simulate, draw, encode, end to end, fractal, peers",
                       description="Measure simulation throughput (Taichi vs numpy and numba, and its share of "
                                   "the machine's peak flop rate), drawing and encoding fps, the HUD, an "
                                   "end-to-end render against the encode-only floor, the matplotlib peer, and "
                                   "the fractal maps, each ratio over interleaved rounds with its spread; "
                                   "write OUT/report.md, OUT/report.json, OUT/targets.md (the targets' table) and "
                                   "OUT/rates.json: this machine's rates, "
                                   "from which `render --out DIR` estimates its run time when they are "
                                   "DIR/bench/rates.json (the default out/bench serves the default out).")
    p.add_argument("--quick", action="store_true", help="small N ladder, short videos, 2 rounds (a few minutes)")
    p.add_argument("--out", type=out_path, default=Path("out/bench"), help="output folder (default: out/bench)")
    p.add_argument("--arch", choices=("cpu", "cuda"), default="cpu", help="Taichi backend (default: cpu)")
    p.add_argument("--repeat", type=lambda t: positive_int(t, MAX_ROUNDS), metavar="R",
                   help=f"interleaved rounds of each comparison with a peer, and the number of timed "
                        f"rigid_chaos renders and encode floors, 1 to {MAX_ROUNDS} (default: 3; --quick: 2)")
    p.add_argument("--phase", help=argparse.SUPPRESS)  # internal: run one phase in this process
    p.add_argument("--result", type=Path, help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def run(args) -> int:
    cfg = QUICK if args.quick else FULL
    if args.repeat is not None:
        cfg = {**cfg, "rounds": args.repeat}
    if args.phase:
        result = PHASES[args.phase](cfg, args.arch, args.out)
        args.result.write_text(json.dumps({**result, "maxrss_mb": maxrss_mb()}))
        return 0
    check_writable(args.out)
    for name in FILES:  # a folder or an immutable file where one goes: refused now, not after minutes of bench
        check_replaceable(args.out / name)
    width = vector_width.planned()  # a bad $PENDULUM_VECTOR_WIDTH stops the bench here, not in its first phase
    ftle = vector_width.planned(tangents=True)
    load = os.getloadavg()  # other work on the machine skews every figure: the report says how much
    print(f"bench: load average {load_text(load)} at the start, {cpu_kind()} CPU, "
          f"{width_text({'vector_width': width, 'llvm_cpu': vector_width.llvm_cpu(), 'vector_width_ftle': ftle})}",
          file=sys.stderr)
    t0, res = time.perf_counter(), {}
    with tempfile.TemporaryDirectory(prefix="pendulum-bench-") as tmp:
        for name in PHASES:
            print(f"bench: {name} ...", file=sys.stderr, flush=True)
            res[name] = run_phase(name, args, Path(tmp))
    report = summarise(res, args.quick, time.perf_counter() - t0, cfg["chaos_s"], load)
    print(f"bench: load average {load_text(report['machine']['load_avg_end'])} at the end", file=sys.stderr)
    with together(args.out):  # the report, the rates and the table appear together, or none of them
        write_atomic(args.out / "report.json", (json.dumps(report, indent=2) + "\n").encode())
        write_atomic(args.out / "report.md", markdown(report).encode())
        # This machine's rates for the run-time budget of renders into the OUT above (render/config/estimate.py)
        rates = {**estimate.measured(res, chaos_scene(cfg)), "created": report["created"], "quick": report["quick"]}
        write_atomic(args.out / "rates.json", (json.dumps(rates, indent=2) + "\n").encode())
        m = report["machine"]
        line = (f"`pendulum bench{' --quick' if report['quick'] else ''}`, {report['created']}, {m['cpus']} CPUs "
                f"({m['cpu']}, {m['cpu_kind']} targets, {width_text(m)}), load average {m['load_avg'][0]:.2f} at the "
                f"start and {m['load_avg_end'][0]:.2f} at the end, {report['rounds']} interleaved rounds, numba "
                f"{report['peers']['numba']}.")
        # for docs/performance.md (benchmarks/readme_figures.py)
        write_atomic(args.out / "targets.md", "\n".join(targets_table(report) + ["", line]).encode() + b"\n")
    for key, t in report["targets"].items():
        print(f"{key} = {fmt(t['value'])} (target {t['goal']}): "
              f"{'met' if t['met'] else 'not measured' if t['met'] is None else 'MISSED'}")
    print(f"-> {args.out}/report.md ({report['wall_s']:.0f} s)")
    return 0


# ---------------------------------------------------------------- phases

def phase_fractal(colouring, cfg, arch, tmp) -> dict:
    """One map preset rendered at 720p as it ships (its accurate step, MP4 + GIF + PNG); fps = frames / wall,
    the certificate included. The full bench renders its first frame before, at the same size, so that the
    timed render finds the same systems built (render/physics/stepper.py) and its kernels in Taichi's cache: a
    smaller warm-up would compile other kernels, since a map's size is a constant of them. The quick one, a
    smoke test, times the compiles too."""
    from ...config.scene import load
    name, seconds = FRACTALS[colouring], cfg["fractal_s"][colouring]
    scene = load(name, SIZE + ([f"video.duration={seconds}"] if seconds else []))
    warm = None if not cfg["warm_maps"] else scene.replace(video={"duration": 1.0 / scene.video.fps})
    wall, meta = timed_render(scene, arch, tmp, warm)
    return {"preset": name, "wall_s": wall, "frames": meta["frames"], "duration_s": scene.video.duration,
            "fps": meta["frames"] / wall, "timings": meta["timings_s"], "integrator": meta["integrator"],
            "map": meta["map"]}


def phase_rainbow(cfg, arch, tmp) -> dict:
    """Drawing fps of rainbow_1000 (1000 pendulums, glow, 720p) over its whole video, the spray included (the
    quick run: its first 3 s, still coherent), timed per frame like the e2e phase's recording: frames 0 and 1
    instantiate kernels."""
    from ...physics.stepper import Run
    from ...draw.canvas import Canvas
    from ...config.scene import load

    scene = load(RAINBOW, [f"video.duration={cfg['rainbow_s']}"] if cfg["rainbow_s"] else [])
    run = Run(scene, arch)
    sim = run.sim
    canvas, timings, draw, frame = Canvas(scene, sim), {"simulate": 0.0}, 0.0, canvas_frame(scene)
    for f in run.frames(timings=timings):
        if f == 2:
            timings["simulate"], draw = 0.0, 0.0
        t = time.perf_counter()
        canvas.draw(frame)
        draw += time.perf_counter() - t
    n = scene.frames - 2
    return {"frames": n, "draw_fps": n / draw, "sim_fps": n / timings["simulate"],
            "size": f"{scene.video.width}x{scene.video.height}", "effects": list(scene.effects)}


def canvas_frame(scene) -> np.ndarray:
    return np.zeros((scene.video.height, scene.video.width, 3), np.uint8)


def phase_hud(cfg, arch, tmp) -> dict:
    """ms per frame of rigid_chaos's HUD alone at 1280x720 (the Hud of render/draw/hud.py, as the canvas calls
    it, without a certificate as in benchmarks/effects.py): drawn onto a blank frame at every frame of the
    simulation, so its spread is the live one. Each of `rounds` rounds runs the whole simulation again and keeps
    the median over its frames after the first two (the first round's compile); the figure is the median of
    the rounds', with their range. A frame's HUD is a quarter to a third of a millisecond (0.30-0.37 ms in the
    bench runs of 2026-12-06 and -07 before its launches were prepared, render/physics/launch.py; 0.22-0.25 after),
    about one wake-up of the thread pool (render/physics/runtime.py), so one round's median moved 21 % between two
    runs of the same code."""
    import taichi as ti
    from ...physics.stepper import Run
    from ...draw.hud import Hud, Info

    scene = chaos_scene(cfg)
    run = Run(scene, arch)
    sim, v = run.sim, scene.video
    hud, frame, rounds = Hud(scene, sim, Info.of(scene), v.width, v.height), canvas_frame(scene), []
    for _ in range(cfg["rounds"]):
        sim.restart()
        ms = []
        for f in run.frames():
            frame.fill(0)
            t = time.perf_counter()
            hud.draw(frame, f / v.fps)
            ti.sync()
            ms.append(1e3 * (time.perf_counter() - t))
        rounds.append(statistics.median(ms[2:]))
    value = statistics.median(rounds)
    return {"frames": len(ms) - 2, "ms": value, "rounds_ms": rounds, "spread": peers.spread(rounds, value),
            "size": f"{v.width}x{v.height}"}


def draw_timer(scene, arch):
    """once(): frames per second of simulating and drawing all the scene's frames, nothing encoded, from the
    start each time (the first call compiles)."""
    from ...physics.stepper import Run
    from ...draw.canvas import Canvas

    built = {}

    def once() -> float:
        if "run" not in built or not built["run"].current:  # a render in between re-initialised Taichi
            run = Run(scene, arch)
            built.update(run=run, canvas=Canvas(scene, run.sim))
            once()  # compiles
        run, canvas, frame = built["run"], built["canvas"], canvas_frame(scene)
        run.sim.restart()
        canvas.restart()
        t = time.perf_counter()
        for _ in run.frames():
            canvas.draw(frame)
        return scene.frames / (time.perf_counter() - t)
    once()
    return once


def phase_matplotlib(cfg, arch, tmp) -> dict:
    """rigid_chaos by ours and by the matplotlib peer, the same frames, in interleaved rounds: to MP4, our render
    against FuncAnimation's save (issue 17), and drawn only, our simulate + draw against the peer's canvas.draw
    (issue 27). Rates are per second (1 / wall for a render, frames / s for drawing)."""
    from ...config.scene import load
    scene = load(CHAOS, [f"video.duration={cfg['peer_s']}", 'video.formats=["mp4"]'])
    one = scene.replace(video={"duration": 1.0 / scene.video.fps})
    timed_render(one, arch, tmp)  # compiles; and the peer's imports are paid before its first round
    peers.matplotlib_render(one, tmp / "mpl.mp4")
    runs = peers.interleave({"ours_render": lambda: 1.0 / timed_render(scene, arch, tmp)[0],
                             "matplotlib_render": lambda: 1.0 / peers.matplotlib_render(scene, tmp / "mpl.mp4"),
                             "ours_draw": draw_timer(scene, arch), "matplotlib_draw": lambda: peers.matplotlib_draw(scene)},
                            cfg["rounds"])
    med = {k: statistics.median(r) for k, r in runs.items()}
    return {"frames": scene.frames, "ours_s": 1.0 / med["ours_render"], "matplotlib_s": 1.0 / med["matplotlib_render"],
            "ours_draw_fps": med["ours_draw"], "matplotlib_draw_fps": med["matplotlib_draw"], "runs": runs,
            "vs": {"render": peers.ratio(runs["ours_render"], runs["matplotlib_render"]),
                   "draw": peers.ratio(runs["ours_draw"], runs["matplotlib_draw"])}}


PHASES = {"sim": phase_sim, "e2e": phase_e2e, "hud": phase_hud, "rainbow": phase_rainbow,
          **{f"fractal_{c}": functools.partial(phase_fractal, c) for c in FRACTALS}, "matplotlib": phase_matplotlib}
