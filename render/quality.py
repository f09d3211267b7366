"""The --quality knob: (method, dt, precision) per level, as each system declares it (System.QUALITY).

The levels come from `pendulum accuracy` figures; see README "Accuracy vs. time".
"""
from . import registry
from .errors import SceneError

LEVELS = ("draft", "standard", "high", "reference")


def integrator_for(level: str, system: str, src: str = "--quality") -> dict:
    if level not in LEVELS:
        raise SceneError(f"{src}: --quality: unknown level {level!r}; choose from {', '.join(LEVELS)}")
    return dict(registry.get(system).QUALITY[level])
