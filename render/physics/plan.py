"""A system as everything but the frame loop sees it, without Taichi: its declaration and the Python side of its
physics.

A system module (render/physics/systems/) subclasses Plan: it declares what the registry, the scene loader and
validation read as class attributes, and writes in numpy what a run is planned from (the step limit, the
initial state, how far a bob can reach). Built on a scene, a Plan is a run planned: its step and initial state,
no field. The system's Taichi side (render/physics/kernels/, on system.System) is imported only where a run is
built (stepper.Run), so listing presets, validating a scene and planning its step import no Taichi
(tests/test_start.py).
"""
import dataclasses
import math

import numpy as np

from . import grid, integrators, keys, poincare


# Planning a map is not free: a 720p map's 381,924 starts and the bound on their fastest rate take 0.23 s. A
# map's certificate plans its scene three times and its shadow's twice (its own step, then each Run's plan and
# system), and the render once more; so this process keeps its last plans, by the scene less its name, up to
# PLANNED_BYTES of starts (a 720p map's are 12 MB; a 4K map's, 129 MB, are planned afresh instead of held).
_PLANNED: dict = {}
PLANNED_BYTES = 64 << 20


def keep_plan(key: str, q0: np.ndarray, v0: np.ndarray, step: tuple):
    """Keep a plan (the oldest go first) if its starts fit within PLANNED_BYTES."""
    if q0.nbytes + v0.nbytes > PLANNED_BYTES:
        return
    _PLANNED[key] = q0, v0, step
    while sum(q.nbytes + v.nbytes for q, v, _ in _PLANNED.values()) > PLANNED_BYTES:
        del _PLANNED[next(iter(_PLANNED))]


class Plan:
    # ---- the declaration (class attributes: read without building anything) ----
    SYSTEM = ""  # the preset's `system` value
    NAME = ""  # prefix of this system's kernel names in metadata ("rigid_advance")
    DOC = ""  # one line for `pendulum presets` and docs/presets.md
    D = 0  # coordinates per pendulum in q (and v)
    LINKS: tuple[str, ...] = ()  # drawing contract: what joins pivot→bob 1→bob 2...: "rod" | "spring"
    ANGLES = False  # q holds the links' angles (a fractal can colour by them)
    KEYS: dict = {}  # preset keys under [pendulums] beyond the chain's (keys.chain) and the common ones
    METHODS: tuple[str, ...] = ()  # integrators this system supports
    DEFAULT_EFFECTS: tuple[str, ...] = ()
    STATE: dict = {}  # `simulate`'s arrays: name -> ("q" | "v", shape per pendulum)
    REFERENCE = ""  # the independent model in render/physics/reference.py ("chain" | "springs")
    ERROR_UNIT = ""  # what a trajectory error is measured in, for reports
    ACCURACY_CASE: tuple[str, float] = ("", 0.0)  # (preset, horizon s) that `pendulum accuracy` measures
    ACCURACY_LADDER: tuple[float, ...] = ()  # dt rungs of the work-precision chart
    CHUNK = 16  # pendulums per group of the advance kernel in f64; f32 takes twice as many (System.advance)

    @classmethod
    def preset_keys(cls) -> dict:
        return keys.chain(len(cls.LINKS), cls.KEYS)

    # ---- one instance per run ----
    def __init__(self, scene, subset=None):
        """The scene's pendulums, or only those at the indices `subset` (the step is the whole scene's): the
        step, refused (SceneError) where the scene pins one beyond its limits."""
        self.start(scene, subset)

    def start(self, scene, subset=None) -> tuple[np.ndarray, np.ndarray]:
        """Plan the run as __init__ says, and return the initial state of its pendulums (for the Taichi side to
        load, which plans through here too: the state is found once)."""
        self.scene = scene
        p = scene.pendulums
        self.count = p.count
        self.method = scene.integrator.method
        self.g = p.gravity
        self.lengths, self.masses = tuple(p.lengths), tuple(p.masses)
        key = repr(dataclasses.replace(scene, name="", description="", budget=None))
        if key in _PLANNED:
            q0, v0, (self.h, self.substeps) = _PLANNED[key]
        else:
            q0, v0 = self.initial_state()
            self.h, self.substeps = integrators.timestep(scene, self.omega_max(q0, v0),
                                                         self.energy_limit(q0, v0, self.method))
            keep_plan(key, q0, v0, (self.h, self.substeps))
        integrators.check_substeps(scene, self.substeps, self.h)  # "auto" is known only now: before any work
        if subset is not None:
            q0, v0 = q0[subset], v0[subset]
        elif key in _PLANNED:  # the kept start stays as it was
            q0, v0 = q0.copy(), v0.copy()
        self.n, self.subset = len(q0), subset
        return q0, v0

    # --------------------------------------------------------------- per-system parts
    def omega_max(self, q0: np.ndarray, v0: np.ndarray) -> float:
        """A bound (rad/s) on the fastest rate of the undamped linearised dynamics over the whole run from these
        initial states: the step limit is the method's limit over it plus the damping rate (integrators.timestep,
        render/physics/stability.py)."""
        raise NotImplementedError

    def energy_limit(self, q0: np.ndarray, v0: np.ndarray, method: str) -> float:
        """The longest step (s) at which `method` keeps the energy gain of the whole run from these initial
        states within integrator.max_drift, where it gains energy on this system (integrators.Method.energy_gain);
        inf where it does not."""
        return math.inf

    def deviation(self, qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
        """How far apart two states are, per pendulum, in the unit of integrator.tolerance: rad on any angle."""
        return np.abs(qa - qb).max(-1)

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def reach(self) -> float:
        """How far from the pivot a bob can get, in m: the canvas frames the scene by it."""
        raise NotImplementedError

    def bob_sizes(self) -> tuple[float, ...]:
        """Each bob's radius relative to the largest (as the cube root of its mass)."""
        top = max(self.masses)
        return tuple((m / top) ** (1 / 3) for m in self.masses)

    def initial_angles(self) -> tuple[np.ndarray, np.ndarray]:
        """Per pendulum, the angle and rate of every link, each (N, links).

        A fan: the preset's angles, the last link's minus spread·i/count; a grid: θ1 × θ2 over [−π, π]², one
        per pixel of the map's plot (render/physics/grid.py)."""
        p, n, links = self.scene.pendulums, self.count, len(self.LINKS)
        th = np.array([[p[f"theta{k}"] for k in range(1, links + 1)]] * n, dtype=np.float64)
        w = np.array([[p[f"omega{k}"] for k in range(1, links + 1)]] * n, dtype=np.float64)
        if p.layout == "grid":
            th, w = grid.grid_state(self.scene, th, w)
        elif p.layout == "shell":
            poincare.shell_start(self.scene, th, w)
        else:
            th[:, -1] = th[:, -1] - p.spread * np.arange(n, dtype=np.float64) / n
        return th, w

    def energy_floor(self) -> float:
        """Energy scale for pendulums whose own energy is near zero."""
        return 1e-3 * sum(self.masses) * max(self.g, 1.0) * sum(self.lengths)
