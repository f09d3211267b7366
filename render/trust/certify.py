"""The faithfulness certificate: until when each pendulum of a render is true to the physics, not round-off.

A shadow integrates the same initial states far more accurately: RK4 in f64 with compensated sums, at the
same step when the main method is of lower order (one order higher at least: its error is thousands of times
smaller), at an eighth of it (FINER) for an order-4 method. Per
pendulum, the first frame at which the main run and the shadow differ by more than integrator.tolerance
(rad on any angle; for springs a fraction of the total length) ends its faithful time. The difference d
stands for the main run's error e up to the shadow's own, which these settings keep below a tenth of it
(measured against DOP853 at rtol 1e-13: tests/test_certify.py); the estimate e ≈ 1.1·d never claims more.

Why not Richardson at half the step: on rigid_chaos in f64, RK4 at dt 1e-3 and at 5e-4 part from the true
trajectory by nearly the same amount after a few seconds (ratio 1.6, not 16: chaos amplifies what round-off
and truncation leave alike), while a quarter step is 16x closer. A shadow must be clearly better, not
better by theory. And better at every step: an independent review (2026-12-07, RK4 in 80-bit long double at
2e-5 as the truth) found the earlier shadow, the main method itself at a quarter of the step with plain sums,
claiming pendulums faithful after they had left the truth. In the round-off regime (RK4 f64 at dt 1e-4 or
2e-4) its 4x as many roundings erred as much as the run, and alike, so they hid each other: 16 and 25 of
rigid_chaos's 100 pendulums over-claimed, one by 4.1 s, and 4 of 8 in triple_chaos. At dt 1e-3 a quarter step
was at times only 1.3x closer, not 256x (a pendulum's error grew 100-fold in 5 s at h/4 and 10-fold at h): 2
over-claimed, by up to 0.6 s. Compensated sums and an eighth of the step: none of the 300, nor of the 8
(benchmarks/certificate_truth.py: claims on average 0.3-0.7 % short of the truth, none later). Only at an exact
equilibrium, where f64 cannot hold the 1e-16 rad a fall starts from, was it found late, by 0.06 s
(docs/from-the-talk.md). tests/test_certify.py holds the shadow under a tenth of the run's error against a
long-double reference.

Both runs cover every pendulum while their states at every frame fit in CERTIFY_BYTES (every shipped preset's
fan: rainbow_1000's first pendulum breaks at 6.70 s, where its 128 evenly spaced ones, as certified before,
say 6.80 s; with the earlier shadow 6.72 and 7.60 s), else a subsample of as many as fit and at least
SUBSAMPLE, evenly spaced over the fan (the ends included). They run before the render: pendulums are
independent, so the certified pendulums' main run is the render's, and a render that would be untrue can stop
before it writes anything.
"""
from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..physics import integrators, registry
from ..physics.stepper import Run
from ..errors import SimulationError

SUBSAMPLE = 128  # pendulums certified at the least (every one, when a scene has no more)
# What the certified pendulums' recorded states may take: the main run's and the shadow's, Taichi's record of
# each, and their difference, 4 float64s a coordinate a frame in all; beyond it a long video's large fan is
# certified on a subsample
CERTIFY_BYTES = 256 << 20
HISTOGRAM_ABOVE = 64  # per-pendulum times in metadata up to this many, a histogram beyond


@dataclasses.dataclass(frozen=True)
class Certificate:
    shadow: dict  # method, dt, precision
    tolerance: float
    unit: str
    indices: np.ndarray  # the pendulums certified
    until_s: np.ndarray  # per certified pendulum: the last frame time at which it was faithful
    duration: float
    cost_s: float
    initial_error: np.ndarray  # per certified pendulum: |run − shadow|·MARGIN after the first frame (tolerance's unit)
    lyapunov: dict | None = None  # with the "lyapunov" effect: λ1 and the horizon it predicts (render/trust/lyapunov.py)

    @property
    def faithful_until_s(self) -> float:
        return float(self.until_s.min())

    @property
    def median_until_s(self) -> float:
        return float(np.median(self.until_s))

    @property
    def fraction_faithful(self) -> float:
        """The fraction of pendulums faithful through the whole video."""
        return float(np.mean(self.until_s >= self.duration))

    def to_dict(self) -> dict:
        d = {"shadow": self.shadow, "tolerance": self.tolerance, "unit": self.unit,
             "faithful_until_s": self.faithful_until_s, "median_until_s": self.median_until_s,
             "fraction_faithful": self.fraction_faithful, "certified": len(self.indices),
             "cost_s": round(self.cost_s, 4)}
        if len(self.indices) <= HISTOGRAM_ABOVE:
            d["pendulums"] = [int(i) for i in self.indices]
            # 4 decimals, rounded down (a frame time 16/60 s read 0.2667, later than it); the 1e-6 keeps 0.35,
            # which float64 holds as 3499.9999999999995e-4, from falling to 0.3499
            d["until_s"] = [math.floor(float(u) * 1e4 + 1e-6) / 1e4 for u in self.until_s]
        else:
            d["pendulums"] = {"first": int(self.indices[0]), "last": int(self.indices[-1]),
                              "count": len(self.indices), "spacing": "even"}
            counts, edges = np.histogram(self.until_s, bins=10, range=(0.0, self.duration))
            d["until_s_histogram"] = {"edges_s": [round(float(e), 4) for e in edges],
                                      "counts": [int(c) for c in counts]}
        if self.lyapunov is not None:
            d["lyapunov"] = self.lyapunov
        return d


def subsample(count: int, limit: int = SUBSAMPLE) -> np.ndarray:
    return np.unique(np.round(np.linspace(0, count - 1, min(count, limit))).astype(np.int64))


