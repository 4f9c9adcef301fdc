"""Which shader variant a draw compiles, as plain functions of a part and the scene: the
material a part draws with (``part_material``) and the defines it owns (``material_defines``,
as the Khronos glTF Sample Renderer's ``material.getDefines()``), a part's defines
(``part_defines``: maps, uv sets, alpha mode, ...), and the scene's (IBL model, lights, the
below-grid fade; the environment's suns: ``sun_defines``). The accuracy modules use the same
functions, so the reference shades the materials the renderer draws."""

from __future__ import annotations

import math

import dataclasses
from dataclasses import replace

import numpy as np

from alight.core.layers import layer_defines
from alight.core.material import LAYERS, Material, with_overrides
from alight.core.shader_names import (
    MATERIAL_MAPS,
    AlphaMode,
    BackgroundMode,
    IblModel,
    glsl_member,
    map_bit,
    map_mask,
)
from alight.ibl.bake import IBLMaps, grid_roughness
from alight.render import normal_spread
from alight.render.bindings import MAX_LIGHTS
from alight.render.normal_spread import SPREAD_MAPS


def part_material(scene, part) -> tuple[Material, bool]:
    """The factors a mesh part draws with, and whether its file's texture maps apply: the file's
    material (its own layer factors, then the scene's overrides) where the scene uses file
    materials, else the scene's material."""
    fm = part.material
    if fm is None or not scene.use_file_materials:
        return scene.material, False
    base = Material(base_color=tuple(fm.base_color), metallic=float(fm.metallic),
                    roughness=float(fm.roughness), specular_f0=tuple(fm.specular_f0),
                    ior=fm.layers.get("ior"), emissive=tuple(fm.emissive), name=part.name)
    layers = {k: v for k, v in fm.layers.items() if k != "ior"}
    if layers:   # the file's own layer factors (alight.exchange.gltf_material)
        base = replace(base, **layers)
    if scene.material_overrides:
        base = with_overrides(base, **scene.material_overrides)
    return base, True


def material_defines(materials) -> dict:
    """The HAS_* defines of the layers the materials use, and only those (alight.core.layers)."""
    return layer_defines(list(materials))


def blends(scene, part) -> bool:
    """Whether the part is drawn blended (its file's alphaMode BLEND, file materials on)."""
    return part.material is not None and scene.use_file_materials and part.material.alpha_mode == "BLEND"


def has_blending_parts(scene) -> bool:
    """Whether a part blends (alphaMode BLEND): it is drawn over the background, so such a
    frame keeps the background pass (the fused resolve composites the background last)."""
    if scene.view == "probe" or scene.mesh is None or not scene.use_file_materials:
        return False
    return any(part.material is not None and part.material.alpha_mode == "BLEND" for part in scene.mesh.parts)


def transmissive_parts(scene) -> list[int]:
    """Indices of the mesh's parts whose material transmits (KHR_materials_transmission)."""
    if scene.view == "probe" or scene.mesh is None:
        return []
    # A part that blends (alphaMode BLEND) is drawn in the blended pass, over the background,
    # and transmits the environment only.
    return [i for i, part in enumerate(scene.mesh.parts)
            if "transmission" in part_material(scene, part)[0].layers() and not blends(scene, part)]


def scene_layer_defines(scene, parts: list[int] | None = None) -> dict:
    """The HAS_* defines of the layers any part of the scene's mesh (or those of ``parts``,
    indices) is drawn with: a scene without layers compiles none."""
    if scene.mesh is None:
        return material_defines([scene.material])
    chosen = range(len(scene.mesh.parts)) if parts is None else parts
    return material_defines(part_material(scene, scene.mesh.parts[i])[0] for i in chosen)


def user_maps_present(scene) -> set[str]:
    """The slots of the user's maps (Scene.texture_maps) whose image is loaded."""
    user = scene.texture_maps.paths() if scene.texture_maps is not None else {}
    return {name for name, path in user.items() if path in scene.texture_images}


