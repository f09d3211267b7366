"""Every exception the CLI maps to an exit code, in one place (no module needs another's internals for them).

- SceneError: bad input (usage, preset, value), exit 2, one line naming the file and the key;
- SimulationError, EncodeError, BatchError: a failure while running, exit 1.
"""


class SceneError(ValueError):
    """Bad input: one line, naming the file and the key."""


class SimulationError(RuntimeError):
    """A failure while running (exit 1), e.g. a numerical blow-up caught by the watchdog."""


class EncodeError(RuntimeError):
    """ffmpeg failed or stopped (exit 1)."""


class BatchError(RuntimeError):
    """The batch could not run at all (e.g. no scheduler): exit 1."""
