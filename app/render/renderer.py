"""Draws a Scene into framebuffers with the forward PBR pass. Knows nothing of any UI.

    forward pass (mesh, or the probe view) -> background pass -> [MSAA resolve | SSAA reduce]
        -> linear radiance (EXR, tests) -> tone map pass -> sRGB (PNG, the editor)

A mesh with transmissive parts (KHR_materials_transmission) is drawn in passes, in this order:

    opaque parts -> copy (what is behind: radiance and coverage, mipmapped) -> transmissive
        parts (reading the copy, common/transmission.glsl) -> background -> [blended parts]

so that what the glass shows is the opaque scene behind it, as the Khronos Sample Viewer does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary, create_headless_context
from alight.core.ibl_models import SUNS_AS_BAKED, ibl_model_index
from alight.core.layers import layer_defines
from alight.core.material import Material, with_overrides
from alight.core.mesh import is_closed
from alight.core.scene import (
    TONEMAPS,
    Camera,
    Display,
    Scene,
    frame_camera,
)
from alight.core.shading import rotate_world_to_map
from alight.core.texture_maps import TextureMaps
from alight.ibl.bake import (
    QUALITY,
    BakeQuality,
    IBLMaps,
    LutCache,
    bake_environment,
    bake_steps,
    roughness_to_grid_step,
)
from alight.ibl.sun import MAX_SUNS
from alight.ibl.transmission_lut import TransmissionLut

GL_SRGB8_ALPHA8 = 0x8C43
AA_MODES = ("none", "msaa", "ssaa")
MAX_LIGHTS = 16   # punctual.glsl's MAX_LIGHTS
MAX_GRID_STEPS = 32  # ibl.glsl's MAX_GRID_STEPS: prefiltered roughness steps (2 levels - 1)

# Texture units, fixed so that binding one map never disturbs another.
UNIT_IRRADIANCE, UNIT_PREFILTERED, UNIT_PREFILTERED_MID, UNIT_LUT, UNIT_ENVIRONMENT, UNIT_RADIANCE = range(6)
MATERIAL_MAPS = ("base_color", "metallic_roughness", "normal", "emissive", "occlusion", "metallic", "roughness",
                 "clearcoat", "clearcoat_roughness", "clearcoat_normal", "sheen_color", "sheen_roughness")
UNIT_MATERIAL = {name: 6 + i for i, name in enumerate(MATERIAL_MAPS)}
UNIT_SHEEN_LUT = 6 + len(MATERIAL_MAPS)   # the sheen LUT (common/sheen.glsl), bound with HAS_SHEEN
UNIT_TRANSMISSION_LUT = UNIT_SHEEN_LUT + 1          # ibl/transmission_lut.comp's table (HAS_VOLUME)
UNIT_SCENE_BEHIND = UNIT_TRANSMISSION_LUT + 1      # the opaque parts' copy (TRANSMISSION_SCENE)
SRGB_MAPS = ("base_color", "emissive", "sheen_color")
# Every sampler gets its own unit: samplers left at the default unit 0 with different types
# (samplerCube and sampler2D) make every draw call fail with GL_INVALID_OPERATION.
SAMPLER_UNITS = {
    "u_irradiance": UNIT_IRRADIANCE, "u_prefiltered_radiance": UNIT_PREFILTERED,
    "u_prefiltered_radiance_mid": UNIT_PREFILTERED_MID, "u_brdf_lut": UNIT_LUT,
    "u_environment": UNIT_ENVIRONMENT, "u_radiance": UNIT_RADIANCE, "u_radiance_source": UNIT_RADIANCE,
    **{f"u_{name}_map": unit for name, unit in UNIT_MATERIAL.items()},
    "u_sheen_lut": UNIT_SHEEN_LUT, "u_transmission_lut": UNIT_TRANSMISSION_LUT, "u_scene_behind": UNIT_SCENE_BEHIND,
}


@dataclass
class Frame:
    """One rendered image: linear radiance (float32 RGBA) and its display encoding (uint8 sRGB),
    both with row 0 at the top. Alpha is 1 where a surface was hit."""

    linear: np.ndarray
    srgb: np.ndarray


class _GpuPart:
    """A mesh part's buffers and textures, uploaded once."""

    def __init__(self, ctx: moderngl.Context, program: moderngl.Program, part):
        vertices = np.hstack([part.positions, part.normals, part.uvs, part.tangents]).astype(np.float32)
        self.vbo = ctx.buffer(np.ascontiguousarray(vertices).tobytes())
        self.ibo = ctx.buffer(np.ascontiguousarray(part.indices, dtype=np.uint32).tobytes())
        self.ctx = ctx
        # A vertex array belongs to one program: one per program this part is drawn with (the
        # shaded pass, a debug view), made on first use.
        self._vaos: dict[int, moderngl.VertexArray] = {}
        self.textures: dict[str, moderngl.Texture] = {}
        self.closed = is_closed(part.positions, part.indices)
        fm = part.material
        if fm is not None:
            for name in MATERIAL_MAPS:
                image = getattr(fm, f"{name}_texture", None)
                if image is not None:
                    self.textures[name] = _upload_image(ctx, image, srgb=name in SRGB_MAPS)

    def vao_for(self, program: moderngl.Program) -> moderngl.VertexArray:
        vao = self._vaos.get(id(program))
        if vao is None:
            vao = self._vaos[id(program)] = self.ctx.vertex_array(
                program, [(self.vbo, "3f 3f 2f 4f", "in_position", "in_normal", "in_uv", "in_tangent")],
                self.ibo, index_element_size=4,
                skip_errors=True)  # a debug view may not read every attribute
        return vao

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self.vbo.release()
        self.ibo.release()
        for tex in self.textures.values():
            tex.release()


