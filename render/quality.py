"""The --quality knob: (method, dt, precision) per system, chosen from `pendulum accuracy` figures.

See README "Accuracy vs. time" for the measurements behind each row.
"""
from .scene import SceneError

LEVELS = ("draft", "standard", "high", "reference")

TABLE = {
    "rigid": {
        "draft": {"method": "rk4", "dt": 1 / 60, "precision": "f32"},
        "standard": {"method": "rk4", "dt": 1e-3, "precision": "f64"},
        "high": {"method": "rk4", "dt": 2.5e-4, "precision": "f64"},
        "reference": {"method": "rk4", "dt": 5e-5, "precision": "f64"},
    },
    "elastic": {
        "draft": {"method": "verlet", "dt": "auto", "precision": "f32"},
        "standard": {"method": "verlet", "dt": "auto", "precision": "f64"},
        "high": {"method": "yoshida4", "dt": "auto", "precision": "f64"},
        "reference": {"method": "yoshida4", "dt": 1e-5, "precision": "f64"},
    },
}


def integrator_for(level: str, system: str, src: str = "--quality") -> dict:
    if level not in LEVELS:
        raise SceneError(f"{src}: --quality: unknown level {level!r}; choose from {', '.join(LEVELS)}")
    if system not in TABLE:
        raise SceneError(f"{src}: system: unknown value {system!r}; choose from {', '.join(TABLE)}")
    return dict(TABLE[system][level])
