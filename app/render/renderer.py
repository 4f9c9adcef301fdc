"""Draws a Scene into framebuffers with the forward PBR pass. Knows nothing of any UI.

The passes of a frame, by anti-aliasing mode and what the caller reads back:

    msaa:  forward pass (mesh, or the probe view) into the multisampled float target (cleared:
           alpha is coverage; half floats when only sRGB is read, HALF_FLOAT_MIN_EXPOSURE)
           -> resolve pass: mean of the samples, the background composited under them, written as
              linear radiance and/or tone-mapped sRGB, whichever is read (render/resolve.frag;
              outside the mesh's screen rectangle the background alone, without the samples);
           with alphaMode BLEND parts (drawn over the background): forward pass -> background
           pass -> blended parts -> blit resolve -> radiance [-> tone map pass]
    none:  forward pass -> background pass (depth-tested to the uncovered pixels); written
           tone mapped as drawn when only sRGB is read (draw_display, the editor's path), else
           linear radiance [-> tone map pass, if sRGB is read too]
    ssaa:  forward and background passes at 2x -> box reduction -> radiance [-> tone map pass]

A mesh with transmissive parts (KHR_materials_transmission) has a forward pass in three steps:

    opaque parts -> copy (what is behind: radiance and coverage, mipmapped) -> transmissive
        parts (reading the copy, common/transmission.glsl)

so that what the glass shows is the opaque scene behind it, as the Khronos Sample Viewer does
(the colour target is then cleared, so that the copy's alpha is the opaque parts' coverage).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary, create_headless_context
from alight.core.ibl_models import SUNS_AS_BAKED
from alight.core.layers import layer_defines
from alight.core.material import LAYERS, Material, with_overrides
from alight.core.mesh import MeshPart, is_closed, sphere
from alight.core.scene import (
    Camera,
    Display,
    Scene,
    default_camera,
)
from alight.core.shader_names import (
    MATERIAL_MAPS,
    AlphaMode,
    BackgroundMode,
    IblModel,
    LightKind,
    Tonemap,
    glsl_member,
    map_bit,
    map_mask,
)
from alight.core.shading import rotate_world_to_map
from alight.core.sphere_lod import (
    MAX_SILHOUETTE_ERROR_PX,
    SPHERE_LOD_SEGMENTS,
    impostor_background_ring,
    impostor_hole_model,
    impostor_proxy_model,
    impostor_proxy_polygon,
    projected_radius_px,
    sphere_segments,
)
from alight.core.texture_footprint import anisotropy_for_view, footprints
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.ibl.bake import (
    QUALITY,
    BakeQuality,
    IBLMaps,
    LutCache,
    bake_environment,
    bake_steps,
    grid_roughness,
    roughness_to_grid_step,
)
from alight.ibl.bake_cache import BakeCache, load_bake, save_bake
from alight.ibl.anisotropy_lut import AnisotropyLut
from alight.ibl.sun import MAX_SUNS
from alight.ibl.transmission_lut import TransmissionLut
from alight.render.ground import GroundPass
from alight.render.shadows import ShadowMaps
from alight.render.visibility_parts import OcclusionParts
from alight.render.tiles import (
    TILE_BYTES,
    Tile,
    TilePlan,
    framebuffer_bytes,
    plan_tiles,
    side_limit,
    tile_matrix,
    tile_origin,
)

GL_SRGB8_ALPHA8 = 0x8C43
GL_FRAMEBUFFER_SRGB = 0x8DB9
AA_MODES = ("none", "msaa", "ssaa")
MAX_LIGHTS = 16   # punctual.glsl's MAX_LIGHTS
MAX_GRID_STEPS = 32  # ibl.glsl's MAX_GRID_STEPS: prefiltered roughness steps (2 levels - 1)
# A multisampled frame read as sRGB only is drawn into half floats (half the bytes written,
# cleared and resolved) where the tone map saturates before the clamp to half's largest value
# could show: 65504 / 4 (one sample of four) at 2^-6 is 256, white in every tone map.
HALF_FLOAT_MAX = 65504.0
HALF_FLOAT_MIN_EXPOSURE = -6.0

# Texture units, fixed so that binding one map never disturbs another.
UNIT_IRRADIANCE, UNIT_PREFILTERED, UNIT_PREFILTERED_MID, UNIT_LUT, UNIT_ENVIRONMENT, UNIT_RADIANCE = range(6)
UNIT_MATERIAL = {name: 6 + i for i, name in enumerate(MATERIAL_MAPS)}
UNIT_SHEEN_LUT = 6 + len(MATERIAL_MAPS)   # the sheen LUT (common/sheen.glsl), bound with HAS_SHEEN
UNIT_TRANSMISSION_LUT = UNIT_SHEEN_LUT + 1          # ibl/transmission_lut.comp's table (HAS_VOLUME)
UNIT_SCENE_BEHIND = UNIT_TRANSMISSION_LUT + 1      # the opaque parts' copy (TRANSMISSION_SCENE)
SRGB_MAPS = ("base_color", "emissive", "sheen_color", "specular_color")
# Every sampler gets its own unit: samplers left at the default unit 0 with different types
# (samplerCube and sampler2D) make every draw call fail with GL_INVALID_OPERATION.
SAMPLER_UNITS = {
    "u_irradiance": UNIT_IRRADIANCE, "u_prefiltered_radiance": UNIT_PREFILTERED,
    "u_prefiltered_radiance_mid": UNIT_PREFILTERED_MID, "u_brdf_lut": UNIT_LUT,
    "u_environment": UNIT_ENVIRONMENT, "u_radiance": UNIT_RADIANCE, "u_radiance_source": UNIT_RADIANCE,
    "u_scene": UNIT_RADIANCE,
    **{f"u_{name}_map": unit for name, unit in UNIT_MATERIAL.items()},
    "u_sheen_lut": UNIT_SHEEN_LUT, "u_transmission_lut": UNIT_TRANSMISSION_LUT, "u_scene_behind": UNIT_SCENE_BEHIND,
}
# KHR_materials_anisotropy's energy ratios (alight.ibl.anisotropy_lut), bound where a program reads them.
UNIT_ANISOTROPY_RATIO_A, UNIT_ANISOTROPY_RATIO_B = UNIT_SCENE_BEHIND + 1, UNIT_SCENE_BEHIND + 2
SAMPLER_UNITS.update(u_anisotropy_ratio_a=UNIT_ANISOTROPY_RATIO_A, u_anisotropy_ratio_b=UNIT_ANISOTROPY_RATIO_B)
# The `stretched` IBL model's lobe table (alight.core.stretched_lobe), bound where a program reads it.
UNIT_STRETCHED_LOBE_A, UNIT_STRETCHED_LOBE_B = UNIT_SCENE_BEHIND + 3, UNIT_SCENE_BEHIND + 4
SAMPLER_UNITS.update(u_stretched_lobe_a=UNIT_STRETCHED_LOBE_A, u_stretched_lobe_b=UNIT_STRETCHED_LOBE_B)
# The shadow atlas (alight.render.shadows): with comparison (PCF) and as depths (the blocker search).
UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH = UNIT_SCENE_BEHIND + 5, UNIT_SCENE_BEHIND + 6
SAMPLER_UNITS.update(u_shadow_atlas=UNIT_SHADOW_ATLAS, u_shadow_depth=UNIT_SHADOW_DEPTH)


@dataclass
class Frame:
    """One rendered image: linear radiance (float32 RGBA) and its display encoding (uint8 sRGB),
    both with row 0 at the top. Alpha is 1 where a surface was hit."""

    linear: np.ndarray
    srgb: np.ndarray


@dataclass
class Strip:
    """Rows y0.. of an image (``ForwardRenderer.render_strips``), as a Frame of those rows."""

    y0: int
    frame: Frame


@dataclass(frozen=True)
class _View:
    """The part of the image a pass draws: the whole image's size, and for a tile its
    off-centre matrix (alight.render.tiles) and its bottom-left pixel in the image."""

    width: int
    height: int
    matrix: np.ndarray | None = None
    origin: tuple[int, int] = (0, 0)


class _GpuPart:
    """A mesh part's buffers, uploaded once, and what its shader variant needs to know.

    The vertex buffer holds position, normal, uv and tangent, then TEXCOORD_1 and COLOR_0 only
    when the part has them (pbr.vert's HAS_UV1, HAS_VERTEX_COLOR). Textures come from the mesh's
    shared set (one upload per image and sampler).
    """

    def __init__(self, ctx: moderngl.Context, part, textures: "_MeshTextures"):
        columns = [part.positions, part.normals, part.uvs, part.tangents]
        self.layout = ["3f 3f 2f 4f", "in_position", "in_normal", "in_uv", "in_tangent"]
        self.has_uv1 = part.uvs1 is not None
        self.has_colors = part.colors is not None
        if self.has_uv1:
            columns.append(part.uvs1)
            self.layout[0] += " 2f"
            self.layout.append("in_uv1")
        if self.has_colors:
            columns.append(part.colors)
            self.layout[0] += " 4f"
            self.layout.append("in_color")
        # Interleaved into one array and handed to GL as it is (no hstack of float64 copies, no
        # tobytes() copy): the CPU side peaks at one vertex buffer's bytes, then lets it go.
        widths = [np.shape(c)[1] for c in columns]
        vertices = np.empty((len(part.positions), sum(widths)), np.float32)
        at = 0
        for column, width in zip(columns, widths):
            vertices[:, at:at + width] = column
            at += width
        self.vbo = ctx.buffer(vertices)
        del vertices
        self.ibo = ctx.buffer(np.ascontiguousarray(part.indices, dtype=np.uint32))
        self.ctx = ctx
        # More per-vertex buffers, (buffer, format, *names), and whether they carry the visibility
        # bake's values (alight.render.visibility_parts: HAS_VISIBILITY).
        self.extra_buffers: list[tuple] = []
        self.has_visibility = False
        # A vertex array belongs to one program: one per program this part is drawn with (the
        # shaded pass, a debug view), made on first use.
        self._vaos: dict[int, moderngl.VertexArray] = {}
        self.textures: dict[str, moderngl.Texture] = {}
        self.infos: dict = {}
        self._part = part
        self._closed: bool | None = None
        self._anisotropy_key = None
        self._anisotropy = 1.0
        positions = np.asarray(part.positions, np.float64)
        self.lo = positions.min(axis=0) if len(positions) else np.zeros(3)    # bounding box corners
        self.hi = positions.max(axis=0) if len(positions) else np.zeros(3)
        self.centre = (self.lo + self.hi) / 2.0
        fm = part.material
        if fm is not None:
            for name, info in fm.textures().items():
                self.infos[name] = info
                self.textures[name] = textures.get(info, srgb=name in SRGB_MAPS)

    @property
    def closed(self) -> bool:
        """Whether the part is closed (alight.core.mesh.is_closed), found on first use: only a
        part without a glTF material's doubleSided needs to know (a 4M-triangle mesh's test
        takes seconds)."""
        if self._closed is None:
            self._closed = is_closed(self._part.positions, self._part.indices)
        return self._closed

    def anisotropy(self, view_projection: np.ndarray, image_size: tuple[int, int],
                   texture_size: tuple[int, int]) -> float:
        """The anisotropic filtering level this view of the part gains from
        (alight.core.texture_footprint), remembered for the last view asked."""
        key = (np.asarray(view_projection, np.float32).tobytes(), tuple(image_size), tuple(texture_size))
        if self._anisotropy_key != key:
            part = self._part
            uvs = part.uvs
            # The uvs the maps read: KHR_texture_transform's scale (gltfpack's dequantization of
            # quantized uvs among them) multiplies the footprint. The transform that stretches
            # the most sets it.
            mats = [np.asarray(info.transform.gl_matrix(), np.float64) for info in self.infos.values()
                    if info.transform is not None and info.tex_coord == 0]
            if mats:
                m = max(mats, key=lambda m: abs(np.linalg.det(m[:2, :2])))
                uvs = np.asarray(uvs, np.float64) @ m[:2, :2].T + m[:2, 2]
            area, p_max, p_min = footprints(part.positions, uvs, part.indices, view_projection,
                                            image_size, texture_size)
            self._anisotropy = anisotropy_for_view(area, p_max, p_min)
            self._anisotropy_key = key
        return self._anisotropy

    def vao_for(self, program: moderngl.Program) -> moderngl.VertexArray:
        vao = self._vaos.get(id(program))
        if vao is None:
            vao = self._vaos[id(program)] = self.ctx.vertex_array(
                program, [(self.vbo, *self.layout), *self.extra_buffers], self.ibo, index_element_size=4,
                skip_errors=True)  # a debug view may not read every attribute
        return vao

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self.vbo.release()
        self.ibo.release()


_ANISOTROPIC_FILTERS = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR_MIPMAP_NEAREST,
                        moderngl.NEAREST_MIPMAP_LINEAR, moderngl.NEAREST_MIPMAP_NEAREST)
_MIN_FILTERS = {"nearest": moderngl.NEAREST, "linear": moderngl.LINEAR,
                "nearest_mipmap_nearest": moderngl.NEAREST_MIPMAP_NEAREST,
                "linear_mipmap_nearest": moderngl.LINEAR_MIPMAP_NEAREST,
                "nearest_mipmap_linear": moderngl.NEAREST_MIPMAP_LINEAR,
                "linear_mipmap_linear": moderngl.LINEAR_MIPMAP_LINEAR}


class _MeshTextures:
    """A mesh's textures, one per (image, colour space, sampler): parts sharing an image share
    its upload. REPEAT and CLAMP_TO_EDGE are the texture's wrap state; MIRRORED_REPEAT is folded
    in the shader (mesh_material.glsl), so its axis is clamped here."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._textures: dict[tuple, moderngl.Texture] = {}

    def get(self, info, srgb: bool) -> moderngl.Texture:
        sampler = info.sampler
        key = (id(info.image), srgb, sampler)
        tex = self._textures.get(key)
        if tex is None:
            tex = _upload_image(self.ctx, info.image, srgb, mipmaps=sampler.mipmaps)
            tex.filter = (_MIN_FILTERS.get(sampler.min_filter, moderngl.LINEAR_MIPMAP_LINEAR),
                          moderngl.NEAREST if sampler.mag_filter == "nearest" else moderngl.LINEAR)
            tex.repeat_x = sampler.wrap_s == "repeat"
            tex.repeat_y = sampler.wrap_t == "repeat"
            if not sampler.mipmaps or sampler.mag_filter == "nearest":
                tex.anisotropy = 1.0
            self._textures[key] = tex
        return tex

    def release(self) -> None:
        for tex in self._textures.values():
            tex.release()
        self._textures.clear()


