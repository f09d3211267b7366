"""`pendulum accuracy`: what each integrator's accuracy costs in time, measured against a DOP853 reference.

Per system, method, precision and step dt it measures the trajectory error at a short horizon, the energy
drift over that horizon, the kernel's wall time per pendulum-step (over a large N) and the observed order;
then it draws work-precision, long-run energy-drift and f32-vs-f64 divergence charts into OUT/.
Precision is fixed per Taichi init, so all f64 runs come first, then all f32 ones: one restart in between.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from . import charts, flagship
from ..trust import quality
from ..physics import reference, registry
from ..physics.stepper import Run
from ..video.atomic import together, write_atomic
from ..config.options import check_replaceable, check_writable, out_path
from ..config.limits import METHODS, PRECISIONS
from ..config.scene import load

COLUMNS = ("system", "method", "precision", "dt", "traj_error", "energy_drift", "ns_per_step", "order")
FPS = 10  # frames of 0.1 s: every dt in the ladders divides it exactly, so the step is exactly dt
# Short-horizon cases, one per system (its preset and horizon); the preset dt (1e-3) is on every ladder.
CASES = {name: registry.get(name).ACCURACY_CASE for name in registry.names()}
LADDER = {name: registry.get(name).ACCURACY_LADDER for name in registry.names()}
QUICK_LADDER = (2e-3, 1e-3)
UNITS = {name: registry.get(name).ERROR_UNIT for name in registry.names()}
CHAOS = flagship.FLAGSHIP  # the fan whose f32-vs-f64 divergence is charted
LONG_DT, LONG_T, QUICK_LONG_T = 1e-3, 100.0, 5.0  # energy-drift run: 1e5 steps at the preset dt
TIMING_N, QUICK_TIMING_N = 20000, 2000
CHAOS_T, QUICK_CHAOS_T, CHAOS_FPS = 12.0, 3.0, 30


def progress(total: int, enabled: bool):
    """step(what): '[done/total] what' on stderr, rewritten in place on a terminal, one line each otherwise."""
    t0, done, tty = time.perf_counter(), [0], sys.stderr.isatty()

    def step(what: str):
        done[0] += 1
        if enabled:
            line = f"accuracy [{done[0]:3d}/{total}] {time.perf_counter() - t0:5.1f}s {what}"
            sys.stderr.write((f"\r{line:<78}" + "\n" * (done[0] == total)) if tty else line + "\n")
            sys.stderr.flush()
    return step


def case_scene(system: str, method: str, precision: str, dt: float, duration: float):
    """The system's preset with this integrator, frames of 1/FPS s (so h is exactly dt) and energy tracked.
    The ladder's coarse rungs may lie past a method's energy limit (render/physics/stability.py): measured knowingly."""
    return load(CASES[system][0]).replace(integrator={"method": method, "dt": dt, "precision": precision,
                                                      "allow_unstable": True},
                                          video={"fps": FPS, "duration": duration}, effects=["energy"])


def advance(scene, frames: int, more: int = 0, arch: str = "cpu"):
    """Advance a fresh system by `frames` frames, then `more`.

    Returns (q at `frames` in float64, max relative energy drift up to there, and with `more` the relative
    energy error (E − E0)/scale per pendulum at every frame, shape (frames + more + 1, N)).
    """
    run = Run(scene, arch)
    sim, series = run.sim, None
    # No watchdog: the coarse rungs may blow up or drift, and that is what is measured.
    for f in run.frames(frames + more + 1, energy=True, watch=False):
        if f <= frames:
            drift = float(sim.drift[None])
        if more and not f:  # the energies of frame 0 are the reference
            e0, scale = (x.to_numpy().astype(np.float64) for x in (sim.e0, sim.escale))
            series = np.zeros((frames + more + 1, sim.n))
        elif more:
            series[f] = (sim.e.to_numpy().astype(np.float64) - e0) / scale
        if f == frames:
            q = sim.q.to_numpy().astype(np.float64)
    return q, drift, series


def timing_kernel(scene, n: int, arch: str = "cpu", target_s: float = 0.02):
    """A compiled advance kernel over n pendulums, as (launch, steps per timed launch ≈ target_s, n)."""
    import taichi as ti

    sim = Run(scene.replace(pendulums={"count": n}), arch).sim
    kernel = f"{sim.NAME}_advance"

    def launch(k):
        sim.launch(kernel, k)
        ti.sync()
    launch(1)  # compiles
    t = time.perf_counter()
    launch(2)
    return launch, max(2, int(target_s / max(time.perf_counter() - t, 1e-6) * 2)), n


def ns_per_step(kernels: dict, rounds: int = 5) -> dict:
    """Best-of-rounds wall time per pendulum-step of each kernel, compile excluded. Round-robin, so a burst of
    load from other processes hits every method alike rather than whichever happened to be timed then."""
    best = dict.fromkeys(kernels, math.inf)
    for _ in range(rounds):
        for key, (launch, k, n) in kernels.items():
            t = time.perf_counter()
            launch(k)
            best[key] = min(best[key], (time.perf_counter() - t) / (n * k) * 1e9)
    return best


def outer_bobs(scene, duration: float, arch: str = "cpu", fps: int = CHAOS_FPS) -> np.ndarray:
    """Outer-bob positions (frames, N, 2) of a scene sampled at fps, computed in float64 from the state."""
    scene = scene.replace(video={"fps": fps, "duration": duration}, effects=["bobs"])
    run = Run(scene, arch)
    return np.array([reference.bob_positions(scene, run.sim.q.to_numpy().astype(np.float64))[:, -1]
                     for _ in run.frames(watch=False)])


def observed_orders(dts, errs) -> list[float]:
    """Order between successive rungs: log(e_i−1/e_i)/log(dt_i−1/dt_i); NaN for the first rung."""
    out = [math.nan]
    for (d0, e0), (d1, e1) in zip(zip(dts, errs), zip(dts[1:], errs[1:])):
        ok = e0 > 0 and e1 > 0 and math.isfinite(e0) and math.isfinite(e1)
        out.append(math.log(e0 / e1) / math.log(d0 / d1) if ok else math.nan)
    return out


def measure(systems, arch="cpu", quick=False, show=False):
    """All measurements; returns (rows, energy {(system, method, precision): series}, chaos {precision: bobs})."""
    ladder = {s: QUICK_LADDER if quick else LADDER[s] for s in systems}
    long_t = QUICK_LONG_T if quick else LONG_T
    n_time = QUICK_TIMING_N if quick else TIMING_N
    refs = {}
    for s in systems:
        horizon = CASES[s][1]
        sc = case_scene(s, METHODS[s][0], "f64", LADDER[s][0], horizon)
        refs[s] = reference.solve(sc, reference.initial_state(sc), horizon)[0]
    chaos_on = load(CHAOS).system in systems
    per_prec = sum(len(METHODS[s]) * len(ladder[s]) for s in systems) + 1 + chaos_on
    fan = len(METHODS[load(CHAOS).system]) * len(ladder.get(load(CHAOS).system, ())) if chaos_on else 0
    step = progress(per_prec * len(PRECISIONS) + fan * len(PRECISIONS) + len(quality.LEVELS) * chaos_on, show)
    rows, energy, chaos = [], {}, {}
    for prec in ("f64", "f32"):  # f64 first: its figures are the ones the quality table leans on
        kernels, block = {}, []
        for s in systems:
            horizon = CASES[s][1]
            frames = round(horizon * FPS)
            for method in METHODS[s]:
                # An explicit step costs the same at any dt: time it once (less noise, fewer compiles).
                # The implicit one iterates more at larger dt, so it is timed on every rung.
                if method != "implicit_midpoint":
                    kernels[(s, method)] = timing_kernel(case_scene(s, method, prec, LONG_DT, horizon), n_time, arch)
                errs = []
                for dt in ladder[s]:
                    sc = case_scene(s, method, prec, dt, horizon)
                    if method == "implicit_midpoint":
                        kernels[(s, method, dt)] = timing_kernel(sc, n_time, arch)
                    # The preset-dt rung runs on for the long energy-drift series.
                    more = round((long_t - horizon) * FPS) if dt == LONG_DT else 0
                    q, drift, series = advance(sc, frames, more, arch)
                    if series is not None:
                        energy[(s, method, prec)] = series
                    err = float(np.max(np.abs(q - refs[s]))) if np.all(np.isfinite(q)) else math.inf
                    errs.append(err)
                    block.append(dict(system=s, method=method, precision=prec, dt=dt, traj_error=err,
                                      energy_drift=drift))
                    step(f"{s} {method} {prec} dt={dt:g}: error {err:.2g}")
                for row, order in zip(block[-len(errs):], observed_orders(ladder[s], errs)):
                    row["order"] = order
        ns = ns_per_step(kernels)
        for row in block:
            key = (row["system"], row["method"])
            row["ns_per_step"] = ns[key] if key in ns else ns[(*key, row["dt"])]
        rows += block
        step(f"{prec}: timed {len(kernels)} kernels over N = {n_time}")
        if chaos_on:
            chaos[prec] = outer_bobs(load(CHAOS).replace(integrator={"precision": prec}),
                                     QUICK_CHAOS_T if quick else CHAOS_T, arch)
            step(f"{CHAOS} {prec}: divergence")
    fan_rows = quality_rows = []
    if chaos_on:
        system = load(CHAOS).system
        ns = {(r["method"], r["precision"], r["dt"]): r["ns_per_step"] for r in rows if r["system"] == system}
        fan_rows = flagship.measure(ladder[system], ns, arch, quick, step)
        quality_rows = flagship.quality_table(arch, quick, step)
    return rows, energy, chaos, fan_rows, quality_rows


# ------------------------------------------------------------------------------------------------ output


def fmt(key, val) -> str:
    if isinstance(val, str):
        return val
    if not math.isfinite(val):
        return "" if key == "order" else str(val)
    return {"dt": f"{val:g}", "ns_per_step": f"{val:.1f}", "order": f"{val:.2f}"}.get(key, f"{val:.3e}")


def csv_text(rows) -> str:
    return "\n".join([",".join(COLUMNS)] + [",".join(fmt(k, r[k]) for k in COLUMNS) for r in rows]) + "\n"


def summary_md(rows, energy) -> str:
    """One row per system and method at the presets' dt in f64: docs/accuracy.md's table."""
    lines = ["| system | method | order | error at the case's horizon | ns per pendulum-step | energy error over "
             "1e5 steps, first third -> last third |", "|---|---|---:|---|---:|---|"]
    for r in rows:
        if r["precision"] != "f64" or r["dt"] != LONG_DT:
            continue
        series = energy.get((r["system"], r["method"], "f64"))
        drift = ""
        if series is not None:
            a = np.abs(series[1:]).max(1)
            third = len(a) // 3
            drift = f"{a[:third].max():.1e} -> {a[-third:].max():.1e}"
        lines.append(f"| {r['system']} | {r['method']} | {r['order']:.2f} | {r['traj_error']:.1e} "
                     f"{UNITS[r['system']].split('[')[-1].rstrip(']')} | {r['ns_per_step']:.0f} | {drift} |")
    return "\n".join(lines) + "\n"


def md_text(rows, energy, quick: bool, note: str = "") -> str:
    cases = ", ".join(f"{s} `{p}` at t = {t:g} s ({UNITS[s]})" for s, (p, t) in CASES.items()
                      if any(r["system"] == s for r in rows))
    lines = ["# Accuracy vs. time", "",
             f"Trajectory error against scipy DOP853 (rtol 1e-13): {cases}; max over pendulums and "
             "coordinates. energy_drift: max relative "
             "energy error over that horizon. ns_per_step: wall time of the advance kernel per pendulum-step "
             f"(N = {QUICK_TIMING_N if quick else TIMING_N}, best of 5 round-robin rounds; explicit methods "
             "timed once, as their cost per step does not depend on dt; implicit_midpoint on every rung). "
             "order: observed, from the previous rung."
             + (" **Quick mode: reduced ladder and N.**" if quick else "") + note, "",
             "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(fmt(k, r[k]) for k in COLUMNS) + " |" for r in rows]
    if energy:
        steps = round((len(next(iter(energy.values()))) - 1) / FPS / LONG_DT)
        lines += ["", f"## Energy over {steps} steps at dt = {LONG_DT:g} s (energy_drift_*.png)", "",
                  "| system | method | precision | max rel. error, first third | last third |", "|" + "---|" * 5]
        order = list(CASES)
        for (s, m, p), series in sorted(energy.items(), key=lambda kv: (order.index(kv[0][0]), kv[0][2] == "f32")):
            a = np.abs(series[1:]).max(1)
            third = len(a) // 3
            lines.append(f"| {s} | {m} | {p} | {a[:third].max():.2e} | {a[-third:].max():.2e} |")
    return "\n".join(lines) + "\n"


def add_parser(sub):
    p = sub.add_parser("accuracy", help="measure error vs. time of every integrator; charts and tables",
                       description="Work-precision and energy-drift charts per system, f32-vs-f64 divergence, "
                                   "accuracy.csv/.md, summary.md, and for the flagship quality.md and "
                                   "faithful_*.png, measured against a scipy DOP853 reference.")
    p.add_argument("--system", choices=(*registry.names(), "all"), default="all",
                   help=f"which system to measure (default: all); the system of {CHAOS} also draws divergence.png")
    p.add_argument("--out", type=out_path, default=Path("out/accuracy"),
                   help="output directory (default: out/accuracy)")
    p.add_argument("--quick", action="store_true", help="two dt rungs, small N, short runs: a smoke test")
    p.add_argument("--arch", choices=("cpu", "cuda"), default="cpu", help="Taichi backend for the kernels")
    p.add_argument("--no-progress", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)


def outputs(systems) -> list[str]:
    """The files a run over `systems` writes into --out (the charts named as render/commands/charts.py names them)."""
    return ["accuracy.csv", "accuracy.md", "summary.md", "quality.md", "divergence.png",
            *(f"{kind}_{s}.png" for s in systems for kind in ("work_precision", "energy_drift")),
            f"work_precision_{CHAOS}.png", f"faithful_{CHAOS}.png"]


def run(args) -> int:
    check_writable(args.out)
    systems = registry.names() if args.system == "all" else (args.system,)
    for name in outputs(systems):  # a folder where one goes: refused now, not after minutes of measuring
        check_replaceable(args.out / name)
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    rows, energy, chaos, fan_rows, quality_rows = measure(systems, args.arch, args.quick, show=not args.no_progress)
    rows.sort(key=lambda r: (systems.index(r["system"]), METHODS[r["system"]].index(r["method"]),
                             r["precision"] != "f64", -r["dt"]))
    with together(args.out):  # the charts and tables appear together: a failure leaves none of them
        charts.accuracy_charts(args.out, rows, energy, chaos, {s: CASES[s] for s in systems}, UNITS, FPS, LONG_DT,
                               CHAOS_FPS)
        write_atomic(args.out / "accuracy.csv", csv_text(rows).encode())
        # Timings share the CPU with whatever else runs: say how busy it was.
        note = (f" Timed with {os.cpu_count()} CPU threads available, {args.arch}; 1-min load average "
                f"{load0:.1f} before, {os.getloadavg()[0]:.1f} after.")
        md = md_text(rows, energy, args.quick, note)
        if fan_rows:
            scene = flagship.flagship(args.quick)
            charts.flagship_charts(args.out, fan_rows, CHAOS, flagship.HORIZON, scene.video.duration,
                                   scene.pendulums.count)
            md += "\n" + flagship.fan_md(fan_rows)
            write_atomic(args.out / "quality.md", flagship.quality_md(quality_rows, args.quick).encode())
        write_atomic(args.out / "accuracy.md", md.encode())
        write_atomic(args.out / "summary.md", summary_md(rows, energy).encode())
    print(f"accuracy: {len(rows)} measurements in {time.perf_counter() - t0:.0f} s -> {args.out}/")
    return 0

