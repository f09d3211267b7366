"""One module per pendulum system; each defines SYSTEM, its System subclass (see render/physics/registry.py)."""
