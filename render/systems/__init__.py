"""One module per pendulum system; each defines SYSTEM, its System subclass (see render/registry.py)."""
