"""What a `pendulum bench` run reports (render/commands/bench/command.py runs the phases): report.json's figures and
the targets they are held to, report.md, and targets.md, the table docs/performance.md shows."""
from __future__ import annotations

import functools
import os
import platform
import time

import numpy as np

from . import peers
from ...physics import vector_width

# Issue 27's table (the older issues' targets it does not restate kept); a goal given per CPU kind (cpu_kind():
# AVX-512's wider vectors speed numpy's sin/cos as much as ours, so the ratios to the peers are lower there).
TARGETS = [("render_over_realtime", "<=", 0.6), ("end_to_end_over_encode_floor", "<=", 1.1),
           ("hud_ms_720p", "<=", 1.0), ("matplotlib_peer_ratio", ">=", 3.3), ("matplotlib_draw_ratio", ">=", 10.0),
           ("fractal_fps.flip_time", ">=", 40.0), ("fractal_fps.divergence", ">=", 10.0),
           ("rigid_rk4_peak_fraction.f64", ">=", 0.35), ("rigid_rk4_peak_fraction.f32", ">=", 0.35),
           ("rigid_f32_steps_per_s_1e5", ">=", {"avx2": 60e6, "avx512": 110e6}),
           ("rigid_f64_steps_per_s_1e5", ">=", {"avx2": 35e6, "avx512": 55e6}),
           ("sim_speedup_vs_numpy_1e5", ">=", {"avx2": 15.0, "avx512": 8.0}),
           ("sim_speedup_vs_numba_1e5", ">=", {"avx2": 4.0, "avx512": 2.5}),
           ("fractal_fps.lyapunov", ">=", 5.0),  # issue 25: the FTLE map at 720p
           ("fractal_peak_mem_mb", "<", 2048.0),  # issue 16
           ("rainbow_1000_draw_fps", ">=", 30.0),  # issue 14: 1000 glowing pendulums at 720p
           ("elastic_speedup_vs_numpy_1e5", ">=", 10.0)]  # issue 17


