"""The frame loop: every run that steps a system from frame time to frame time steps through Run.frames.

A Run starts Taichi for its scene (runtime.init: nothing is restarted when it already runs with those
settings), then builds the scene's system in it, so no caller has to remember to start Taichi first, or in
which precision. Run.frames then, frame by frame: advances the state to the next frame time in substeps
(the system's advance kernel, or a map's own), moves the clock, measures the energy and runs the watchdog
(NaN/inf anywhere, energy drift beyond the tolerance: System.check) before it yields the frame. Whether the
run stays faithful is the caller's to judge from what is yielded (render/trust/certify.py, quality.py: the
tolerance is the certificate's).

Taichi has one runtime per process: a Run built before Taichi was restarted in another precision has lost
its fields (runtime.generation), and says so instead of reading freed memory.
"""
from __future__ import annotations

import time

from . import registry
from .integrators import DEFAULT_MAX_DRIFT


class Run:
    """One system of `scene` (only the pendulums at `subset`, if given) in a Taichi runtime started for it.

    precision: the runtime's, where it is not the scene's (a comparison draws every panel from f64 states).
    keep_log: add this run's kernels and fields to those logged so far (runtime.launched, .allocated: what
    metadata reports), as one drawing pass of several systems does, instead of starting the log afresh."""

    def __init__(self, scene, arch: str = "cpu", threads: int | None = None, subset=None,
                 precision: str | None = None, keep_log: bool = False):
        # Taichi is imported with the first Run, not with this module: the certificate's and the quality
        # levels' modules import Run, and the run-time estimate reads their sizes without running anything.
        from . import runtime

        self.scene = scene
        self.arch = runtime.init(arch, precision or scene.integrator.precision, threads, keep_log)  # the one in use
        self.generation = runtime.generation()
        self.sim = registry.kernels(scene.system)(scene, subset)

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
