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

The renderer is a facade over modules with one job each: alight.render.targets (framebuffers,
tile sizes), gpu_mesh (meshes, textures, full-screen draws), variants (which shader variant a
part and scene compile), bindings (texture units, uniforms, the lights block, lookup tables),
sphere_impostor (the built-in sphere's stand-ins), passes (the passes above, top to bottom),
with shadows, ground, tiles and visibility_parts beside them.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary, create_headless_context
from alight.core.material import Material
from alight.core.scene import Camera, Display, Scene, default_camera
from alight.core.sphere_lod import MAX_SILHOUETTE_ERROR_PX
from alight.ibl.bake import QUALITY, BakeQuality, IBLMaps, bake_steps, run_to_completion
from alight.ibl.bake_cache import BakeCache, load_bake, save_bake
from alight.render import passes, variants
from alight.render.bindings import UNIT_SCRATCH, LightsBlock, LookupTables, assign_units
from alight.render.gpu_mesh import FullscreenDraws, GpuMeshes, GpuPart
from alight.render.ground import GroundPass
from alight.render.passes import FrameContext
from alight.render.shadows import ShadowMaps
from alight.render.targets import HALF_FLOAT_MAX, HALF_FLOAT_MIN_EXPOSURE, Targets, tiled_targets
from alight.render.tiles import TILE_BYTES, TilePlan
from alight.render.visibility_parts import OcclusionParts

__all__ = ["AA_MODES", "ForwardRenderer", "Frame", "GL_FRAMEBUFFER_SRGB", "HALF_FLOAT_MAX",
           "HALF_FLOAT_MIN_EXPOSURE", "Strip"]

GL_FRAMEBUFFER_SRGB = 0x8DB9
AA_MODES = ("none", "msaa", "ssaa")


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


class ForwardRenderer:
    """Owns a GL context's programs, uploaded meshes, bakes and targets.

    ``with ForwardRenderer() as r:`` releases everything on exit. Bakes are cached per environment
    content and quality, in memory and in ``bake_cache`` (alight.ibl.bake_cache: on disk, shared
    by every process; None keeps them in memory only), so rendering many materials under one
    environment bakes once, and so does every later process. ``bakes_run`` counts the bakes
    that ran, ``bakes_loaded`` those read from the disk cache.
    """

    #: the most bytes one tile's framebuffers may take (alight.render.tiles); larger images are
    #: drawn in tiles. A class attribute so that a test (or a caller short of GPU memory) lowers it.
    tile_bytes: int = TILE_BYTES
    #: how many bakes stay in memory (None: all). The editor, visiting environment after
    #: environment, bounds it; the API and batch keep every bake, since callers hold their maps.
    max_bakes: int | None = None

    def __init__(self, ctx: moderngl.Context | None = None, shaders: ShaderLibrary | None = None,
                 bake_cache: BakeCache | None | str = "default"):
        # A renderer that makes its own context makes it current where it starts work: every
        # ForwardRenderer() is an EGL context of its own, and creating one makes it current, so
        # an older renderer's calls would go to the newer one's context (other programs under the
        # same names: GL_INVALID_OPERATION and black maps). A context given is the caller's to manage.
        self._owns_context = ctx is None
        self.ctx = ctx or create_headless_context()
        self.ctx.default_texture_unit = UNIT_SCRATCH   # (alight.render.bindings: off every unit a pass binds)
        self.shaders = shaders or ShaderLibrary(self.ctx)
        self.tables = LookupTables(self.ctx, self.shaders)   # LUTs and lobe tables (alight.render.bindings)
        self.luts = self.tables.luts
        self.anisotropy_lut = self.tables.anisotropy_lut
        self.bake_cache = BakeCache() if bake_cache == "default" else bake_cache
        self.bakes_run = 0
        self.bakes_loaded = 0
        self.meshes = GpuMeshes(self.ctx, self.shaders)   # uploaded meshes and maps (alight.render.gpu_mesh)
        self.draws = FullscreenDraws(self.ctx)
        self.lights = LightsBlock(self.ctx)    # punctual.glsl's Lights block
        # Meshes drawn with the visibility bake (Scene.occlusion; alight.render.visibility_parts).
        self.visibility_parts = OcclusionParts(self.ctx, self.bake_cache)
        self.screen_ao = None     # alight.render.screen_ao.ScreenAO, made by the first frame with --occlusion gtao
        # draw_hdr/draw_display refine screen-space GTAO over frames of an unchanged view (the
        # editor; ``refining`` says whether another frame would), where a still takes its passes at once.
        self.screen_ao_temporal = False
        self.last_occlusion_reason = ""   # "gtao ..." where the last scene pass drew screen-space GTAO
        # Why the last scene pass's ground caught nothing ('' where it caught a shadow or there was
        # none): "shadows off" or "no light"; a front end says it in its own words (the CLI's
        # warning names its flags, the editor's status row its controls).
        self.last_ground_idle = ""
        self.shadow_maps = ShadowMaps(self.ctx)   # drawn where a scene can be shadowed (alight.render.shadows)
        self.ground_pass: GroundPass | None = None   # Scene.ground's square, made on first use
        # How far the built-in sphere's outline may fall inside the true one, in output pixels
        # (alight.core.sphere_lod); 0 draws the sphere's own tessellation.
        self.sphere_max_error_px = MAX_SILHOUETTE_ERROR_PX
        # The built-in sphere drawn as an impostor where it can be (alight.render.sphere_impostor);
        # False draws its tessellation in every pass (the tests compare the two).
        self.sphere_impostor = True
        # With the impostor and one sample a pixel, the background drawn around a hole the impostor
        # fills, without a depth buffer (passes.draw_scene); False: depth-tested after it (tests compare).
        self.background_ring = True
        # How mesh files are shaded under 4x MSAA (alight.render.vbuffer MESH_SHADING): "forward"
        # once per triangle covering a pixel's samples, "vbuffer" from a visibility buffer, each
        # 2x2 block once per visible triangle in it, where the scene allows it; "auto" (the
        # default) the visibility buffer only where the mesh is dense on screen (vbuffer.dense:
        # fewer covered pixels per triangle than vbuffer.auto_threshold, which grows with the
        # pixel's cost), where it is faster.
        self.mesh_shading = "auto"
        # How the user named mesh_shading, for the one warning a render gives where "vbuffer" was
        # asked for and the forward pass drew (passes.note_mesh_shading; the CLI: --mesh-shading).
        self.mesh_shading_option = "mesh_shading"
        # What the last passes drew, for tests and benchmarks: the sphere's level, whether the
        # background's ring was drawn, the impostor's coverage samples (or None), and per
        # textured part's name the anisotropic filtering level.
        self.last_sphere_segments: int | None = None
        self.last_background_ring = False
        self.last_sphere_impostor: int | None = None
        self.last_anisotropy: dict[str, float] = {}
        self.last_vbuffer = False   # whether the last scene pass (a render: its every tile) shaded its mesh from the visibility buffer
        # ... and why (vbuffer.choose): why the forward pass where it drew, a phrase
        self.last_mesh_shading_reason = ""
        self._bakes: dict[tuple, IBLMaps] = {}
        self._targets: Targets | None = None
        self._units_assigned: set[int] = set()

    # --- resources -----------------------------------------------------------------------

    def make_current(self) -> None:
        """Make this renderer's own context current (the entry points do); a context given to the
        constructor is left to its owner."""
        if self._owns_context:
            self.ctx.__enter__()    # eglMakeCurrent; the same context again costs next to nothing

    def bake(self, env, quality: BakeQuality | str = "medium") -> IBLMaps:
        """The maps of ``env`` at ``quality`` (a name of QUALITY, or a BakeQuality): ``bake_steps``
        run to its end, kept in memory and in the disk cache."""
        return run_to_completion(self.bake_steps(env, quality))

    def bake_steps(self, env, quality: BakeQuality | str = "medium"):
        """``bake`` in steps (alight.ibl.bake.bake_steps): yields (fraction, label) between GPU passes
        and returns the maps, cached as ``bake`` caches them (a cached bake yields nothing, one
        on disk is loaded in the first step)."""
        self.make_current()
        q = QUALITY[quality] if isinstance(quality, str) else quality
        key = (env.content_hash, q)
        if key not in self._bakes:
            maps = self._load_bake(env, q)
            if maps is None:
                maps = yield from bake_steps(self.ctx, self.shaders, env, q, self.luts)
                self._keep_bake(env, maps)
            self._remember_bake(key, maps)
        return self._bakes[key]

    def _remember_bake(self, key: tuple, maps: IBLMaps) -> None:
        """Keep a bake in memory; beyond ``max_bakes`` the oldest leaves the GPU (its maps are
        released: a caller must not hold maps older than the last ``max_bakes`` bakes). It stays
        in the disk cache, so asking for it again loads it rather than baking."""
        self._bakes[key] = maps
        while self.max_bakes is not None and len(self._bakes) > max(1, self.max_bakes):
            oldest = next(iter(self._bakes))
            self._bakes.pop(oldest).release()

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

    def program(self, vertex: str, fragment: str, defines: dict | None = None) -> moderngl.Program:
        """The library's program, its samplers pointed at their units (alight.render.bindings)."""
        prog = self.shaders.program(vertex, fragment, defines)
        if id(prog) not in self._units_assigned:
            assign_units(prog)
            self._units_assigned.add(id(prog))
        return prog

    def use_shaders(self, shaders: ShaderLibrary) -> None:
        """Switch to a freshly compiled library (the editor's shader hot reload) and release the
        old one. Vertex arrays are tied to the program they were made with, so the mesh and
        full-screen VAOs are rebuilt on the next draw; the bakes stay valid."""
        old, self.shaders = self.shaders, shaders
        self.tables.use_shaders(shaders)
        self.draws.release_vaos()
        self._units_assigned.clear()
        self.meshes.use_shaders(shaders)
        old.reload()

    def transmission_lut(self) -> moderngl.Texture:
        """The transmission LUT (alight.ibl.transmission_lut), baked or read on first use."""
        return self.tables.transmission_lut()

    def stretched_lobe_textures(self) -> tuple[moderngl.Texture, moderngl.Texture]:
        """The `stretched` model's lobe table (alight.core.stretched_lobe) as two RGBA32F textures."""
        return self.tables.stretched_lobe_textures()

    def forget_map_textures(self, keep_paths) -> None:
        """Release the uploaded maps whose path is not in ``keep_paths``."""
        self.meshes.forget_map_textures(keep_paths)

    def release(self) -> None:
        """Release every GL object the renderer made, and its context if it made that too."""
        if self._owns_context and isinstance(self.ctx.mglo, moderngl.mgl.InvalidObject):
            return      # released already
        self.make_current()
        for maps in self._bakes.values():
            maps.release()
        self._bakes.clear()
        self.meshes.release()
        self.visibility_parts.release()
        if self.screen_ao is not None:
            self.screen_ao.release()
            self.screen_ao = None
        if self._targets:
            self._targets.release()
            self._targets = None
        self.shadow_maps.release()
        if self.ground_pass is not None:
            self.ground_pass.release()
            self.ground_pass = None
        if self.bake_cache is not None:
            self.bake_cache.close()
        self.tables.release()
        self.draws.release()
        self.shaders.reload()
        if self._owns_context:
            self.ctx.release()

    def __enter__(self) -> "ForwardRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

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
        one strip's pixels at a time. A size within the GL limits and ``tile_bytes`` is one strip."""
        self.make_current()
        if scene.view == "probe":
            aa = "none"  # the probe view's normals are exact per pixel centre: no blending
        if aa == "msaa":
            samples = min(samples, self.ctx.max_samples)
            if samples < 2:
                aa = "none"   # this GL has no multisampled float framebuffers
        # Half floats only where the fused resolve reads them and nothing but sRGB is read.
        # (Not with transmissive parts: their copy of the opaque parts keeps floats.)
        half = (aa == "msaa" and read_srgb and not read_linear and not variants.has_blending_parts(scene)
                and not variants.transmissive_parts(scene) and scene.display.exposure >= HALF_FLOAT_MIN_EXPOSURE)
        plan, targets = self._tiled_targets(width, height, aa, samples, tile, half)
        for y0, linear, srgb in passes.frame_strips(self, scene, maps, plan, targets, width, height, aa,
                                                    read_linear, read_srgb):
            yield Strip(y0, Frame(linear, srgb))
            self.make_current()     # the caller may have drawn with another renderer in between

    def _tiled_targets(self, width: int, height: int, aa: str, samples: int,
                       tile: tuple[int, int] | None, half: bool = False) -> tuple[TilePlan, Targets]:
        def forget() -> None:
            self._targets = None

        return tiled_targets(self.ctx, width, height, aa, samples, tile,
                             lambda w, h: self._targets_for(w, h, aa, samples, half), forget, self.tile_bytes)

    def _targets_for(self, width: int, height: int, aa: str, samples: int, half: bool = False) -> Targets:
        """The framebuffers for one tile, kept while the size and mode stay."""
        t = self._targets
        half = half and aa == "msaa"
        if t is None or (t.width, t.height, t.aa, t.samples, t.half) != (width, height, aa, samples, half):
            if t is not None:
                t.release()
            self._targets = Targets(self.ctx, width, height, aa, samples, half)
        return self._targets

    def draw_hdr(self, scene: Scene, maps: IBLMaps | None, targets: Targets) -> None:
        """The scene pass with its background into ``targets.radiance`` (linear, resolved)."""
        passes.draw_scene(self, scene, maps, targets, targets.draw)

    def draw_display(self, scene: Scene, maps: IBLMaps | None, targets: Targets,
                     into: moderngl.Framebuffer | None = None, into_encodes_srgb: bool = False) -> moderngl.Framebuffer:
        """What ``draw_hdr`` then ``tonemap`` (opaque) leave in ``targets.display``, in one pass:
        the scene's programs tone map as they write (common/output_encoding.glsl), so neither the
        float image nor the tone map pass is needed (the editor's view). Without anti-aliasing
        only: a resolve must average radiance, not display values; and without parts that blend,
        the ground, transmission or the probe (those go through radiance and the tone map pass).

        ``into``: a framebuffer with a depth buffer (the editor's window) to draw the one pass
        into instead of ``targets.display``, at its bottom-left, targets' size. Returns the
        framebuffer that holds the picture: ``into`` where the one pass could be used, else
        ``targets.display_fbo``.

        ``into_encodes_srgb``: ``into`` is sRGB-capable (EditorWindow probes its window), so the
        passes write tone-mapped linear values with GL_FRAMEBUFFER_SRGB on and the framebuffer's
        write stage applies the sRGB curve (GL 4.5 section 17.3.7). A GPU does that for free;
        llvmpipe's encoder is a polynomial, 2.1 ms cheaper than the shader's pow() on a
        860x720 frame, within 1 LSB of the exact curve (on the editor's ball a fifth of the values
        1 LSB off; tests/editor_window_checks.py bounds it)."""
        if targets.aa != "none" or scene.view == "probe" or variants.transmissive_parts(scene) or scene.ground \
                or variants.has_blending_parts(scene):
            # (transmissive parts read the opaque parts' radiance, which must not be tone mapped;
            # the ground darkens radiance, and blended parts blend radiance, before the tone map,
            # as every other anti-aliasing mode does: the one pass wrote them opaque)
            self.draw_hdr(scene, maps, targets)
            # A transparent background keeps the coverage as alpha, as the one pass below does
            # (the editor shows it over a checkerboard; opaque, MSAA's view was black there).
            self.tonemap(targets.radiance, scene.display, targets.display_fbo,
                         opaque=scene.display.background != "transparent")
            return targets.display_fbo
        fbo = into or targets.display_draw()
        srgb = into is not None and into_encodes_srgb
        if srgb:
            self.ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
        try:
            passes.draw_scene(self, scene, maps, targets, fbo, scene.display, srgb_by_framebuffer=srgb)
        finally:
            if srgb:
                self.ctx.disable_direct(GL_FRAMEBUFFER_SRGB)
        return into or targets.display_fbo

    def refining(self) -> bool:
        """Whether drawing the last frame's view again would refine it: screen-space GTAO's passes
        not all taken yet (``screen_ao_temporal``). An interactive loop draws until it is false."""
        return self.screen_ao is not None and self.screen_ao.refining and self.last_occlusion_reason.startswith("gtao")

    def draw_mesh_parts(self, scene: Scene, prog, camera: Camera, view_projection: np.ndarray,
                        blend: bool | None = None, parts: list[int] | None = None,
                        image_size: tuple[int, int] | None = None) -> None:
        """Draw the scene's mesh parts (pbr.vert's transforms, seen from ``camera``), each with
        its material's factors and maps bound.

        ``prog``: one program for every part (the reference's G-buffer), or a function from a
        part's defines (alight.render.variants.part_defines) to its program. ``blend``: None draws
        every part; False the parts that do not blend; True those that do (alphaMode BLEND),
        sorted back to front by the distance of their centres, with blending on and depth writes
        off. ``parts``: only these (indices into the mesh's parts), within what ``blend`` selects.
        Culling follows the material (glTF doubleSided: false culls back faces); a part without
        a glTF material is culled where it is closed, seen from both sides where it is open.
        ``image_size``: the whole image's (width, height) in pixels (default: the viewport's),
        which picks the built-in sphere's level (alight.render.sphere_impostor.lod_parts).
        """
        passes.draw_mesh_parts(self, FrameContext(), scene, prog, camera, view_projection, blend, parts, image_size)

    def tonemap(self, radiance: moderngl.Texture, display: Display, fbo: moderngl.Framebuffer,
                opaque: bool = True) -> None:
        """render/tonemap.frag: ``radiance`` exposed and tone mapped into ``fbo``."""
        passes.tonemap(self, radiance, display, fbo, opaque)

    def fullscreen(self, prog: moderngl.Program) -> None:
        """One full-screen triangle with ``prog`` into the bound framebuffer (render/fullscreen.vert)."""
        self.draws.triangle(prog)

    # --- what a scene draws ----------------------------------------------------------------

    def camera_for(self, scene: Scene, aspect: float) -> Camera:
        if scene.camera is not None:
            return scene.camera
        if scene.mesh is None:
            return Camera()
        return default_camera(scene.mesh, aspect)   # a built-in from its 3/4 view (Mesh.view)

    def layer_defines(self, scene: Scene, parts: list[int] | None = None) -> dict:
        """The HAS_* defines of the layers any part of the scene's mesh (or those of ``parts``,
        indices) is drawn with (alight.core.layers): a scene without layers compiles none."""
        return variants.scene_layer_defines(scene, parts)

    def transmissive_parts(self, scene: Scene) -> list[int]:
        """Indices of the mesh's parts whose material transmits (KHR_materials_transmission)."""
        return variants.transmissive_parts(scene)

    # Kept for the tests and benchmarks that reach in (the passes call _below_grid_defines
    # through the renderer, so that a test can replace it).
    def _below_grid_defines(self, scene: Scene, maps: IBLMaps | None, materials, map_mask: int = 0) -> dict:
        return variants.below_grid_defines(scene, maps, materials, map_mask)

    _has_blending_parts = staticmethod(variants.has_blending_parts)

    @staticmethod
    def _part_material(scene: Scene, part) -> tuple[Material, bool]:
        return variants.part_material(scene, part)

    def upload_step(self, upload) -> bool:
        """One step of a staged upload (``upload`` made off the GL thread by
        alight.render.mesh_upload.prepare_upload): a few MiB of its textures' levels, or once they
        are all written, the mesh's buffers. Returns True when ``upload.mesh`` is whole on the
        GPU, drawn from then on with no upload in its frame. For a front end that keeps drawing
        frames meanwhile (the editor); ``upload.drop()`` releases an upload left unfinished."""
        return upload.step(self.ctx, self.shaders, self.meshes, self.shadow_maps)

    def _gpu_mesh(self, mesh) -> list[GpuPart]:
        return self.meshes.parts(mesh)
