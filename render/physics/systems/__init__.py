"""One module per pendulum system; each defines SYSTEM, its Plan subclass (see render/physics/registry.py), and
imports no Taichi: its Taichi side is the module of the same name in render/physics/kernels/."""
