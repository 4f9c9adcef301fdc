"""The image-based-lighting models the forward pass can use, by name.

Each name selects one function of ``shaders/common/ibl.glsl`` (compiled in through the
``IBL_MODEL`` define, so only the chosen model's code runs per pixel). ``lecture`` is the seed
lecture's ``cook_torrance_IBL`` and never changes: it is the point the others are measured from.
Each model after it adds one fix, so the chart (``alight chart``) shows what each is worth;
``app/accuracy/converged.py``'s ``ibl_converged`` is the numpy twin of every model.
"""

from __future__ import annotations

IBL_MODELS: dict[str, str] = {
    "lecture": "the seed lecture's cook_torrance_IBL: kd and F from fresnel_schlick_roughness(n.v), "
               "specular = prefiltered(R) (F A + B)",
    "lecture-schlick": "the lecture with plain Fresnel-Schlick at n.v for kd and F (no roughness term)",
    "karis": "Karis' split as published: specular prefiltered(R) (F0 A + B), diffuse weight "
             "(1 - F0)(1 - Fc averaged over the cosine lobe)",
    "dominant": "karis, fetched at the specular lobe's mean direction (from the BRDF LUT) instead of R",
    "alight": "dominant for the environment without its compact sources, and those sources (the sun) "
              "through the exact BRDF",
    "stretched": "alight, with the lobe's shape from two round fetches fitted to the real lobe in lobe "
                 "space (app/core/stretched_lobe.json) instead of one at its mean direction",
}

DEFAULT_IBL_MODEL = "alight"

# Models whose maps hold the compact sources as the lecture's bake would (the shader adds them as
# baked); the others shade them exactly.
SUNS_AS_BAKED = ("lecture", "lecture-schlick", "karis", "dominant")


def ibl_model_index(name: str) -> int:
    """The value of the shader's IBL_MODEL define for ``name`` (its position in IBL_MODELS)."""
    try:
        return list(IBL_MODELS).index(name)
    except ValueError:
        raise ValueError(f"unknown IBL model '{name}' (known: {', '.join(IBL_MODELS)})") from None
