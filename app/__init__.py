"""alight: a physically based material editor and headless renderer."""

__version__ = "0.1.0"

# The Python API (app/api.py), imported on first use so that ``import app`` stays cheap
# (no moderngl, no trimesh): ``from app import AlightRenderer`` triggers it.
_LAZY = {
    "AlightRenderer": "app.api",
    "Material": "app.material",
    "load_preset": "app.material",
    "Camera": "app.scene",
    "Light": "app.scene",
    "AlightError": "app.errors",
}
__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'app' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)
