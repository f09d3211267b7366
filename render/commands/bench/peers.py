"""The numba and matplotlib peers of `pendulum bench`, the interleaved rounds that time them, and the keys
of issues 17 and 27 they give.

The peer is what a user would write in one page: @njit(parallel=True, fastmath=True), a prange over the
pendulums, RK4 with the state in locals, math.sin / math.cos. It is an independent implementation of the
rigid and elastic equations (as render/physics/reference.py is for numpy), run in the bench's sim phase, in the same
process and the same run as the Taichi kernel it is compared with. numba is a bench-only extra
(pip install -e '.[bench]'), never a runtime dependency: without it the numba keys are null.

Every ratio against a peer comes from interleaved rounds: ours, the peer, ours again, ..., each side timed
once per round, so that a load that comes and goes on a shared machine falls on both sides alike. A ratio is
the ratio of the two sides' medians; its spread is the range of the ratios round by round.
"""
from __future__ import annotations

import math
import statistics
import time

try:
    import numba
except ImportError:  # the bench says so once and writes null
    numba = None

MISSING = ("numba is not installed (pip install 'taichi-pendulum[bench]', or in a checkout pip install -e "
           "'.[bench]'): the numba peer is skipped, its keys are null")


def numba_rk4(scene, dtype):
    """advance(q, v, steps, h) in place on (N, D) arrays of `dtype`, for the scene's model (render/physics/reference.py:
    a chain of two rods, or two springs); None without numba or for another model. Constants are of `dtype`,
    so f32 stays f32 arithmetic."""
    p = scene.pendulums
    chain = scene.model == "chain" and len(p.lengths) == 2
    if numba is None or not (chain or scene.model == "springs"):
        return None
    from numba import njit, prange
    f = dtype.type
    (m1, m2), (l1, l2), g = (f(m) for m in p.masses), (f(x) for x in p.lengths), f(p.gravity)
    half, two, six = f(0.5), f(2.0), f(6.0)

    if chain:
        @njit(fastmath=True, inline="always")
        def accel(q1, q2, w1, w2):
            s1, c1, s2, c2 = math.sin(q1), math.cos(q1), math.sin(q2), math.cos(q2)
            sd, cd = s1 * c2 - c1 * s2, c1 * c2 + s1 * s2
            den = two * (m1 + m2 * sd * sd)
            a1 = (-g * (two * m1 + m2) * s1 - m2 * g * (sd * c2 - cd * s2)
                  - two * sd * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * cd)) / (l1 * den)
            a2 = two * sd * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * c1 + w2 * w2 * l2 * m2 * cd) / (l2 * den)
            return a1, a2

        @njit(parallel=True, fastmath=True)
        def advance(q, v, steps, h):
            for i in prange(q.shape[0]):
                x1, x2, w1, w2 = q[i, 0], q[i, 1], v[i, 0], v[i, 1]
                for _ in range(steps):
                    a1, b1 = accel(x1, x2, w1, w2)
                    p1, p2, u1, u2 = x1 + half * h * w1, x2 + half * h * w2, w1 + half * h * a1, w2 + half * h * b1
                    a2, b2 = accel(p1, p2, u1, u2)
                    r1, r2, y1, y2 = x1 + half * h * u1, x2 + half * h * u2, w1 + half * h * a2, w2 + half * h * b2
                    a3, b3 = accel(r1, r2, y1, y2)
                    s1, s2, z1, z2 = x1 + h * y1, x2 + h * y2, w1 + h * a3, w2 + h * b3
                    a4, b4 = accel(s1, s2, z1, z2)
                    x1 += h / six * (w1 + two * u1 + two * y1 + z1)
                    x2 += h / six * (w2 + two * u2 + two * y2 + z2)
                    w1 += h / six * (a1 + two * a2 + two * a3 + a4)
                    w2 += h / six * (b1 + two * b2 + two * b3 + b4)
                q[i, 0], q[i, 1], v[i, 0], v[i, 1] = x1, x2, w1, w2
        return advance

    k1, k2, tiny = f(p.stiffness / p.lengths[0]), f(p.stiffness / p.lengths[1]), f(1e-12)

    @njit(fastmath=True, inline="always")
    def pull(dx, dy, k, rest):
        r = math.sqrt(dx * dx + dy * dy)
        s = -k * (r - rest) / max(r, tiny)
        return s * dx, s * dy

    @njit(fastmath=True, inline="always")
    def accel4(x):
        f1x, f1y = pull(x[0], x[1], k1, l1)
        f2x, f2y = pull(x[2] - x[0], x[3] - x[1], k2, l2)
        return ((f1x - f2x) / m1, (f1y - f2y) / m1 - g, f2x / m2, f2y / m2 - g)

    @njit(parallel=True, fastmath=True)
    def advance_elastic(q, v, steps, h):
        for i in prange(q.shape[0]):
            x = (q[i, 0], q[i, 1], q[i, 2], q[i, 3])
            u = (v[i, 0], v[i, 1], v[i, 2], v[i, 3])
            for _ in range(steps):
                a1 = accel4(x)
                x2 = (x[0] + half * h * u[0], x[1] + half * h * u[1], x[2] + half * h * u[2], x[3] + half * h * u[3])
                u2 = (u[0] + half * h * a1[0], u[1] + half * h * a1[1], u[2] + half * h * a1[2],
                      u[3] + half * h * a1[3])
                a2 = accel4(x2)
                x3 = (x[0] + half * h * u2[0], x[1] + half * h * u2[1], x[2] + half * h * u2[2],
                      x[3] + half * h * u2[3])
                u3 = (u[0] + half * h * a2[0], u[1] + half * h * a2[1], u[2] + half * h * a2[2],
                      u[3] + half * h * a2[3])
                a3 = accel4(x3)
                x4 = (x[0] + h * u3[0], x[1] + h * u3[1], x[2] + h * u3[2], x[3] + h * u3[3])
                u4 = (u[0] + h * a3[0], u[1] + h * a3[1], u[2] + h * a3[2], u[3] + h * a3[3])
                a4 = accel4(x4)
                x = (x[0] + h / six * (u[0] + two * u2[0] + two * u3[0] + u4[0]),
                     x[1] + h / six * (u[1] + two * u2[1] + two * u3[1] + u4[1]),
                     x[2] + h / six * (u[2] + two * u2[2] + two * u3[2] + u4[2]),
                     x[3] + h / six * (u[3] + two * u2[3] + two * u3[3] + u4[3]))
                u = (u[0] + h / six * (a1[0] + two * a2[0] + two * a3[0] + a4[0]),
                     u[1] + h / six * (a1[1] + two * a2[1] + two * a3[1] + a4[1]),
                     u[2] + h / six * (a1[2] + two * a2[2] + two * a3[2] + a4[2]),
                     u[3] + h / six * (a1[3] + two * a2[3] + two * a3[3] + a4[3]))
            for k in range(4):
                q[i, k], v[i, k] = x[k], u[k]
    return advance_elastic


