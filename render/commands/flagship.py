"""The flagship fan, rigid_chaos, under every integrator, for `pendulum accuracy`: how long it stays true against
what it costs, and what each --quality level buys on it.

Truth is scipy DOP853 (rtol 1e-13) from the same initial states, sampled at FPS; a pendulum is faithful until
its angles first differ from it by more than integrator.tolerance (1e-3 rad), as the certificate measures.
"""
from __future__ import annotations

import io
import time

import numpy as np

from ..trust import certify
from ..physics import reference
from ..video.pipeline import simulate
from ..trust.quality import LEVELS, TARGET
from ..config.limits import METHODS
from ..config.scene import load

FLAGSHIP = "rigid_chaos"
FPS = 30  # frames compared with the reference
HORIZON = 2.0  # s: where the work-precision error is read
QUICK = ["pendulums.count=10", "video.duration=4"]


def flagship(quick: bool, *extra: str):
    return load(FLAGSHIP, [*(QUICK if quick else []), *extra])


def measure(ladder, ns_per_step: dict, arch: str, quick: bool, step) -> list[dict]:
    """Per method, precision and dt: the fan's error at HORIZON, its first and median faithful times, and the
    cost from the kernel timings {(method, precision, dt): ns per pendulum-step}."""
    scene = flagship(quick, f"video.fps={FPS}")
    t = np.arange(scene.frames) / FPS
    truth, _ = reference.solve(scene, reference.initial_state(scene), t[-1], t_eval=t)
    at = round(min(HORIZON, t[-1]) * FPS)
    indices = np.arange(scene.pendulums.count)
    rows = []
    for prec in ("f64", "f32"):
        for method in METHODS[scene.system]:
            for dt in ladder:
                # the ladder's coarse rungs may be past a method's energy limit (render/physics/stability.py): measured
                sc = scene.replace(integrator={"method": method, "dt": dt, "precision": prec, "allow_unstable": True})
                q, sim = certify.trajectory(sc, indices, arch)
                until = certify.faithful_times(sim.deviation(q, truth) / sc.integrator.tolerance, FPS,
                                               sc.video.duration)
                rows.append({"method": method, "precision": prec, "dt": dt,
                             "error": float(np.abs(q[at] - truth[at]).max()),
                             "first_s": float(until.min()), "median_s": float(np.median(until)),
                             "cost_us": ns_per_step[(method, prec, dt)] / dt / 1e3})
                step(f"{FLAGSHIP} {method} {prec} dt={dt:g}: faithful, median {rows[-1]['median_s']:.2f} s")
    return rows


def quality_table(arch: str, quick: bool, step) -> list[dict]:
    """Each --quality level on the flagship: what it chose, the certificate, and the wall time of
    `pendulum simulate` at that level (pilots, certificate and simulation, and its .npz compressed, into memory:
    nothing is written outside the output folder)."""
    rows = []
    for level in LEVELS:
        scene = load(FLAGSHIP, QUICK if quick else [], quality=level)
        t0 = time.perf_counter()
        info = simulate(scene, None, arch=arch)
        np.savez_compressed(io.BytesIO(), **info["arrays"])
        wall = time.perf_counter() - t0
        f, chosen = info["faithfulness"], info["quality"]["chosen"]
        rows.append({"level": level, "target": f"{100 * TARGET[level]:.0f} %" if level in TARGET else "finest",
                     "met": info["quality"].get("met", True), **chosen, "first_s": f["faithful_until_s"],
                     "median_s": f["median_until_s"], "duration": scene.video.duration, "wall_s": wall,
                     "simulate_s": info["timings_s"]["simulate"]})
        step(f"{FLAGSHIP} --quality {level}: {chosen['method']} dt={chosen['dt']:g} {chosen['precision']}")
    return rows


def quality_md(rows: list[dict], quick: bool) -> str:
    """docs/certified-renders.md's quality table, as `pendulum accuracy` measured it."""
    d = rows[0]["duration"]
    lines = [f"Each `--quality` level on `{FLAGSHIP}` ({'quick mode, ' if quick else ''}{d:g} s of video), "
             "from `pendulum accuracy` (out/accuracy/quality.md). Target: the median pendulum stays faithful "
             "(within 1e-3 rad of the truth) for that share of the video. Faithful times are the render's own "
             "certificate; wall time is `pendulum simulate` at that level, pilots and certificate included.", "",
             "| level | target | met | method | dt | precision | faithful until (first / median) | wall s "
             "(of which simulation) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['level']} | {r['target']} | {'yes' if r['met'] else '**no**'} | {r['method']} | "
                     f"{r['dt']:.3g} | {r['precision']} | {_t(r['first_s'], d)} / {_t(r['median_s'], d)} | "
                     f"{r['wall_s']:.1f} ({r['simulate_s']:.1f}) |")
    return "\n".join(lines) + "\n"


def _t(t: float, d: float) -> str:
    return f"{d:g} s (all)" if t >= d else f"{t:.2f} s"


def fan_md(rows: list[dict]) -> str:
    lines = [f"## {FLAGSHIP}: faithful time against cost (faithful_{FLAGSHIP}.png)", "",
             "| method | precision | dt | error at 2 s [rad] | faithful until, first / median [s] | "
             "µs per pendulum per simulated s |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['method']} | {r['precision']} | {r['dt']:g} | {r['error']:.2e} | "
                     f"{r['first_s']:.2f} / {r['median_s']:.2f} | {r['cost_us']:.1f} |")
    return "\n".join(lines) + "\n"
