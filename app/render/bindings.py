"""What the passes bind: the one table of texture units, the uniform setters, the lights block
and the per-view lighting inputs (the IBL maps, the suns, the background's), and the lookup
tables the layers read. Like Filament's PerViewUniforms, the lights block is prepared from a
scene and committed once: an unchanged block costs no upload."""

from __future__ import annotations

import math

import moderngl
import numpy as np

from alight.core.ibl_models import SUNS_AS_BAKED
from alight.core.layers.iridescence import iridescence_uniforms
from alight.core.material import Material
from alight.core.shader_names import MATERIAL_MAPS, BackgroundMode, LightKind, glsl_member
from alight.core.shading import rotate_world_to_map
from alight.ibl.anisotropy_lut import AnisotropyLut
from alight.ibl.bake import IBLMaps, LutCache, roughness_to_grid_step
from alight.ibl.sun import MAX_SUNS
from alight.ibl.transmission_lut import TransmissionLut

MAX_LIGHTS = 16   # punctual.glsl's MAX_LIGHTS
MAX_GRID_STEPS = 32  # ibl.glsl's MAX_GRID_STEPS: prefiltered roughness steps (2 levels - 1)

# Texture units, fixed so that binding one map never disturbs another.
UNIT_IRRADIANCE, UNIT_PREFILTERED, UNIT_PREFILTERED_MID, UNIT_LUT, UNIT_ENVIRONMENT, UNIT_RADIANCE = range(6)
UNIT_MATERIAL = {name: 6 + i for i, name in enumerate(MATERIAL_MAPS)}
UNIT_SHEEN_LUT = 6 + len(MATERIAL_MAPS)   # the sheen LUT (common/sheen.glsl), bound with HAS_SHEEN
UNIT_TRANSMISSION_LUT = UNIT_SHEEN_LUT + 1          # ibl/transmission_lut.comp's table (HAS_VOLUME)
UNIT_SCENE_BEHIND = UNIT_TRANSMISSION_LUT + 1      # the opaque parts' copy (TRANSMISSION_SCENE)
# KHR_materials_anisotropy's energy ratios (alight.ibl.anisotropy_lut), bound where a program reads them.
UNIT_ANISOTROPY_RATIO_A, UNIT_ANISOTROPY_RATIO_B = UNIT_SCENE_BEHIND + 1, UNIT_SCENE_BEHIND + 2
# The `stretched` IBL model's lobe table (alight.core.stretched_lobe), bound where a program reads it.
UNIT_STRETCHED_LOBE_A, UNIT_STRETCHED_LOBE_B = UNIT_SCENE_BEHIND + 3, UNIT_SCENE_BEHIND + 4
# The shadow atlas (alight.render.shadows): with comparison (PCF) and as depths (the blocker search).
UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH = UNIT_SCENE_BEHIND + 5, UNIT_SCENE_BEHIND + 6
UNIT_VISIBILITY = UNIT_SCENE_BEHIND + 7   # the visibility buffer (alight.render.vbuffer)
# Screen-space GTAO (alight.render.screen_ao): the visibility the forward pass reads, and the unit
# its own passes read the depth and the raw visibility from, and the earlier passes' mean.
UNIT_SCREEN_AO, UNIT_SCREEN_AO_WORK = UNIT_SCENE_BEHIND + 8, UNIT_SCENE_BEHIND + 9
UNIT_SCREEN_AO_HISTORY = UNIT_SCREEN_AO_WORK + 1
# ... and the same three for the occluders' normals (the forward pass's, the raw's while denoising;
# the earlier passes' mean), and the prepass's face normals the search reads.
UNIT_SCREEN_AO_OCCLUDERS, UNIT_SCREEN_AO_OCCLUDERS_HISTORY = UNIT_SCREEN_AO_HISTORY + 1, UNIT_SCREEN_AO_HISTORY + 2
UNIT_SCREEN_AO_NORMALS = UNIT_SCREEN_AO_HISTORY + 3
# moderngl binds every texture it creates or writes on ctx.default_texture_unit (its scratch unit,
# by default the last fragment unit: 31 here, which was UNIT_STRETCHED_LOBE_A: a clearcoat map
# uploaded at its first draw replaced the lobe table). ForwardRenderer moves it past every unit above
# (GL 4.5 guarantees 80 combined units).
UNIT_SCRATCH = UNIT_SCREEN_AO_NORMALS + 1
# Every sampler gets its own unit: samplers left at the default unit 0 with different types
# (samplerCube and sampler2D) make every draw call fail with GL_INVALID_OPERATION.
SAMPLER_UNITS = {
    "u_irradiance": UNIT_IRRADIANCE, "u_prefiltered_radiance": UNIT_PREFILTERED,
    "u_prefiltered_radiance_mid": UNIT_PREFILTERED_MID, "u_brdf_lut": UNIT_LUT,
    "u_environment": UNIT_ENVIRONMENT, "u_radiance": UNIT_RADIANCE, "u_radiance_source": UNIT_RADIANCE,
    "u_scene": UNIT_RADIANCE,
    **{f"u_{name}_map": unit for name, unit in UNIT_MATERIAL.items()},
    "u_sheen_lut": UNIT_SHEEN_LUT, "u_transmission_lut": UNIT_TRANSMISSION_LUT, "u_scene_behind": UNIT_SCENE_BEHIND,
    "u_anisotropy_ratio_a": UNIT_ANISOTROPY_RATIO_A, "u_anisotropy_ratio_b": UNIT_ANISOTROPY_RATIO_B,
    "u_stretched_lobe_a": UNIT_STRETCHED_LOBE_A, "u_stretched_lobe_b": UNIT_STRETCHED_LOBE_B,
    "u_shadow_atlas": UNIT_SHADOW_ATLAS, "u_shadow_depth": UNIT_SHADOW_DEPTH,
    "u_visibility": UNIT_VISIBILITY, "u_screen_ao": UNIT_SCREEN_AO,
    "u_screen_ao_occluders": UNIT_SCREEN_AO_OCCLUDERS,
}