def interleave(sides: dict, rounds: int) -> dict[str, list[float]]:
    """{side: [its rate in each round]}: each side's callable run once per round, in the dict's order."""
    runs = {name: [] for name in sides}
    for _ in range(rounds):
        for name, once in sides.items():
            runs[name].append(once())
    return runs


def ratio(ours: list[float], peer: list[float] | None) -> dict | None:
    """ours over peer (rates, one per round): the medians' ratio, the range of the per-round ratios, and
    that range as % of the ratio; None when the peer did not run."""
    if not peer:
        return None
    return spread([a / b for a, b in zip(ours, peer)], statistics.median(ours) / statistics.median(peer))


def spread(per: list[float], value: float) -> dict:
    """A figure and its rounds' range, that range as % of it, and how many rounds."""
    return {"value": value, "min": min(per), "max": max(per), "spread_pct": 100.0 * (max(per) - min(per)) / value,
            "rounds": len(per)}


def throughput_keys(rows: list[dict], render_s: float, video_s: float, mpl: dict | None = None) -> dict:
    """Issue 17's report keys from the sim phase's rows at N = 1e5, the timed rigid_chaos render and the
    matplotlib phase; a ratio against a peer that did not run (numba missing) is null. The rows come in
    sim.SIM_PRESETS' order: the rigid pendulum's system first, then the elastic one's. Their spreads are
    in spreads()."""
    rigid, elastic = list(dict.fromkeys(r["system"] for r in rows))[:2]
    at = {(r["system"], r["precision"]): r for r in rows if r["n"] == 10**5}

    def ratio_of(system, peer):
        r = at.get((system, "f64"))
        return r["taichi"] / r[peer] if r and r.get(peer) else None
    return {"sim_speedup_vs_numba_1e5": ratio_of(rigid, "numba"),
            "rigid_f64_steps_per_s_1e5": at[(rigid, "f64")]["taichi"],
            "rigid_f32_steps_per_s_1e5": at[(rigid, "f32")]["taichi"],
            "elastic_speedup_vs_numpy_1e5": ratio_of(elastic, "numpy"),
            "elastic_speedup_vs_numba_1e5": ratio_of(elastic, "numba"),
            "render_over_realtime": render_s / video_s,
            "matplotlib_peer_ratio": mpl["matplotlib_s"] / mpl["ours_s"] if mpl else None}


