"""The frame loop: every run that steps a system from frame time to frame time steps through Run.frames, or,
where nothing is drawn or measured between frames (the certificate's runs), through Run.record, the same
steps in one launch.

A Run starts Taichi for its scene (runtime.init: nothing is restarted when it already runs with those
settings), then builds the scene's system in it, so no caller has to remember to start Taichi first, or in
which precision. Run.frames then, frame by frame: advances the state to the next frame time in substeps
(the system's advance kernel, or a map's own), moves the clock, measures the energy and runs the watchdog
(NaN/inf anywhere, energy drift beyond the tolerance: System.check) before it yields the frame. Whether the
run stays faithful is the caller's to judge from what is yielded (render/trust/certify.py, quality.py: the
tolerance is the certificate's).

Taichi has one runtime per process: a Run built before Taichi was restarted in another precision has lost
its fields (runtime.generation), and says so instead of reading freed memory.

A system's kernels are compiled for its instance: every constant it holds (the pendulum count, masses,
lengths, method...) is baked into them, and Taichi compiles them afresh for each new instance, a second or
more per kernel. So a Run reuses a system that an earlier run of the same runtime built with the same
constants, once nothing else holds it: only the state, the clock and the step (kernel arguments, not
constants) change. `pendulum accuracy` steps each case at several dt; a process that renders one scene
twice compiles once.
"""
from __future__ import annotations

import gc
import sys
import time

import numpy as np

from . import registry
from .integrators import DEFAULT_MAX_DRIFT


class Run:
    """One system of `scene` (only the pendulums at `subset`, if given) in a Taichi runtime started for it.

    precision: the runtime's, where it is not the scene's (a comparison draws every panel from f64 states).
    keep_log: add this run's kernels and fields to those logged so far (runtime.launched, .allocated: what
    metadata reports), as one drawing pass of several systems does, instead of starting the log afresh.
    compensated: RK4 with compensated sums, the certificate's shadow (System)."""

    def __init__(self, scene, arch: str = "cpu", threads: int | None = None, subset=None,
                 precision: str | None = None, keep_log: bool = False, compensated: bool = False):
        # Taichi is imported with the first Run, not with this module: the certificate's and the quality
        # levels' modules import Run, and the run-time estimate reads their sizes without running anything.
        from . import runtime

        self.scene = scene
        tangents = scene.fractal == "lyapunov"  # the FTLE map's kernels take fewer lanes well (vector_width)
        self.arch = runtime.init(arch, precision or scene.integrator.precision, threads, keep_log, tangents)  # in use
        self.generation = runtime.generation()
        self.sim = build(scene, subset, precision, compensated)

    @property
    def current(self) -> bool:
        """Whether Taichi still runs the fields this run was built with."""
        from . import runtime

        return self.generation == runtime.generation()

    def frames(self, count: int | None = None, *, substeps: int | None = None, h: float | None = None,
               advance=None, energy: bool | None = None, watch: bool = True, timings: dict | None = None):
        """Yield each frame index f < count (default: the scene's frames) with the system at that frame's time;
        frame 0 is the state it stands in (t = 0 after a restart).

        substeps, h: the steps per frame (default: the scene's). advance(substeps, h) launches what moves the
        state one frame on (default: the system's advance kernel; a map stops pixels at their events); the
        clock is kept here. energy: measure it every frame (default: when the scene tracks it), frame 0 as
        the reference. watch: the watchdog raises SimulationError on NaN/inf and, with energy, on drift
        beyond integrator.max_drift; off where a blow-up is a result, not an error (pilots, measurements).
        timings["simulate"] gathers the wall time spent here."""
        if not self.current:
            raise RuntimeError(f"{self.scene.name}: Taichi was restarted since this run was built: its fields "
                               f"are gone; build a new Run")
        sim = self.sim
        count = self.scene.frames if count is None else count
        substeps = sim.substeps if substeps is None else substeps
        h = sim.h if h is None else h
        advance = advance or (lambda n, dt: sim.launch(f"{sim.NAME}_advance", n, dt))
        energy = self.scene.has("energy") if energy is None else energy
        max_drift = (self.scene.integrator.max_drift or DEFAULT_MAX_DRIFT) if energy else None
        for f in range(count):
            t = time.perf_counter()
            if f:
                advance(substeps, h)
                sim.t += substeps * h
            if energy:
                sim.measure_energy(first=f == 0)
            if watch:
                sim.check(f, max_drift)
            if timings is not None:
                timings["simulate"] += time.perf_counter() - t
            yield f

    def record(self, frames: int, substeps: int | None = None, h: float | None = None,
               watch: bool = False):
        """From the state it stands in (frame 0), `frames` frames of `substeps` steps of h (default: the
        scene's): the states (frames, N, D) at every frame time in float64, in one launch (System.record),
        where nothing is drawn between frames; the clock moves on as in frames(). No energy is measured.
        watch: a blow-up (NaN/inf, or beyond 1e30) raises SimulationError naming its first frame, as the
        watchdog would have; without, it is a result.

        A launch costs 30-60 us of Python however little it does: rigid_chaos's certificate (100 pendulums, two
        runs of 1200 frames) took 0.44-0.49 s in 4800 launches (under cProfile 0.71 s, 0.22 s of it in kernels),
        and 0.13-0.16 s in two; triple_chaos 0.58-0.62 s and 0.21-0.24 s, rainbow_1000 0.77-0.83 s and
        0.14-0.16 s (`python benchmarks/certificate_time.py PRESET`, 2-core Xeon, AVX-512, 2026-12-06)."""
        if not self.current:
            raise RuntimeError(f"{self.scene.name}: Taichi was restarted since this run was built: its fields "
                               f"are gone; build a new Run")
        from . import runtime
        sim = self.sim
        substeps = sim.substeps if substeps is None else substeps
        h = sim.h if h is None else h
        out = np.empty((frames, sim.n, sim.D))
        if frames:
            sim.record(out, substeps, h, runtime.serial(sim.n * substeps * frames))
        t0 = sim.t
        sim.t += max(frames - 1, 0) * substeps * h
        if watch and int(sim.bad[None]) < sim.n:  # the first frame at which System.watch would have said so
            bad = ~(np.abs(out) < 1e30).all(axis=2)
            f = int(bad.any(axis=1).argmax()) if bad.any() else frames - 1  # else v alone, at the last frame
            i = int(bad[f].argmax()) if bad.any() else int(sim.bad[None])
            raise sim.blew_up(f, t0 + f * substeps * h, sim.index(i), "NaN/inf")
        return out