def assign_units(prog: moderngl.Program) -> None:
    """Point every sampler ``prog`` kept at its unit in SAMPLER_UNITS."""
    for name, unit in SAMPLER_UNITS.items():
        set_uniform(prog, name, unit)


def set_uniform(prog, name: str, value, write: bool = False) -> None:
    """Set a uniform if the compiler kept it (unused uniforms are optimised away); ``write``:
    ``value`` is bytes (arrays, matrices)."""
    member = prog.get(name, None)
    if member is None:
        return
    if write:
        member.write(value)
    else:
        member.value = value


def set_material(prog, m: Material) -> None:
    """The material's factors (common/material_layers.glsl); a layer not compiled in has no uniform."""
    set_uniform(prog, "u_base_color", tuple(float(x) for x in m.base_color))
    set_uniform(prog, "u_metallic", float(m.metallic))
    set_uniform(prog, "u_roughness", float(m.roughness))
    set_uniform(prog, "u_specular_f0", tuple(float(x) for x in m.specular_f0))
    set_uniform(prog, "u_emissive", tuple(float(x) for x in m.emissive))
    set_uniform(prog, "u_clearcoat", float(m.clearcoat))
    set_uniform(prog, "u_clearcoat_roughness", float(m.clearcoat_roughness))
    set_uniform(prog, "u_sheen_color", tuple(float(x) for x in m.sheen_color))
    set_uniform(prog, "u_sheen_roughness", float(m.sheen_roughness))
    set_uniform(prog, "u_anisotropy_strength", float(m.anisotropy_strength))
    set_uniform(prog, "u_anisotropy_rotation", float(m.anisotropy_rotation))
    set_uniform(prog, "u_transmission", float(m.transmission))
    set_uniform(prog, "u_ior", float(m.ior))
    set_uniform(prog, "u_thickness", float(m.thickness))
    set_uniform(prog, "u_attenuation_color", tuple(float(x) for x in m.attenuation_color))
    set_uniform(prog, "u_attenuation_distance", float(min(m.attenuation_distance, 3.0e38)))
    set_uniform(prog, "u_dispersion", float(m.dispersion))
    set_uniform(prog, "u_diffuse_transmission", float(m.diffuse_transmission))
    set_uniform(prog, "u_diffuse_transmission_color", tuple(float(x) for x in m.diffuse_transmission_color))
    for name, value in iridescence_uniforms(m).items():   # common/material_iridescence.glsl
        set_uniform(prog, name, value)


def rotation_cos_sin(deg: float) -> tuple[float, float]:
    """u_env_rotation: (cos, sin) of -deg, the map's rotation about +y (docs/conventions.md)."""
    t = math.radians(-deg)
    return (math.cos(t), math.sin(t))