def certified(scene) -> np.ndarray:
    """The pendulums a fan's certificate runs: all of them while their states fit in CERTIFY_BYTES, else as
    many as fit (at least SUBSAMPLE), evenly spaced."""
    each = 4 * 8 * registry.get(scene.system).D * (scene.frames + 1)
    return subsample(scene.pendulums.count, max(SUBSAMPLE, CERTIFY_BYTES // each))


MARGIN = 1.1  # the shadow's own error is below a tenth of the main run's: e ≤ 1.1·d
FINER = 8  # the shadow's step over an order-4 main method's


def shadow_scene(scene, h: float):
    """The shadow's settings: RK4 in f64 (run with compensated sums: trajectory) at the main step, or at a
    quarter of it for an order-4 main method."""
    high = integrators.METHOD[scene.integrator.method].order >= 4
    return scene.replace(integrator={"method": "rk4", "dt": h / FINER if high else h, "precision": "f64",
                                     "trig": "inline", "allow_unstable": True})


def trajectory(scene, indices: np.ndarray, arch: str, threads=None, frames: int | None = None,
               compensated: bool = False):
    """The states (frames, len(indices), D) of those pendulums at every frame time (the first `frames`
    frames, or all), in float64, a blow-up among them as NaN/inf; and the system that ran them."""
    run = Run(scene, arch, threads, subset=indices, compensated=compensated)
    frames = scene.frames if frames is None else min(frames, scene.frames)
    return record(run, frames), run.sim


def record(run: Run, frames: int, substeps: int | None = None, h: float | None = None,
           watch: bool = False) -> np.ndarray:
    """From the state it stands in, `substeps` steps of h per frame (default: the scene's): the states at
    every frame time, in float64, in one launch (Run.record). watch: a blow-up raises (the certified run's);
    without, it is a result. No energy is measured: the render's own run watches it."""
    return run.record(frames, substeps, h, watch)


def faithful_times(errors: np.ndarray, fps: int, duration: float) -> np.ndarray:
    """Per pendulum, the last frame time before the error first exceeds 1, from errors (frames, N) in units
    of the tolerance; the duration where it never does."""
    broke = errors > 1.0
    first = np.where(broke.any(0), broke.argmax(0), -1)
    return np.where(first < 0, duration, (first - 1) / fps)


# Certificates this process computed, by what they depend on (_key), most recent last. A process that sets up
# the same physics twice, at another frame size or format (a notebook, `show` and then `render`, a batch
# sweep over the video keys), certifies it once: the runs are deterministic, so a second run could only
# repeat the first.
_MEMO: dict = {}
MEMO_SIZE = 16


def _key(scene, arch: str, threads, indices: np.ndarray) -> str:
    """Everything the certificate reads from the scene: the physics, the integrator, the frame times and the
    effects (which decide the kernels), not the frame's size, the formats, the name or the budget."""
    v = scene.video
    return repr((scene.system, scene.effects, sorted(scene.pendulums.items()), scene.integrator, v.fps, v.duration,
                 scene.fractal, scene.map, arch, threads, indices.tobytes()))


def certify(scene, arch: str = "cpu", threads=None, indices: np.ndarray | None = None) -> Certificate:
    """Run the main settings and the shadow on a subsample; per pendulum, until when they agree."""
    t0 = time.perf_counter()
    if indices is None:
        indices = certified(scene)
    key = _key(scene, arch, threads, indices)
    if key in _MEMO:
        cert, h = _MEMO.pop(key)
        _MEMO[key] = cert, h
        check(scene, cert, h)  # this scene's name in the refusal
        return dataclasses.replace(cert, cost_s=time.perf_counter() - t0)
    shadow_first = scene.integrator.precision != "f64"  # then the render's own init comes last
    if shadow_first:
        plan = registry.get(scene.system)(scene, subset=indices[:1])  # the step only
        ref, _ = trajectory(shadow_scene(scene, plan.h), indices, arch, threads, compensated=True)
    run = Run(scene, arch, threads, subset=indices)
    main = record(run, scene.frames, watch=True)  # a blow-up, not an untrue run: the watchdog says so
    sim = run.sim
    shadow = shadow_scene(scene, sim.h)
    if not shadow_first:
        ref, _ = trajectory(shadow, indices, arch, threads, compensated=True)
    tol = scene.integrator.tolerance
    errors = MARGIN * sim.deviation(main, ref) / tol
    errors[~np.isfinite(errors)] = np.inf  # a blow-up is as unfaithful as it gets
    until = faithful_times(errors, scene.video.fps, scene.video.duration)
    cls = registry.get(scene.system)
    cert = Certificate({"method": shadow.integrator.method, "dt": shadow.integrator.dt, "precision": "f64"}, tol,
                       "rad" if cls.ANGLES else "of the total length", indices, until, scene.video.duration,
                       time.perf_counter() - t0, errors[min(1, len(errors) - 1)] * tol)
    _MEMO[key] = cert, sim.h
    while len(_MEMO) > MEMO_SIZE:
        del _MEMO[next(iter(_MEMO))]
    check(scene, cert, sim.h)
    return cert


def check(scene, cert: Certificate, h: float):
    """The faithfulness watchdog: refuse a run whose median pendulum is untrue for most of the video."""
    least = scene.integrator.min_faithful * scene.video.duration
    if cert.median_until_s < least:
        i = scene.integrator
        raise SimulationError(
            f"{scene.name}: the median pendulum stays faithful only until {cert.median_until_s:.2f} s, less than "
            f"integrator.min_faithful = {i.min_faithful:g} of the {scene.video.duration:g} s, at tolerance "
            f"{cert.tolerance:g} {cert.unit} ({i.method}, dt={h:.3g} s, {i.precision}); use a finer --quality "
            f"(standard or high), or --set integrator.min_faithful=0 to accept an untrue result knowingly")