def summarise(res: dict, quick: bool, wall: float, chaos_s: float, load_at_start: list[float]) -> dict:
    """report.json from the phases' results `res` (render/commands/bench/command.py): a run of `wall` seconds whose
    end-to-end render was `chaos_s` seconds of video, with the machine's load average at its start."""
    from ...video.encode import ffmpeg_version

    at = {f"{r['system']}_{r['precision']}": r["speedup"] for r in res["sim"]["rows"] if r["n"] == 10**5}
    headline = f"{res['sim']['rows'][0]['system']}_f64"
    e2e, rb = res["e2e"], res["rainbow"]  # the render and its encode floor, alternating (e2e.py)
    fr = {k.removeprefix("fractal_"): v for k, v in res.items() if k.startswith("fractal_")}  # per colouring
    rows, mpl, pk = res["sim"]["rows"], res["matplotlib"], res["sim"]["peak"]
    kind = cpu_kind()
    rep = {"quick": quick, "wall_s": wall, "created": time.strftime("%Y-%m-%d %H:%M:%S"),
           "rounds": mpl["vs"]["render"]["rounds"],
           "machine": {"cpus": os.cpu_count(), "cpu": cpu_model(), "cpu_kind": kind,
                       "simd": vector_width.simd_flags(),
                       "vector_width": vector_width.planned(),  # the phases' processes set it so
                       "vector_width_ftle": vector_width.planned(tangents=True),  # and the FTLE map's
                       "llvm_cpu": vector_width.llvm_cpu(),  # what Taichi's LLVM takes the CPU for
                       "python": platform.python_version(), "numpy": np.__version__, "ffmpeg": ffmpeg_version(),
                       "load_avg": list(load_at_start), "load_avg_end": list(os.getloadavg())},
           "end_to_end_over_encode_floor": e2e["wall_s"] / e2e["floor_s"],
           "sim_speedup_vs_numpy_1e5": at[headline], "sim_speedup_vs_numpy_1e5_by_case": at,  # f64: presets'
           "fractal_fps": {c: r["fps"] for c, r in fr.items()},  # docs/performance.md: one per colouring
           "fractal_peak_mem_mb": max(r["peak_mem_mb"] for r in fr.values()),
           "rainbow_1000_draw_fps": rb["draw_fps"], "rainbow_1000": rb,
           "draw_fps": e2e["draw_fps"], "sim_draw_fps": e2e["sim_draw_fps"], "encode_fps": e2e["encode_fps"],
           "end_to_end_s": e2e["wall_s"], "encode_floor_s": e2e["floor_s"], "frames": e2e["frames"],
           "end_to_end_rounds_s": e2e["rounds_s"], "encode_floor_rounds_s": e2e["floor_rounds_s"],
           "end_to_end_fixed_s": e2e["fixed_s"], "end_to_end_timings": e2e["timings"], "fractal": fr,
           "sim": res["sim"]["rows"], "peak_mem_mb": {k: v["peak_mem_mb"] for k, v in res.items()}, "targets": {},
           **peers.throughput_keys(rows, e2e["wall_s"], chaos_s, mpl),
           "matplotlib_peer": mpl, "matplotlib_draw_ratio": mpl["vs"]["draw"]["value"],
           "hud_ms_720p": res["hud"]["ms"], "hud": res["hud"],
           "peak_gflops": {p: v["peak_gflops"] for p, v in pk.items()},
           "rigid_rk4_peak_fraction": {p: v["fraction"]["value"] for p, v in pk.items()}, "peak": pk,
           "spread": {**peers.spreads(rows, mpl), **{f"rigid_rk4_peak_fraction.{p}": v["fraction"]
                                                     for p, v in pk.items()},
                      # a floor and a render per round, alternating: round i's render over its floor
                      "render_over_realtime": peers.ratio(e2e["rounds_s"], [chaos_s] * len(e2e["rounds_s"])),
                      "end_to_end_over_encode_floor": peers.ratio(e2e["rounds_s"], e2e["floor_rounds_s"]),
                      "hud_ms_720p": res["hud"].get("spread")},
           "peers": {"numba": peers.numba.__version__ if peers.numba else peers.MISSING},
           "compiled": {k: v["compiled"] for k, v in res.items() if v.get("compiled")},  # kernels, by phase
           "rerun": [k for k, v in res.items() if v.get("rerun")]}
    rep.update({"hud_ms_per_frame": rep["hud_ms_720p"],  # the same figures, named as the first targets were
                **{f"peak_flops_{p}": v["peak_gflops"] * 1e9 for p, v in pk.items()},
                **{f"rigid_rk4_fraction_of_peak_{p}": v["fraction"]["value"] for p, v in pk.items()}})
    for key, op, goal in TARGETS:
        goal = goal.get(kind, goal["avx2"]) if isinstance(goal, dict) else goal
        val = functools.reduce(lambda d, k: d[k], key.split("."), rep)  # "fractal_fps.flip_time"
        met = None if val is None else val <= goal if op == "<=" else val >= goal if op == ">=" else val < goal
        rep["targets"][key] = {"value": val, "goal": f"{op} {goal:g}", "met": met,
                               "value_over_goal": None if val is None else val / goal, "spread": rep["spread"].get(key)}
    return rep


def targets_table(r: dict) -> list[str]:
    """The targets as a table: report.md's, and targets.md's, which docs/performance.md shows."""
    return table(["target", "measured", f"range over {r['rounds']} rounds", "goal", "met", "measured / goal"],
                 [[k, fmt(g["value"]), spread_text(g["spread"]), g["goal"], "yes" if g["met"] else "not measured"
                   if g["met"] is None else "**no**", fmt(g["value_over_goal"], ".2f")] for k, g in r["targets"].items()])


def fmt(val, spec=".3g") -> str:
    return "null" if val is None else format(val, spec)


def spread_text(s: dict | None, spec=".3g") -> str:
    """A figure's per-round range and its width in % of the figure; blank for one measured in a single round."""
    return "" if s is None else f"{s['min']:{spec}}..{s['max']:{spec}} ({s['spread_pct']:.0f} %)"


def rounds_text(seconds: list[float]) -> str:
    """Each round's time, in the order they ran: the median beside it is one of them (or between two)."""
    return "rounds " + ", ".join(f"{x:.2f}" for x in seconds) + " s"


def with_spread(s: dict | None, spec=".2f") -> str:
    return "null" if s is None else f"**{s['value']:{spec}}** ({spread_text(s, spec)})"


def width_text(machine: dict) -> str:
    w, cpu, ftle = machine.get("vector_width"), machine.get("llvm_cpu"), machine.get("vector_width_ftle")
    lanes = f"vectorised at {w} lanes" if w else "vectorised at LLVM's own width"
    lanes += f" ({ftle} for the FTLE map)" if ftle and ftle != w else ""
    return f"LLVM's CPU {cpu}, kernels {lanes}" if cpu else f"kernels {lanes}"