def lights_block(scene) -> bytes:
    """punctual.glsl's Lights block (std140): vector and type, radiance, count, spot direction,
    and the spot's cone scale and offset with the range (KHR_lights_punctual's recommended
    falloff: scale = 1 / max(0.001, cos inner - cos outer), offset = -cos outer * scale)."""
    vectors = np.zeros((MAX_LIGHTS, 4), np.float32)
    radiance = np.zeros((MAX_LIGHTS, 4), np.float32)
    spots = np.zeros((MAX_LIGHTS, 4), np.float32)
    cones = np.zeros((MAX_LIGHTS, 4), np.float32)
    lights = scene.lights[:MAX_LIGHTS]
    for i, light in enumerate(lights):
        vectors[i, :3] = light.vector
        vectors[i, 3] = float(glsl_member(LightKind, light.kind))
        radiance[i, :3] = np.asarray(light.color, np.float32) * light.intensity
        if light.kind == "spot":
            d = np.asarray(light.direction, np.float64)
            spots[i, :3] = d / max(np.linalg.norm(d), 1e-30)
            cos_inner = math.cos(math.radians(light.inner_cone_deg))
            cos_outer = math.cos(math.radians(light.outer_cone_deg))
            scale = 1.0 / max(0.001, cos_inner - cos_outer)
            cones[i, :2] = (scale, -cos_outer * scale)
        if light.range is not None and light.kind != "directional":
            cones[i, 2] = light.range
    return (vectors.tobytes() + radiance.tobytes() + np.array([len(lights), 0, 0, 0], np.int32).tobytes()
            + spots.tobytes() + cones.tobytes())


class LightsBlock:
    """The Lights uniform block at binding 0: ``prepare`` a scene's lights, ``commit`` them once
    (uploaded only when they changed) before the draws that read them; ``write`` does both."""

    def __init__(self, ctx: moderngl.Context):
        self._ubo = ctx.buffer(reserve=MAX_LIGHTS * 64 + 16)
        self._uploaded = b""
        self._pending = b""

    def prepare(self, scene) -> None:
        self._pending = lights_block(scene)

    def commit(self) -> None:
        if self._pending != self._uploaded:  # unchanged lights cost no upload
            self._ubo.write(self._pending)
            self._uploaded = self._pending
        self._ubo.bind_to_uniform_block(0)

    def write(self, scene) -> None:
        self.prepare(scene)
        self.commit()

    def release(self) -> None:
        self._ubo.release()


class LookupTables:
    """The tables shading reads beside the environment's maps, each baked or uploaded on first
    use: the BRDF and sheen LUTs (``luts``), the anisotropy energy ratios, the transmission LUT
    and the `stretched` model's lobe table."""

    def __init__(self, ctx: moderngl.Context, shaders):
        self.ctx = ctx
        self.luts = LutCache(ctx, shaders)
        self.anisotropy_lut = AnisotropyLut(ctx, shaders)   # baked on first anisotropic draw
        self._shaders = shaders
        self._stretched_lobe: tuple[moderngl.Texture, moderngl.Texture] | None = None
        self._transmission_lut: TransmissionLut | None = None

    def use_shaders(self, shaders) -> None:
        self._shaders = shaders
        self.luts.shaders = shaders

    def transmission_lut(self) -> moderngl.Texture:
        """The transmission LUT (alight.ibl.transmission_lut), baked or read on first use."""
        if self._transmission_lut is None:
            self._transmission_lut = TransmissionLut(self.ctx, self._shaders)
        return self._transmission_lut.texture()

    def stretched_lobe_textures(self) -> tuple[moderngl.Texture, moderngl.Texture]:
        """The `stretched` model's lobe table (alight.core.stretched_lobe) as two RGBA32F textures,
        linear filtering clamped at the edges (texel centres are the fitted cells)."""
        if self._stretched_lobe is None:
            from alight.core.stretched_lobe import lobe_table

            textures = []
            for part in lobe_table():
                data = np.ascontiguousarray(part).tobytes()
                tex = self.ctx.texture((part.shape[1], part.shape[0]), 4, data, dtype="f4")
                tex.repeat_x = tex.repeat_y = False
                tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
                textures.append(tex)
            self._stretched_lobe = (textures[0], textures[1])
        return self._stretched_lobe

    def bind_layer_luts(self, defines: dict) -> None:
        """The tables a compiled-in layer reads (the sheen LUT, the transmission LUT)."""
        if "HAS_SHEEN" in defines:
            self.luts.sheen().use(UNIT_SHEEN_LUT)
        if "HAS_VOLUME" in defines and "HAS_TRANSMISSION" in defines:   # (a diffuse transmission's volume reads none)
            self.transmission_lut().use(UNIT_TRANSMISSION_LUT)

    def release(self) -> None:
        self.luts.release()
        self.anisotropy_lut.release()
        if self._stretched_lobe is not None:
            for tex in self._stretched_lobe:
                tex.release()
            self._stretched_lobe = None
        if self._transmission_lut is not None:
            self._transmission_lut.release()