def part_defines(scene, gpu_part, part, user_maps: set[str]) -> dict:
    """The shader variant a part needs (pbr.frag, mesh_material.glsl): the maps it reads, their
    mirrored axes, whether it has a second uv set, vertex colours, alpha mode, unlit and the layers
    its material uses. A part with none of these compiles to the plain opaque shader.
    ``gpu_part``: its alight.render.gpu_mesh.GpuPart; ``user_maps``: ``user_maps_present``."""
    fm = part.material
    file_material = fm is not None and scene.use_file_materials
    defines: dict = {}
    if file_material:
        present = set(gpu_part.textures)
        # Which uv set each map reads and its KHR_texture_transform are uniforms
        # (map_uv_uniforms), not a mask a map: a select or a mat3 multiply costs less than a
        # variant of its own, compiled by LLVM at its first draw on llvmpipe (TextureTransformMultiTest's
        # nine materials: benchmarks/results/compile.md). Two flags stay, set for every textured
        # part of a mesh where some map uses the feature (gpu_mesh.mark_mesh_uv_features), so a
        # file that uses neither pays nothing and the parts of one that does share programs:
        # HAS_UV1 (a part without TEXCOORD_1 reads the attribute's constant, and u_map_uv1 is 0
        # for it) and HAS_TEXTURE_TRANSFORM (every map multiplies, by the identity where it has
        # no transform). The mirrored wraps stay masks (their fold and textureGrad cost every fetch).
        masks = {"MAP_MIRROR_S_MASK": 0, "MAP_MIRROR_T_MASK": 0}
        for name, info in gpu_part.infos.items():
            bit = map_bit(name)
            if info.sampler.wrap_s == "mirrored_repeat":
                masks["MAP_MIRROR_S_MASK"] |= bit
            if info.sampler.wrap_t == "mirrored_repeat":
                masks["MAP_MIRROR_T_MASK"] |= bit
        defines.update({k: v for k, v in masks.items() if v})
        own = gpu_part.infos.values()   # (a part outside GpuMeshes.parts: its own maps decide)
        if gpu_part.infos and getattr(gpu_part, "mesh_reads_uv1",
                                      gpu_part.has_uv1 and any(i.tex_coord == 1 for i in own)):
            defines["HAS_UV1"] = None
        if gpu_part.infos and getattr(gpu_part, "mesh_transforms", any(i.transform is not None for i in own)):
            defines["HAS_TEXTURE_TRANSFORM"] = None
        if fm.alpha_mode == "MASK":
            defines["ALPHA_MODE"] = int(AlphaMode.MASK)
        elif fm.alpha_mode == "BLEND":
            defines["ALPHA_MODE"] = int(AlphaMode.BLEND)
        if fm.unlit:
            defines["UNLIT"] = None
    else:
        present = set(user_maps)
    if gpu_part.has_colors and scene.use_file_materials:
        defines["HAS_VERTEX_COLOR"] = None
    if gpu_part.has_visibility:
        defines["HAS_VISIBILITY"] = None
        if getattr(gpu_part, "has_sky_weight", False):
            defines["HAS_SKY_WEIGHT"] = None
    if getattr(gpu_part, "packed", False):
        defines["PACKED_VERTICES"] = None
    defines["MATERIAL_MAPS_MASK"] = map_mask(present & set(MATERIAL_MAPS))
    if normal_spread.NORMAL_MAP_TOKSVIG and present & set(SPREAD_MAPS):
        # the normal map's spread widens the roughness (alight.render.normal_spread)
        defines["NORMAL_MAP_TOKSVIG"] = 1
    if normal_spread.NORMAL_MAP_LOD_BIAS and present & set(SPREAD_MAPS):
        # the normal maps are fetched one level finer (mesh_material.glsl normal_from_map)
        defines["NORMAL_MAP_LOD_BIAS"] = f"{normal_spread.NORMAL_MAP_LOD_BIAS:.6f}"
    defines.update(material_defines([part_material(scene, part)[0]]))
    return defines


