"""The package's version, in a leaf module: render/__init__.py re-exports the API lazily from modules that
need the version, so they read it here rather than from the package (which would make an import cycle)."""
__version__ = "0.1.0"