def bind_ibl(program: moderngl.Program, scene, maps: IBLMaps | None, tables: LookupTables) -> None:
    """The environment's maps and uniforms (ibl.glsl), where the scene has IBL on and maps."""
    enabled = bool(scene.ibl_enabled and maps is not None)
    set_uniform(program, "u_ibl_enabled", enabled)
    if not enabled:
        return
    maps.irradiance.use(UNIT_IRRADIANCE)
    # Models that shade the compact sources exactly read the source cube without them below
    # the prefiltered grid; the lecture's models read it as seen (ibl.glsl).
    if scene.ibl_model not in SUNS_AS_BAKED and maps.lighting_environment is not None:
        maps.lighting_environment.use(UNIT_ENVIRONMENT)
    else:
        maps.environment.use(UNIT_ENVIRONMENT)
    maps.prefiltered_radiance.use(UNIT_PREFILTERED)
    maps.prefiltered_radiance_mid.use(UNIT_PREFILTERED_MID)
    maps.brdf_lut.use(UNIT_LUT)
    if "u_anisotropy_ratio_a" in program:
        ratio_a, ratio_b = tables.anisotropy_lut.textures()
        ratio_a.use(UNIT_ANISOTROPY_RATIO_A)
        ratio_b.use(UNIT_ANISOTROPY_RATIO_B)
    if "u_stretched_lobe_a" in program:
        lobe_a, lobe_b = tables.stretched_lobe_textures()
        lobe_a.use(UNIT_STRETCHED_LOBE_A)
        lobe_b.use(UNIT_STRETCHED_LOBE_B)
    set_uniform(program, "u_prefiltered_max_mip", maps.prefiltered_max_mip)
    set_uniform(program, "u_env_rotation", rotation_cos_sin(scene.env_rotation_deg))
    set_uniform(program, "u_env_intensity", float(scene.env_intensity))
    write_suns(program, scene, maps)


def sun_world_directions(scene, maps: IBLMaps | None) -> np.ndarray:
    """(K, 3) world directions toward the compact sources the bake left out of ``maps`` (K <=
    MAX_SUNS; (0, 3) without maps): the map texel in direction m lights world direction
    R_y(+deg) m (docs/conventions.md)."""
    if maps is None or not maps.suns:
        return np.zeros((0, 3))
    return np.array([rotate_world_to_map(sun.direction, -scene.env_rotation_deg) for sun in maps.suns[:MAX_SUNS]],
                    np.float64).reshape(-1, 3)


def write_suns(program: moderngl.Program, scene, maps: IBLMaps) -> None:
    """The compact sources the bake left out of the maps, in world space (ibl.glsl adds them)."""
    suns = maps.suns[:MAX_SUNS]
    directions = np.zeros((MAX_SUNS, 3), np.float32)
    powers = np.zeros((MAX_SUNS, 3), np.float32)
    spreads = np.zeros(MAX_SUNS, np.float32)
    for i, sun in enumerate(suns):
        spreads[i] = sun.spread
        powers[i] = np.asarray(sun.power) * scene.env_intensity
    directions[:len(suns)] = sun_world_directions(scene, maps)
    scale = np.zeros(MAX_GRID_STEPS, np.float32)
    scale[:len(maps.sun_prefilter_scale)] = maps.sun_prefilter_scale[:MAX_GRID_STEPS]
    set_uniform(program, "u_sun_count", len(suns))
    set_uniform(program, "u_sun_direction", directions.tobytes(), write=True)
    set_uniform(program, "u_sun_power", powers.tobytes(), write=True)
    set_uniform(program, "u_sun_spread", spreads.tobytes(), write=True)
    set_uniform(program, "u_sun_prefilter_scale", scale.tobytes(), write=True)


def bind_background(prog: moderngl.Program, scene, maps: IBLMaps | None, inverse_vp: np.ndarray,
                    mode: int) -> None:
    """common/background.glsl's inputs for BACKGROUND_MODE ``mode``; ``inverse_vp``: the
    inverse of the pass's (4, 4) view-projection, for the background's rays."""
    if mode == BackgroundMode.COLOR:
        prog["u_color"] = tuple(scene.display.background_color)
    elif mode in (BackgroundMode.ENV, BackgroundMode.BLUR):
        maps.environment.use(UNIT_ENVIRONMENT)
        maps.prefiltered_radiance.use(UNIT_PREFILTERED)
        # Grid A's mip for the blur roughness (half the grid step; see bake.grid_roughness).
        levels = maps.quality.prefiltered_levels
        blur_mip = max(0.0, roughness_to_grid_step(scene.display.blur_roughness, levels) / 2)
        set_uniform(prog, "u_blur_mip", float(blur_mip))
        set_uniform(prog, "u_inverse_view_projection", inverse_vp.tobytes(), write=True)
        set_uniform(prog, "u_env_rotation", rotation_cos_sin(scene.env_rotation_deg))
        set_uniform(prog, "u_env_intensity", float(scene.env_intensity))
