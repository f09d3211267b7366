"""The --quality levels by name: what the scene loader and the command line check a level against.

Apart from render/trust/quality.py, which chooses the integrator a level calls for and so starts Taichi: a
bad --quality is refused, and `pendulum --help` lists the levels, without it.
"""
from ..errors import SceneError

LEVELS = ("draft", "standard", "high", "reference")


def check_level(level: str, src: str = "--quality"):
    if level not in LEVELS:
        raise SceneError(f"{src}: --quality: unknown level {level!r}; choose from {', '.join(LEVELS)}")