def spreads(rows: list[dict], mpl: dict | None = None) -> dict:
    """{report key: ratio()} for the keys of throughput_keys (and the bench's own) that compare with a peer."""
    rigid, elastic = list(dict.fromkeys(r["system"] for r in rows))[:2]
    at = {(r["system"], r["precision"]): r.get("vs", {}) for r in rows if r["n"] == 10**5}
    out = {"sim_speedup_vs_numpy_1e5": at[(rigid, "f64")].get("numpy"),
           "sim_speedup_vs_numba_1e5": at[(rigid, "f64")].get("numba"),
           "elastic_speedup_vs_numpy_1e5": at[(elastic, "f64")].get("numpy"),
           "elastic_speedup_vs_numba_1e5": at[(elastic, "f64")].get("numba")}
    if mpl:
        out["matplotlib_peer_ratio"], out["matplotlib_draw_ratio"] = mpl["vs"]["render"], mpl["vs"]["draw"]
    return out


def timer(step, n: int, min_s: float):
    """once(): work per second of one run of step(k), which does k steps of n units of work each (n pendulums'
    substeps, or flops); k is chosen here so that a run takes at least min_s (the first call compiles). The
    bench's kernels, its numpy and numba peers and the peak rate are all timed by it."""
    step(1)
    k = max(1, int(1e4 / n))
    while True:
        t = time.perf_counter()
        step(k)
        dt = time.perf_counter() - t
        if dt >= min_s:
            break
        k = max(k + 1, int(k * min(20.0, 1.3 * min_s / max(dt, 1e-6))))

    def once() -> float:
        t = time.perf_counter()
        step(k)
        return n * k / (time.perf_counter() - t)
    return once


def numba_timer(scene, q, v, h: float, n: int, min_s: float, timer):
    """The numba peer timed from the bench's (D, N) initial state: the bench's `timer` over its advance (a
    callable giving pendulum-substeps per second of one run); None (and one line on stderr) without numba."""
    import sys

    import numpy as np
    dtype = np.dtype(np.float64 if scene.integrator.precision == "f64" else np.float32)
    advance = numba_rk4(scene, dtype)
    if advance is None:
        if numba is None and not _said:
            print(f"bench: {MISSING}", file=sys.stderr)
            _said.append(True)
        return None
    qn, vn, hn = np.ascontiguousarray(q.T, dtype), np.ascontiguousarray(v.T, dtype), dtype.type(h)
    return timer(lambda k: advance(qn, vn, k, hn), n, min_s)  # the timer's first call compiles


