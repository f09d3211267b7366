"""The Lyapunov spectrum of chosen pendulums: how fast nearby states part, the rate behind the certificate.

Benettin's method (Benettin et al. 1980; Skokos 2008): 2D tangent vectors per pendulum, in canonical
(q, p), are carried through every frame by the exact tangent map of the numerical flow (render/physics/tangent.py)
and re-orthonormalised by QR (numpy, per frame). λ_i(t) = (1/t)·Σ_frames ln |R_ii|, the running estimate,
and the spectrum is its value at the end of the run.

The checks it reports, per pendulum:
- the sum of the exponents, (1/T)·ln |det DΦ_T|, which for this project's damping (−c·p on every one of the
  D coordinates) is −D·c exactly, at any duration; its defect is the numerical flow's volume error (RK4 at
  dt 1e-3: below 1e-10 1/s on classic and damped_heavy, tests/test_lyapunov.py);
- the pairs' sums λ_i + λ_{2D+1−i}, which tend to −c in the long run only: 0 for a Hamiltonian flow, and −c
  for one damped by −c·p on every coordinate, whose flow is conformally symplectic (Dressler 1988).

Error estimate: batch means of the per-frame rates r_f = ln |R_ii| / (frame time). The last half of the run
(past the tangent basis's alignment transient) is cut into BLOCKS blocks of L frames; their means' standard
deviation s_L is the spread of an L-frame average, so a mean over all F frames has standard error
s_L·sqrt(L/F) (blocks long enough to be independent; variance ∝ 1/length). That is the noise; but a running
average also carries the start's transient, a bias that fades like 1/t, which no block spread shows (the
pairs' per-frame sums barely fluctuate, yet at 20 s of classic they are still 0.03 from 0). Its size at T is
what the running average moved over the last half, |λ(T) − λ(T/2)| (for a bias C/t exactly C/T). The error
reported is Z = 2 standard errors plus that drift. The pairs' errors are computed the same way from the
summed rates (their fluctuations are correlated: adding the exponents' errors would overstate them).

Cost, measured on the shared 2-core machine at a load of about 8 (indicative only): per frame of classic (1
pendulum, 17 RK4 substeps) the tangent map took 3 to 5 ms, of which about 1 ms is its kernel and the rest the
Taichi launches that move seeds and images (about 0.5 ms each there), the primal frame about 1 ms, numpy's
QR 0.2 ms: launch-bound, so 8 pendulums cost little more than 1, and fewer frames (a lower video.fps, with
the same dt) cost less at the same result (the R product does not depend on how often QR runs, up to
round-off). The forward-mode kernel compiles in about 2 s (rigid) to 5 s (triple).
"""
from __future__ import annotations

import dataclasses
import math
import sys
import time

import numpy as np

from . import certify
from ..physics import grid, registry
from ..physics.stepper import Run
from ..errors import SceneError, SimulationError
from ..physics.tangent import TangentFlow, check_method

CAP = 8  # pendulums measured by default: the certified ones, evenly thinned to this many
MOST = 128  # pendulums --pendulums may name
BLOCKS = 10
Z = 2.0  # the error reported is Z standard errors
TANGENT_COST = 3  # a dual step costs about this many primal steps (the steps budget counts them)
# The command's cap: 1e11 pendulum-steps is about an hour of rigid f64 RK4 at estimate.RATES, so that rate prices
# them in time too (seconds()), with FRAME_S a frame, for `pendulum lyapunov`'s run-time budget.
STEP_LIMIT = 10 ** 11
STEP_RATE = STEP_LIMIT / 3600.0  # pendulum-steps a second (tangents included) for the time estimate
FRAME_S = 5e-3  # the launches and QR of one frame, whatever the pendulums (measured 3-5 ms: see Cost above)


def default_pendulums(scene) -> np.ndarray:
    """The certificate's pendulums (render/trust/certify.py; a map's trust lattice), thinned evenly to CAP."""
    certified = grid.trust_indices(scene) if scene.fractal else certify.certified(scene)
    return certified[certify.subsample(len(certified), CAP)]


def chosen(scene, given: list[int] | None) -> np.ndarray:
    """The pendulums to measure: `given` (validated against the scene) or the default."""
    if not given:
        return default_pendulums(scene)
    count = scene.pendulums.count
    bad = [i for i in given if not 0 <= i < count]
    if bad:
        raise SceneError(f"--pendulums {bad[0]}: no such pendulum; {scene.name} has {count} "
                         f"(0 to {count - 1})")
    if len(set(given)) != len(given):
        raise SceneError(f"--pendulums: {', '.join(map(str, given))}: a pendulum named twice")
    if len(given) > MOST:
        raise SceneError(f"--pendulums: {len(given)} pendulums; at most {MOST}")
    return np.array(given, dtype=np.int64)