def load_text(load) -> str:
    return " / ".join(f"{x:.2f}" for x in load) + " (1 / 5 / 15 min)"


def cpu_kind() -> str:
    """"avx512" or "avx2" (also for a CPU with neither): the kind the targets are chosen by."""
    return "avx512" if "avx512f" in vector_width.simd_flags() else "avx2"


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
           f"{r['created']}, {m['cpus']} CPUs ({m['cpu']}; {', '.join(m['simd']) or 'no AVX'}: {m['cpu_kind']} "
           f"targets; {width_text(m)}), Python {m['python']}, numpy {m['numpy']}, ffmpeg {m['ffmpeg']}. "
           "Every figure comes from "
           f"this one run ({r['wall_s']:.0f} s); load average {load_text(m['load_avg'])} at the start, "
           f"{load_text(m['load_avg_end'])} at the end. Each ratio to a peer is the ratio of medians over "
           f"{r['rounds']} interleaved rounds (ours, the peer, ours again, ...), with the range of the per-round "
           "ratios beside it.", "", "## Targets", ""]
    out += targets_table(r)
    compiled = r.get("compiled", {})
    if compiled:
        twice = [f"{k} ({n})" for k, n in compiled.items() if k in r["rerun"]]
        once = [f"{k} ({n})" for k, n in compiled.items() if k not in r["rerun"]]
        out += ["", " ".join(
            (["Run twice, the second run's figures kept, since the first compiled kernels (how many): "
              f"{', '.join(twice)}."] if twice else []) +
            ([f"Timed with compiles in them (a quick run does not run a phase again): {', '.join(once)}."]
             if once else []))]
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
         f"{r['encode_fps']:.0f} fps, {r['encode_floor_s']:.2f} s ({rounds_text(r['encode_floor_rounds_s'])})"],
        ["end-to-end render", f"{r['end_to_end_s']:.2f} s ({rounds_text(r['end_to_end_rounds_s'])})"],
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
    out += table(["system", "precision", "N", "Taichi", "numpy", "speedup (range)", "numba (N=1e5)",
                  "vs numba (range)", "max diff after 100 steps (N=100)"],
                 [[s["system"], s["precision"], f"{s['n']:.0e}", f"{s['taichi'] / 1e6:.2f}",
                   f"{s['numpy'] / 1e6:.2f}", with_spread(s["vs"]["numpy"]),
                   "" if s["n"] != 10**5 else fmt(s["numba"] and s["numba"] / 1e6, ".2f"),
                   "" if s["n"] != 10**5 else with_spread(s["vs"]["numba"]), f"{s['agree']:.1e}"]
                  for s in r["sim"]])
    out += ["", "## Peak floating-point rate (render/commands/bench/peak.py) and the rigid RK4 kernel's share of it "
            "(N=1e5)", ""]
    out += table(["precision", "peak GFLOP/s", "flops per RK4 step", "rigid RK4 GFLOP/s", "fraction of peak (range)"],
                 [[p, f"{v['peak_gflops']:.1f}", v["flops_per_step"], f"{v['rigid_rk4_gflops']:.1f}",
                   with_spread(v["fraction"], ".3f")] for p, v in r["peak"].items()])
    mp, h = r["matplotlib_peer"], r["hud"]
    out += ["", f"## rigid_chaos against the matplotlib peer, {mp['frames']} frames, 1280x720", ""]
    out += table(["", "ours", "matplotlib", "ours / matplotlib (range)"], [
        ["to MP4 (wall s)", f"{mp['ours_s']:.2f} s", f"{mp['matplotlib_s']:.2f} s", with_spread(mp["vs"]["render"])],
        ["drawn, no encoding (fps)", f"{mp['ours_draw_fps']:.0f}", f"{mp['matplotlib_draw_fps']:.1f}",
         with_spread(mp["vs"]["draw"])]])
    rounds = f"; its {len(h['rounds_ms'])} rounds' medians {spread_text(h['spread'])}" if h.get("spread") else ""
    out += ["", f"HUD alone at {h['size']}: **{h['ms']:.2f} ms** per frame (median of {h['frames']} frames{rounds})."]
    out += ["", "## Peak memory per phase (process tree)", ""]
    out += table(["phase", "MB"], [[k + (" (includes the memory-mapped raw frames)" if k == "e2e" else ""),
                                    f"{v:.0f}"] for k, v in r["peak_mem_mb"].items()])
    return "\n".join(out) + "\n"
