"""alight: a physically based material editor and headless renderer.

The public names, imported on first use so that ``import alight`` stays cheap (no moderngl,
trimesh or GL until something renders)::

    import alight

    with alight.Renderer(256, quality="low") as r:
        r.set_material("gold", roughness=0.3).save("gold.png")

- ``Renderer``: the headless renderer (``alight.frontends.api``);
- ``Material``, ``Camera``, ``Light``: the scene's plain state (``alight.core``);
- ``Environment``, ``load_environment``: equirectangular maps (``alight.ibl.environment``);
- ``load_preset``, ``list_presets``, ``save_preset``: the F0 table's preset files;
- ``Error``: what a bad input raises (one line naming the file or field, then the problem);
- ``AlightWarning``: the category of what the API says it drew without (a Python warning).

The subpackages, by concern (a lower layer never imports a higher one):
``core`` (math, GPU context, material, scene, meshes) < ``exchange`` (files in and out) <
``ibl`` (environments and the bake) < ``render`` (the forward renderer) < ``accuracy``
(ground truth, twins, metrics, chart, auto quality) < ``frontends`` (CLI, API, batch, pytest
plugin, editor). ``shaders/`` mirrors it: ``common/``, ``ibl/``, ``render/``, ``accuracy/``.

Two names the code uses throughout: "the lecture" is Learn OpenGL's PBR chapters by Joey de
Vries (Theory, Lighting, Diffuse irradiance, Specular IBL), the split sum alight starts from
(``docs/explanation/shading-model.md``); "the conventions" are ``docs/conventions.md``
(coordinates, the equirect mapping, the probe view, the material model, the BRDF, the ground
truth).
"""

__version__ = "0.1.0"

_LAZY = {
    "Renderer": "alight.frontends.api",
    "Material": "alight.core.material",
    "Camera": "alight.core.scene",
    "Light": "alight.core.scene",
    "Environment": "alight.ibl.environment",
    "load_environment": "alight.ibl.environment",
    "load_preset": "alight.exchange.presets",
    "list_presets": "alight.exchange.presets",
    "save_preset": "alight.exchange.presets",
    "Error": "alight.errors",
    "AlightWarning": "alight.errors",
}
__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'alight' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name if name != "Error" else "AlightError")
    globals()[name] = value   # later lookups skip this function
    return value


def __dir__():
    return sorted(__all__)
