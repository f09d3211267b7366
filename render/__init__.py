"""pendulum: double-pendulum presets to MP4 and GIF, simulated and drawn with Taichi."""
import os

from .version import __version__  # noqa: F401

# Before any module imports taichi: no network version check, no banner on stdout.
os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")

