"""Image-based light: ``environment`` (equirectangular maps, the studio), ``sun`` (compact
sources taken out of the maps and shaded exactly) and ``bake`` (the GLSL passes of
``shaders/ibl/``: irradiance, prefiltered radiance, the BRDF LUT). Builds on ``core`` and
``exchange``."""