def map_uv_uniforms(gpu_part, file_maps: bool) -> tuple[int, np.ndarray]:
    """What mesh_material.glsl's map_uv() reads of a part: ``u_map_uv1`` (MATERIAL_MAPS bits of
    the maps read with TEXCOORD_1; glTF textureInfo texCoord) and ``u_map_transform`` (a 3x3
    KHR_texture_transform matrix per map slot, on alight's OpenGL uvs; identity where a map has
    none, which leaves the uvs exactly as they are). ``file_maps``: the part's file maps apply
    (else the user's maps: TEXCOORD_0, untransformed)."""
    transforms = np.tile(np.eye(3, dtype=np.float32), (len(MATERIAL_MAPS), 1, 1))
    uv1 = 0
    if file_maps:
        for name, info in gpu_part.infos.items():
            if info.transform is not None:
                transforms[MATERIAL_MAPS.index(name)] = info.transform.gl_matrix()
            if info.tex_coord == 1 and gpu_part.has_uv1:
                uv1 |= map_bit(name)
    return uv1, transforms


def ibl_defines(scene) -> dict:
    """The shader defines that pick the scene's IBL model (app/core/ibl_models.py)."""
    defines = {"IBL_MODEL": int(glsl_member(IblModel, scene.ibl_model))}
    if scene.ibl_model == "stretched":
        from alight.core.stretched_lobe import ROUGHNESS_FULL, ROUGHNESS_START

        defines["STRETCHED_ROUGHNESS_START"] = f"{ROUGHNESS_START:.6f}"
        defines["STRETCHED_ROUGHNESS_FULL"] = f"{ROUGHNESS_FULL:.6f}"
    if scene.multiple_scattering:
        defines["MULTIPLE_SCATTERING"] = None
    return defines


def light_defines(scene) -> dict:
    """punctual.glsl's PUNCTUAL_SPOT and PUNCTUAL_RANGE, only for scenes that have such lights."""
    lights = scene.lights[:MAX_LIGHTS]
    defines: dict = {}
    if any(light.kind == "spot" for light in lights):
        defines["PUNCTUAL_SPOT"] = None
    if any(light.range is not None and light.kind != "directional" for light in lights):
        defines["PUNCTUAL_RANGE"] = None
    return defines


def sun_defines(maps: IBLMaps | None) -> dict:
    """``{"IBL_SUNS": 0}`` where the environment drawn has no compact source (``maps.suns``, what
    app/ibl/sun.py took out of the map; no maps: none), so common/suns.glsl compiles its loops
    out; else nothing (the count is a uniform). Decided from the maps each pass binds, so a
    switch to an environment with a sun (the editor's, a batch's next map) compiles the variant
    with the loops before it draws: the suns are never bound to a program without them."""
    return {} if maps is not None and maps.suns else {"IBL_SUNS": 0}


# The maps that cannot lower a roughness (MATERIAL_MAPS bits): any other map compiled in keeps
# the prefiltered lookup's path below the grid (ibl.glsl IBL_BELOW_GRID). (The normal maps'
# spread, NORMAL_MAP_TOKSVIG, only raises one: stretched_span_defines minds that.)
ROUGHNESS_FREE_MAPS = {"base_color", "normal", "emissive", "occlusion", "metallic", "specular", "specular_color"}


