"""pendulum: double-pendulum presets to MP4 and GIF, simulated and drawn with Taichi."""
__version__ = "0.1.0"
