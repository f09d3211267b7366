"""`pendulum bench`: how close a render comes to the encoder's floor, simulation vs numpy, and the fractal.

Every phase runs in its own subprocess (a fresh Taichi runtime) while this process samples the resident memory
of that process tree (ffmpeg included), so all figures of one report come from one run. Precision is fixed
per Taichi init, so the simulation phase runs f32, then f64. Method and findings: benchmarks/README.md.
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ..config import estimate
from . import peers
from ..physics import reference
from ..video.atomic import write_atomic
from ..errors import SimulationError
from ..config.options import check_writable

CHAOS, RAINBOW = "rigid_chaos", "rainbow_1000"
FRACTALS = {"angles": "fractal", "flip_time": "fractal_flip", "divergence": "fractal_divergence",
            "lyapunov": "fractal_lyapunov"}  # colouring: preset (each measured at 720p: SIZE)
SIZE = ["video.width=1280", "video.height=720"]
SIM_PRESETS = ("rigid_chaos", "elastic_fan")  # one per system measured; the first gives the headline figure
# fractal_s: seconds of each map rendered (None: the preset's own). A flip map speeds up as pixels flip and
# stop, so it is timed over its whole 20 s; the others cost about the same every frame, so 2 s tell (the FTLE
# map, 10 to 20 times a plain advance per frame, 1 s).
FULL = {"ladder": [100, 1000, 10**4, 10**5, 10**6], "chaos_s": 20.0, "min_s": 0.3, "rainbow_s": None, "peer_s": 10.0,
        "fractal_s": {"angles": 2.0, "flip_time": None, "divergence": 2.0, "lyapunov": 1.0}}
QUICK = {"ladder": [100, 10**4, 10**5], "chaos_s": 2.0, "min_s": 0.1, "rainbow_s": 3.0, "peer_s": 1.0,
         "fractal_s": {"angles": 0.1, "flip_time": 0.1, "divergence": 0.1, "lyapunov": 0.1}}  # smoke: a few frames
TARGETS = [("end_to_end_over_encode_floor", "<=", 1.3), ("sim_speedup_vs_numpy_1e5", ">=", 15.0),  # 10 in issue 8
           ("fractal_fps.flip_time", ">=", 5.0), ("fractal_peak_mem_mb", "<", 2048.0),  # issues 8 and 16
           ("rainbow_1000_draw_fps", ">=", 30.0),  # issue 14: 1000 glowing pendulums at 720p
           ("sim_speedup_vs_numba_1e5", ">=", 3.0), ("rigid_f64_steps_per_s_1e5", ">=", 30e6),  # issue 17
           ("rigid_f32_steps_per_s_1e5", ">=", 60e6), ("elastic_speedup_vs_numpy_1e5", ">=", 10.0),
           ("render_over_realtime", "<=", 1.0), ("matplotlib_peer_ratio", ">=", 12.0)]


LOAD_AT_START: list[float] = [math.nan] * 3


def add_parser(sub):
    p = sub.add_parser("bench", help="performance report: simulate, draw, encode, end to end, fractal",
                       description="Measure simulation throughput (Taichi vs numpy), drawing and encoding fps, "
                                   "an end-to-end render against the encode-only floor, and the fractal maps; "
                                   "write OUT/report.md, OUT/report.json and OUT/rates.json: this machine's rates, "
                                   "from which `render --out DIR` estimates its run time when they are "
                                   "DIR/bench/rates.json (the default out/bench serves the default out).")
    p.add_argument("--quick", action="store_true", help="small N ladder and short videos (about 30 s)")
    p.add_argument("--out", type=Path, default=Path("out/bench"), help="output folder (default: out/bench)")
    p.add_argument("--arch", choices=("cpu", "cuda"), default="cpu", help="Taichi backend (default: cpu)")
    p.add_argument("--phase", help=argparse.SUPPRESS)  # internal: run one phase in this process
    p.add_argument("--result", type=Path, help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def run(args) -> int:
    cfg = QUICK if args.quick else FULL
    if args.phase:
        result = PHASES[args.phase](cfg, args.arch, args.out)
        args.result.write_text(json.dumps({**result, "maxrss_mb": maxrss_mb()}))
        return 0
    check_writable(args.out)
    LOAD_AT_START[:] = os.getloadavg()  # other work on the machine skews every figure: the report says how much
    t0, res = time.perf_counter(), {}
    with tempfile.TemporaryDirectory(prefix="pendulum-bench-") as tmp:
        for name in PHASES:
            print(f"bench: {name} ...", file=sys.stderr, flush=True)
            res[name] = run_phase(name, args, Path(tmp))
    report = summarise(res, args.quick, time.perf_counter() - t0)
    args.out.mkdir(parents=True, exist_ok=True)
    write_atomic(args.out / "report.json", (json.dumps(report, indent=2) + "\n").encode())
    write_atomic(args.out / "report.md", markdown(report).encode())
    # This machine's rates for the run-time budget of renders into the OUT above (render/config/estimate.py)
    rates = {**estimate.measured(res, chaos_scene(cfg)), "created": report["created"], "quick": report["quick"]}
    write_atomic(args.out / "rates.json", (json.dumps(rates, indent=2) + "\n").encode())
    m = report["machine"]
    write_atomic(args.out / "targets.md", "\n".join(  # for docs/performance.md (benchmarks/readme_figures.py)
        targets_table(report) + ["", f"`pendulum bench{' --quick' if report['quick'] else ''}`, {report['created']}, "
                                 f"{m['cpus']} CPUs ({m['cpu']}), load average {m['load_avg'][0]:.2f} at the start, "
                                 f"numba {report['peers']['numba']}."]).encode() + b"\n")
    for key, t in report["targets"].items():
        print(f"{key} = {fmt(t['value'])} (target {t['goal']}): "
              f"{'met' if t['met'] else 'not measured' if t['met'] is None else 'MISSED'}")
    print(f"-> {args.out}/report.md ({report['wall_s']:.0f} s)")
    return 0


# ---------------------------------------------------------------- running phases, measuring memory

def run_phase(name: str, args, tmp: Path) -> dict:
    """One phase in a subprocess; its result plus the peak resident memory of its process tree."""
    result = tmp / f"{name}.json"
    cmd = [sys.executable, "-m", "render", "bench", "--phase", name, "--result", str(result), "--out", str(tmp),
           "--arch", args.arch] + (["--quick"] if args.quick else [])
    proc, peak = subprocess.Popen(cmd, stdout=subprocess.DEVNULL), 0
    try:  # the sum over the tree at one instant, which ru_maxrss (the largest single process) cannot give
        while proc.poll() is None:
            peak = max(peak, tree_rss(proc.pid))
            time.sleep(0.05)
    finally:
        if proc.poll() is None:  # interrupted: do not leave the phase running
            proc.terminate()
            proc.wait()
    code = proc.returncode
    if code != 0:
        raise SimulationError(f"bench phase {name!r} failed (exit {code}); see the messages above")
    out = json.loads(result.read_text())
    out["peak_mem_mb"] = max(peak / 2**20, out.pop("maxrss_mb"))  # /proc may be missing, or miss a spike
    return out


def tree_rss(pid: int) -> int:
    """Resident bytes of a process and all its descendants (Linux /proc; 0 elsewhere)."""
    total, todo, page = 0, [pid], os.sysconf("SC_PAGE_SIZE")
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/statm") as f:
                total += int(f.read().split()[1]) * page
            for tid in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{tid}/children") as f:
                    todo += [int(c) for c in f.read().split()]
        except (OSError, ValueError):
            pass
    return total


def maxrss_mb() -> float:  # the largest single process: this phase, or one of its ffmpeg children
    import resource
    return max(resource.getrusage(w).ru_maxrss for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)) / 1024


# ---------------------------------------------------------------- phases

def phase_sim(cfg, arch, tmp) -> dict:
    """Pendulum-substeps per second of the Taichi kernel and of the numpy baseline: same RK4, same state."""
    import taichi as ti
    from ..video import pipeline
    from ..physics import runtime
    from ..config.scene import load

    rows = []
    for prec in ("f32", "f64"):
        runtime.init(arch, prec)
        for preset in SIM_PRESETS:
            for n in cfg["ladder"]:
                scene = load(preset, [f"pendulums.count={n}", 'integrator.method="rk4"', "integrator.dt=1e-3",
                                      f'integrator.precision="{prec}"', 'effects=["bobs"]'])  # no energy
                sim = pipeline.make_system(scene)
                kern, q0, v0 = f"{sim.NAME}_advance", sim.q.to_numpy().T.copy(), sim.v.to_numpy().T.copy()
                if n == cfg["ladder"][0]:  # first check that both integrate the same thing
                    base = Baseline(scene, q0, v0, sim.h)
                    sim.launch(kern, 100)
                    for _ in range(100):
                        base.step()
                    agree = float(np.abs(sim.q.to_numpy().T - base.q).max())
                base = Baseline(scene, q0, v0, sim.h)
                taichi = rate(lambda k: (sim.launch(kern, k), ti.sync()), n, cfg["min_s"])
                numpy = rate(lambda k: [base.step() for _ in range(k)], n, cfg["min_s"])
                nb = peers.numba_rate(scene, q0, v0, sim.h, n, cfg["min_s"], rate) if n == 10**5 else None
                rows.append({"system": scene.system, "precision": prec, "n": n, "taichi": taichi, "numpy": numpy,
                             "numba": nb,
                             "speedup": taichi / numpy, "agree": agree})
    return {"rows": rows}


def rate(step, n: int, min_s: float) -> float:
    """Pendulum-substeps per second; step(k) advances all n pendulums k substeps. Best of 3 runs >= min_s."""
    step(1)  # compiles
    k, runs = max(1, int(1e4 / n)), []
    while len(runs) < 3:
        t = time.perf_counter()
        step(k)
        dt = time.perf_counter() - t
        if dt >= min_s:
            runs.append(n * k / dt)
        else:
            k = max(k + 1, int(k * min(20.0, 1.3 * min_s / max(dt, 1e-6))))
    return max(runs)


class Baseline:
    """The numpy-vectorised peer: RK4 on render/physics/reference.py's independent model, in the run's precision,
    on (D, N) arrays so that every row is contiguous."""

    def __init__(self, scene, q, v, h: float):
        self.scene, self.q, self.v, self.h = scene, q, v, h

    def step(self):
        self.q, self.v = reference.rk4_step(self.scene, self.q, self.v, self.h)


def chaos_scene(cfg):
    from ..config.scene import load
    return load(CHAOS, [f"video.duration={cfg['chaos_s']}"])


def phase_encode(cfg, arch, tmp) -> dict:
    """Draw rigid_chaos's frames into a raw file (timing simulate and draw), then time only the encoding of
    those frames (memory-mapped) through the same Encoder: the floor an end-to-end render cannot beat."""
    from ..video import pipeline
    from ..physics import runtime
    from ..draw.canvas import Canvas
    from ..video.encode import Encoder

    scene = chaos_scene(cfg)
    runtime.init(arch, scene.integrator.precision)
    sim = pipeline.make_system(scene)
    canvas, raw, timings, draw = Canvas(scene, sim), tmp / "frames.raw", {"simulate": 0.0}, 0.0
    with open(raw, "wb") as fh:
        for f in pipeline.frames(scene, sim, timings):
            if f == 2:  # frames 0 and 1 instantiate the kernels; time the steady state
                timings["simulate"], draw = 0.0, 0.0
            t = time.perf_counter()
            frame = canvas.draw()
            draw += time.perf_counter() - t
            fh.write(memoryview(frame).cast("B"))
    v, n = scene.video, scene.frames - 2
    frames = np.memmap(raw, np.uint8, "r", shape=(scene.frames, v.height, v.width, 3))
    (tmp / "floor").mkdir(exist_ok=True)
    t = time.perf_counter()
    enc = Encoder(tmp / "floor", scene.name, v, scene.frames)
    for f in range(scene.frames):
        enc.write(frames[f])
    enc.close()
    floor = time.perf_counter() - t
    del frames
    raw.unlink()
    return {"draw_fps": n / draw, "sim_draw_fps": n / (draw + timings["simulate"]), "floor_s": floor,
            "encode_fps": scene.frames / floor}


def timed_render(scene, arch, tmp, warm_scene=None) -> tuple[float, dict]:
    """Wall time of pipeline.render, after a warm-up render (Taichi init, kernel cache); and its metadata."""
    from ..video import pipeline
    if warm_scene is not None:
        pipeline.render(warm_scene, tmp / "warm", arch=arch)
    t = time.perf_counter()
    meta = pipeline.render(scene, tmp / "timed", arch=arch)
    return time.perf_counter() - t, meta


def phase_e2e(cfg, arch, tmp) -> dict:
    scene = chaos_scene(cfg)
    one = scene.replace(video={"duration": 1.0 / scene.video.fps})
    wall, meta = timed_render(scene, arch, tmp, one)
    fixed, _ = timed_render(one, arch, tmp)  # what every render pays besides its frames
    return {"wall_s": wall, "frames": meta["frames"], "timings": meta["timings_s"], "fixed_s": fixed}


def phase_fractal(colouring, cfg, arch, tmp) -> dict:
    """One map preset rendered at 720p as it ships (its accurate step, MP4 + GIF + PNG), after a small warm-up
    render that compiles the same kernels; fps = frames / wall, the certificate included."""
    from ..config.scene import load
    name, seconds = FRACTALS[colouring], cfg["fractal_s"][colouring]
    scene = load(name, SIZE + ([f"video.duration={seconds}"] if seconds else []))
    warm = load(name, ["video.width=256", "video.height=144", "video.duration=0.05"])
    wall, meta = timed_render(scene, arch, tmp, warm)
    return {"preset": name, "wall_s": wall, "frames": meta["frames"], "duration_s": scene.video.duration,
            "fps": meta["frames"] / wall, "timings": meta["timings_s"], "integrator": meta["integrator"],
            "map": meta["map"]}


def phase_rainbow(cfg, arch, tmp) -> dict:
    """Drawing fps of rainbow_1000 (1000 pendulums, glow, 720p) over its whole video, the spray included (the
    quick run: its first 3 s, still coherent), timed per frame like the encode phase: frames 0 and 1
    instantiate kernels."""
    from ..video import pipeline
    from ..physics import runtime
    from ..draw.canvas import Canvas
    from ..config.scene import load

    scene = load(RAINBOW, [f"video.duration={cfg['rainbow_s']}"] if cfg["rainbow_s"] else [])
    runtime.init(arch, scene.integrator.precision)
    sim = pipeline.make_system(scene)
    canvas, timings, draw, frame = Canvas(scene, sim), {"simulate": 0.0}, 0.0, canvas_frame(scene)
    for f in pipeline.frames(scene, sim, timings):
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


def phase_matplotlib(cfg, arch, tmp) -> dict:
    """rigid_chaos to MP4 by our render and by the matplotlib FuncAnimation peer, the same frames (issue 17)."""
    from ..config.scene import load
    scene = load(CHAOS, [f"video.duration={cfg['peer_s']}", 'video.formats=["mp4"]'])
    ours, _ = timed_render(scene, arch, tmp, scene.replace(video={"duration": 1.0 / scene.video.fps}))
    return {"frames": scene.frames, "ours_s": ours, "matplotlib_s": peers.matplotlib_render(scene, tmp / "mpl.mp4")}


PHASES = {"sim": phase_sim, "encode": phase_encode, "e2e": phase_e2e, "rainbow": phase_rainbow,
          **{f"fractal_{c}": functools.partial(phase_fractal, c) for c in FRACTALS}, "matplotlib": phase_matplotlib}


# ---------------------------------------------------------------- report

def summarise(res: dict, quick: bool, wall: float) -> dict:
    from ..video.encode import ffmpeg_version

    at = {f"{r['system']}_{r['precision']}": r["speedup"] for r in res["sim"]["rows"] if r["n"] == 10**5}
    headline = f"{res['sim']['rows'][0]['system']}_f64"
    enc, e2e, rb = res["encode"], res["e2e"], res["rainbow"]
    fr = {c: res[f"fractal_{c}"] for c in FRACTALS}
    rep = {"quick": quick, "wall_s": wall, "created": time.strftime("%Y-%m-%d %H:%M:%S"),
           "machine": {"cpus": os.cpu_count(), "cpu": cpu_model(), "python": platform.python_version(),
                       "numpy": np.__version__, "ffmpeg": ffmpeg_version(), "load_avg": LOAD_AT_START},
           "end_to_end_over_encode_floor": e2e["wall_s"] / enc["floor_s"],
           "sim_speedup_vs_numpy_1e5": at[headline], "sim_speedup_vs_numpy_1e5_by_case": at,  # f64: presets'
           "fractal_fps": {c: r["fps"] for c, r in fr.items()},  # DESIGN.md: per colouring
           "fractal_peak_mem_mb": max(r["peak_mem_mb"] for r in fr.values()),
           "rainbow_1000_draw_fps": rb["draw_fps"], "rainbow_1000": rb,
           "draw_fps": enc["draw_fps"], "sim_draw_fps": enc["sim_draw_fps"], "encode_fps": enc["encode_fps"],
           "end_to_end_s": e2e["wall_s"], "encode_floor_s": enc["floor_s"], "frames": e2e["frames"],
           "end_to_end_fixed_s": e2e["fixed_s"], "end_to_end_timings": e2e["timings"], "fractal": fr,
           "sim": res["sim"]["rows"], "peak_mem_mb": {k: v["peak_mem_mb"] for k, v in res.items()}, "targets": {},
           **peers.throughput_keys(res["sim"]["rows"], e2e["wall_s"], (QUICK if quick else FULL)["chaos_s"],
                                   res["matplotlib"]), "matplotlib_peer": res["matplotlib"],
           "peers": {"numba": peers.numba.__version__ if peers.numba else peers.MISSING}}
    for key, op, goal in TARGETS:
        val = functools.reduce(lambda d, k: d[k], key.split("."), rep)  # "fractal_fps.flip_time"
        met = None if val is None else val <= goal if op == "<=" else val >= goal if op == ">=" else val < goal
        rep["targets"][key] = {"value": val, "goal": f"{op} {goal:g}", "met": met,
                               "value_over_goal": None if val is None else val / goal}
    return rep


def targets_table(r: dict) -> list[str]:
    """The targets as a table: report.md's, and targets.md's, which docs/performance.md shows."""
    return table(["target", "measured", "goal", "met", "measured / goal"],
                 [[k, fmt(g["value"]), g["goal"], "yes" if g["met"] else "not measured" if g["met"] is None
                   else "**no**", fmt(g["value_over_goal"], ".2f")] for k, g in r["targets"].items()])


def fmt(val, spec=".3g") -> str:
    return "null" if val is None else format(val, spec)


def cpu_model() -> str:
    try:
        return next(x.split(":", 1)[1].strip() for x in open("/proc/cpuinfo") if x.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or "unknown"


def table(head: list[str], rows: list[list]) -> list[str]:
    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + ["| " + " | ".join(map(str, r)) + " |"
                                                                       for r in rows]


def markdown(r: dict) -> str:
    m, t = r["machine"], r["end_to_end_timings"]
    missed = [k for k, g in r["targets"].items() if not g["met"]]
    out = [f"# pendulum bench{' --quick' if r['quick'] else ''}", "",
           f"{r['created']}, {m['cpus']} CPUs ({m['cpu']}), Python {m['python']}, numpy {m['numpy']}, ffmpeg "
           f"{m['ffmpeg']}. Every figure comes from this one run ({r['wall_s']:.0f} s).", "", "## Targets", ""]
    out += targets_table(r)
    if missed:
        out += ["", f"Missed: {', '.join(missed)}. What limits it is profiled in benchmarks/README.md."]
    if r["quick"]:
        out += ["", "Quick run: short videos, where the fixed cost of a render and the easy early frames weigh "
                "most; only the full run speaks to the targets."]
    out += ["", f"## rigid_chaos, 1280x720 at 60 fps, {r['frames']} frames, N=100, MP4 + GIF", ""]
    out += table(["measure", "value"], [
        ["simulate + draw, no encoding", f"{r['sim_draw_fps']:.0f} fps"],
        ["draw only", f"{r['draw_fps']:.0f} fps"],
        ["encode only: the floor (same frames, same Encoder)",
         f"{r['encode_fps']:.0f} fps, {r['encode_floor_s']:.2f} s"],
        ["end-to-end render", f"{r['end_to_end_s']:.2f} s"],
        ["end-to-end / floor", f"**{r['end_to_end_over_encode_floor']:.3f}**"],
        ["fixed cost in it (a one-frame render)", f"{r['end_to_end_fixed_s']:.2f} s"],
        ["render's split: simulate / draw / waiting for the encoder",
         f"{t['simulate']:.2f} / {t['draw']:.2f} / {t['encode']:.2f} s"]])
    out += ["", "## Fractal maps: one pendulum per pixel of the plot, 1280x720, MP4 + GIF (+ PNG)", ""]
    out += table(["colouring", "preset", "frames", "integrator", "plot", "render wall", "fps",
                  "certify / simulate / draw / encode wait", "events (trusted)", "peak MB"],
                 [[c, f["preset"], f"{f['frames']} ({f['duration_s']:g} s)",
                   f"{f['integrator']['method']} dt={f['integrator']['dt']:.3g} s x{f['integrator']['substeps']} "
                   f"{f['integrator']['precision']}", f"{f['map']['plot']['width']}²",
                   f"{f['wall_s']:.1f} s", f"**{f['fps']:.2f}**",
                   " / ".join(f"{f['timings'][k]:.1f}" for k in ("certify", "simulate", "draw", "encode")) + " s",
                   f"{f['map'].get('events', '–')} ({f['map'].get('events_trusted', f['map'].get('trusted'))})",
                   f"{f['peak_mem_mb']:.0f}"]  # an FTLE map has no events: its trusted pixels
                  for c, f in r["fractal"].items()])
    rb = r["rainbow_1000"]
    out += ["", f"## rainbow_1000: 1000 pendulums, {', '.join(rb['effects'])}, {rb['size']}", ""]
    out += table(["measure", "value"], [
        ["frames timed", rb["frames"]],
        ["draw only", f"**{rb['draw_fps']:.1f} fps** ({1e3 / rb['draw_fps']:.1f} ms per frame)"],
        ["simulate only", f"{rb['sim_fps']:.0f} fps"]])
    out += ["", "## Simulation: million pendulum-substeps per second (RK4, dt ~1e-3; Taichi on all cores, "
            "numpy on one)", ""]
    out += table(["system", "precision", "N", "Taichi", "numpy", "speedup", "numba (N=1e5)",
                  "max diff after 100 steps (N=100)"],
                 [[s["system"], s["precision"], f"{s['n']:.0e}", f"{s['taichi'] / 1e6:.2f}",
                   f"{s['numpy'] / 1e6:.2f}", f"{s['speedup']:.2f}",
                   "" if s["n"] != 10**5 else fmt(s["numba"] and s["numba"] / 1e6, ".2f"), f"{s['agree']:.1e}"]
                  for s in r["sim"]])
    out += ["", "## Peak memory per phase (process tree)", ""]
    out += table(["phase", "MB"], [[k + (" (includes the memory-mapped raw frames)" if k == "encode" else ""),
                                    f"{v:.0f}"] for k, v in r["peak_mem_mb"].items()])
    return "\n".join(out) + "\n"
