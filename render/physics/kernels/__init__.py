"""Each system's Taichi side: the module named as its own in render/physics/systems/ defines KERNELS, a
@ti.data_oriented subclass of the system's Plan and of system.System (see render/physics/registry.py)."""