def _upload_image(ctx: moderngl.Context, image: np.ndarray, srgb: bool, mipmaps: bool = True) -> moderngl.Texture:
    """An RGBA uint8 image (alight.core.mesh gives RGBA) as a texture, mipmapped unless told not."""
    image = np.asarray(image, dtype=np.uint8)
    if image.shape[2] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
    # Images arrive top row first; texture coordinate v = 0 is the bottom row (OpenGL, trimesh).
    data = np.ascontiguousarray(image[::-1, :, :4])
    h, w = data.shape[:2]
    tex = ctx.texture((w, h), 4, data.tobytes(), internal_format=GL_SRGB8_ALPHA8 if srgb else None)
    if mipmaps:
        tex.build_mipmaps()
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        tex.anisotropy = 8.0
    else:
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return tex


class _Targets:
    """Framebuffers for one output size and anti-aliasing mode, kept between frames."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int, aa: str, samples: int, half: bool = False):
        self.ctx = ctx
        self.width, self.height, self.aa, self.samples = width, height, aa, samples
        self.half = half and aa == "msaa"     # the MSAA colour in half floats (HALF_FLOAT_MIN_EXPOSURE)
        self._display_draw = None
        self._behind: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self.draw = self.depth = self.radiance_fbo = self.radiance = self.display_fbo = self.display = None
        self._both_fbo = None
        self._single: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self.color = None
        try:
            self._allocate()
        except Exception:
            self.release()
            raise

    def _allocate(self) -> None:
        ctx, width, height, aa, samples = self.ctx, self.width, self.height, self.aa, self.samples
        # Linear radiance at the output size: drawn into directly without anti-aliasing, else the
        # MSAA resolve or the SSAA reduction lands here.
        self.radiance = ctx.texture((width, height), 4, dtype="f4")
        self.radiance.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.radiance_fbo = ctx.framebuffer([self.radiance])
        scale = 2 if aa == "ssaa" else 1
        self.draw_size = (width * scale, height * scale)
        ms = samples if aa == "msaa" else 0
        if aa == "msaa":
            # A texture, not a renderbuffer: render/resolve.frag reads its samples.
            self.color = ctx.texture(self.draw_size, 4, samples=ms, dtype="f2" if self.half else "f4")
        elif aa == "ssaa":
            self.color = ctx.texture(self.draw_size, 4, dtype="f4")
        else:
            self.color = self.radiance
        self.depth = ctx.depth_renderbuffer(self.draw_size, samples=ms)
        self.draw = ctx.framebuffer([self.color], self.depth)
        self.display = ctx.texture((width, height), 4, dtype="f1")
        self.display_fbo = ctx.framebuffer([self.display])

    def behind(self) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        """What transmissive parts see behind them: the opaque parts' radiance with alpha =
        coverage (premultiplied: uncovered pixels are 0), at the draw size, mipmapped so that a
        rough surface reads it blurred (common/transmission.glsl: scene_behind). Half floats:
        a blurred view through glass needs no more than 11 bits."""
        if self._behind is None:
            tex = self.ctx.texture(self.draw_size, 4, dtype="f2")
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            self._behind = (tex, self.ctx.framebuffer([tex]))
        return self._behind

    def single(self) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        """A single-sample colour target at the draw size, in the multisampled one's format, where
        the built-in sphere's impostor writes its coverage-weighted radiance for the fused resolve
        (ForwardRenderer._sphere_impostor). No depth: the proxy is one flat polygon facing the eye."""
        if self._single is None:
            tex = self.ctx.texture(self.draw_size, 4, dtype="f2" if self.half else "f4")
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._single = (tex, self.ctx.framebuffer([tex]))
        return self._single

    def display_draw(self) -> moderngl.Framebuffer:
        """The display image with the depth buffer, for ForwardRenderer.draw_display (no AA only)."""
        if self._display_draw is None:
            self._display_draw = self.ctx.framebuffer([self.display], self.depth)
        return self._display_draw

    def resolve_fbo(self, radiance: bool, display: bool) -> moderngl.Framebuffer:
        """Where render/resolve.frag writes: the radiance, the display image, or both (in that
        order: its RADIANCE_OUTPUT at location 0, DISPLAY_OUTPUT at 1)."""
        if radiance and display:
            if self._both_fbo is None:
                self._both_fbo = self.ctx.framebuffer([self.radiance, self.display])
            return self._both_fbo
        return self.radiance_fbo if radiance else self.display_fbo

    def release(self) -> None:
        owned = [self._both_fbo, self._display_draw, self.draw, self.depth, self.radiance_fbo,
                 self.radiance, self.display_fbo, self.display]
        if self.color is not self.radiance:
            owned.append(self.color)
        if self._behind is not None:
            owned.extend(self._behind[::-1])
        if self._single is not None:
            owned.extend(self._single[::-1])
        for obj in owned:
            if obj is not None:
                obj.release()


class ForwardRenderer:
    """Owns a GL context's programs, uploaded meshes, bakes and targets.

    ``with ForwardRenderer() as r:`` releases everything on exit. Bakes are cached per environment
    content and quality, in memory and in ``bake_cache`` (alight.ibl.bake_cache: on disk, shared
    by every process; None keeps them in memory only), so rendering many materials under one
    environment bakes once, and so does every later process. ``bakes_run`` counts the bakes
    that ran, ``bakes_loaded`` those read from the disk cache.
    """

    def __init__(self, ctx: moderngl.Context | None = None, shaders: ShaderLibrary | None = None,
                 bake_cache: BakeCache | None | str = "default"):
        self.ctx = ctx or create_headless_context()
        self.shaders = shaders or ShaderLibrary(self.ctx)
        self.luts = LutCache(self.ctx, self.shaders)
        self.bake_cache = BakeCache() if bake_cache == "default" else bake_cache
        self.bakes_run = 0
        self.bakes_loaded = 0
        # Meshes drawn with the visibility bake (Scene.occlusion; alight.render.visibility_parts).
        self.visibility_parts = OcclusionParts(self.ctx, self.bake_cache)
        self.anisotropy_lut = AnisotropyLut(self.ctx, self.shaders)   # baked on first anisotropic draw
        self._stretched_lobe: tuple[moderngl.Texture, moderngl.Texture] | None = None   # uploaded on first use
        self._transmission_lut: TransmissionLut | None = None
        self._bakes: dict[tuple, IBLMaps] = {}
        self._meshes: dict[int, tuple[object, list[_GpuPart], _MeshTextures]] = {}
        # The built-in sphere's coarser levels (alight.core.sphere_lod), by the mesh's id and segments.
        self._sphere_lods: dict[tuple[int, int], tuple[object, list[_GpuPart], _MeshTextures]] = {}
        self.last_sphere_segments: int | None = None   # the level the last mesh pass drew (tests, benchmarks)
        # How far the built-in sphere's outline may fall inside the true one, in output pixels
        # (alight.core.sphere_lod); 0 draws the sphere's own tessellation.
        self.sphere_max_error_px = MAX_SILHOUETTE_ERROR_PX
        # The built-in sphere drawn as an impostor where it can be (_sphere_impostor); False draws
        # its tessellation in every pass (the tests compare the two).
        self.sphere_impostor = True
        # With the impostor and one sample a pixel, the background drawn around a hole the impostor
        # fills, without a depth buffer (_draw_scene); False: depth-tested after it (tests compare).
        self.background_ring = True
        self.last_background_ring = False   # whether the last scene pass drew it
        self.last_sphere_impostor: int | None = None   # the last mesh pass's coverage samples, or None
        self.last_anisotropy: dict[str, float] = {}    # per textured part's name, the level it was last drawn with
        # Set by _draw_scene: 1, 4 (into the fused resolve's single-sample stand-in, _Targets.single,
        # which _resolve then reads), 0 (none: a multisampled target).
        self._impostor_samples = 1
        self._impostor_model: np.ndarray | None = None   # the proxy's placement while _draw_scene runs
        self._targets: _Targets | None = None
        self.shadow_maps = ShadowMaps(self.ctx)   # drawn where a scene can be shadowed (alight.render.shadows)
        self._shadowed = False                    # set by _draw_scene: this pass reads the shadow maps
        self._ground_pass: GroundPass | None = None   # Scene.ground's square, made on first use
        self._lights_ubo = self.ctx.buffer(reserve=MAX_LIGHTS * 64 + 16)
        self._lights_bytes = b""
        self._fullscreen_vaos: dict = {}   # by program id (and 'ring': _draw_background)
        self._units_assigned: set[int] = set()
        self._display_output: Display | None = None   # set while draw_display runs
        self._srgb_by_framebuffer = False   # set while draw_display writes into a framebuffer that encodes sRGB
        self._ring_buffer: moderngl.Buffer | None = None   # the background's ring (_draw_background)
        self._half_output = False     # set while a scene pass draws into half floats (_Targets.half)
        # User-loaded texture maps (Scene.texture_maps): (path, sRGB) -> (image, texture),
        # uploaded once per decoded image.
        self._map_textures: dict[tuple[str, bool], tuple[np.ndarray, moderngl.Texture]] = {}

    # --- resources -----------------------------------------------------------------------

    def bake(self, env, quality: BakeQuality | str = "medium") -> IBLMaps:
        q = QUALITY[quality] if isinstance(quality, str) else quality
        key = (env.content_hash, q)
        if key not in self._bakes:
            maps = self._load_bake(env, q)
            if maps is None:
                maps = bake_environment(self.ctx, self.shaders, env, q, self.luts)
                self._keep_bake(env, maps)
            self._bakes[key] = maps
        return self._bakes[key]

    def bake_steps(self, env, quality: BakeQuality | str = "medium"):
        """``bake`` in steps (alight.ibl.bake.bake_steps): yields (fraction, label) between GPU passes
        and returns the maps, cached as ``bake`` caches them (a cached bake yields nothing, one
        on disk is loaded in the first step)."""
        q = QUALITY[quality] if isinstance(quality, str) else quality
        key = (env.content_hash, q)
        if key not in self._bakes:
            maps = self._load_bake(env, q)
            if maps is None:
                maps = yield from bake_steps(self.ctx, self.shaders, env, q, self.luts)
                self._keep_bake(env, maps)
            self._bakes[key] = maps
        return self._bakes[key]

    def _load_bake(self, env, q: BakeQuality) -> IBLMaps | None:
        if self.bake_cache is None:
            return None
        maps = load_bake(self.bake_cache, self.ctx, self.shaders, env, q, self.luts)
        self.bakes_loaded += maps is not None
        return maps

    def _keep_bake(self, env, maps: IBLMaps) -> None:
        self.bakes_run += 1
        if self.bake_cache is not None:
            save_bake(self.bake_cache, self.shaders, env, maps)

    def _gpu_mesh(self, mesh, program=None) -> list[_GpuPart]:
        entry = self._meshes.get(id(mesh))
        if entry is None or entry[0] is not mesh:
            if entry is not None:
                _release_mesh(entry)
            textures = _MeshTextures(self.ctx)
            entry = (mesh, [_GpuPart(self.ctx, part, textures) for part in mesh.parts], textures)
            self._meshes[id(mesh)] = entry
        return entry[1]

    def _drawn_parts(self, mesh, camera: Camera, image_size: tuple[int, int]) -> tuple[list[_GpuPart], float | None]:
        """The GPU parts a pass draws for ``mesh``, and the radius of the true sphere they stand
        for where ``mesh`` is the built-in sphere (else None).

        The built-in sphere (``Mesh.lod_sphere``) seen by a perspective camera from outside is
        drawn at the coarsest level whose outline stays within ``sphere_max_error_px`` at
        ``image_size`` (the whole image's pixels; alight.core.sphere_lod), never finer than its
        own, and its fragments are shaded on the true sphere (mesh_material.glsl SPHERE_SURFACE),
        so the level moves the outline only. Every pass of a frame, every tile, picks the same."""
        own = self._gpu_mesh(mesh)
        self.last_sphere_segments = None
        if mesh.lod_sphere is None or len(mesh.parts) != 1 or camera.ortho_half_height is not None:
            return own, None
        radius, segments = mesh.lod_sphere
        vp = camera.view_projection(image_size[0] / image_size[1])
        radius_px = projected_radius_px(vp, (0.0, 0.0, 0.0), radius, image_size)
        if not math.isfinite(radius_px):    # the eye at or inside the sphere: drawn as given
            return own, None
        n = sphere_segments(radius_px, self.sphere_max_error_px,
                            levels=tuple(x for x in SPHERE_LOD_SEGMENTS if x < segments) + (segments,))
        self.last_sphere_segments = n
        if n == segments:
            return own, radius
        return [self._sphere_stand_in(mesh, n, lambda: sphere(n, n // 2, radius).parts[0])], radius

    def _sphere_stand_in(self, mesh, key, make_part) -> _GpuPart:
        """A part drawn in place of the built-in sphere ``mesh``'s own (a coarser level, the
        impostor's proxy), kept by ``key`` while ``mesh`` is the one drawn; ``make_part`` builds
        its MeshPart, which takes the sphere's material, name and element."""
        for old in [k for k, e in self._sphere_lods.items() if e[0] is not mesh]:   # another mesh's
            _release_mesh(self._sphere_lods.pop(old))
        entry = self._sphere_lods.get((id(mesh), key))
        if entry is None:
            part = mesh.parts[0]
            stand_in = dataclasses.replace(make_part(), material=part.material, name=part.name, element=part.element)
            textures = _MeshTextures(self.ctx)
            entry = self._sphere_lods[(id(mesh), key)] = (mesh, [_GpuPart(self.ctx, stand_in, textures)], textures)
        return entry[1][0]

    def _sphere_impostor(self, scene: Scene, camera: Camera, image_size: tuple[int, int],
                         view_projection: np.ndarray | None = None) -> tuple[np.ndarray, float] | None:
        """Where the built-in sphere is drawn as an impostor, the (4, 4) matrix that places its
        proxy (column vectors) and the outline's radius in pixels; else None.

        The proxy is a 16-sided polygon facing the eye around the sphere's outline with 2 px to
        spare (alight.core.sphere_lod.impostor_proxy_model): few, large triangles. Each of its
        pixels tests its sample rays against the true sphere (mesh_material.glsl SPHERE_IMPOSTOR)
        and is shaded as the tessellated ball's are (SPHERE_SURFACE: on the true sphere, at the
        pixel centre), with the sphere's own uv and tangent there (mesh_material.glsl surface_uv,
        surface_tangent), so only the outline's coverage changes: it is the true sphere's. Used
        for a perspective camera outside the sphere with the proxy between the clipping planes;
        not for what a file's material could ask of a part and the built-in sphere's cannot
        (blending, masks, vertex colours, texture transforms, a second uv set, mirroring).
        ``view_projection``: the camera's for ``image_size`` (not a tile's), where the caller has
        it."""
        mesh = scene.mesh
        if (not self.sphere_impostor or scene.view == "probe" or mesh is None or scene.ground or mesh.lod_sphere is None
                or len(mesh.parts) != 1 or camera.ortho_half_height is not None):
            return None
        radius = mesh.lod_sphere[0]
        if view_projection is None:
            view_projection = camera.view_projection(image_size[0] / image_size[1])
        vp = np.asarray(view_projection, np.float64)
        radius_px = projected_radius_px(vp, (0.0, 0.0, 0.0), radius, image_size)
        model = impostor_proxy_model(camera.position, radius, radius_px)
        if model is None:
            return None
        clip = _PROXY_POINTS @ model.T @ vp
        if not (np.abs(clip[:, 2]) < 0.999 * clip[:, 3]).all():    # (w > 0 too)
            return None
        part = mesh.parts[0]
        defines = self._part_defines(scene, self._gpu_mesh(mesh)[0], part, self._user_maps_present(scene))
        if any(k in defines for k in ("ALPHA_MODE", "UNLIT", "HAS_VERTEX_COLOR", "HAS_UV1")):
            return None
        if any(defines.get(k) for k in ("MAP_UV1_MASK", "MAP_TRANSFORM_MASK", "MAP_MIRROR_S_MASK", "MAP_MIRROR_T_MASK")):
            return None
        return model, radius_px

    def _impostor_proxy(self, mesh) -> _GpuPart:
        """The impostor's proxy polygon (alight.core.sphere_lod.impostor_proxy_polygon), placed by
        the model matrix of _sphere_impostor; its normals, uvs and tangents are never read."""
        def make_part() -> MeshPart:
            positions, indices = impostor_proxy_polygon()
            n = len(positions)
            return MeshPart("", positions, np.tile(np.float32([0.0, 0.0, 1.0]), (n, 1)), np.zeros((n, 2), np.float32),
                            np.tile(np.float32([1.0, 0.0, 0.0, 1.0]), (n, 1)), indices, None)

        return self._sphere_stand_in(mesh, "proxy", make_part)

    def _targets_for(self, width: int, height: int, aa: str, samples: int, half: bool = False) -> _Targets:
        t = self._targets
        half = half and aa == "msaa"
        if t is None or (t.width, t.height, t.aa, t.samples, t.half) != (width, height, aa, samples, half):
            if t is not None:
                t.release()
            self._targets = _Targets(self.ctx, width, height, aa, samples, half)
        return self._targets

    def use_shaders(self, shaders: ShaderLibrary) -> None:
        """Switch to a freshly compiled library (the editor's shader hot reload) and release the
        old one. Vertex arrays are tied to the program they were made with, so the mesh and
        full-screen VAOs are rebuilt on the next draw; the bakes stay valid."""
        old, self.shaders = self.shaders, shaders
        self.luts.shaders = shaders
        for vao in self._fullscreen_vaos.values():
            vao.release()
        self._fullscreen_vaos.clear()
        self._units_assigned.clear()
        for entry in [*self._meshes.values(), *self._sphere_lods.values()]:
            _release_mesh(entry)
        self._meshes.clear()
        self._sphere_lods.clear()
        old.reload()

    def _user_textures(self, scene: Scene) -> dict[str, moderngl.Texture]:
        """The scene's user-loaded maps as textures by slot, uploaded on first use of an image."""
        if scene.texture_maps is None:
            return {}
        out = {}
        for slot, path in scene.texture_maps.paths().items():
            image = scene.texture_images.get(path)
            if image is None:
                continue
            key = (path, slot in SRGB_MAPS)
            entry = self._map_textures.get(key)
            if entry is None or entry[0] is not image:
                if entry is not None:
                    entry[1].release()
                entry = self._map_textures[key] = (image, _upload_image(self.ctx, image, srgb=key[1]))
            out[slot] = entry[1]
        return out

    def forget_map_textures(self, keep_paths) -> None:
        """Release the uploaded maps whose path is not in ``keep_paths``."""
        for key in [k for k in self._map_textures if k[0] not in keep_paths]:
            self._map_textures.pop(key)[1].release()

    def release(self) -> None:
        self.forget_map_textures(())
        for maps in self._bakes.values():
            maps.release()
        self._bakes.clear()
        for entry in [*self._meshes.values(), *self._sphere_lods.values()]:
            _release_mesh(entry)
        self._meshes.clear()
        self._sphere_lods.clear()
        self.visibility_parts.release()
        if self._targets:
            self._targets.release()
            self._targets = None
        self.luts.release()
        self.shadow_maps.release()
        if self._ground_pass is not None:
            self._ground_pass.release()
            self._ground_pass = None
        if self.bake_cache is not None:
            self.bake_cache.close()
        self.anisotropy_lut.release()
        if self._stretched_lobe is not None:
            for tex in self._stretched_lobe:
                tex.release()
            self._stretched_lobe = None
        if self._transmission_lut is not None:
            self._transmission_lut.release()
        for vao in self._fullscreen_vaos.values():
            vao.release()
        self._fullscreen_vaos.clear()
        if self._ring_buffer is not None:
            self._ring_buffer.release()
            self._ring_buffer = None
        self.shaders.reload()

    def transmission_lut(self) -> moderngl.Texture:
        """The transmission LUT (alight.ibl.transmission_lut), baked or read on first use."""
        if self._transmission_lut is None:
            self._transmission_lut = TransmissionLut(self.ctx, self.shaders)
        return self._transmission_lut.texture()

    def __enter__(self) -> "ForwardRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def program(self, vertex: str, fragment: str, defines: dict | None = None) -> moderngl.Program:
        prog = self.shaders.program(vertex, fragment, defines)
        if id(prog) not in self._units_assigned:
            for name, unit in SAMPLER_UNITS.items():
                _set(prog, name, unit)
            self._units_assigned.add(id(prog))
        return prog

    # --- drawing -------------------------------------------------------------------------

    def render(self, scene: Scene, maps: IBLMaps | None, width: int, height: int,
               aa: str = "msaa", samples: int = 4, read_linear: bool = True, read_srgb: bool = True,
               tile: tuple[int, int] | None = None) -> Frame:
        """Draw ``scene`` lit by ``maps`` (None: no environment) and read the results back.
        An image one framebuffer cannot hold is drawn in tiles (``render_strips``) with the same
        pixels; ``tile`` forces tiles of at most that size."""
        linear = srgb = None
        for strip in self.render_strips(scene, maps, width, height, aa, samples, read_linear, read_srgb, tile):
            rows = (strip.frame.linear if read_linear else strip.frame.srgb)
            if strip.y0 == 0 and rows is not None and len(rows) == height:
                return strip.frame          # one pass: no copy
            if read_linear:
                if linear is None:
                    linear = np.empty((height, width, 4), np.float32)
                linear[strip.y0:strip.y0 + len(strip.frame.linear)] = strip.frame.linear
            if read_srgb:
                if srgb is None:
                    srgb = np.empty((height, width, 4), np.uint8)
                srgb[strip.y0:strip.y0 + len(strip.frame.srgb)] = strip.frame.srgb
        return Frame(linear, srgb)

    def render_strips(self, scene: Scene, maps: IBLMaps | None, width: int, height: int,
                      aa: str = "msaa", samples: int = 4, read_linear: bool = True, read_srgb: bool = True,
                      tile: tuple[int, int] | None = None) -> Iterator[Strip]:
        """``render`` strip by strip, top first (alight.render.tiles): each Strip holds a band of
        whole rows, drawn as one or more tiles, so a caller that writes and drops each one holds
        one strip's pixels at a time. A size within the GL limits and TILE_BYTES is one strip."""
        if scene.view == "probe":
            aa = "none"  # the probe view's normals are exact per pixel centre: no blending
        if aa == "msaa":
            samples = min(samples, self.ctx.max_samples)
            if samples < 2:
                aa = "none"   # this GL has no multisampled float framebuffers
        # Half floats only where the fused resolve reads them and nothing but sRGB is read.
        # (Not with transmissive parts: their copy of the opaque parts keeps floats.)
        half = (aa == "msaa" and read_srgb and not read_linear and not self._has_blending_parts(scene)
                and not self.transmissive_parts(scene) and scene.display.exposure >= HALF_FLOAT_MIN_EXPOSURE)
        plan, targets = self._tiled_targets(width, height, aa, samples, tile, half)
        opaque = scene.display.background != "transparent"
        for tiles in plan.strips():
            rows = tiles[0].height
            linear = np.empty((rows, width, 4), np.float32) if read_linear and not plan.single else None
            srgb = np.empty((rows, width, 4), np.uint8) if read_srgb and not plan.single else None
            for t in tiles:
                view = None if plan.single else _View(width, height, tile_matrix(plan, t), tile_origin(plan, t))
                # Only the images that are read are made (module docstring).
                if aa == "msaa" and not self._has_blending_parts(scene):
                    self._draw_scene(scene, maps, targets, targets.draw, view=view, background=False)
                    self._resolve(scene, maps, targets, read_linear, read_srgb)
                elif aa == "none" and read_srgb and not read_linear and opaque and scene.view != "probe" \
                        and not scene.ground:   # (the ground darkens radiance: it blends before the tone map)
                    self._draw_scene(scene, maps, targets, targets.display_draw(), scene.display, view=view)
                else:
                    self._draw_scene(scene, maps, targets, targets.draw, view=view)
                    if read_srgb:
                        self.tonemap(targets.radiance, scene.display, targets.display_fbo, opaque=opaque)
                if read_linear:
                    block = _read(targets.radiance_fbo, t, "f4", np.float32)
                    if plan.single:
                        linear = block.copy()
                    else:
                        linear[:, t.x:t.x + t.width] = block
                if read_srgb:
                    block = _read(targets.display_fbo, t, "f1", np.uint8)
                    if plan.single:
                        srgb = block.copy()
                    else:
                        srgb[:, t.x:t.x + t.width] = block
            if linear is not None and scene.view == "probe":
                linear[linear[:, :, 3] == 0.0] = 0.0  # docs/conventions.md: probe background radiance is 0
            yield Strip(tiles[0].y, Frame(linear, srgb))

    def _tiled_targets(self, width: int, height: int, aa: str, samples: int,
                       tile: tuple[int, int] | None, half: bool = False) -> tuple[TilePlan, _Targets]:
        """The tile plan for this size and the framebuffers of one tile. Where the GL refuses
        them (out of memory, an incomplete framebuffer), tiles a quarter the size are tried."""
        budget = TILE_BYTES
        limits = {key: self.ctx.info.get(key) for key in (
            "GL_MAX_TEXTURE_SIZE", "GL_MAX_RENDERBUFFER_SIZE", "GL_MAX_VIEWPORT_DIMS",
            "GL_MAX_FRAMEBUFFER_WIDTH", "GL_MAX_FRAMEBUFFER_HEIGHT")}
        while True:
            plan = plan_tiles(width, height, side_limit(limits, aa), framebuffer_bytes(aa, samples), budget, tile=tile)
            try:
                return plan, self._targets_for(plan.tile_width, plan.tile_height, aa, samples, half)
            except moderngl.Error as exc:
                self._targets = None
                if plan.tile_width * plan.tile_height <= 16 * 16:
                    reason = " ".join(str(exc).split()) or type(exc).__name__
                    raise AlightError(f"OpenGL: cannot make a {plan.tile_width}x{plan.tile_height} framebuffer "
                                      f"({aa}) for a {width}x{height} image ({reason})") from None
                budget = min(budget, plan.tile_width * plan.tile_height * framebuffer_bytes(aa, samples)) // 4
                tile = None

    @staticmethod
    def _has_blending_parts(scene: Scene) -> bool:
        """Whether a part blends (alphaMode BLEND): it is drawn over the background, so such a
        frame keeps the background pass (the fused resolve composites the background last)."""
        if scene.view == "probe" or scene.mesh is None or not scene.use_file_materials:
            return False
        return any(part.material is not None and part.material.alpha_mode == "BLEND" for part in scene.mesh.parts)

    def draw_hdr(self, scene: Scene, maps: IBLMaps | None, targets: _Targets) -> None:
        self._draw_scene(scene, maps, targets, targets.draw)

    def draw_display(self, scene: Scene, maps: IBLMaps | None, targets: _Targets,
                     into: moderngl.Framebuffer | None = None, into_encodes_srgb: bool = False) -> moderngl.Framebuffer:
        """What ``draw_hdr`` then ``tonemap`` (opaque) leave in ``targets.display``, in one pass:
        the scene's programs tone map as they write (common/output_encoding.glsl), so neither the
        float image nor the tone map pass is needed (the editor's view). Without anti-aliasing
        only: a resolve must average radiance, not display values.

        ``into``: a framebuffer with a depth buffer (the editor's window) to draw the one pass
        into instead of ``targets.display``, at its bottom-left, targets' size. Returns the
        framebuffer that holds the picture: ``into`` where the one pass could be used, else
        ``targets.display_fbo``.

        ``into_encodes_srgb``: ``into`` is sRGB-capable (EditorWindow probes its window), so the
        passes write tone-mapped linear values with GL_FRAMEBUFFER_SRGB on and the framebuffer's
        write stage applies the sRGB curve (GL 4.5 section 17.3.7). A GPU does that for free;
        llvmpipe's encoder is a polynomial, 2.1 ms cheaper than the shader's pow() on a
        860x720 frame, within 1 LSB of the exact curve (on the editor's ball a fifth of the values
        1 LSB off; tests/editor_window_checks.py bounds it). Not with parts that blend: GL would blend them in
        linear space, the shader-encoded path blends sRGB values."""
        if targets.aa != "none" or scene.view == "probe" or self.transmissive_parts(scene) or scene.ground:
            # (transmissive parts read the opaque parts' radiance, which must not be tone mapped;
            # the ground darkens radiance, before the tone map)
            self.draw_hdr(scene, maps, targets)
            self.tonemap(targets.radiance, scene.display, targets.display_fbo)
            return targets.display_fbo
        fbo = into or targets.display_draw()
        srgb = into is not None and into_encodes_srgb and not self._has_blending_parts(scene)
        if srgb:
            self.ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
        self._srgb_by_framebuffer = srgb
        try:
            self._draw_scene(scene, maps, targets, fbo, scene.display)
        finally:
            if srgb:
                self.ctx.disable_direct(GL_FRAMEBUFFER_SRGB)
            self._srgb_by_framebuffer = False
        return into or targets.display_fbo

    def _draw_scene(self, scene: Scene, maps: IBLMaps | None, targets: _Targets, fbo: moderngl.Framebuffer,
                    display_output: Display | None = None, view: _View | None = None,
                    background: bool = True) -> None:
        ctx = self.ctx
        self._display_output = display_output
        self._half_output = targets.half and fbo is targets.draw
        width, height = targets.draw_size
        scale = width // targets.width      # SSAA draws 2x2 sub-pixels per output pixel
        view = view or _View(targets.width, targets.height)
        aspect = view.width / view.height
        # The probe's own camera is orthographic; its backdrop is drawn as the default camera sees it.
        camera = Camera() if scene.view == "probe" else self.camera_for(scene, aspect)
        # The built-in sphere as an impostor (_sphere_impostor): with one coverage sample a pixel
        # into a single-sample target, with 4 into the fused resolve's single-sample stand-in for
        # the multisampled one (its mean already taken); never into a multisampled target.
        view_projection = camera.view_projection(aspect)
        impostor = self._sphere_impostor(scene, camera, (view.width, view.height), view_projection)
        self._impostor_model = impostor[0] if impostor else None
        if targets.aa != "msaa":
            self._impostor_samples = 1
        elif self._impostor_model is not None and fbo is targets.draw and not background:
            self._impostor_samples = 4
            fbo = targets.single()[1]
        else:
            self._impostor_samples = 0
        self._shadowed = self._prepare_shadows(scene, maps)    # (its own framebuffer: before this pass's)
        fbo.use()
        ctx.viewport = (0, 0, width, height)
        if view.matrix is not None:     # a tile: the whole image's projection, off centre
            view_projection = (view_projection.astype(np.float64) @ view.matrix).astype(np.float32)
        inverse_vp = np.linalg.inv(view_projection).astype(np.float32)
        self._last_inverse_vp = inverse_vp    # the resolve's background rays (this frame or tile)
        # Only the fused resolve reads it (_resolve): computed there, from this pass's inputs.
        self._last_surface_rect_args = (scene, view_projection, (targets.width, targets.height))
        ring = None
        if self.background_ring and impostor and self._impostor_samples == 1 and background \
                and self._background_mode(scene, maps) != BackgroundMode.TRANSPARENT \
                and not self.transmissive_parts(scene):
            hole = impostor_hole_model(camera.position, scene.mesh.lod_sphere[0], impostor[1])
            ring = impostor_background_ring(hole, view_projection) if hole is not None else None
        # Colour too: the MSAA resolve tells covered samples by their alpha (render/resolve.frag),
        # and transmissive parts read the opaque parts' coverage from it. The whole framebuffer:
        # llvmpipe clears whole tiles lazily, and a scissored clear (the mesh's rectangle only)
        # made a 1920x1080 4x frame 7-9% slower here, alternated in one process.
        self.last_background_ring = ring is not None
        # With the background's ring no depth is read or written (colour only).
        fbo.depth_mask = ring is None
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        fbo.depth_mask = True
        self._write_lights(scene)
        if ring is not None:
            # The one sphere's impostor with one sample a pixel: the background first, around a
            # hole inside the sphere's outline (sphere_lod.impostor_background_ring), then the
            # impostor over it. Every pixel is written once or, in the thin band between the hole
            # and the outline, twice, and no depth buffer is cleared, tested or written: 3.5-5% of
            # the editor's 860x720 scene pass on llvmpipe (two renderers alternated in one process).
            ctx.disable(moderngl.DEPTH_TEST)
            self._draw_background(scene, maps, inverse_vp, ring)
        else:
            ctx.enable(moderngl.DEPTH_TEST)
            ctx.depth_func = "<="
        if scene.view == "probe":
            self._draw_probe(scene, maps, view.width * scale, (view.origin[0] * scale, view.origin[1] * scale))
        elif scene.mesh is not None:
            self._draw_mesh(scene, maps, camera, view_projection, blend=False, targets=targets, fbo=fbo,
                            pixels_per_radian=view.height * scale / 2.0 / math.tan(math.radians(camera.fov_y_deg) / 2.0),
                            image_size=(view.width, view.height))
            if not background:     # (the fused resolve composites the background under it)
                self._draw_ground(scene, maps, view_projection)
        # After the surfaces: the depth test keeps the background's shading off covered pixels.
        if background and ring is None:
            self._draw_background(scene, maps, inverse_vp)
            if scene.view != "probe" and scene.mesh is not None:
                self._draw_ground(scene, maps, view_projection)
            # Then what blends (alphaMode BLEND) over both, back to front (glTF 2.0 section 3.9.4).
            # (The fused MSAA resolve, background=False, is used only for scenes with none.)
            if scene.view != "probe" and scene.mesh is not None:
                self._draw_mesh(scene, maps, camera, view_projection, blend=True, image_size=(view.width, view.height))
        ctx.disable(moderngl.DEPTH_TEST)
        if display_output is None and background:
            self._finish_radiance(targets)
        self._display_output = None
        self._half_output = False
        self._impostor_model = None

    def _prepare_shadows(self, scene: Scene, maps: IBLMaps | None) -> bool:
        """The shadow maps for ``scene``, drawn where out of date (alight.render.shadows);
        whether this pass reads them. The casters: every part but those that blend."""
        ground = scene.ground and scene.view != "probe" and scene.mesh is not None and bool(scene.mesh.parts)
        if scene.view == "probe" or scene.mesh is None or not self.shadow_maps.wanted(scene, maps, receivers=ground):
            self.shadow_maps.last_active = False
            return False
        gpu_parts = [g for g, part in zip(self._gpu_mesh(scene.mesh), scene.mesh.parts)
                     if not (part.material is not None and scene.use_file_materials and part.material.alpha_mode == "BLEND")]

        def draw_parts(matrix: bytes, parts) -> None:
            prog = self.program("render/shadow_depth.vert", "render/shadow_depth.frag")
            prog["u_view_projection"].write(matrix)
            for gpu_part in parts:
                gpu_part.vao_for(prog).render(moderngl.TRIANGLES)

        bounds = GroundPass.ground_for(scene.mesh).bounds if ground else None
        return self.shadow_maps.prepare(scene, maps, gpu_parts, draw_parts, bounds)

    def _draw_ground(self, scene: Scene, maps: IBLMaps | None, view_projection: np.ndarray) -> None:
        """Scene.ground's shadow catcher (alight.render.ground) into the bound framebuffer, after
        the surfaces (and the background, where a pass draws one). Only where shadows are drawn:
        a ground without them takes nothing from the background."""
        if not (scene.ground and self._shadowed and scene.mesh is not None):
            return
        if self._ground_pass is None:
            self._ground_pass = GroundPass(self.ctx)
        prog = self._scene_program("render/ground.vert", "render/ground.frag",
                                   {**_light_defines(scene), "HAS_SHADOWS": None})
        self._bind_ibl(prog, scene, maps)
        self.shadow_maps.bind(prog, UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH)
        self._ground_pass.draw(prog, GroundPass.ground_for(scene.mesh), view_projection)

    def _surface_rect(self, scene: Scene, view_projection: np.ndarray,
                      size: tuple[int, int]) -> tuple[int, int, int, int] | None:
        """(x, y, width, height) in pixels of ``size`` holding every pixel the mesh can cover:
        the projected corners of its parts' bounding boxes, a pixel wider each way. None: the
        whole image (the probe view, or a box reaching behind the eye)."""
        if scene.view == "probe":
            return None
        if scene.mesh is None:
            return (0, 0, 0, 0)
        parts = self._gpu_mesh(scene.mesh)
        if not parts:
            return (0, 0, 0, 0)
        lo = np.min([p.lo for p in parts], axis=0)
        hi = np.max([p.hi for p in parts], axis=0)
        if scene.ground and self._shadowed:     # the ground's square is drawn too (_draw_ground)
            g = GroundPass.ground_for(scene.mesh)
            lo = np.minimum(lo, g.centre - (g.half_size, 0.0, g.half_size))
            hi = np.maximum(hi, g.centre + (g.half_size, 0.0, g.half_size))
        corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        clip = corners @ np.asarray(view_projection, np.float64)
        if (clip[:, 3] <= 1e-6).any():
            return None
        pixels = (clip[:, :2] / clip[:, 3:] * 0.5 + 0.5) * np.array(size, np.float64)
        x0, y0 = np.clip(np.floor(pixels.min(axis=0)) - 1, 0, size).astype(int)
        x1, y1 = np.clip(np.ceil(pixels.max(axis=0)) + 1, 0, size).astype(int)
        return (int(x0), int(y0), int(max(x1 - x0, 0)), int(max(y1 - y0, 0)))

    def camera_for(self, scene: Scene, aspect: float) -> Camera:
        if scene.camera is not None:
            return scene.camera
        if scene.mesh is None:
            return Camera()
        return default_camera(scene.mesh, aspect)   # a built-in from its 3/4 view (Mesh.view)

    @staticmethod
    def _ibl_defines(scene: Scene) -> dict:
        """The shader defines that pick the scene's IBL model (app/core/ibl_models.py)."""
        defines = {"IBL_MODEL": int(glsl_member(IblModel, scene.ibl_model))}
        if scene.multiple_scattering:
            defines["MULTIPLE_SCATTERING"] = None
        return defines

    # The maps that cannot change a roughness (MATERIAL_MAPS bits): any other map compiled in keeps
    # the prefiltered lookup's path below the grid (ibl.glsl IBL_BELOW_GRID).
    _ROUGHNESS_FREE_MAPS = {"base_color", "normal", "emissive", "occlusion", "metallic", "specular", "specular_color"}

    def _below_grid_defines(self, scene: Scene, maps: IBLMaps | None, materials, map_mask: int = 0) -> dict:
        """``{"IBL_BELOW_GRID": 0}`` when no roughness the pass can shade lies below the prefiltered
        grid's first step: the materials' roughness (and their coat's) is at or above it, no
        compiled-in map can lower one, and no layer or IBL model reads the maps at a roughness of
        its own. Else nothing: the shader keeps the fade into the source cube (ibl.glsl)."""
        if maps is None or not scene.ibl_enabled:
            return {}
        unsafe = {name for i, name in enumerate(MATERIAL_MAPS) if map_mask & (1 << i)} - self._ROUGHNESS_FREE_MAPS
        if unsafe or map_mask >> len(MATERIAL_MAPS):
            return {}
        first_step = grid_roughness(0, maps.quality.prefiltered_levels)
        if scene.ibl_model == "stretched":
            return {}   # its fetches' roughness is the material's times a fitted factor below 1
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

    def _scene_program(self, vertex: str, fragment: str, defines: dict | None = None) -> moderngl.Program:
        """A scene pass's program: with DISPLAY_OUTPUT and the display's uniforms while
        ``draw_display`` runs (common/output_encoding.glsl)."""
        display = self._display_output
        if display is None:
            if self._half_output:
                defines = {**(defines or {}), "HALF_FLOAT_OUTPUT": None}
            return self.program(vertex, fragment, defines)
        defines = {**(defines or {}), "DISPLAY_OUTPUT": None, "TONEMAP_MODE": int(glsl_member(Tonemap, display.tonemap))}
        if self._srgb_by_framebuffer:
            defines["SRGB_BY_FRAMEBUFFER"] = None
        prog = self.program(vertex, fragment, defines)
        _set(prog, "u_exposure_scale", float(2.0 ** display.exposure))
        return prog

    def _bind_ibl(self, program: moderngl.Program, scene: Scene, maps: IBLMaps | None) -> None:
        enabled = bool(scene.ibl_enabled and maps is not None)
        _set(program, "u_ibl_enabled", enabled)
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
            ratio_a, ratio_b = self.anisotropy_lut.textures()
            ratio_a.use(UNIT_ANISOTROPY_RATIO_A)
            ratio_b.use(UNIT_ANISOTROPY_RATIO_B)
        if "u_stretched_lobe_a" in program:
            lobe_a, lobe_b = self.stretched_lobe_textures()
            lobe_a.use(UNIT_STRETCHED_LOBE_A)
            lobe_b.use(UNIT_STRETCHED_LOBE_B)
        _set(program, "u_prefiltered_max_mip", maps.prefiltered_max_mip)
        _set(program, "u_env_rotation", _rotation_cos_sin(scene.env_rotation_deg))
        _set(program, "u_env_intensity", float(scene.env_intensity))
        self._write_suns(program, scene, maps)

    def stretched_lobe_textures(self) -> tuple[moderngl.Texture, moderngl.Texture]:
        """The `stretched` model's lobe table (alight.core.stretched_lobe) as two RGBA32F textures,
        linear filtering clamped at the edges (texel centres are the fitted cells)."""
        if self._stretched_lobe is None:
            from alight.core.stretched_lobe import lobe_table

            textures = []
            for part in lobe_table():
                tex = self.ctx.texture((part.shape[1], part.shape[0]), 4, np.ascontiguousarray(part).tobytes(), dtype="f4")
                tex.repeat_x = tex.repeat_y = False
                tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
                textures.append(tex)
            self._stretched_lobe = (textures[0], textures[1])
        return self._stretched_lobe

    @staticmethod
    def _write_suns(program: moderngl.Program, scene: Scene, maps: IBLMaps) -> None:
        """The compact sources the bake left out of the maps, in world space (ibl.glsl adds them)."""
        suns = maps.suns[:MAX_SUNS]
        directions = np.zeros((MAX_SUNS, 3), np.float32)
        powers = np.zeros((MAX_SUNS, 3), np.float32)
        spreads = np.zeros(MAX_SUNS, np.float32)
        for i, sun in enumerate(suns):
            spreads[i] = sun.spread
            # The map texel in direction m lights world direction R_y(+deg) m (docs/conventions.md).
            directions[i] = rotate_world_to_map(sun.direction, -scene.env_rotation_deg)
            powers[i] = np.asarray(sun.power) * scene.env_intensity
        scale = np.zeros(MAX_GRID_STEPS, np.float32)
        scale[:len(maps.sun_prefilter_scale)] = maps.sun_prefilter_scale[:MAX_GRID_STEPS]
        _set(program, "u_sun_count", len(suns))
        _set(program, "u_sun_direction", directions.tobytes(), write=True)
        _set(program, "u_sun_power", powers.tobytes(), write=True)
        _set(program, "u_sun_spread", spreads.tobytes(), write=True)
        _set(program, "u_sun_prefilter_scale", scale.tobytes(), write=True)

    def _write_lights(self, scene: Scene) -> None:
        """punctual.glsl's Lights block: vector and type, radiance, count, spot direction, and
        the spot's cone scale and offset with the range (KHR_lights_punctual's recommended
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
        data = (vectors.tobytes() + radiance.tobytes() + np.array([len(lights), 0, 0, 0], np.int32).tobytes()
                + spots.tobytes() + cones.tobytes())
        if data != self._lights_bytes:  # unchanged lights cost no upload
            self._lights_ubo.write(data)
            self._lights_bytes = data
        self._lights_ubo.bind_to_uniform_block(0)

    @staticmethod
    def _background_mode(scene: Scene, maps: IBLMaps | None) -> BackgroundMode:
        """common/background.glsl's BACKGROUND_MODE for the scene: an environment background without
        an environment draws nothing."""
        mode = glsl_member(BackgroundMode, scene.display.background)
        if mode in (BackgroundMode.ENV, BackgroundMode.BLUR) and maps is None:
            return BackgroundMode.TRANSPARENT
        return mode

    @staticmethod
    def _bind_background(prog: moderngl.Program, scene: Scene, maps: IBLMaps | None, inverse_vp: np.ndarray,
                         mode: int) -> None:
        """common/background.glsl's inputs."""
        if mode == BackgroundMode.COLOR:
            prog["u_color"] = tuple(scene.display.background_color)
        elif mode in (BackgroundMode.ENV, BackgroundMode.BLUR):
            maps.environment.use(UNIT_ENVIRONMENT)
            maps.prefiltered_radiance.use(UNIT_PREFILTERED)
            # Grid A's mip for the blur roughness (half the grid step; see bake.grid_roughness).
            levels = maps.quality.prefiltered_levels
            _set(prog, "u_blur_mip", float(max(0.0, roughness_to_grid_step(scene.display.blur_roughness, levels) / 2)))
            _set(prog, "u_inverse_view_projection", inverse_vp.tobytes(), write=True)
            _set(prog, "u_env_rotation", _rotation_cos_sin(scene.env_rotation_deg))
            _set(prog, "u_env_intensity", float(scene.env_intensity))

    def _draw_background(self, scene: Scene, maps: IBLMaps | None, inverse_vp: np.ndarray,
                         ring: np.ndarray | None = None) -> None:
        """The background pass: a full-screen triangle, or ``ring``'s triangles ((n, 2) NDC
        points, sphere_lod.impostor_background_ring) where the impostor fills the rest."""
        mode = self._background_mode(scene, maps)
        if mode == BackgroundMode.TRANSPARENT:
            return
        defines = {"BACKGROUND_MODE": int(mode)}
        if ring is not None:
            defines["BACKGROUND_RING"] = None
        prog = self._scene_program("render/background.vert", "render/background.frag", defines)
        self._bind_background(prog, scene, maps, inverse_vp, mode)
        if ring is None:
            self._fullscreen(prog)
            return
        if self._ring_buffer is None:
            self._ring_buffer = self.ctx.buffer(reserve=ring.nbytes)
        self._ring_buffer.write(ring.tobytes())
        vao = self._fullscreen_vaos.get((id(prog), "ring"))
        if vao is None:
            vao = self._fullscreen_vaos[(id(prog), "ring")] = self.ctx.vertex_array(prog, [(self._ring_buffer, "2f", "in_ndc")])
        vao.render(moderngl.TRIANGLES, vertices=len(ring))

    def _resolve(self, scene: Scene, maps: IBLMaps | None, targets: _Targets, radiance: bool, display: bool) -> None:
        """render/resolve.frag: the multisampled surfaces resolved, the background under them, into
        the radiance and/or the display image (at least one is written, so a frame is complete)."""
        radiance = radiance or not display
        mode = self._background_mode(scene, maps)
        # After the sphere's impostor the surfaces are in the single-sample stand-in, resolved already.
        single = self._impostor_samples == 4
        defines = {"BACKGROUND_MODE": int(mode), "SCENE_SAMPLES": 1 if single else targets.samples}
        scene_texture = targets.single()[0] if single else targets.color
        if radiance:
            defines["RADIANCE_OUTPUT"] = None
        if display:
            defines["DISPLAY_OUTPUT"] = 1 if radiance else 0
            defines["TONEMAP_MODE"] = int(glsl_member(Tonemap, scene.display.tonemap))
        w, h = targets.width, targets.height
        rect = self._surface_rect(*self._last_surface_rect_args)
        if rect is None or rect == (0, 0, w, h):
            passes = [(defines, None)]
        else:
            # Outside the mesh's rectangle no sample was drawn: the background alone, without
            # reading the samples (NO_SURFACES), in up to four strips around it; then the
            # resolve inside it. Every pixel is written once.
            x, y, rw, rh = rect
            strips = [(0, 0, w, y), (0, y + rh, w, h - y - rh), (0, y, x, rh), (x + rw, y, w - x - rw, rh)]
            passes = [({**defines, "NO_SURFACES": None}, strip) for strip in strips if strip[2] > 0 and strip[3] > 0]
            if rw > 0 and rh > 0:
                passes.append((defines, rect))
        targets.resolve_fbo(radiance, display).use()
        self.ctx.viewport = (0, 0, w, h)
        try:
            for pass_defines, scissor in passes:
                prog = self.program("render/background.vert", "render/resolve.frag", pass_defines)
                # The rays of the scene pass just drawn (for a tile, the whole image's projection off centre).
                self._bind_background(prog, scene, maps, self._last_inverse_vp, mode)
                scene_texture.use(UNIT_RADIANCE)
                _set(prog, "u_scene", UNIT_RADIANCE)
                _set(prog, "u_exposure_scale", float(2.0 ** scene.display.exposure))
                _set(prog, "u_opaque", scene.display.background != "transparent")
                self.ctx.scissor = scissor
                self._fullscreen(prog)
        finally:
            self.ctx.scissor = None

    def _draw_probe(self, scene: Scene, maps: IBLMaps | None, size: int, origin: tuple[int, int] = (0, 0)) -> None:
        defines = {**self._ibl_defines(scene), **self._below_grid_defines(scene, maps, [scene.material]),
                   **layer_defines([scene.material])}
        prog = self.program("render/fullscreen.vert", "render/probe.frag", defines)
        m = scene.material
        prog["u_size"] = float(size)
        _set(prog, "u_pixel_origin", tuple(float(x) for x in origin))
        _set_material(prog, m)
        self._bind_layer_luts(defines)
        self._bind_ibl(prog, scene, maps)
        self._fullscreen(prog)

    def _draw_mesh(self, scene: Scene, maps: IBLMaps | None, camera: Camera, view_projection: np.ndarray,
                   blend: bool = False, targets: _Targets | None = None, fbo: moderngl.Framebuffer | None = None,
                   pixels_per_radian: float = 1.0, image_size: tuple[int, int] | None = None) -> None:
        """The parts that blend (``blend``) or the rest, each with its shader variant: the
        scene's IBL model and debug view, plus only the features the part uses (_part_defines).
        The rest is drawn as the module docstring says: the opaque parts, then, where any part
        transmits, a copy of what they left in ``fbo`` and the transmissive parts reading it
        (TRANSMISSION_SCENE; ``pixels_per_radian``: the image's rows per radian at its centre,
        for the copy's blur)."""
        defines = self._ibl_defines(scene)
        defines.update(_light_defines(scene))
        user_maps = self._user_maps_present(scene)
        parts = list(zip(self._gpu_mesh(scene.mesh), scene.mesh.parts))
        any_maps = 0
        for gpu_part, part in parts:
            any_maps |= self._part_defines(scene, gpu_part, part, user_maps)["MATERIAL_MAPS_MASK"]
        defines.update(self._below_grid_defines(scene, maps, [self._part_material(scene, part)[0] for _, part in parts],
                                                any_maps))
        if scene.debug_view:
            defines["DEBUG_VIEW"] = None
        if self._shadowed:
            defines["HAS_SHADOWS"] = None
        bound: set[int] = set()

        def program_for(part_defines: dict) -> moderngl.Program:
            all_defines = {**defines, **part_defines}
            prog = self._scene_program("render/pbr.vert", "render/pbr.frag", all_defines)
            if id(prog) not in bound:
                bound.add(id(prog))
                if scene.debug_view:
                    _set(prog, "u_debug_view", int(scene.debug_view))
                    _set(prog, "u_debug_mip", float(scene.debug_mip))
                self._bind_ibl(prog, scene, maps)
                if self._shadowed:
                    self.shadow_maps.bind(prog, UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH)
            self._bind_layer_luts(all_defines)
            return prog

        if blend:
            self.draw_mesh_parts(scene, program_for, camera, view_projection, blend=True, image_size=image_size)
            return
        transmissive = self.transmissive_parts(scene)
        opaque = [i for i in range(len(scene.mesh.parts)) if i not in transmissive]
        if opaque:
            self.draw_mesh_parts(scene, program_for, camera, view_projection, blend=False, parts=opaque,
                                 image_size=image_size)
        if not transmissive:
            return
        behind, behind_fbo = targets.behind()
        self.ctx.copy_framebuffer(behind_fbo, fbo)   # the MSAA resolve too, where there is one
        behind.build_mipmaps()
        fbo.use()
        behind.use(UNIT_SCENE_BEHIND)
        if not (scene.ibl_enabled and maps is not None):
            # The thin-walled lobe's energy is the BRDF LUT's A, which _bind_ibl binds only with
            # an environment.
            q = QUALITY["medium"]
            self.luts.get(q.lut_size, q.lut_samples).use(UNIT_LUT)

        def transmissive_program(part_defines: dict) -> moderngl.Program:
            prog = program_for({**part_defines, "TRANSMISSION_SCENE": None})
            _set(prog, "u_behind_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
            _set(prog, "u_behind_pixels_per_radian", float(pixels_per_radian))
            return prog

        self.draw_mesh_parts(scene, transmissive_program, camera, view_projection, blend=False, parts=transmissive,
                             image_size=image_size)

    def _bind_layer_luts(self, defines: dict) -> None:
        """The tables a compiled-in layer reads (the sheen LUT, the transmission LUT), baked on
        first use."""
        if "HAS_SHEEN" in defines:
            self.luts.sheen().use(UNIT_SHEEN_LUT)
        if "HAS_VOLUME" in defines:
            self.transmission_lut().use(UNIT_TRANSMISSION_LUT)

    def layer_defines(self, scene: Scene, parts: list[int] | None = None) -> dict:
        """The HAS_* defines of the layers any part of the scene's mesh (or those of ``parts``,
        indices) is drawn with (alight.core.layers): a scene without layers compiles none."""
        if scene.mesh is None:
            return layer_defines([scene.material])
        chosen = range(len(scene.mesh.parts)) if parts is None else parts
        return layer_defines(self._part_material(scene, scene.mesh.parts[i])[0] for i in chosen)

    def transmissive_parts(self, scene: Scene) -> list[int]:
        """Indices of the mesh's parts whose material transmits (KHR_materials_transmission)."""
        if scene.view == "probe" or scene.mesh is None:
            return []
        # A part that blends (alphaMode BLEND) is drawn in the blended pass, over the background,
        # and transmits the environment only.
        return [i for i, part in enumerate(scene.mesh.parts)
                if "transmission" in self._part_material(scene, part)[0].layers()
                and not (part.material is not None and scene.use_file_materials and part.material.alpha_mode == "BLEND")]

    @staticmethod
    def _user_maps_present(scene: Scene) -> set[str]:
        user = scene.texture_maps.paths() if scene.texture_maps is not None else {}
        return {name for name, path in user.items() if path in scene.texture_images}

    @staticmethod
    def _part_defines(scene: Scene, gpu_part: _GpuPart, part, user_maps: set[str]) -> dict:
        """The shader variant a part needs (pbr.frag, mesh_material.glsl): the maps it reads, their
        uv sets, transforms and mirrored axes, vertex colours, alpha mode, unlit and the layers
        its material uses. A part with none of these compiles to the plain opaque shader."""
        fm = part.material
        file_material = fm is not None and scene.use_file_materials
        defines: dict = {}
        if file_material:
            present = set(gpu_part.textures)
            masks = {"MAP_UV1_MASK": 0, "MAP_TRANSFORM_MASK": 0, "MAP_MIRROR_S_MASK": 0, "MAP_MIRROR_T_MASK": 0}
            for name, info in gpu_part.infos.items():
                bit = map_bit(name)
                if info.tex_coord == 1 and gpu_part.has_uv1:
                    masks["MAP_UV1_MASK"] |= bit
                if info.transform is not None:
                    masks["MAP_TRANSFORM_MASK"] |= bit
                if info.sampler.wrap_s == "mirrored_repeat":
                    masks["MAP_MIRROR_S_MASK"] |= bit
                if info.sampler.wrap_t == "mirrored_repeat":
                    masks["MAP_MIRROR_T_MASK"] |= bit
            defines.update({k: v for k, v in masks.items() if v})
            if masks["MAP_UV1_MASK"]:
                defines["HAS_UV1"] = None
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
        defines["MATERIAL_MAPS_MASK"] = map_mask(present & set(MATERIAL_MAPS))
        # The layers this part's material uses, and only those (alight.core.layers).
        defines.update(layer_defines([ForwardRenderer._part_material(scene, part)[0]]))
        return defines

    def draw_mesh_parts(self, scene: Scene, prog, camera: Camera, view_projection: np.ndarray,
                        blend: bool | None = None, parts: list[int] | None = None,
                        image_size: tuple[int, int] | None = None) -> None:
        """Draw the scene's mesh parts (pbr.vert's transforms, seen from ``camera``), each with
        its material's factors and maps bound.

        ``prog``: one program for every part (the reference's G-buffer), or a function from a
        part's defines (``_part_defines``) to its program. ``blend``: None draws every part;
        False the parts that do not blend; True those that do (alphaMode BLEND), sorted back to
        front by the distance of their centres, with blending on and depth writes off. ``parts``:
        only these (indices into the mesh's parts), within what ``blend`` selects.
        Culling follows the material (glTF doubleSided: false culls back faces); a part without
        a glTF material is culled where it is closed, seen from both sides where it is open.
        ``image_size``: the whole image's (width, height) in pixels (default: the viewport's),
        which picks the built-in sphere's level (``_drawn_parts``).
        """
        ctx = self.ctx
        user_maps = self._user_maps_present(scene)
        user = self._user_textures(scene)
        tiling = scene.texture_maps or TextureMaps()
        items = []
        size = image_size or tuple(ctx.viewport[2:])
        # The built-in sphere as an impostor (_sphere_impostor, decided once per scene pass in
        # _draw_scene), by forward programs only; else its level or the mesh as given.
        proxy_model = self._impostor_model if callable(prog) and self._impostor_samples else None
        self.last_sphere_impostor = None
        model = np.eye(4, dtype=np.float32)
        if proxy_model is None:
            drawn, sphere_radius = self._drawn_parts(scene.mesh, camera, size)
        else:
            self.last_sphere_segments = None
            drawn = [self._impostor_proxy(scene.mesh)]
            sphere_radius = scene.mesh.lod_sphere[0]
            model = np.ascontiguousarray(proxy_model.T, dtype=np.float32)   # GLSL reads columns
            self.last_sphere_impostor = self._impostor_samples
        if callable(prog) and sphere_radius is None and proxy_model is None:
            drawn = self._occluded_parts(scene, drawn)
        chosen = None if parts is None else set(parts)
        for index, (gpu_part, part) in enumerate(zip(drawn, scene.mesh.parts)):
            fm = part.material
            blends = fm is not None and scene.use_file_materials and fm.alpha_mode == "BLEND"
            if (blend is None or blends == blend) and (chosen is None or index in chosen):
                items.append((gpu_part, part))
        if not items:
            return
        if blend:
            eye = np.asarray(camera.position, np.float64)
            items.sort(key=lambda item: -float(np.linalg.norm(item[0].centre - eye)))
            ctx.enable(moderngl.BLEND)
            # Straight alpha over what is behind; coverage accumulates in alpha (premultiplied).
            ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)
            ctx.depth_mask = False
        prepared: set[int] = set()
        try:
            for gpu_part, part in items:
                if callable(prog):
                    part_defines = self._part_defines(scene, gpu_part, part, user_maps)
                    if sphere_radius is not None:
                        part_defines["SPHERE_SURFACE"] = None
                    if proxy_model is not None:
                        part_defines["SPHERE_IMPOSTOR"] = self._impostor_samples
                    program = prog(part_defines)
                else:
                    program = prog
                if id(program) not in prepared:
                    prepared.add(id(program))
                    _set(program, "u_model", model.tobytes(), write=True)
                    _set(program, "u_normal_matrix", np.eye(3, dtype=np.float32).tobytes(), write=True)
                    _set(program, "u_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
                    _set(program, "u_camera_position", tuple(float(x) for x in camera.position))
                    _set(program, "u_sphere_radius", float(sphere_radius or 0.0))
                    if proxy_model is not None:   # (_draw_scene's inverse of this pass's view_projection)
                        _set(program, "u_inverse_view_projection", self._last_inverse_vp.tobytes(), write=True)
                        _set(program, "u_viewport_size", tuple(float(x) for x in ctx.viewport[2:]))
                material, maps_used = self._part_material(scene, part)
                _set_material(program, material)
                fm = part.material if maps_used else None
                _set(program, "u_normal_scale", float(fm.normal_scale) if fm else 1.0)
                _set(program, "u_clearcoat_normal_scale", float(fm.clearcoat_normal_scale) if fm else 1.0)
                _set(program, "u_occlusion_strength", float(fm.occlusion_strength) if fm else 1.0)
                _set(program, "u_alpha", float(fm.alpha) if fm else 1.0)
                _set(program, "u_alpha_cutoff", float(fm.alpha_cutoff) if fm else 0.5)
                _set(program, "u_specular_factor", float(fm.specular_factor) if fm else 1.0)
                _set(program, "u_specular_f90", float(fm.specular_f90) if fm else 1.0)
                _set(program, "u_specular_color_f0", tuple(float(x) for x in fm.specular_color_f0) if fm
                     else tuple(float(x) for x in material.specular_f0))
                # A file's maps use its own UVs as they are; the user's maps are tiled.
                _set(program, "u_uv_scale", (1.0, 1.0) if maps_used else tuple(map(float, tiling.uv_scale)))
                _set(program, "u_uv_offset", (0.0, 0.0) if maps_used else tuple(map(float, tiling.uv_offset)))
                if maps_used and any(info.transform is not None for info in gpu_part.infos.values()):
                    transforms = np.tile(np.eye(3, dtype=np.float32), (len(MATERIAL_MAPS), 1, 1))
                    for name, info in gpu_part.infos.items():
                        if info.transform is not None:
                            transforms[MATERIAL_MAPS.index(name)] = info.transform.gl_matrix()
                    member = program.get("u_map_transform", None)
                    if member is not None:
                        # GLSL mat3 is column-major: upload the transposes. The compiler trims the
                        # array after the last slot the variant reads.
                        used = transforms.transpose(0, 2, 1)[:member.array_length]
                        member.write(np.ascontiguousarray(used, dtype=np.float32).tobytes())
                bound_maps = []
                for name in MATERIAL_MAPS:
                    tex = gpu_part.textures.get(name) if maps_used else user.get(name)
                    _set(program, f"u_has_{name}_map", tex is not None)
                    if tex is not None:
                        tex.use(UNIT_MATERIAL[name])
                        if tex.filter[0] in _ANISOTROPIC_FILTERS and tex.filter[1] != moderngl.NEAREST:
                            bound_maps.append(tex)   # (a sampler's nearest magnification keeps 1: _MeshTextures)
                if bound_maps:
                    # Anisotropic filtering where this view gains from it (alight.core.texture_footprint),
                    # not everywhere: on llvmpipe 8x costs a textured frame 2-5x. Measured on
                    # TEXCOORD_0 as the file gives it (not a TEXCOORD_1 map's uvs, nor the user
                    # maps' tiling).
                    finest = max((t.size for t in bound_maps), key=lambda wh: wh[0] * wh[1])
                    if scene.mesh is not None and scene.mesh.lod_sphere is not None:
                        # The built-in sphere: its stand-ins (the impostor's proxy, coarser levels)
                        # have other uvs than the ball they stand for, so all take the full level.
                        level = 8.0
                    else:
                        level = gpu_part.anisotropy(camera.view_projection(size[0] / size[1]), size, finest)
                    self.last_anisotropy[part.name] = level
                    for tex in bound_maps:
                        if tex.anisotropy != level:
                            tex.anisotropy = level
                if part.element.startswith("meshes["):
                    # A glTF primitive: the file decides (the default material is single-sided).
                    cull = not (part.material is not None and part.material.double_sided)
                else:
                    # A closed mesh's back faces are hidden: culling them halves the triangles
                    # rasterised and stops back faces drawn first from being shaded and then
                    # overwritten (35% of the ball's cost on llvmpipe). Open meshes are seen from
                    # behind (the shader flips n).
                    cull = gpu_part.closed
                if cull:
                    ctx.front_face = "ccw"
                    ctx.enable(moderngl.CULL_FACE)
                else:
                    ctx.disable(moderngl.CULL_FACE)
                gpu_part.vao_for(program).render(moderngl.TRIANGLES)
        finally:
            ctx.disable(moderngl.CULL_FACE)
            if blend:
                ctx.disable(moderngl.BLEND)
                ctx.depth_mask = True

    def _occluded_parts(self, scene: Scene, drawn: list[_GpuPart]) -> list[_GpuPart]:
        """The mesh's parts refined and baked with visibility where ``scene.occlusion`` wants
        them (alight.render.visibility_parts), else ``drawn``."""
        textures = self._meshes[id(scene.mesh)][2]
        return self.visibility_parts.parts_for(scene.mesh, scene.occlusion, drawn,
                                        lambda part: _GpuPart(self.ctx, part, textures))

    @staticmethod
    def _part_material(scene: Scene, part) -> tuple[Material, bool]:
        """The factors for a part, and whether its file's texture maps apply."""
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

    def _finish_radiance(self, targets: _Targets) -> None:
        if targets.aa == "msaa":
            self.ctx.copy_framebuffer(targets.radiance_fbo, targets.draw)  # the resolve
        elif targets.aa == "ssaa":
            prog = self.program("render/fullscreen.vert", "render/downsample.frag")
            targets.color.use(UNIT_RADIANCE)
            prog["u_factor"] = 2
            targets.radiance_fbo.use()
            self.ctx.viewport = (0, 0, targets.width, targets.height)
            self._fullscreen(prog)

    def tonemap(self, radiance: moderngl.Texture, display: Display, fbo: moderngl.Framebuffer,
                opaque: bool = True) -> None:
        prog = self.program("render/fullscreen.vert", "render/tonemap.frag",
                            {"TONEMAP_MODE": int(glsl_member(Tonemap, display.tonemap))})
        radiance.use(UNIT_RADIANCE)
        prog["u_exposure_scale"] = float(2.0 ** display.exposure)
        prog["u_opaque"] = opaque
        fbo.use()
        self.ctx.viewport = (0, 0) + fbo.size
        self._fullscreen(prog)

    def _fullscreen(self, prog: moderngl.Program) -> None:
        vao = self._fullscreen_vaos.get(id(prog))
        if vao is None:
            vao = self._fullscreen_vaos[id(prog)] = self.ctx.vertex_array(prog, [])
        vao.render(moderngl.TRIANGLES, vertices=3)


# The impostor's proxy polygon as homogeneous points (rows), for _sphere_impostor's clipping check.
_PROXY_POINTS = np.hstack([impostor_proxy_polygon()[0], np.ones((len(impostor_proxy_polygon()[0]), 1))]).astype(np.float64)


def _light_defines(scene: Scene) -> dict:
    """punctual.glsl's PUNCTUAL_SPOT and PUNCTUAL_RANGE, only for scenes that have such lights."""
    lights = scene.lights[:MAX_LIGHTS]
    defines: dict = {}
    if any(light.kind == "spot" for light in lights):
        defines["PUNCTUAL_SPOT"] = None
    if any(light.range is not None and light.kind != "directional" for light in lights):
        defines["PUNCTUAL_RANGE"] = None
    return defines


def _release_mesh(entry) -> None:
    for part in entry[1]:
        part.release()
    entry[2].release()


def _read(fbo: moderngl.Framebuffer, tile: Tile, dtype: str, np_dtype) -> np.ndarray:
    """The tile's pixels from the bottom-left of ``fbo``, rows top first (a view, not a copy)."""
    data = fbo.read(viewport=(0, 0, tile.width, tile.height), components=4, dtype=dtype)
    return np.frombuffer(data, np_dtype).reshape(tile.height, tile.width, 4)[::-1]


def _rotation_cos_sin(deg: float) -> tuple[float, float]:
    t = math.radians(-deg)
    return (math.cos(t), math.sin(t))


def _set(prog: moderngl.Program, name: str, value, write: bool = False) -> None:
    """Set a uniform if the compiler kept it (unused uniforms are optimised away)."""
    member = prog.get(name, None)
    if member is None:
        return
    if write:
        member.write(value)
    else:
        member.value = value


def _set_material(prog: moderngl.Program, m: Material) -> None:
    _set(prog, "u_base_color", tuple(float(x) for x in m.base_color))
    _set(prog, "u_metallic", float(m.metallic))
    _set(prog, "u_roughness", float(m.roughness))
    _set(prog, "u_specular_f0", tuple(float(x) for x in m.specular_f0))
    _set(prog, "u_emissive", tuple(float(x) for x in m.emissive))
    # The layers' factors (common/material_layers.glsl); a layer not compiled in has no uniform.
    _set(prog, "u_clearcoat", float(m.clearcoat))
    _set(prog, "u_clearcoat_roughness", float(m.clearcoat_roughness))
    _set(prog, "u_sheen_color", tuple(float(x) for x in m.sheen_color))
    _set(prog, "u_sheen_roughness", float(m.sheen_roughness))
    _set(prog, "u_anisotropy_strength", float(m.anisotropy_strength))
    _set(prog, "u_anisotropy_rotation", float(m.anisotropy_rotation))
    _set(prog, "u_transmission", float(m.transmission))
    _set(prog, "u_ior", float(m.ior))
    _set(prog, "u_thickness", float(m.thickness))
    _set(prog, "u_attenuation_color", tuple(float(x) for x in m.attenuation_color))
    _set(prog, "u_attenuation_distance", float(min(m.attenuation_distance, 3.0e38)))
    _set(prog, "u_dispersion", float(m.dispersion))
    _set(prog, "u_diffuse_transmission", float(m.diffuse_transmission))
    _set(prog, "u_diffuse_transmission_color", tuple(float(x) for x in m.diffuse_transmission_color))
