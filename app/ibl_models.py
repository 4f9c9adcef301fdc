"""The image-based-lighting models the forward pass can use, by name.

Each name selects one branch of ``shaders/common/ibl.glsl`` (compiled in through the
``IBL_MODEL`` define, so only the chosen model's code runs per pixel). ``lecture`` is the seed
lecture's ``cook_torrance_IBL`` and never changes: it is the point the others are measured from.
"""

from __future__ import annotations

IBL_MODELS: dict[str, str] = {
    "lecture": "the seed lecture's cook_torrance_IBL: kd and F from fresnel_schlick_roughness(n.v), "
               "specular = prefiltered(R) (F A + B)",
}

DEFAULT_IBL_MODEL = "lecture"


def ibl_model_index(name: str) -> int:
    """The value of the shader's IBL_MODEL define for ``name`` (its position in IBL_MODELS)."""
    try:
        return list(IBL_MODELS).index(name)
    except ValueError:
        raise ValueError(f"unknown IBL model '{name}' (known: {', '.join(IBL_MODELS)})") from None
