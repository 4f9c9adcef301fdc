"""Names the Python side and the GLSL side share, from one source.

Every value a shader compares with a number that Python chose (the IBL model, the alpha mode, the
background, a light's kind, the debug view, the tone curve, a material map's bit) is an enum here;
``glsl_defines()`` turns them into the ``#define``s that ``app/core/gpu.py``'s ``load_source``
puts at the top of every shader, so ``#if IBL_MODEL == IBL_MODEL_STRETCHED`` in GLSL and
``IblModel.STRETCHED`` in Python are one number by construction (as Filament names its quality
choices, ``SPECULAR_D_GGX``). ``SHADER_OPTIONS`` lists the defines Python may pass to a program,
with what each one does: ``load_source`` refuses any other, and ``tests/test_shader_names.py``
checks that every name a shader's preprocessor tests is generated here, declared here, or defined
by a shader itself.
"""

from __future__ import annotations

from enum import IntEnum

from alight.core.ibl_models import IBL_MODELS
from alight.core.mesh import ALPHA_MODES
from alight.core.scene import BACKGROUNDS, LIGHT_KINDS, TONEMAPS


def _enum(name: str, members) -> type[IntEnum]:
    """An IntEnum whose members are ``members`` in order (0, 1, ...), named in upper case."""
    return IntEnum(name, {_glsl_name(m): i for i, m in enumerate(members)})


def _glsl_name(label: str) -> str:
    """'diffuse only (IBL)' -> 'DIFFUSE_ONLY_IBL': a label as an identifier both languages accept."""
    out = "".join(c.upper() if c.isalnum() else "_" for c in label)
    while "__" in out:
        out = out.replace("__", "_")
    return out.strip("_")


def glsl_member(enum: type[IntEnum], label: str) -> IntEnum:
    """The member of ``enum`` for the user-facing ``label`` ('lecture-schlick' -> LECTURE_SCHLICK).
    ValueError naming the known labels if there is none."""
    try:
        return enum[_glsl_name(label)]
    except KeyError:
        known = ", ".join(m.name.lower() for m in enum)
        raise ValueError(f"unknown {enum.__name__} '{label}' (known: {known})") from None


# The forward pass's IBL models (app/core/ibl_models.py), in IBL_MODELS' order: ibl.glsl's IBL_MODEL.
IblModel = _enum("IblModel", IBL_MODELS)


# A light's kind (KHR_lights_punctual's types; app/core/scene.py LIGHT_KINDS' order): common/punctual.glsl's
# u_light_vector[i].w.
LightKind = _enum("LightKind", LIGHT_KINDS)


# glTF 2.0 material.alphaMode (app/core/mesh.py ALPHA_MODES' order): render/pbr.frag's ALPHA_MODE.
AlphaMode = _enum("AlphaMode", ALPHA_MODES)


# What the background pass draws where no surface is (app/core/scene.py BACKGROUNDS' order):
# common/background.glsl's BACKGROUND_MODE. TRANSPARENT draws nothing (alpha 0).
BackgroundMode = _enum("BackgroundMode", BACKGROUNDS)

# The tone curves (app/core/scene.py TONEMAPS' order): common/tonemapping.glsl's TONEMAP_MODE.
Tonemap = _enum("Tonemap", TONEMAPS)

# The debug views (common/debug_views.glsl's u_debug_view), in the editor's menu order.
DEBUG_VIEWS = ("shaded", "base colour", "normal", "roughness", "metallic", "F0", "n.v", "diffuse only (IBL)",
               "specular only (IBL)", "irradiance", "prefiltered radiance at mip", "BRDF LUT", "D (first light)",
               "G (first light)", "F (first light)")
DebugView = _enum("DebugView", DEBUG_VIEWS)
# Views that show values, not radiance: drawn without exposure or tone mapping.
DATA_VIEWS = frozenset({DebugView.BASE_COLOUR, DebugView.NORMAL, DebugView.ROUGHNESS, DebugView.METALLIC,
                        DebugView.F0, DebugView.N_V, DebugView.BRDF_LUT, DebugView.D_FIRST_LIGHT,
                        DebugView.G_FIRST_LIGHT, DebugView.F_FIRST_LIGHT})

# A material's texture maps, one bit each in common/mesh_material.glsl's MATERIAL_MAPS_MASK (and the
# MAP_*_MASK defines), and one texture unit each in this order (app/render/renderer.py).
MATERIAL_MAPS = ("base_color", "metallic_roughness", "normal", "emissive", "occlusion", "metallic", "roughness",
                 "clearcoat", "clearcoat_roughness", "clearcoat_normal", "sheen_color", "sheen_roughness", "anisotropy",
                 "transmission", "thickness", "specular", "specular_color", "iridescence", "iridescence_thickness",
                 "diffuse_transmission")


