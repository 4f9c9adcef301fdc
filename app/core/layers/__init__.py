"""The glTF layers beyond the lecture's BRDF: which a material uses, the shader
defines that compile them in, and their numpy twins.

One module per layer mirrors its GLSL file (``shaders/common/<layer>.glsl``), function by
function; ``stack`` mirrors how they stack on the base (``shaders/common/layers.glsl``) and is
the exact layered BRDF the ground truth sums (``alight.accuracy.ground_truth``). The layers and
their fields are ``alight.core.material.LAYERS``; docs/layers.md defines each one exactly.

A material without layers compiles none of this: ``layer_defines`` sets a layer's ``HAS_*``
define only when some material drawn uses it (llvmpipe runs both sides of a branch, so a
uniform "off" would still cost).
"""

from __future__ import annotations

from typing import Iterable

from alight.core.material import LAYERS, Material

# The compile-time define of each layer (shaders/common/surface.glsl, layers.glsl).
LAYER_DEFINES: dict[str, str] = {
    "clearcoat": "HAS_CLEARCOAT",
    "sheen": "HAS_SHEEN",
    "anisotropy": "HAS_ANISOTROPY",
    "transmission": "HAS_TRANSMISSION",
    "volume": "HAS_VOLUME",
    "iridescence": "HAS_IRIDESCENCE",
    "dispersion": "HAS_DISPERSION",
    "diffuse_transmission": "HAS_DIFFUSE_TRANSMISSION",
}
assert set(LAYER_DEFINES) == set(LAYERS)


def used_layers(materials: Iterable[Material]) -> frozenset[str]:
    """The union of ``Material.layers()`` over ``materials``."""
    used: set[str] = set()
    for m in materials:
        used |= m.layers()
    return frozenset(used)


def layer_defines(materials: Iterable[Material]) -> dict[str, None]:
    """The shader defines for the layers any of ``materials`` uses, e.g. {'HAS_CLEARCOAT': None}
    (ShaderLibrary's form: a name without a value), in a fixed order."""
    used = used_layers(materials)
    return {define: None for layer, define in LAYER_DEFINES.items() if layer in used}
