"""--quality LEVEL: a guarantee on the scene rendered, met by the cheapest integrator that pilot runs show meets it.

draft, standard and high ask that the median pendulum stay faithful (render/trust/certify.py) for 50 %, 75 % and
100 % of the video at integrator.tolerance. Candidates are every method the system offers, in f32 and f64,
at each step of LADDER that is stable for this scene; each costs its force evaluations per simulated second
(f32 at half weight: it runs about twice as fast in SIMD lanes). Per method and precision, a bisection over
the steps (faithful time grows as the step shrinks, down to round-off) finds the coarsest step that meets the
target, each try a pilot run of PILOT pendulums of the fan against one fine reference (RK4, f64, half the
finest step) that stops as soon as the outcome is known; the cheapest setting found is chosen. When none does, the most faithful is taken and the
render says so. reference is the finest setting, whatever it costs.
"""
from __future__ import annotations

import math
import sys

import numpy as np

from . import certify
from .levels import LEVELS  # noqa: F401 - quality.LEVELS, the levels this module meets
from ..physics import integrators, registry
from ..physics.stepper import Run
from ..errors import SceneError

TARGET = {"draft": 0.5, "standard": 0.75, "high": 1.0}  # of the duration, for the median pendulum
LADDER = (1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)  # steps tried, besides one step per frame
PILOT = 16  # pendulums of the fan the pilots run on


def setting(method: str, dt: float, precision: str) -> dict:
    return {"method": method, "dt": dt, "precision": precision}


def cost(s: dict, fps: int) -> float:
    """Force evaluations per simulated second, f32 at half weight."""
    steps = math.ceil(1.0 / (fps * s["dt"]) - 1e-9) * fps
    return integrators.METHOD[s["method"]].evals * steps * (0.5 if s["precision"] == "f32" else 1.0)


def offered(scene, plan) -> list[dict]:
    """candidates() for the scene's Plan (registry.get): its rate bound and each method's energy
    limit, from its own initial states."""
    q0, v0 = plan.initial_state()
    return candidates(scene, plan.omega_max(q0, v0), {m: plan.energy_limit(q0, v0, m) for m in plan.METHODS})


def candidates(scene, rate: float, energy: dict) -> list[dict]:
    """Every stable (method, dt, precision) the system offers, cheapest first; `energy` holds each method's
    energy limit (System.energy_limit)."""
    frame = 1.0 / scene.video.fps
    limit = {m: integrators.step_limit(_with(scene, setting(m, frame, "f64")), rate, energy[m])
             for m in registry.get(scene.system).METHODS}
    out = [setting(m, dt, p) for m in limit for p in ("f32", "f64")
           for dt in (frame, *(d for d in LADDER if d < frame)) if dt < limit[m]]
    return sorted(out, key=lambda s: (cost(s, scene.video.fps), s["precision"] == "f32"))


