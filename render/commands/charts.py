"""The charts of `pendulum accuracy`: work-precision, energy drift, f32-vs-f64 divergence, and the flagship's
faithful time against cost. Drawn with matplotlib (Agg), written atomically."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from ..physics.integrators import METHOD
from ..video.atomic import write_atomic

STYLE = {"f64": "-", "f32": "--"}
COST = "cost: wall time per pendulum per simulated second [µs]  (= ns per step / dt)"


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, ax, path: Path, xlabel: str, ylabel: str, title: str, **legend):
    ax.set(xlabel=xlabel, ylabel=ylabel, title=title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, **legend)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    write_atomic(path, buf.getvalue())
    _plt().close(fig)


def lines_by_method(ax, rows, x, y, plot="loglog", ring=None):
    """One line per method and precision (f64 solid, f32 dashed); rows with x(r), y(r) finite."""
    for m in dict.fromkeys(r["method"] for r in rows):
        for p in ("f64", "f32"):
            pts = [(x(r), y(r), r["dt"]) for r in rows if (r["method"], r["precision"]) == (m, p)
                   and math.isfinite(y(r))]
            if pts:
                xs, ys, dts = map(np.array, zip(*pts))
                getattr(ax, plot)(xs, ys, STYLE[p], marker="o", ms=4, color=METHOD[m].color, label=f"{m} {p}")
                if ring is not None:
                    at = dts == ring
                    getattr(ax, plot)(xs[at], ys[at], "o", ms=10, mfc="none", color=METHOD[m].color)


def accuracy_charts(out: Path, rows, energy, chaos, cases, units, fps, long_dt, chaos_fps):
    """Per system: work-precision and energy drift; and the f32-vs-f64 divergence of the flagship."""
    plt = _plt()
    for s, (preset, horizon) in cases.items():
        mine = [r for r in rows if r["system"] == s]
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(8, 5.5))
        lines_by_method(ax, mine, lambda r: r["ns_per_step"] / r["dt"] / 1e3,
                        lambda r: max(r["traj_error"], 1e-16), ring=long_dt)
        save(fig, ax, out / f"work_precision_{s}.png", COST, f"trajectory error at t = {horizon:g} s, {units[s]}",
             f"Work-precision, {s} ({preset}): each curve a dt ladder, ring = dt 1e-3", ncol=2)

        fig, ax = plt.subplots(figsize=(8, 5.5))
        steps = 0
        for (s2, m, p), series in energy.items():
            if s2 == s:  # running max: a bounded error stays flat, a drift keeps climbing
                ax.semilogy(np.arange(1, len(series)) / fps, np.maximum.accumulate(np.abs(series[1:]).max(1)),
                            STYLE[p], color=METHOD[m].color, label=f"{m} {p}")
                steps = round((len(series) - 1) / fps / long_dt)
        save(fig, ax, out / f"energy_drift_{s}.png", "simulated time [s]",
             "relative energy error so far, max |E − E0| / |E0| [1]",
             f"Energy drift, {s} ({preset}): {steps} steps of dt = {long_dt:g} s", ncol=2)
    if chaos:
        divergence_chart(out / "divergence.png", chaos, chaos_fps)


def divergence_chart(path: Path, chaos, chaos_fps):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    b64, b32 = chaos["f64"], chaos["f32"]
    t = np.arange(len(b64)) / chaos_fps
    near = np.median(np.linalg.norm(np.diff(b64, axis=1), axis=-1), 1)
    err = np.linalg.norm(b32 - b64, axis=-1)
    ax.semilogy(t, np.sqrt(((b64 - b64.mean(1, keepdims=True)) ** 2).sum(-1).mean(1)), color="gray",
                label="f64: spread of the fan (RMS about its centroid)")
    ax.semilogy(t, near, color="tab:blue", label="f64: neighbour gap (median) — what must be resolved")
    ax.semilogy(t, np.median(np.linalg.norm(np.diff(b32, axis=1), axis=-1), 1), ":", color="tab:red",
                label="f32: neighbour gap (median)")
    ax.semilogy(t, np.median(err, 1), color="black", label="f32 − f64, same pendulum (median)")
    ax.semilogy(t, err.max(1), color="black", lw=0.7, ls="--", label="f32 − f64, same pendulum (max)")
    lost = np.nonzero(np.median(err, 1) > near)[0]
    if len(lost):
        t_lost = t[lost[0]]
        ax.axvline(t_lost, color="tab:red", lw=1)
        ax.text(t_lost + 0.15, ax.get_ylim()[0] * 1.5, f"f32 error > neighbour gap from t = {t_lost:.1f} s",
                fontsize=8, color="tab:red", va="bottom")
    save(fig, ax, path, "simulated time [s]", "distance between outer bobs [m]",
         "rigid_chaos: 100 pendulums 1e-6 rad apart (rk4, dt 1e-3), f64 vs f32", loc="lower right")


def flagship_charts(out: Path, rows, name: str, horizon: float, duration: float, count: int):
    """Work-precision of the fan (error at the horizon against cost) and its median faithful time against cost."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    lines_by_method(ax, rows, lambda r: r["cost_us"], lambda r: max(r["error"], 1e-16), ring=1e-3)
    save(fig, ax, out / f"work_precision_{name}.png", COST,
         f"largest angle error of the fan at t = {horizon:g} s [rad]",
         f"Work-precision, {name} ({count} pendulums): each curve a dt ladder, ring = dt 1e-3", ncol=2)
    fig, ax = plt.subplots(figsize=(8, 5.5))
    lines_by_method(ax, rows, lambda r: r["cost_us"], lambda r: r["median_s"], plot="semilogx", ring=1e-3)
    ax.set_ylim(0, duration * 1.02)
    save(fig, ax, out / f"faithful_{name}.png", COST, "median pendulum faithful until [s] (1e-3 rad of DOP853)",
         f"What accuracy buys: {name}, {duration:g} s, {count} pendulums; ring = dt 1e-3", ncol=2)


def lyapunov_chart(path: Path, t: np.ndarray, running: np.ndarray, pendulums, name: str, expected_sum: float):
    """The running estimates of the spectrum against time: running (F, n, 2D), one colour per exponent, one
    line per pendulum; and their sum, which must sit on −D·c (dashed) at every time."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    dim = running.shape[2]
    for k in range(dim):
        for j, p in enumerate(pendulums):
            ax.plot(t, running[:, j, k], color=f"C{k}", lw=1.0, alpha=1.0 if j == 0 else 0.45,
                    label=f"λ{k + 1}" if j == 0 else None)
    ax.plot(t, running[:, 0].sum(-1), color="black", lw=0.8, label="sum (first pendulum)")
    ax.axhline(expected_sum, color="black", ls="--", lw=0.8, label=f"−D·c = {expected_sum + 0.0:g} 1/s")
    ax.set_xscale("log")
    which = ", ".join(map(str, pendulums[:8])) + (", ..." if len(pendulums) > 8 else "")
    save(fig, ax, path, "simulated time t [s]", "running estimate (1/t)·Σ ln |R_ii| [1/s]",
         f"Lyapunov spectrum, {name}: pendulum {which} (QR every frame)", ncol=2)