def below_grid_defines(scene, maps: IBLMaps | None, materials, map_mask: int = 0) -> dict:
    """``{"IBL_BELOW_GRID": 0}`` when no roughness the pass can shade lies below the prefiltered
    grid's first step: the materials' roughness (and their coat's) is at or above it, no
    compiled-in map (``map_mask``, MATERIAL_MAPS bits) can lower one, and no layer or IBL model
    reads the maps at a roughness of its own. Else nothing: the shader keeps the fade into the
    source cube (ibl.glsl)."""
    if maps is None or not scene.ibl_enabled:
        return {}
    unsafe = {name for i, name in enumerate(MATERIAL_MAPS) if map_mask & (1 << i)} - ROUGHNESS_FREE_MAPS
    if unsafe or map_mask >> len(MATERIAL_MAPS):
        return {}
    first_step = grid_roughness(0, maps.quality.prefiltered_levels)
    if scene.ibl_model == "stretched" and materials:
        from alight.core.stretched_lobe import ROUGHNESS_START, lobe_table

        # its two fetches, taken above ROUGHNESS_START, read at the material's roughness times
        # sqrt(beta) (a fitted factor, down to 0.66): their lowest must be on the grid too
        rough = [float(m.roughness) for m in materials]
        lowest = max(ROUGHNESS_START, min(rough)) * math.sqrt(float(lobe_table()[..., 3].min()))
        if max(rough) > ROUGHNESS_START and lowest < first_step:
            return {}
    for m in materials:
        if m.layers() - {"clearcoat"}:
            # sheen, anisotropy and transmission read the prefiltered maps at a roughness of
            # their own (a LUT's or the stretched lobe's), which may lie below the grid
            return {}
        # the base layer's roughness, and the coat's when the coat is on (a layer that is off
        # is compiled out, and its roughness field keeps glTF's default 0)
        used = {"roughness"} | {f for layer in m.layers() for f in LAYERS[layer]}
        for f in dataclasses.fields(m):
            if f.name in used and f.name.endswith("roughness") and float(getattr(m, f.name)) < first_step:
                return {}
    return {"IBL_BELOW_GRID": 0}


def stretched_span_defines(scene, materials, map_mask: int = 0) -> dict:
    """The `stretched` model's STRETCHED_SPAN (ibl.glsl): 0 where every roughness the pass shades
    is at or below ROUGHNESS_START (the single round fetch only), 2 where all are at or above
    ROUGHNESS_FULL (the two fitted fetches only), else nothing (1: both, blended). llvmpipe runs
    both sides of a branch, so the blend's three fetches cost every pixel unless compiled out
    (1.5x the built-in sphere's frame)."""
    if scene.ibl_model != "stretched":
        return {}
    from alight.core.stretched_lobe import ROUGHNESS_FULL, ROUGHNESS_START

    unsafe = {name for i, name in enumerate(MATERIAL_MAPS) if map_mask & (1 << i)} - ROUGHNESS_FREE_MAPS
    if unsafe or map_mask >> len(MATERIAL_MAPS) or not materials:
        return {}
    # the base layer's roughness only: the layers' own lobes fetch at their roughness directly
    rough = [float(m.roughness) for m in materials]
    # a normal map's spread can only raise it (NORMAL_MAP_TOKSVIG): never below ROUGHNESS_START
    widens = normal_spread.NORMAL_MAP_TOKSVIG and map_mask & map_bit("normal")
    if max(rough) <= ROUGHNESS_START and not widens:
        return {"STRETCHED_SPAN": 0}
    if min(rough) >= ROUGHNESS_FULL:
        return {"STRETCHED_SPAN": 2}
    return {}


def background_mode(scene, maps: IBLMaps | None) -> BackgroundMode:
    """common/background.glsl's BACKGROUND_MODE for the scene: an environment background without
    an environment draws nothing."""
    mode = glsl_member(BackgroundMode, scene.display.background)
    if mode in (BackgroundMode.ENV, BackgroundMode.BLUR) and maps is None:
        return BackgroundMode.TRANSPARENT
    return mode


def alpha_to_coverage(variant: dict, ctx) -> dict:
    """An alphaMode MASK part drawn into a multisampled framebuffer tests its alpha per sample
    (ALPHA_TO_COVERAGE = the sample count: common/mesh_material.glsl alpha_coverage_mask), so the
    cutoff's edges are antialiased as a triangle's are; single-sampled, the plain test."""
    samples = getattr(ctx.fbo, "samples", 0) or 0
    if variant.get("ALPHA_MODE") == int(AlphaMode.MASK) and samples > 1:
        variant["ALPHA_TO_COVERAGE"] = int(samples)
    return variant