def choose(scene, arch: str = "cpu", threads=None):
    """The scene with the integrator its quality level calls for, and a report of the choice."""
    level = scene.quality
    if level is None:
        return scene, {"level": None, "chosen": _as_dict(scene.integrator), "why": "the preset's own settings"}
    cls = registry.get(scene.system)
    plan = cls(scene)
    cands = offered(scene, plan)
    if not cands:
        raise SceneError(f"{scene.source}: --quality {level}: no integrator is stable for this scene at the steps "
                         f"tried ({', '.join(f'{d:g}' for d in LADDER)} s)")
    if level == "reference":
        best = min(cands, key=lambda s: (s["precision"] != "f64", s["dt"], -integrators.METHOD[s["method"]].order))
        return _with(scene, best), {"level": level, "chosen": best, "why": "the finest step in f64, whatever it costs"}
    duration = scene.video.duration
    need = TARGET[level] * duration
    pilot = Pilot(scene, arch, threads, min(s["dt"] for s in cands) / 2, need)
    fps, tried, chosen = scene.video.fps, [], None

    def meets(s: dict) -> bool:
        median = pilot.median_until(s, need)
        tried.append({**s, "cost": cost(s, fps), "median_until_s": median, "pilot_until_s": pilot.horizon})
        return median >= need

    for prec in ("f64", "f32"):  # one Taichi runtime per precision: all f64 pilots first
        for method in registry.get(scene.system).METHODS:
            # Faithful time grows as the step shrinks (until round-off): bisect for the coarsest step that
            # meets the target, among those cheaper than the choice so far.
            ladder = [s for s in cands if (s["method"], s["precision"]) == (method, prec)
                      and (chosen is None or cost(s, fps) < cost(chosen, fps))]
            lo, hi = 0, len(ladder)  # ladder[hi:] meet the target (hi = len: none known to)
            while lo < hi:
                mid = (lo + hi) // 2
                if meets(ladder[mid]):
                    hi = mid
                else:
                    lo = mid + 1
            if hi < len(ladder):
                chosen = ladder[hi]
    report = {"level": level, "target": f"median pendulum faithful for {100 * TARGET[level]:.0f} % of the "
                                         f"{duration:g} s at {scene.integrator.tolerance:g}",
              "pilots": {"pendulums": len(pilot.indices), "tried": tried}}
    if chosen is None:
        best = max(tried, key=lambda r: (r["median_until_s"], -r["cost"]))
        chosen = {k: best[k] for k in ("method", "dt", "precision")}
        print(f"pendulum: --quality {level}: no setting keeps the median pendulum faithful for "
              f"{100 * TARGET[level]:.0f} % of {duration:g} s; using the most faithful, {_name(chosen)} "
              f"(median {best['median_until_s']:.2f} s in pilot runs)", file=sys.stderr)
        report.update(met=False, why="no candidate met the target: the most faithful one")
    else:
        report.update(met=True, why=f"the cheapest of {len(cands)} stable candidates that meets the target, "
                                    f"found by bisection in {len(tried)} pilot runs")
    report["chosen"] = chosen
    return _with(scene, chosen), report


class Pilot:
    """PILOT pendulums of the scene against one fine reference, re-run for each candidate setting."""

    def __init__(self, scene, arch, threads, ref_dt: float, need: float):
        self.scene, self.arch, self.threads = scene, arch, threads
        self.indices = certify.subsample(scene.pendulums.count, PILOT)
        # compensated sums, as the certificate's shadow: plain, its round-off grew like the finest candidate's
        ref = _with(scene, {**setting("rk4", ref_dt, "f64"), "trig": "inline"})
        # As far as the target needs: a pilot's outcome is known there.
        self.frames = min(scene.frames, math.ceil(need * scene.video.fps) + 2)
        # How far a pilot looks: a pendulum still faithful there is faithful "until" here, no further (the
        # certificate's whole duration where the pilot runs to the end), so no report claims what no run saw.
        self.horizon = scene.video.duration if self.frames == scene.frames else (self.frames - 1) / scene.video.fps
        self.ref, _ = certify.trajectory(ref, self.indices, arch, threads, self.frames, compensated=True)
        self.runs = {}

    def median_until(self, s: dict, need: float) -> float:
        """The median pendulum's faithful time under setting s, run only as far as it takes to know: at most
        self.horizon, which the target never exceeds."""
        scene = _with(self.scene, s)
        key = (s["method"], s["precision"])
        if key not in self.runs or not self.runs[key].current:  # one compile per method and runtime
            self.runs[key] = Run(scene, self.arch, self.threads, subset=self.indices)
        run = self.runs[key]
        sim = run.sim
        sim.restart()
        fps, tol = scene.video.fps, scene.integrator.tolerance
        substeps = math.ceil(1.0 / (fps * s["dt"]) - 1e-9)
        h = 1.0 / (fps * substeps)
        until = np.full(len(self.indices), self.horizon)
        half = len(self.indices) // 2
        # No watchdog: a blow-up is an outcome here (NaN is broken), not an error.
        for f in run.frames(self.frames, substeps=substeps, h=h, energy=False, watch=False):
            if not f:
                continue  # the start, where every setting agrees
            err = certify.MARGIN * sim.deviation(sim.q.to_numpy(), self.ref[f]) / tol
            fresh = (until >= self.horizon) & ~(err <= 1.0)  # NaN counts as broken
            until[fresh] = (f - 1) / fps
            if np.sum(until < self.horizon) > half and f / fps <= need:
                break  # the median has broken before the target: no need to run on
        return float(np.median(until))


def _with(scene, s: dict):
    return scene.replace(integrator={**s, "allow_unstable": False})


def _as_dict(integ) -> dict:
    return {"method": integ.method, "dt": integ.dt, "precision": integ.precision}


def _name(s: dict) -> str:
    return f"{s['method']} dt={s['dt']:.3g} {s['precision']}"
