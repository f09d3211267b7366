"""pendulum: double-pendulum presets to MP4 and GIF, simulated and drawn with Taichi."""
import os

# Before any module imports taichi: no network version check, no banner on stdout.
os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")

__version__ = "0.1.0"