HOST_ONLY = ("scene", "subset", "h", "substeps")  # what the kernels take as arguments or never read
_built: list = []  # (generation, constants, system, bytes of its fields by name) of this process's systems


def build(scene, subset=None, precision: str | None = None, compensated: bool = False):
    """The scene's system in the current runtime: a free one built earlier with the same constants, loaded
    with this scene's start, or a new one (compensated: see System)."""
    from . import runtime
    # the step and the constants, no field
    plan = registry.kernels(scene.system)(scene, subset, allocate=False, compensated=compensated)
    key = constants(plan, precision or scene.integrator.precision)
    _built[:] = [b for b in _built if b[0] == runtime.generation()]  # a restart freed the others' fields
    same = [entry for entry in _built if key is not None and entry[1] == key]
    if same and all(sys.getrefcount(entry[2]) > FREE for entry in same):
        gc.collect()  # a finished run's generator and closures may hold its system in a cycle until then
    for entry in same:
        if sys.getrefcount(entry[2]) <= FREE:
            sim = entry[2]
            vars(sim).update(vars(plan))
            sim.restart()
            for name, size in entry[3].items():  # what this run holds, for its metadata
                runtime.allocated[name] = runtime.allocated.get(name, 0) + size
            return sim
    before = dict(runtime.allocated)
    sim = registry.kernels(scene.system)(scene, subset, compensated=compensated)
    if key is not None:
        _built.append((runtime.generation(), key, sim,
                       {k: v - before.get(k, 0) for k, v in runtime.allocated.items() if v != before.get(k, 0)}))
    return sim


FREE = 2  # sys.getrefcount of a system only _built holds: its tuple and the call's argument


def constants(plan, precision: str):
    """What a system's kernels bake in: every plain value it holds (the host-only ones aside), with the
    energy watch and the precision its solver tolerance follows; None where it holds anything else, which
    is then never reused."""
    def plain(v):
        if isinstance(v, (list, tuple)):
            items = tuple(plain(x) for x in v)
            return None if None in items else items
        return v if isinstance(v, (bool, int, float, str)) or v is None else None

    items = []
    for name, value in sorted(vars(plan).items()):
        if name in HOST_ONLY:
            continue
        if value is not None and plain(value) is None:
            return None
        items.append((name, plain(value)))
    return type(plan), precision, plan.scene.has("energy"), tuple(items)