def check(scene, indices: np.ndarray):
    """Refuse, before any work, what cannot run: an integrator without a tangent map, a run beyond the
    step budget (the tangent vectors' dual steps counted), a spectrum of fewer than two frames."""
    check_method(scene)
    if scene.frames < 2 * BLOCKS + 1:
        raise SceneError(f"{scene.source}: video.duration: {scene.video.duration:g} s at {scene.video.fps} fps "
                         f"gives {scene.frames} frames; the spectrum's error needs at least {2 * BLOCKS + 1}")
    steps = _steps(scene, indices)
    if steps > STEP_LIMIT:
        raise SceneError(f"{scene.source}: video.duration: the spectrum needs about {steps:.3g} "
                         f"pendulum-steps (tangent vectors included), beyond the budget of "
                         f"{STEP_LIMIT:.0e}; use fewer --pendulums or a shorter video.duration")


def _steps(scene, indices: np.ndarray) -> float:
    plan = registry.get(scene.system)(scene, subset=indices[:1])
    return scene.frames * plan.substeps * len(indices) * (1 + 2 * plan.D * TANGENT_COST)


def seconds(scene, indices: np.ndarray) -> float:
    """The spectrum's estimated run time: its steps at STEP_RATE, and each frame's launches (FRAME_S), which
    are most of it where many frames have few substeps."""
    return _steps(scene, indices) / STEP_RATE + scene.frames * FRAME_S