_said: list = []


def matplotlib_figure(scene):
    """The matplotlib peer as a user would write it: numpy RK4 (render/physics/reference.py) and rods, bobs and 1 s
    trails as three artist collections, drawn by Agg at the scene's size. Returns (figure, frame(f)): frame f
    moves the artists to frame f (stepping the simulation one frame on from the previous f)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection

    from ...physics import reference, registry

    plan = registry.get(scene.system)(scene)  # the step and the initial state, no Taichi
    q, v = (a.T.copy() for a in reference.initial_state(scene))
    v_ = scene.video
    fig = plt.figure(figsize=(v_.width / 100, v_.height / 100), dpi=100, facecolor="black")
    ax = fig.add_axes((0, 0, 1, 1), facecolor="black")
    reach = 1.1 * plan.reach()
    ax.set_xlim(-reach * v_.width / v_.height, reach * v_.width / v_.height)
    ax.set_ylim(-reach, reach)
    ax.set_axis_off()
    colours = plt.cm.viridis(np.linspace(0, 1, plan.n))
    rods = LineCollection([], colors=colours, linewidths=1.5)
    trails = LineCollection([], colors=colours, linewidths=1.0, alpha=0.5)
    ax.add_collection(trails)
    ax.add_collection(rods)
    links = len(plan.LINKS)
    bobs = ax.scatter(np.zeros(plan.n * links), np.zeros(plan.n * links), s=12, c=np.repeat(colours, links, 0))
    history = []

    def frame(f):
        nonlocal q, v
        if f:
            for _ in range(plan.substeps):
                q, v = reference.rk4_step(scene, q, v, plan.h)
        pts = reference.bob_positions(scene, q.T)  # (N, bobs, 2)
        chain = np.concatenate([np.zeros((len(pts), 1, 2)), pts], axis=1)
        history.append(pts[:, -1])
        del history[:-max(2, int(v_.fps * v_.trail_seconds))]
        rods.set_segments(chain)
        trails.set_segments(np.stack(history, axis=1))
        bobs.set_offsets(pts.reshape(-1, 2))
        return rods, trails, bobs
    return fig, frame


def matplotlib_render(scene, out_file) -> float:
    """The matplotlib peer's frames by FuncAnimation, saved as MP4 by ffmpeg at this project's x264 settings.
    Returns its wall time in s (simulation included)."""
    import time

    import imageio_ffmpeg
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter, FuncAnimation

    from ...video import mp4

    t0 = time.perf_counter()
    fig, frame = matplotlib_figure(scene)
    matplotlib.rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
    writer = FFMpegWriter(fps=scene.video.fps, codec="libx264",
                          extra_args=[*mp4.x264_threads(), "-preset", mp4.PRESET, "-crf", mp4.CRF, "-pix_fmt", "yuv420p"])
    FuncAnimation(fig, frame, frames=scene.frames, blit=False).save(str(out_file), writer=writer, dpi=100)
    plt.close(fig)
    return time.perf_counter() - t0


def matplotlib_draw(scene) -> float:
    """The peer's frames drawn and nothing encoded: per frame what its writer does before piping to ffmpeg
    (canvas.draw, then the RGBA buffer read). Frames per second, the simulation included as in ours."""
    import time

    import matplotlib.pyplot as plt
    import numpy as np

    t0 = time.perf_counter()
    fig, frame = matplotlib_figure(scene)
    for f in range(scene.frames):
        frame(f)
        fig.canvas.draw()
        np.asarray(fig.canvas.buffer_rgba())  # the H×W×4 frame a writer would take
    plt.close(fig)
    return scene.frames / (time.perf_counter() - t0)
