"""The bench's simulation phase: our RK4 kernels against the numpy-vectorised peer (and numba's at N = 1e5), and
the rigid kernel against the machine's peak rate (render/commands/bench/peak.py), over a ladder of pendulum counts in
f32 and f64.

Apart from render/commands/bench/command.py, which runs the phases and times the renders, because this one measures
kernels, not files: steps per second, each side timed in the same interleaved rounds (render/commands/bench/peers.py).
"""
import statistics

import numpy as np

from . import peak, peers
from ...physics import reference

SIM_PRESETS = ("rigid_chaos", "elastic_fan")  # one per system measured; the first gives the headline figure


def phase_sim(cfg, arch, tmp) -> dict:
    """Pendulum-substeps per second of the Taichi kernel and of the numpy baseline, same RK4, same state, in
    interleaved rounds; at N = 1e5 the numba peer too, and for the rigid kernel the peak rate of
    render/commands/bench/peak.py, whose ratio to the kernel's flop rate is rigid_rk4_peak_fraction."""
    import taichi as ti
    from ...physics.stepper import Run
    from ...config.scene import load

    rows, peaks = [], {}
    for prec in ("f32", "f64"):
        for preset in SIM_PRESETS:
            for n in cfg["ladder"]:
                scene = load(preset, [f"pendulums.count={n}", 'integrator.method="rk4"', "integrator.dt=1e-3",
                                      f'integrator.precision="{prec}"', 'effects=["bobs"]'])  # no energy
                sim = Run(scene, arch).sim
                kern, q0, v0 = f"{sim.NAME}_advance", sim.q.to_numpy().T.copy(), sim.v.to_numpy().T.copy()
                if n == cfg["ladder"][0]:  # first check that both integrate the same thing
                    base = Baseline(scene, q0, v0, sim.h)
                    sim.launch(kern, 100)
                    for _ in range(100):
                        base.step()
                    agree = float(np.abs(sim.q.to_numpy().T - base.q).max())
                base = Baseline(scene, q0, v0, sim.h)
                sides = {"taichi": peers.timer(lambda k: (sim.launch(kern, k), ti.sync()), n, cfg["min_s"]),
                         "numpy": peers.timer(lambda k: [base.step() for _ in range(k)], n, cfg["min_s"])}
                if n == 10**5:
                    nb = peers.numba_timer(scene, q0, v0, sim.h, n, cfg["min_s"], peers.timer)
                    sides.update({"numba": nb} if nb else {})
                    if preset == SIM_PRESETS[0]:  # the rigid double pendulum, whose flops peak.py counts
                        sides["peak"] = peak.Peak().timer(cfg["min_s"])
                runs = peers.interleave(sides, cfg["rounds"])
                med = {k: statistics.median(r) for k, r in runs.items()}
                rows.append({"system": scene.system, "precision": prec, "n": n, "taichi": med["taichi"],
                             "numpy": med["numpy"], "numba": med.get("numba"),
                             "speedup": med["taichi"] / med["numpy"], "agree": agree,
                             "vs": {p: peers.ratio(runs["taichi"], runs.get(p)) for p in ("numpy", "numba")},
                             "rounds": runs})
                if "peak" in runs:  # the kernel's flop rate, round by round, over the peak's in the same round
                    per = peak.rigid_rk4_flops(prec, scene.pendulums.lengths, scene.pendulums.masses)
                    flops = [r * per for r in runs["taichi"]]
                    peaks[prec] = {"peak_gflops": med["peak"] / 1e9, "rigid_rk4_gflops": statistics.median(flops) / 1e9,
                                   "flops_per_step": per, "fraction": peers.ratio(flops, runs["peak"])}
    return {"rows": rows, "peak": peaks}


class Baseline:
    """The numpy-vectorised peer: RK4 on render/physics/reference.py's independent model, in the run's precision,
    on (D, N) arrays so that every row is contiguous."""

    def __init__(self, scene, q, v, h: float):
        self.scene, self.q, self.v, self.h = scene, q, v, h

    def step(self):
        self.q, self.v = reference.rk4_step(self.scene, self.q, self.v, self.h)