def error(rates: np.ndarray) -> np.ndarray:
    """The error of the mean of `rates` (F, ...) over all F frames: Z standard errors by batch means of the
    last half, plus how far the running mean still moved over that half."""
    total = len(rates)
    tail = rates[total // 2:]
    size = len(tail) // BLOCKS
    means = tail[len(tail) - size * BLOCKS:].reshape(BLOCKS, size, *rates.shape[1:]).mean(1)
    drift = np.abs(rates.mean(0) - rates[:total // 2].mean(0))
    return Z * means.std(0, ddof=1) * math.sqrt(size / total) + drift


def spectrum(scene, indices: np.ndarray, arch: str = "cpu", threads=None, progress: bool = False) -> dict:
    """Per pendulum, the running estimates (frames, 2D) of the spectrum, in f64 with the scene's integrator;
    and the per-frame log growths ln |R_ii|. Returns {"t": (F,), "running": (F, n, 2D), "logs": ...}."""
    s64 = scene.replace(integrator={"precision": "f64"})
    run = Run(s64, arch, threads, subset=indices)
    sim = run.sim
    flow = TangentFlow(sim)
    dim = 2 * sim.D
    basis = np.tile(np.eye(dim), (sim.n, 1, 1))  # the initial basis: the canonical axes
    frames = scene.frames - 1
    logs = np.empty((frames, sim.n, dim))
    t0 = time.perf_counter()
    for f in run.frames(energy=False):  # the NaN watchdog on
        if f:  # the images of the frame just stepped
            basis, r = np.linalg.qr(images)
            logs[f - 1] = np.log(np.abs(np.diagonal(r, axis1=1, axis2=2)))
            if not np.isfinite(logs[f - 1]).all():
                bad = int(np.nonzero(~np.isfinite(logs[f - 1]).all(1))[0][0])
                raise SimulationError(f"{scene.name}: frame {f} (t={sim.t:.4g} s): pendulum {indices[bad]}: the "
                                      f"tangent vectors became degenerate or not finite")
            if progress and ((f - 1) % 60 == 0 or f == frames):
                sys.stderr.write(f"\rlyapunov {100 * f / frames:3.0f}%  {time.perf_counter() - t0:5.1f}s")
                sys.stderr.flush()
        if f < frames:
            images = flow.frame(basis)  # DΦ of the frame ahead, from the state before the step
    if progress:
        sys.stderr.write("\n")
    frame_dt = sim.substeps * sim.h
    t = frame_dt * np.arange(1, frames + 1)
    return {"t": t, "running": np.cumsum(logs, 0) / t[:, None, None], "rates": logs / frame_dt,
            "D": sim.D, "h": sim.h, "substeps": sim.substeps, "cost_s": time.perf_counter() - t0}


def summary(run: dict, damping: float) -> list[dict]:
    """Per pendulum: the exponents (descending), their errors, and the checks."""
    out = []
    D, rates = run["D"], run["rates"]
    for j in range(rates.shape[1]):
        r = rates[:, j]
        order = np.argsort(-r.mean(0), kind="stable")  # Benettin's columns come out descending; make sure
        r = r[:, order]
        lam, err = r.mean(0), error(r)
        pairs = r[:, :D] + r[:, ::-1][:, :D]  # λ_i + λ_{2D+1-i}
        out.append({"exponents": lam.tolist(), "errors": err.tolist(), "duration_s": float(run["t"][-1]),
                    "frames": len(r),
                    "checks": {"sum": float(lam.sum()), "expected_sum": 0.0 - D * damping,
                               "sum_defect": float(lam.sum() + D * damping),
                               "pair_sums": pairs.mean(0).tolist(), "pair_errors": error(pairs).tolist(),
                               "expected_pair_sum": 0.0 - damping},
                    "columns": order.tolist()})  # the Benettin columns, as sorted
    return out


def horizons(scene, indices: np.ndarray, lam1: list[float], arch: str, threads) -> list[dict]:
    """What λ1 predicts against what the certificate measures, for the pendulums `indices`."""
    return predictions(certify.certify(scene.replace(integrator={"min_faithful": 0.0}), arch, threads, indices), lam1)


def predictions(cert, lam1: list[float]) -> list[dict]:
    """Per certified pendulum: the horizon ln(tol / e0)/λ1 from the error e0 after the first frame (run against
    the certificate's shadow, as certify measures it), beside the certificate's faithful time. Errors are
    injected every step, not once, so it is a rough guide."""
    tol, out = cert.tolerance, []
    for k, e0 in enumerate(cert.initial_error):
        ok = lam1[k] > 0 and e0 > 0
        out.append({"tolerance": tol, "unit": cert.unit, "initial_error": float(e0),
                    "predicted_horizon_s": float(math.log(tol / e0) / lam1[k]) if ok else None,
                    "faithful_until_s": float(cert.until_s[k]),
                    "faithful_through_the_end": bool(cert.until_s[k] >= cert.duration)})
    return out


def for_certificate(scene, cert, arch: str = "cpu", threads=None) -> dict:
    """metadata's faithfulness.lyapunov for a render with the "lyapunov" effect: λ1 of the certified pendulums
    (thinned evenly to CAP) and the horizon it predicts, beside the faithful time the certificate measured."""
    pick = certify.subsample(len(cert.indices), CAP)
    indices = cert.indices[pick]
    run = spectrum(scene, indices, arch, threads)
    rows = summary(run, scene.pendulums.damping if scene.has("damping") else 0.0)
    lam1 = [r["exponents"][0] for r in rows]
    sub = dataclasses.replace(cert, indices=indices, until_s=cert.until_s[pick], initial_error=cert.initial_error[pick])
    return {"unit": "1/s", "method": "Benettin, QR every frame, the exact tangent map (render/trust/lyapunov.py)",
            "cost_s": round(run["cost_s"], 3),
            "pendulums": [{"pendulum": int(i), "lambda1": lam, "lambda1_error": r["errors"][0], **pred}
                          for i, lam, r, pred in zip(indices, lam1, rows, predictions(sub, lam1))]}


def measure(scene, indices: np.ndarray, arch: str = "cpu", threads=None, progress: bool = False):
    """lyapunov.json's content (a dict) and the running estimates for the chart."""
    check(scene, indices)
    run = spectrum(scene, indices, arch, threads, progress)
    damping = scene.pendulums.damping if scene.has("damping") else 0.0
    rows = summary(run, damping)
    faith = horizons(scene, indices, [r["exponents"][0] for r in rows], arch, threads)
    for i, row, f in zip(indices, rows, faith):
        row["pendulum"] = int(i)
        row["faithfulness"] = f
    doc = {"preset": scene.name, "preset_hash": scene.hash(), "system": scene.system, "unit": "1/s",
           "coordinates": "canonical (q, p): p = momenta(q, v) of the system",
           "method": {"integrator": scene.integrator.method, "dt": run["h"], "substeps": run["substeps"],
                      "precision": "f64", "tangent": "forward-mode AD of the integrator's frame map (Taichi FwdMode)",
                      "orthonormalisation": "QR every frame", "initial_basis": "the canonical axes"},
           "error": f"{Z:g} standard errors, by batch means of the per-frame rates over the run's last half "
                    f"({BLOCKS} blocks)",
           "cost_s": round(run["cost_s"], 3), "pendulums": rows}
    return doc, run