def map_bit(name: str) -> int:
    """The bit of map ``name`` (a MATERIAL_MAPS entry) in MATERIAL_MAPS_MASK. ValueError if unknown."""
    return 1 << MATERIAL_MAPS.index(name)


def map_mask(names) -> int:
    """MATERIAL_MAPS_MASK for the maps ``names`` (any iterable of MATERIAL_MAPS entries)."""
    return sum(map_bit(n) for n in set(names))


# The defines Python passes to programs (gpu.ShaderCache.program / compute), with what each does.
# A define with a value takes a number (or one of the generated names above); the others are flags.
SHADER_OPTIONS: dict[str, str] = {
    # What the pass writes.
    "DISPLAY_OUTPUT": "the pass writes display values (exposure, tone curve, sRGB) instead of radiance",
    "RADIANCE_OUTPUT": "the resolve writes linear radiance",
    "HALF_FLOAT_OUTPUT": "radiance scaled into half-float range (very low exposures)",
    "SRGB_BY_FRAMEBUFFER": "the window's framebuffer applies the sRGB curve (GL_FRAMEBUFFER_SRGB)",
    "TONEMAP_MODE": "the tone curve compiled in (a Tonemap value)",
    # Environment light.
    "IBL_MODEL": "the IBL model compiled in (an IblModel value)",
    "IBL_BELOW_GRID": "the stretched lobe below its fitted grid falls back to the dominant direction",
    "IBL_SUNS": "0: the environment has no compact source; its loops are compiled out (common/suns.glsl)",
    "MULTIPLE_SCATTERING": "multiple-scattering energy compensation of the specular lobe",
    # Punctual lights.
    "PUNCTUAL_SPOT": "some light is a spot (the cone attenuation is compiled in)",
    "PUNCTUAL_RANGE": "some light has a range (KHR_lights_punctual's range attenuation)",
    # The material and the mesh's attributes.
    "ALPHA_MODE": "the part's alpha mode (an AlphaMode value)",
    "ALPHA_TO_COVERAGE": "MASK under MSAA: the alpha test per sample, this many samples a pixel "
                         "(common/mesh_material.glsl alpha_coverage_mask)",
    "UNLIT": "KHR_materials_unlit: base colour only",
    "HAS_VERTEX_COLOR": "the mesh has COLOR_0",
    "HAS_UV1": "a map of the mesh reads TEXCOORD_1 (u_map_uv1 picks each map's set)",
    "HAS_TEXTURE_TRANSFORM": "a map of the mesh has KHR_texture_transform (u_map_transform, identity for the others)",
    "PACKED_VERTICES": "normals and tangents arrive as int16 snorm (alight.render.gpu_mesh.pack_snorm16)",
    "NORMAL_MAP_TOKSVIG": "the normal maps' A is their normals' spread, added to the roughness "
                          "(alight.render.normal_spread, surface.glsl normal_map_roughness)",
    "NORMAL_SPREAD_MAX": "the largest spread sigma^2 a normal map's A keeps (render/normal_spread.comp; "
                         "alight.render.normal_spread MAX_SPREAD)",
    "NORMAL_SPREAD_FLOOR": "a spread sigma^2 below this is written as 0 (render/normal_spread.comp; "
                           "alight.render.normal_spread SPREAD_FLOOR)",
    "NORMAL_FLAT_LENGTH": "a decoded normal this short reads as (0, 0, 1), and |Na| is clipped to it "
                          "(render/normal_spread.comp; alight.render.normal_spread FLAT_LENGTH)",
    "NORMAL_MAP_LOD_BIAS": "the normal maps' level-of-detail bias, log2 (alight.render.normal_spread, "
                          "common/mesh_material.glsl normal_from_map)",
    "MATERIAL_MAPS_MASK": "the maps present, a bit each (map_mask)",
    "MAP_MIRROR_S_MASK": "maps whose sampler mirrors in s",
    "MAP_MIRROR_T_MASK": "maps whose sampler mirrors in t",
    "HAS_CLEARCOAT": "KHR_materials_clearcoat",
    "HAS_SHEEN": "KHR_materials_sheen",
    "HAS_ANISOTROPY": "KHR_materials_anisotropy",
    "HAS_TRANSMISSION": "KHR_materials_transmission",
    "HAS_VOLUME": "KHR_materials_volume",
    "HAS_IRIDESCENCE": "KHR_materials_iridescence",
    "HAS_DISPERSION": "KHR_materials_dispersion",
    "HAS_DIFFUSE_TRANSMISSION": "KHR_materials_diffuse_transmission",
    "TRANSMISSION_SCENE": "transmission refracts a copy of the opaque scene behind the part",
    "ANISOTROPY_LOOKUP": "how the anisotropic lobe's IBL is looked up (1: table, 2: fetches)",
    "ANISOTROPY_FETCHES": "the number of prefiltered fetches along the stretched anisotropic lobe",
    # Light that is blocked.
    "HAS_SHADOWS": "shadow maps are read for the lights and suns (app/render/shadows.py)",
    "HAS_VISIBILITY": "the visibility bake's per-vertex occlusion, bent normal and bounce are read "
                      "(app/core/visibility.py, common/occlusion.glsl)",
    "HAS_SKY_WEIGHT": "the visible sky weight of the environment drawn is read with the visibility bake "
                      "(app/core/sky_weight.py, common/occlusion.glsl)",
    "HAS_SCREEN_AO": "screen-space GTAO's visibility is read per pixel (app/render/screen_ao.py, "
                     "common/occlusion.glsl)",
    "GTAO_OCCLUDERS": "GTAO's occluded share sees the occluders' radiance, lit by the sky their own normals "
                      "see where the screen shows them facing the point, else as the point is "
                      "(common/occlusion.glsl)",
    "GTAO_FACING_RAMP_LOW": "with GTAO_OCCLUDERS: where the facing occluders' V less the point's is below this, "
                            "their light is held to the point's (app/core/gtao.py FACING_RAMP)",
    "GTAO_FACING_RAMP_HIGH": "... and above this, their own",
    "GTAO_MULTI_BOUNCE": "GTAO's visibility takes the paper's albedo fit of the occluders' interreflections "
                         "(common/gtao.glsl)",
    "GTAO_SLICES": "GTAO's slice directions per pixel (render/gtao.frag; app/core/gtao.py SLICES)",
    "GTAO_STEPS": "GTAO's depth samples per side of a slice (render/gtao.frag; app/core/gtao.py STEPS)",
    "GTAO_THICKNESS": "GTAO's occluders are taken as solid this share of their part's size (bounding-box "
                      "diagonal) behind their front in view depth (render/gtao.frag; app/core/gtao.py THICKNESS)",
    "GTAO_FACING_THICKNESS": "GTAO's facing occluders light the band only down to this share of their part's "
                             "size behind their front (render/gtao.frag; app/core/gtao.py FACING_THICKNESS)",
    "GTAO_THIN_OCCLUDER": "GTAO's falloff stretches an occluder's depth in front of the point beyond "
                          "GTAO_THICKNESS by 1 + this (common/gtao.glsl gtao_falloff_weight; app/core/gtao.py THIN_OCCLUDER)",
    # Views and passes.
    "DEBUG_VIEW": "the editor's debug views are compiled in (u_debug_view picks one)",
    "SPHERE_IMPOSTOR": "the built-in sphere drawn as an impostor with this many samples a pixel",
    "SPHERE_SURFACE": "the built-in sphere's uv and tangent computed from the shaded point",
    "BACKGROUND_MODE": "what the background pass draws (a BackgroundMode value)",
    "BACKGROUND_RING": "the background drawn as a ring around the impostor's outline",
    "SCENE_SAMPLES": "the scene target's samples a pixel, read by the resolve",
    "NO_SURFACES": "the resolve runs where no surface was drawn (background only)",
    "VBUFFER_SHADING": "a part shaded from the visibility buffer, its vertices fetched (app/render/vbuffer.py)",
    "VERTEX_WORDS": "the 32-bit words per vertex in the part's vertex buffer (app/render/vbuffer.py vertex_layout)",
    "NORMAL_AT": "the normal's offset in a vertex, in words",
    "UV_AT": "TEXCOORD_0's offset in a vertex, in words",
    "UV1_AT": "TEXCOORD_1's offset in a vertex, in words",
    "COLOR_AT": "COLOR_0's offset in a vertex, in words",
    "NORMAL_SNORM16": "the vertex buffer's normals are int16 snorm (app/render/gpu_mesh.py PACK_VERTICES)",
    "UV_HALF": "the vertex buffer's TEXCOORD_0 is two half floats",
    "TANGENT_SNORM16": "the tangent buffer holds int16 snorm",
}


def glsl_defines() -> dict[str, int]:
    """Every generated name and its value, as ``load_source`` writes them (``#define NAME value``)."""
    out: dict[str, int] = {}
    for prefix, enum in (("IBL_MODEL", IblModel), ("LIGHT", LightKind), ("ALPHA_MODE", AlphaMode),
                         ("BACKGROUND", BackgroundMode), ("TONEMAP", Tonemap), ("DEBUG_VIEW", DebugView)):
        for member in enum:
            out[f"{prefix}_{member.name}"] = int(member)
    for name in MATERIAL_MAPS:
        out[f"MAP_{name.upper()}"] = map_bit(name)
    out["MAP_SLOTS"] = len(MATERIAL_MAPS)
    out["MAP_ALL"] = (1 << len(MATERIAL_MAPS)) - 1
    return out


def glsl_header() -> list[str]:
    """The ``#define`` lines of ``glsl_defines()``, in a fixed order."""
    return [f"#define {k} {v}" for k, v in glsl_defines().items()]
