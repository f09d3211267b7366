"""The --quality knob: (method, dt, precision) per system, chosen from `pendulum accuracy` figures.

Figures from out/accuracy/accuracy.md (2-core CPU, N = 20000): trajectory error against DOP853 at t = 2 s on
`classic` (rigid, rad) and at t = 1 s on `elastic_fan` (elastic, m), and the kernel's ns per pendulum-step.
Timings moved by up to 1.5x between runs on a shared machine; the orderings below held in every run. See README
"Accuracy vs. time".
"""
from .scene import SceneError

LEVELS = ("draft", "standard", "high", "reference")

TABLE = {
    # Rigid: RK4 beats implicit_midpoint at every cost (dt 1e-3: 1.8e-10 vs 5.6e-6 rad for about the same
    # ns/step), and its energy error over 1e5 steps stays ~1e-9, so every level is RK4; only dt and precision move.
    "rigid": {
        # One step per 60 fps frame. f32 halves the cost of f64's trig (77-112 vs 167-220 ns/step) and its error
        # floor (~3e-6 rad) sits below what dt 1/60 makes anyway (rung 0.02: 9e-5 rad).
        "draft": {"method": "rk4", "dt": 1 / 60, "precision": "f32"},
        # 2.8e-9 rad: 350x below the 1e-6 rad gap between rigid_chaos's neighbours, at half high's cost.
        "standard": {"method": "rk4", "dt": 2e-3, "precision": "f64"},
        "high": {"method": "rk4", "dt": 1e-3, "precision": "f64"},  # 1.8e-10 rad
        # 1.3e-13 rad: as close as the DOP853 reference itself; smaller steps only add round-off.
        "reference": {"method": "rk4", "dt": 2e-4, "precision": "f64"},
    },
    # Elastic: symplectic methods keep the energy error flat (verlet 7e-4, yoshida4 2e-6 after 1e5 steps)
    # where RK4's creeps up (1.4e-5 -> 4.3e-5). "auto" follows the spring stiffness (1e-3 on elastic_fan).
    "elastic": {
        # verlet: 2.5e-5 m at 1e-3 in f32 or f64 (its truncation error is above f32's floor), ~20 ns/step;
        # symplectic_euler costs the same for 3.5e-3 m. f32 does not speed up this sqrt-bound kernel on a
        # CPU but does on GPUs.
        "draft": {"method": "verlet", "dt": "auto", "precision": "f32"},
        "standard": {"method": "verlet", "dt": "auto", "precision": "f64"},
        "high": {"method": "yoshida4", "dt": "auto", "precision": "f64"},  # 6.5e-8 m at 1e-3, ~3x verlet's cost
        # 5.7e-12 m at 1e-4, the reference's own level; 1e-5 would cost 10x for nothing.
        "reference": {"method": "yoshida4", "dt": 1e-4, "precision": "f64"},
    },
}


def integrator_for(level: str, system: str, src: str = "--quality") -> dict:
    if level not in LEVELS:
        raise SceneError(f"{src}: --quality: unknown level {level!r}; choose from {', '.join(LEVELS)}")
    if system not in TABLE:
        raise SceneError(f"{src}: system: unknown value {system!r}; choose from {', '.join(TABLE)}")
    return dict(TABLE[system][level])