def _upload_image(ctx: moderngl.Context, image: np.ndarray, srgb: bool) -> moderngl.Texture:
    """An RGBA uint8 image (alight.core.mesh gives RGBA) as a mipmapped texture."""
    image = np.asarray(image, dtype=np.uint8)
    if image.shape[2] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
    # Images arrive top row first; texture coordinate v = 0 is the bottom row (OpenGL, trimesh).
    data = np.ascontiguousarray(image[::-1, :, :4])
    h, w = data.shape[:2]
    tex = ctx.texture((w, h), 4, data.tobytes(), internal_format=GL_SRGB8_ALPHA8 if srgb else None)
    tex.build_mipmaps()
    tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    tex.anisotropy = 8.0
    return tex


class _Targets:
    """Framebuffers for one output size and anti-aliasing mode, kept between frames."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int, aa: str, samples: int):
        self.ctx = ctx
        self.width, self.height, self.aa, self.samples = width, height, aa, samples
        # Linear radiance at the output size: drawn into directly without anti-aliasing, else the
        # MSAA resolve or the SSAA reduction lands here.
        self.radiance = ctx.texture((width, height), 4, dtype="f4")
        self.radiance.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.radiance_fbo = ctx.framebuffer([self.radiance])
        scale = 2 if aa == "ssaa" else 1
        self.draw_size = (width * scale, height * scale)
        ms = samples if aa == "msaa" else 0
        if aa == "msaa":
            self.color = ctx.renderbuffer(self.draw_size, 4, samples=ms, dtype="f4")
        elif aa == "ssaa":
            self.color = ctx.texture(self.draw_size, 4, dtype="f4")
        else:
            self.color = self.radiance
        self.depth = ctx.depth_renderbuffer(self.draw_size, samples=ms)
        self.draw = ctx.framebuffer([self.color], self.depth)
        self.display = ctx.texture((width, height), 4, dtype="f1")
        self.display_fbo = ctx.framebuffer([self.display])
        self._display_draw = None
        self._behind: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None

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

    def display_draw(self) -> moderngl.Framebuffer:
        """The display image with the depth buffer, for ForwardRenderer.draw_display (no AA only)."""
        if self._display_draw is None:
            self._display_draw = self.ctx.framebuffer([self.display], self.depth)
        return self._display_draw

    def release(self) -> None:
        owned = [self.draw, self.depth, self.radiance_fbo, self.radiance, self.display_fbo, self.display]
        if self._display_draw is not None:
            owned.insert(0, self._display_draw)
        if self.color is not self.radiance:
            owned.append(self.color)
        if self._behind is not None:
            owned.extend(self._behind[::-1])
        for obj in owned:
            obj.release()


class ForwardRenderer:
    """Owns a GL context's programs, uploaded meshes, bakes and targets.

    ``with ForwardRenderer() as r:`` releases everything on exit. Bakes are cached per environment
    content and quality, so rendering many materials under one environment bakes once.
    """

    def __init__(self, ctx: moderngl.Context | None = None, shaders: ShaderLibrary | None = None):
        self.ctx = ctx or create_headless_context()
        self.shaders = shaders or ShaderLibrary(self.ctx)
        self.luts = LutCache(self.ctx, self.shaders)
        self._transmission_lut: TransmissionLut | None = None
        self._bakes: dict[tuple, IBLMaps] = {}
        self._meshes: dict[int, tuple[object, list[_GpuPart]]] = {}
        self._targets: _Targets | None = None
        self._lights_ubo = self.ctx.buffer(reserve=MAX_LIGHTS * 32 + 16)
        self._lights_bytes = b""
        self._fullscreen_vaos: dict[int, moderngl.VertexArray] = {}
        self._units_assigned: set[int] = set()
        self._display_output: Display | None = None   # set while draw_display runs
        # User-loaded texture maps (Scene.texture_maps): (path, sRGB) -> (image, texture),
        # uploaded once per decoded image.
        self._map_textures: dict[tuple[str, bool], tuple[np.ndarray, moderngl.Texture]] = {}

    # --- resources -----------------------------------------------------------------------

    def bake(self, env, quality: BakeQuality | str = "medium") -> IBLMaps:
        q = QUALITY[quality] if isinstance(quality, str) else quality
        key = (env.content_hash, q)
        if key not in self._bakes:
            self._bakes[key] = bake_environment(self.ctx, self.shaders, env, q, self.luts)
        return self._bakes[key]

    def bake_steps(self, env, quality: BakeQuality | str = "medium"):
        """``bake`` in steps (alight.ibl.bake.bake_steps): yields (fraction, label) between GPU passes
        and returns the maps, cached as ``bake`` caches them (a cached bake yields nothing)."""
        q = QUALITY[quality] if isinstance(quality, str) else quality
        key = (env.content_hash, q)
        if key not in self._bakes:
            maps = yield from bake_steps(self.ctx, self.shaders, env, q, self.luts)
            self._bakes[key] = maps
        return self._bakes[key]

    def _gpu_mesh(self, mesh, program) -> list[_GpuPart]:
        entry = self._meshes.get(id(mesh))
        if entry is None or entry[0] is not mesh:
            entry = (mesh, [_GpuPart(self.ctx, program, part) for part in mesh.parts])
            self._meshes[id(mesh)] = entry
        return entry[1]

    def _targets_for(self, width: int, height: int, aa: str, samples: int) -> _Targets:
        t = self._targets
        if t is None or (t.width, t.height, t.aa, t.samples) != (width, height, aa, samples):
            if t is not None:
                t.release()
            self._targets = _Targets(self.ctx, width, height, aa, samples)
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
        for _, parts in self._meshes.values():
            for part in parts:
                part.release()
        self._meshes.clear()
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
        for _, parts in self._meshes.values():
            for part in parts:
                part.release()
        self._meshes.clear()
        if self._targets:
            self._targets.release()
            self._targets = None
        self.luts.release()
        if self._transmission_lut is not None:
            self._transmission_lut.release()
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
               aa: str = "msaa", samples: int = 4, read_linear: bool = True, read_srgb: bool = True) -> Frame:
        """Draw ``scene`` lit by ``maps`` (None: no environment) and read the results back."""
        if scene.view == "probe":
            aa = "none"  # the probe view's normals are exact per pixel centre: no blending
        targets = self._targets_for(width, height, aa, samples)
        self.draw_hdr(scene, maps, targets)
        self.tonemap(targets.radiance, scene.display, targets.display_fbo, opaque=scene.display.background != "transparent")
        linear = srgb = None
        if read_linear:
            linear = np.frombuffer(targets.radiance_fbo.read(components=4, dtype="f4"), np.float32)
            linear = linear.reshape(height, width, 4)[::-1].copy()
            if scene.view == "probe":
                linear[linear[:, :, 3] == 0.0] = 0.0  # CONVENTIONS.md: probe background radiance is 0
        if read_srgb:
            srgb = np.frombuffer(targets.display_fbo.read(components=4, dtype="f1"), np.uint8)
            srgb = srgb.reshape(height, width, 4)[::-1].copy()
        return Frame(linear, srgb)

    def draw_hdr(self, scene: Scene, maps: IBLMaps | None, targets: _Targets) -> None:
        self._draw_scene(scene, maps, targets, targets.draw)

    def draw_display(self, scene: Scene, maps: IBLMaps | None, targets: _Targets) -> None:
        """What ``draw_hdr`` then ``tonemap`` (opaque) leave in ``targets.display``, in one pass:
        the scene's programs tone map as they write (common/output_encoding.glsl), so neither the
        float image nor the tone map pass is needed (the editor's view). Without anti-aliasing
        only: a resolve must average radiance, not display values."""
        if targets.aa != "none" or scene.view == "probe" or self.transmissive_parts(scene):
            # (transmissive parts read the opaque parts' radiance, which must not be tone mapped)
            self.draw_hdr(scene, maps, targets)
            self.tonemap(targets.radiance, scene.display, targets.display_fbo)
            return
        self._draw_scene(scene, maps, targets, targets.display_draw(), scene.display)

    def _draw_scene(self, scene: Scene, maps: IBLMaps | None, targets: _Targets, fbo: moderngl.Framebuffer,
                    display_output: Display | None = None) -> None:
        ctx = self.ctx
        self._display_output = display_output
        width, height = targets.draw_size
        fbo.use()
        ctx.viewport = (0, 0, width, height)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        aspect = width / height
        # The probe's own camera is orthographic; its backdrop is drawn as the default camera sees it.
        camera = Camera() if scene.view == "probe" else self.camera_for(scene, aspect)
        view_projection = camera.view_projection(aspect)
        inverse_vp = np.linalg.inv(view_projection).astype(np.float32)
        self._write_lights(scene)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        if scene.view == "probe":
            self._draw_probe(scene, maps, width)
        elif scene.mesh is not None:
            self._draw_mesh(scene, maps, camera, view_projection, targets, fbo)
        # After the surfaces: the depth test keeps the background's shading off covered pixels.
        self._draw_background(scene, maps, inverse_vp)
        ctx.disable(moderngl.DEPTH_TEST)
        if display_output is None:
            self._finish_radiance(targets)
        self._display_output = None

    def camera_for(self, scene: Scene, aspect: float) -> Camera:
        if scene.camera is not None:
            return scene.camera
        if scene.mesh is None:
            return Camera()
        center, radius = scene.mesh.bounding_sphere()
        return frame_camera(center, max(radius, 1e-6), aspect=aspect)

    @staticmethod
    def _ibl_defines(scene: Scene) -> dict:
        """The shader defines that pick the scene's IBL model (app/core/ibl_models.py)."""
        defines = {"IBL_MODEL": ibl_model_index(scene.ibl_model)}
        if scene.multiple_scattering:
            defines["MULTIPLE_SCATTERING"] = None
        return defines

    def _scene_program(self, vertex: str, fragment: str, defines: dict | None = None) -> moderngl.Program:
        """A scene pass's program: with DISPLAY_OUTPUT and the display's uniforms while
        ``draw_display`` runs (common/output_encoding.glsl)."""
        display = self._display_output
        if display is None:
            return self.program(vertex, fragment, defines)
        prog = self.program(vertex, fragment, {**(defines or {}), "DISPLAY_OUTPUT": None})
        _set(prog, "u_exposure_scale", float(2.0 ** display.exposure))
        _set(prog, "u_tonemap", TONEMAPS.index(display.tonemap))
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
        _set(program, "u_prefiltered_max_mip", maps.prefiltered_max_mip)
        _set(program, "u_env_rotation", _rotation_cos_sin(scene.env_rotation_deg))
        _set(program, "u_env_intensity", float(scene.env_intensity))
        self._write_suns(program, scene, maps)

    @staticmethod
    def _write_suns(program: moderngl.Program, scene: Scene, maps: IBLMaps) -> None:
        """The compact sources the bake left out of the maps, in world space (ibl.glsl adds them)."""
        suns = maps.suns[:MAX_SUNS]
        directions = np.zeros((MAX_SUNS, 3), np.float32)
        powers = np.zeros((MAX_SUNS, 3), np.float32)
        spreads = np.zeros(MAX_SUNS, np.float32)
        for i, sun in enumerate(suns):
            spreads[i] = sun.spread
            # The map texel in direction m lights world direction R_y(+deg) m (CONVENTIONS.md).
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
        vectors = np.zeros((MAX_LIGHTS, 4), np.float32)
        radiance = np.zeros((MAX_LIGHTS, 4), np.float32)
        lights = scene.lights[:MAX_LIGHTS]
        for i, light in enumerate(lights):
            vectors[i, :3] = light.vector
            vectors[i, 3] = 0.0 if light.kind == "point" else 1.0
            radiance[i, :3] = np.asarray(light.color, np.float32) * light.intensity
        data = vectors.tobytes() + radiance.tobytes() + np.array([len(lights), 0, 0, 0], np.int32).tobytes()
        if data != self._lights_bytes:  # unchanged lights cost no upload
            self._lights_ubo.write(data)
            self._lights_bytes = data
        self._lights_ubo.bind_to_uniform_block(0)

    def _draw_background(self, scene: Scene, maps: IBLMaps | None, inverse_vp: np.ndarray) -> None:
        mode = scene.display.background
        if mode == "transparent" or (mode in ("env", "blur") and maps is None):
            return
        prog = self._scene_program("render/background.vert", "render/background.frag",
                                   {"BACKGROUND_MODE": {"env": 0, "blur": 1, "color": 2}[mode]})
        if mode == "color":
            prog["u_color"] = tuple(scene.display.background_color)
        else:
            maps.environment.use(UNIT_ENVIRONMENT)
            maps.prefiltered_radiance.use(UNIT_PREFILTERED)
            # Grid A's mip for the blur roughness (half the grid step; see bake.grid_roughness).
            levels = maps.quality.prefiltered_levels
            _set(prog, "u_blur_mip", float(max(0.0, roughness_to_grid_step(scene.display.blur_roughness, levels) / 2)))
            _set(prog, "u_inverse_view_projection", inverse_vp.tobytes(), write=True)
            _set(prog, "u_env_rotation", _rotation_cos_sin(scene.env_rotation_deg))
            _set(prog, "u_env_intensity", float(scene.env_intensity))
        self._fullscreen(prog)

    def _draw_probe(self, scene: Scene, maps: IBLMaps | None, size: int) -> None:
        defines = {**self._ibl_defines(scene), **layer_defines([scene.material])}
        prog = self.program("render/fullscreen.vert", "render/probe.frag", defines)
        m = scene.material
        prog["u_size"] = float(size)
        _set_material(prog, m)
        self._bind_layer_luts(defines)
        self._bind_ibl(prog, scene, maps)
        self._fullscreen(prog)

    def _draw_mesh(self, scene: Scene, maps: IBLMaps | None, camera: Camera, view_projection: np.ndarray,
                   targets: _Targets, fbo: moderngl.Framebuffer) -> None:
        """The mesh's parts: opaque ones, then (where any part transmits) a copy of what they
        left in ``fbo`` and the transmissive parts reading it (the module docstring's order).
        Each pass compiles only its own parts' layers."""
        transmissive = self.transmissive_parts(scene)
        opaque = [i for i in range(len(scene.mesh.parts)) if i not in transmissive]
        if opaque:
            prog = self._mesh_program(scene, maps, opaque)
            self.draw_mesh_parts(scene, prog, camera, view_projection, opaque)
        if not transmissive:
            return
        behind, behind_fbo = targets.behind()
        self.ctx.copy_framebuffer(behind_fbo, fbo)   # the MSAA resolve too, where there is one
        behind.build_mipmaps()
        fbo.use()
        prog = self._mesh_program(scene, maps, transmissive, {"TRANSMISSION_SCENE": None})
        behind.use(UNIT_SCENE_BEHIND)
        if not (scene.ibl_enabled and maps is not None):
            # The thin-walled lobe's energy is the BRDF LUT's A, which _bind_ibl bound only with
            # an environment.
            q = QUALITY["medium"]
            self.luts.get(q.lut_size, q.lut_samples).use(UNIT_LUT)
        _set(prog, "u_behind_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
        half_fov = math.radians(camera.fov_y_deg) / 2.0
        _set(prog, "u_behind_pixels_per_radian", float(targets.draw_size[1] / 2.0 / math.tan(half_fov)))
        self.draw_mesh_parts(scene, prog, camera, view_projection, transmissive)

    def _mesh_program(self, scene: Scene, maps: IBLMaps | None, parts: list[int],
                      extra_defines: dict | None = None) -> moderngl.Program:
        """pbr.frag compiled for ``parts``: the scene's IBL model and maps, those parts' layers."""
        # A debug view (the editor's) is a separate compile, so the normal path pays nothing.
        defines = self._ibl_defines(scene)
        defines["MATERIAL_MAPS_MASK"] = self._map_mask(scene)
        defines.update(self.layer_defines(scene, parts))
        defines.update(extra_defines or {})
        if scene.debug_view:
            defines["DEBUG_VIEW"] = None
        prog = self._scene_program("render/pbr.vert", "render/pbr.frag", defines)
        if scene.debug_view:
            _set(prog, "u_debug_view", int(scene.debug_view))
            _set(prog, "u_debug_mip", float(scene.debug_mip))
        self._bind_ibl(prog, scene, maps)
        self._bind_layer_luts(defines)
        return prog

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
        return [i for i, part in enumerate(scene.mesh.parts)
                if "transmission" in self._part_material(scene, part)[0].layers()]

    def _map_mask(self, scene: Scene) -> int:
        """mesh_material.glsl's MATERIAL_MAPS_MASK: a bit per map any part is drawn with."""
        user = scene.texture_maps.paths() if scene.texture_maps is not None else {}
        used = {name for name, path in user.items() if path in scene.texture_images}
        for gpu_part, part in zip(self._gpu_mesh(scene.mesh, None), scene.mesh.parts):
            if part.material is not None and scene.use_file_materials:
                used.update(gpu_part.textures)
        return sum(1 << i for i, name in enumerate(MATERIAL_MAPS) if name in used)

    def draw_mesh_parts(self, scene: Scene, prog: moderngl.Program, camera: Camera,
                        view_projection: np.ndarray, parts: list[int] | None = None) -> None:
        """Draw every part of the scene's mesh (or those of ``parts``, indices) with ``prog``
        (pbr.vert's transforms, seen from ``camera``): each part's material factors and maps
        bound, back faces culled where the part is closed."""
        ctx = self.ctx
        _set(prog, "u_model", np.eye(4, dtype=np.float32).tobytes(), write=True)
        _set(prog, "u_normal_matrix", np.eye(3, dtype=np.float32).tobytes(), write=True)
        _set(prog, "u_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
        _set(prog, "u_camera_position", tuple(float(x) for x in camera.position))
        user = self._user_textures(scene)
        tiling = scene.texture_maps or TextureMaps()
        chosen = None if parts is None else set(parts)
        for index, (gpu_part, part) in enumerate(zip(self._gpu_mesh(scene.mesh, prog), scene.mesh.parts)):
            if chosen is not None and index not in chosen:
                continue
            material, maps_used = self._part_material(scene, part)
            _set_material(prog, material)
            fm = part.material if maps_used else None
            _set(prog, "u_normal_scale", float(getattr(fm, "normal_scale", 1.0)) if fm else 1.0)
            _set(prog, "u_clearcoat_normal_scale", float(getattr(fm, "clearcoat_normal_scale", 1.0)) if fm else 1.0)
            _set(prog, "u_occlusion_strength", float(getattr(fm, "occlusion_strength", 1.0)) if fm else 1.0)
            # A file's maps use its own UVs as they are; the user's maps are tiled.
            _set(prog, "u_uv_scale", (1.0, 1.0) if maps_used else tuple(map(float, tiling.uv_scale)))
            _set(prog, "u_uv_offset", (0.0, 0.0) if maps_used else tuple(map(float, tiling.uv_offset)))
            for name in MATERIAL_MAPS:
                tex = gpu_part.textures.get(name) if maps_used else user.get(name)
                _set(prog, f"u_has_{name}_map", tex is not None)
                if tex is not None:
                    tex.use(UNIT_MATERIAL[name])
            # A closed mesh's back faces are hidden: culling them halves the triangles rasterised
            # and stops back faces drawn first from being shaded and then overwritten (35% of
            # the ball's cost on llvmpipe). Open meshes are seen from behind (the shader flips n).
            if gpu_part.closed:
                ctx.front_face = "ccw"
                ctx.enable(moderngl.CULL_FACE)
            else:
                ctx.disable(moderngl.CULL_FACE)
            gpu_part.vao_for(prog).render(moderngl.TRIANGLES)
        ctx.disable(moderngl.CULL_FACE)

    @staticmethod
    def _part_material(scene: Scene, part) -> tuple[Material, bool]:
        """The factors for a part, and whether its file's texture maps apply."""
        fm = part.material
        if fm is None or not scene.use_file_materials:
            return scene.material, False
        base = Material(base_color=tuple(fm.base_color), metallic=float(fm.metallic),
                        roughness=float(fm.roughness), specular_f0=scene.material.specular_f0,
                        ior=scene.material.ior, emissive=tuple(fm.emissive), name=part.name)
        layers = getattr(fm, "layers", None)
        if layers:   # the file's own layer fields and ior (alight.exchange.gltf_material)
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
        prog = self.program("render/fullscreen.vert", "render/tonemap.frag")
        radiance.use(UNIT_RADIANCE)
        prog["u_exposure_scale"] = float(2.0 ** display.exposure)
        prog["u_tonemap"] = TONEMAPS.index(display.tonemap)
        prog["u_opaque"] = opaque
        fbo.use()
        self.ctx.viewport = (0, 0) + fbo.size
        self._fullscreen(prog)

    def _fullscreen(self, prog: moderngl.Program) -> None:
        vao = self._fullscreen_vaos.get(id(prog))
        if vao is None:
            vao = self._fullscreen_vaos[id(prog)] = self.ctx.vertex_array(prog, [])
        vao.render(moderngl.TRIANGLES, vertices=3)


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
