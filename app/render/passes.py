"""The passes of a frame, top to bottom (the module docstring of alight.render.renderer says
which run for which anti-aliasing mode and read-back): the scene pass (surfaces, background,
ground, blended parts), the mesh's draws, the MSAA resolve, the SSAA reduction, the tone map.

Each scene pass decides once what its draws share (the impostor, shadows, the output
encoding, its matrices) and hands it on in a FrameContext, which the resolve after it reads:
no draw depends on what an earlier call left in the renderer. ``r`` is the ForwardRenderer,
whose resources (programs, meshes, tables, targets) the passes use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from alight.core.mesh import single_sided
from alight.core.scene import Camera, Display
from alight.core.shader_names import BackgroundMode, Tonemap, glsl_member
from alight.core.sphere_lod import impostor_background_ring, impostor_hole_model
from alight.core.texture_maps import TextureMaps
from alight.errors import warn
from alight.ibl.bake import QUALITY, IBLMaps
from alight.render.bindings import (
    UNIT_LUT,
    UNIT_RADIANCE,
    UNIT_SCENE_BEHIND,
    UNIT_SHADOW_ATLAS,
    UNIT_SHADOW_DEPTH,
    bind_background,
    bind_ibl,
    set_material,
    set_uniform,
    sun_world_directions,
)
from alight.render.gpu_mesh import GpuPart
from alight.render import vbuffer
from alight.render.part_bindings import _bind_view, bind_part, set_culling
from alight.render.ground import GroundPass
from alight.render.shadows import casters as shadow_casters
from alight.render.visibility_parts import environment_texels, light_through, occluder_materials
from alight.render.sphere_impostor import impostor_placement, lod_parts, proxy_part
from alight.render.targets import Targets, View, read_tile
from alight.render.tiles import TilePlan, tile_matrix, tile_origin
from alight.render.variants import (
    alpha_to_coverage,
    background_mode,
    blends,
    has_blending_parts,
    ibl_defines,
    light_defines,
    material_defines,
    part_defines,
    part_material,
    stretched_span_defines,
    sun_defines,
    transmissive_parts,
    user_maps_present,
)


@dataclass
class FrameContext:
    """What one scene pass decided, for its draws and for the resolve after it."""

    display: Display | None = None     # DISPLAY_OUTPUT: tone mapped as drawn (draw_display)
    srgb_by_framebuffer: bool = False  # SRGB_BY_FRAMEBUFFER: the framebuffer encodes sRGB
    half_output: bool = False          # HALF_FLOAT_OUTPUT: into the half-float MSAA target
    # The built-in sphere's impostor (alight.render.sphere_impostor): the proxy's (4, 4)
    # placement or None, and its coverage samples: 1, 4 (into Targets.single, which the fused
    # resolve reads), 0 (a multisampled target: no impostor).
    impostor_model: np.ndarray | None = None
    impostor_samples: int = 1
    # The mesh shaded from the visibility buffer (alight.render.vbuffer) into Targets.single,
    # which the fused resolve reads.
    vbuffer: bool = False
    shadowed: bool = False             # the pass reads the shadow maps (alight.render.shadows)
    view_projection: np.ndarray | None = None   # the pass's (a tile's: the image's, off centre)
    inverse_vp: np.ndarray | None = None        # its inverse: the background's rays
    image_size: tuple[int, int] = (0, 0)        # the targets' output size (width, height)
    sun_directions: np.ndarray | None = None    # (K, 3) world: the compact sources (the bake's sun bounce)
    maps: IBLMaps | None = None                 # the environment drawn (the bake's visible sky weight)
    screen_ao: bool = False                     # the opaque parts read screen-space GTAO (alight.render.screen_ao)
    ao_pixel_scale: float = 0.0                 # pixels per world unit at clip w = 1, at the draw size
    still: bool = False                         # a still image (render_strips): GTAO takes all its passes now


# --- a frame: the passes for each anti-aliasing mode, tile by tile -------------------------

def frame_strips(r, scene, maps: IBLMaps | None, plan: TilePlan, targets: Targets, width: int, height: int,
                 aa: str, read_linear: bool, read_srgb: bool):
    """ForwardRenderer.render_strips's strips: each tile drawn with the passes its mode needs
    (alight.render.renderer's docstring) and read back; yields (y0, linear, srgb)."""
    opaque = scene.display.background != "transparent"
    blending = has_blending_parts(scene)
    strips = plan.strips()
    shading = []    # each tile's (r.last_vbuffer, r.last_mesh_shading_reason)

    def read_into(strip: np.ndarray | None, fbo, t, dtype: str, np_dtype) -> np.ndarray:
        """The strip with tile ``t`` of ``fbo`` read into it; a single tile is the image itself
        (copied: read_tile gives a read-only view of the read's bytes, rows reversed)."""
        block = read_tile(fbo, t, dtype, np_dtype)
        if plan.single:
            return block.copy()
        strip[:, t.x:t.x + t.width] = block
        return strip

    for number, tiles in enumerate(strips):
        rows = tiles[0].height
        linear = np.empty((rows, width, 4), np.float32) if read_linear and not plan.single else None
        srgb = np.empty((rows, width, 4), np.uint8) if read_srgb and not plan.single else None
        for t in tiles:
            view = None if plan.single else View(width, height, tile_matrix(plan, t), tile_origin(plan, t))
            # Only the images that are read are made.
            if aa == "msaa" and not blending:
                frame = draw_scene(r, scene, maps, targets, targets.draw, view=view, background=False, still=True)
                resolve(r, frame, scene, maps, targets, read_linear, read_srgb)
            elif aa == "none" and read_srgb and not read_linear and opaque and scene.view != "probe" \
                    and not scene.ground and not blending:
                # (the ground darkens radiance and blended parts blend radiance: before the tone map)
                draw_scene(r, scene, maps, targets, targets.display_draw(), scene.display, view=view, still=True)
            else:
                draw_scene(r, scene, maps, targets, targets.draw, view=view, still=True)
                if read_srgb:
                    tonemap(r, targets.radiance, scene.display, targets.display_fbo, opaque=opaque)
            shading.append((r.last_vbuffer, r.last_mesh_shading_reason))
            if read_linear:
                linear = read_into(linear, targets.radiance_fbo, t, "f4", np.float32)
            if read_srgb:
                srgb = read_into(srgb, targets.display_fbo, t, "f1", np.uint8)
        if linear is not None and scene.view == "probe":
            linear[linear[:, :, 3] == 0.0] = 0.0  # docs/conventions.md: probe background radiance is 0
        if number == len(strips) - 1:   # (before the last yield: a caller may stop there)
            note_mesh_shading(r, shading)
        yield tiles[0].y, linear, srgb


def note_mesh_shading(r, shading: list[tuple[bool, str]]) -> None:
    """A render's mesh shading from its tiles' (vbuffer?, reason): r.last_vbuffer where every
    tile took the visibility buffer, r.last_mesh_shading_reason the first forward tile's reason;
    and where ``r.mesh_shading`` asked for "vbuffer" and some tile was drawn by the forward pass,
    one warning line naming the reason (once per render, not per tile or pass)."""
    forward = [reason for used, reason in shading if not used]
    r.last_vbuffer = bool(shading) and not forward
    r.last_mesh_shading_reason = forward[0] if forward else (shading[0][1] if shading else "")
    if forward and getattr(r, "mesh_shading", "auto") == "vbuffer":
        some = "" if len(forward) == len(shading) else f"{len(forward)} of its {len(shading)} tiles "
        warn(f"{getattr(r, 'mesh_shading_option', 'mesh_shading')} vbuffer: {some}drawn with the forward pass "
             f"({forward[0]})")


# --- the scene pass ----------------------------------------------------------------------

def draw_scene(r, scene, maps: IBLMaps | None, targets: Targets, fbo: moderngl.Framebuffer,
               display: Display | None = None, view: View | None = None, background: bool = True,
               srgb_by_framebuffer: bool = False, still: bool = False) -> FrameContext:
    """One scene pass into ``fbo`` (at the targets' draw size): the surfaces, and with
    ``background`` the background, the ground and the blended parts; ``display``: written tone
    mapped (DISPLAY_OUTPUT); ``still``: a still image, not a frame of a view that may stay
    (FrameContext.still). Returns what it decided, for the resolve."""
    ctx = r.ctx
    frame = FrameContext(display=display, srgb_by_framebuffer=srgb_by_framebuffer, still=still,
                         half_output=targets.half and fbo is targets.draw,
                         image_size=(targets.width, targets.height), sun_directions=sun_world_directions(scene, maps),
                         maps=maps)
    width, height = targets.draw_size
    scale = width // targets.width      # SSAA draws 2x2 sub-pixels per output pixel
    view = view or View(targets.width, targets.height)
    aspect = view.width / view.height
    # The probe's own camera is orthographic; its backdrop is drawn as the default camera sees it.
    camera = Camera() if scene.view == "probe" else r.camera_for(scene, aspect)
    # The built-in sphere as an impostor: with one coverage sample a pixel into a single-sample
    # target, with 4 into the fused resolve's single-sample stand-in for the multisampled one
    # (its mean already taken); never into a multisampled target.
    view_projection = camera.view_projection(aspect)
    impostor = impostor_placement(r.meshes, scene, camera, (view.width, view.height), view_projection) \
        if r.sphere_impostor else None
    frame.impostor_model = impostor[0] if impostor else None
    if targets.aa != "msaa":
        frame.impostor_samples = 1
    elif frame.impostor_model is not None and fbo is targets.draw and not background:
        frame.impostor_samples = 4
        fbo = targets.single()[1]
    else:
        frame.impostor_samples = 0
    frame.screen_ao = frame.impostor_model is None and scene.view != "probe" and scene.mesh is not None \
        and r.visibility_parts.screen_wanted(scene.mesh, scene.occlusion)
    if frame.screen_ao:
        # Half the image's height in draw pixels times the projection's P[1][1] (a tile's view
        # keeps the whole image's projection).
        frame.ao_pixel_scale = 0.5 * view.height * scale * float(camera.projection_matrix(aspect)[1][1])
    r.last_occlusion_reason = ""
    if frame.screen_ao:
        r.last_occlusion_reason = "gtao" if scene.occlusion == "gtao" else \
            "gtao (auto: the mesh has more vertices than auto bakes, AUTO_MAX_VERTICES)"
    if frame.impostor_model is None:    # (without an impostor only 4x msaa is eligible: vbuffer.choose)
        use, r.last_mesh_shading_reason = vbuffer.choose(r, scene, targets, fbo, background, view_projection,
                                                         (view.width, view.height), maps)
    else:
        use, r.last_mesh_shading_reason = False, "the built-in sphere has its own impostor"
    r.last_vbuffer = use
    if use:
        frame.vbuffer = True
        fbo = targets.single()[1]
    frame.shadowed = prepare_shadows(r, scene, maps)    # (its own framebuffer: before this pass's)
    r.last_ground_idle = ""
    if scene.ground and scene.mesh is not None and not frame.shadowed and scene.view != "probe":
        # (a ground with no shadow to catch draws nothing: the picture equals the one without it)
        # (the front end says it in its own words: the CLI's flags, the API's setters, the editor's controls)
        r.last_ground_idle = "shadows off" if scene.shadows == "off" else "no light"
    fbo.use()
    ctx.viewport = (0, 0, width, height)
    if view.matrix is not None:     # a tile: the whole image's projection, off centre
        view_projection = (view_projection.astype(np.float64) @ view.matrix).astype(np.float32)
    frame.view_projection = view_projection
    frame.inverse_vp = inverse_vp = np.linalg.inv(view_projection).astype(np.float32)
    ring = None
    if r.background_ring and impostor and frame.impostor_samples == 1 and background \
            and background_mode(scene, maps) != BackgroundMode.TRANSPARENT \
            and not transmissive_parts(scene):
        hole = impostor_hole_model(camera.position, scene.mesh.lod_sphere[0], impostor[1])
        ring = impostor_background_ring(hole, view_projection) if hole is not None else None
    # Colour too: the MSAA resolve tells covered samples by their alpha (render/resolve.frag),
    # and transmissive parts read the opaque parts' coverage from it. The whole framebuffer:
    # llvmpipe clears whole tiles lazily, and a scissored clear (the mesh's rectangle only)
    # made a 1920x1080 4x frame 7-9% slower here, alternated in one process.
    r.last_background_ring = ring is not None
    # With the background's ring no depth is read or written (colour only).
    fbo.depth_mask = ring is None
    fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
    fbo.depth_mask = True
    r.lights.write(scene)
    if ring is not None:
        # The one sphere's impostor with one sample a pixel: the background first, around a
        # hole inside the sphere's outline (sphere_lod.impostor_background_ring), then the
        # impostor over it. Every pixel is written once or, in the thin band between the hole
        # and the outline, twice, and no depth buffer is cleared, tested or written: 3.5-5% of
        # the editor's 860x720 scene pass on llvmpipe (two renderers alternated in one process).
        ctx.disable(moderngl.DEPTH_TEST)
        draw_background(r, frame, scene, maps, inverse_vp, ring)
    else:
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
    if scene.view == "probe":
        draw_probe(r, scene, maps, view.width * scale, (view.origin[0] * scale, view.origin[1] * scale))
    elif scene.mesh is not None:
        draw_mesh(r, frame, scene, maps, camera, view_projection, blend=False, targets=targets, fbo=fbo,
                  pixels_per_radian=view.height * scale / 2.0 / math.tan(math.radians(camera.fov_y_deg) / 2.0),
                  image_size=(view.width, view.height))
        if not background:     # (the fused resolve composites the background under it)
            draw_ground(r, frame, scene, maps, view_projection)
    # After the surfaces: the depth test keeps the background's shading off covered pixels.
    if background and ring is None:
        draw_background(r, frame, scene, maps, inverse_vp)
        if scene.view != "probe" and scene.mesh is not None:
            draw_ground(r, frame, scene, maps, view_projection)
        # Then what blends (alphaMode BLEND) over both, back to front (glTF 2.0 section 3.9.4).
        # (The fused MSAA resolve, background=False, is used only for scenes with none.)
        if scene.view != "probe" and scene.mesh is not None:
            draw_mesh(r, frame, scene, maps, camera, view_projection, blend=True, image_size=(view.width, view.height))
    ctx.disable(moderngl.DEPTH_TEST)
    if display is None and background:
        finish_radiance(r, targets)
    return frame


def scene_program(r, frame: FrameContext, vertex: str, fragment: str, defines: dict | None = None) -> moderngl.Program:
    """A scene pass's program: with DISPLAY_OUTPUT and the display's uniforms where the pass
    writes tone mapped (common/output_encoding.glsl), HALF_FLOAT_OUTPUT into half floats."""
    display = frame.display
    if display is None:
        if frame.half_output:
            defines = {**(defines or {}), "HALF_FLOAT_OUTPUT": None}
        return r.program(vertex, fragment, defines)
    defines = {**(defines or {}), "DISPLAY_OUTPUT": None, "TONEMAP_MODE": int(glsl_member(Tonemap, display.tonemap))}
    if frame.srgb_by_framebuffer:
        defines["SRGB_BY_FRAMEBUFFER"] = None
    prog = r.program(vertex, fragment, defines)
    set_uniform(prog, "u_exposure_scale", float(2.0 ** display.exposure))
    return prog


def prepare_shadows(r, scene, maps: IBLMaps | None) -> bool:
    """The shadow maps for ``scene``, drawn where out of date (alight.render.shadows); whether
    this pass reads them. The casters: every part but those that blend or let light through
    (alight.render.shadows.casters)."""
    ground = scene.ground and scene.view != "probe" and scene.mesh is not None and bool(scene.mesh.parts)
    if scene.view == "probe" or scene.mesh is None or not r.shadow_maps.wanted(scene, maps, receivers=ground):
        r.shadow_maps.last_active = False
        return False
    kept = [(g, part) for g, part, cast in zip(r.meshes.parts(scene.mesh), scene.mesh.parts, shadow_casters(scene))
            if cast and not blends(scene, part)]
    gpu_parts = [g for g, _ in kept]
    # A single-sided part (glTF doubleSided false) casts from the faces whose front faces the
    # light only: its back faces, as the light sees them, are culled (the camera pass's rule,
    # the light as the camera). Two-sided parts cast from both sides.
    one_way = {id(g): single_sided(part) for g, part in kept}

    def draw_parts(matrix: bytes, parts) -> None:
        ctx = r.ctx
        prog = r.program("render/shadow_depth.vert", "render/shadow_depth.frag")
        prog["u_view_projection"].write(matrix)
        for gpu_part in parts:
            if one_way.get(id(gpu_part), False):
                ctx.front_face = "ccw"
                ctx.enable(moderngl.CULL_FACE)
            else:
                ctx.disable(moderngl.CULL_FACE)
            gpu_part.vao_for(prog).render(moderngl.TRIANGLES)
        ctx.disable(moderngl.CULL_FACE)

    bounds = GroundPass.ground_for(scene.mesh).bounds if ground else None
    return r.shadow_maps.prepare(scene, maps, gpu_parts, draw_parts, bounds)


def draw_ground(r, frame: FrameContext, scene, maps: IBLMaps | None, view_projection: np.ndarray) -> None:
    """Scene.ground's shadow catcher (alight.render.ground) into the bound framebuffer, after
    the surfaces (and the background, where a pass draws one). Only where shadows are drawn:
    a ground without them takes nothing from the background."""
    if not (scene.ground and frame.shadowed and scene.mesh is not None):
        return
    if r.ground_pass is None:
        r.ground_pass = GroundPass(r.ctx)
    defines = {**light_defines(scene), **sun_defines(maps), "HAS_SHADOWS": None}
    prog = scene_program(r, frame, "render/ground.vert", "render/ground.frag", defines)
    bind_ibl(prog, scene, maps, r.tables)
    r.shadow_maps.bind(prog, UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH)
    r.ground_pass.draw(prog, GroundPass.ground_for(scene.mesh), view_projection)


def draw_background(r, frame: FrameContext, scene, maps: IBLMaps | None, inverse_vp: np.ndarray,
                    ring: np.ndarray | None = None) -> None:
    """The background pass: a full-screen triangle, or ``ring``'s triangles ((n, 2) NDC
    points, sphere_lod.impostor_background_ring) where the impostor fills the rest."""
    mode = background_mode(scene, maps)
    if mode == BackgroundMode.TRANSPARENT:
        return
    defines = {"BACKGROUND_MODE": int(mode)}
    if ring is not None:
        defines["BACKGROUND_RING"] = None
    prog = scene_program(r, frame, "render/background.vert", "render/background.frag", defines)
    bind_background(prog, scene, maps, inverse_vp, mode)
    if ring is None:
        r.draws.triangle(prog)
    else:
        r.draws.ring(prog, ring)


def draw_probe(r, scene, maps: IBLMaps | None, size: int, origin: tuple[int, int] = (0, 0)) -> None:
    """The probe view (render/probe.frag): the material on the unit sphere, per pixel centre."""
    defines = {**ibl_defines(scene), **sun_defines(maps), **r._below_grid_defines(scene, maps, [scene.material]),
               **stretched_span_defines(scene, [scene.material]), **material_defines([scene.material])}
    prog = r.program("render/fullscreen.vert", "render/probe.frag", defines)
    prog["u_size"] = float(size)
    set_uniform(prog, "u_pixel_origin", tuple(float(x) for x in origin))
    set_material(prog, scene.material)
    r.tables.bind_layer_luts(defines)
    bind_ibl(prog, scene, maps, r.tables)
    r.draws.triangle(prog)


# --- the mesh ------------------------------------------------------------------------------

def draw_mesh(r, frame: FrameContext, scene, maps: IBLMaps | None, camera: Camera, view_projection: np.ndarray,
              blend: bool = False, targets: Targets | None = None, fbo: moderngl.Framebuffer | None = None,
              pixels_per_radian: float = 1.0, image_size: tuple[int, int] | None = None) -> None:
    """The parts that blend (``blend``) or the rest, each with its shader variant: the scene's
    IBL model and debug view, plus only the features the part uses (variants.part_defines).
    The rest is drawn as alight.render.renderer's docstring says: the opaque parts, then, where
    any part transmits, a copy of what they left in ``fbo`` and the transmissive parts reading
    it (TRANSMISSION_SCENE; ``pixels_per_radian``: the image's rows per radian at its centre,
    for the copy's blur)."""
    defines = ibl_defines(scene)
    defines.update(sun_defines(maps))
    defines.update(light_defines(scene))
    user_maps = user_maps_present(scene)
    parts = list(zip(r.meshes.parts(scene.mesh), scene.mesh.parts))
    any_maps = 0
    for gpu_part, part in parts:
        any_maps |= part_defines(scene, gpu_part, part, user_maps)["MATERIAL_MAPS_MASK"]
    # (through the renderer, where a test replaces it)
    materials = [part_material(scene, part)[0] for _, part in parts]
    defines.update(r._below_grid_defines(scene, maps, materials, any_maps))
    defines.update(stretched_span_defines(scene, materials, any_maps))
    if scene.debug_view:
        defines["DEBUG_VIEW"] = None
    if frame.shadowed:
        defines["HAS_SHADOWS"] = None
    bound: set[int] = set()

    def program_for(variant: dict, vertex: str = "render/pbr.vert", fragment: str = "render/pbr.frag") -> moderngl.Program:
        all_defines = {**defines, **variant}
        prog = scene_program(r, frame, vertex, fragment, all_defines)
        if id(prog) not in bound:
            bound.add(id(prog))
            if scene.debug_view:
                set_uniform(prog, "u_debug_view", int(scene.debug_view))
                set_uniform(prog, "u_debug_mip", float(scene.debug_mip))
            bind_ibl(prog, scene, maps, r.tables)
            if frame.shadowed:
                r.shadow_maps.bind(prog, UNIT_SHADOW_ATLAS, UNIT_SHADOW_DEPTH)
        r.tables.bind_layer_luts(all_defines)
        return prog

    if blend:
        draw_mesh_parts(r, frame, scene, program_for, camera, view_projection, blend=True, image_size=image_size)
        return
    if frame.vbuffer:
        # The baked parts where Scene.occlusion wants them, as draw_mesh_parts draws them.
        # (with the environment drawn, so they keep their visible sky weight)
        drawn = occluded_parts(r, scene, r.meshes.parts(scene.mesh), frame.sun_directions, frame.maps)
        shading_program = program_for
        if frame.screen_ao:    # (its shading pass reads the visibility at gl_FragCoord as the forward pass does)
            shading_program = screen_ao_program(r, frame, scene, camera, view_projection, fbo,
                                                list(range(len(scene.mesh.parts))), program_for)
        vbuffer.draw(r, frame, scene, camera, view_projection, targets, shading_program, image_size, drawn)
        return
    transmissive = transmissive_parts(scene)
    opaque = [i for i in range(len(scene.mesh.parts)) if i not in transmissive]
    opaque_program = program_for
    if opaque and frame.screen_ao:
        opaque_program = screen_ao_program(r, frame, scene, camera, view_projection, fbo, opaque, program_for)
    if opaque:
        draw_mesh_parts(r, frame, scene, opaque_program, camera, view_projection, blend=False, parts=opaque,
                        image_size=image_size)
    if not transmissive:
        return
    behind, behind_fbo = targets.behind()
    r.ctx.copy_framebuffer(behind_fbo, fbo)   # the MSAA resolve too, where there is one
    behind.build_mipmaps()
    fbo.use()
    behind.use(UNIT_SCENE_BEHIND)
    if not (scene.ibl_enabled and maps is not None):
        # The thin-walled lobe's energy is the BRDF LUT's A, which bind_ibl binds only with
        # an environment.
        q = QUALITY["medium"]
        r.luts.get(q.lut_size, q.lut_samples).use(UNIT_LUT)

    def transmissive_program(variant: dict) -> moderngl.Program:
        prog = program_for({**variant, "TRANSMISSION_SCENE": None})
        set_uniform(prog, "u_behind_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
        set_uniform(prog, "u_behind_pixels_per_radian", float(pixels_per_radian))
        return prog

    draw_mesh_parts(r, frame, scene, transmissive_program, camera, view_projection, blend=False, parts=transmissive,
                    image_size=image_size)


def screen_ao_program(r, frame: FrameContext, scene, camera: Camera, view_projection: np.ndarray,
                      fbo: moderngl.Framebuffer, opaque: list[int], program_for):
    """Screen-space GTAO of the ``opaque`` parts that do not blend (alight.render.screen_ao), drawn
    at ``fbo``'s draw size before them; returns ``program_for`` with the defines that read it.
    ``fbo`` is bound again, with its viewport, afterwards."""
    from alight.render.screen_ao import ScreenAO, defines as screen_defines

    if getattr(r, "screen_ao", None) is None:
        r.screen_ao = ScreenAO(r.ctx)
    viewport = r.ctx.viewport
    items = [(g, p) for i, (g, p) in enumerate(zip(r.meshes.parts(scene.mesh), scene.mesh.parts))
             if i in opaque and not blends(scene, p)]
    lo = np.min([g.lo for g, _ in items], axis=0) if items else np.zeros(3)
    hi = np.max([g.hi for g, _ in items], axis=0) if items else np.zeros(3)
    radius = r.screen_ao.radius_fraction * float(np.linalg.norm(np.asarray(hi) - np.asarray(lo)))
    r.screen_ao.draw(r, [g for g, _ in items], [p for _, p in items], (viewport[2], viewport[3]), view_projection,
                     frame.inverse_vp, camera, frame.ao_pixel_scale, max(radius, 1e-6),
                     keep=getattr(r, "screen_ao_temporal", False) and not frame.still)
    fbo.use()
    r.ctx.viewport = viewport
    r.ctx.enable(moderngl.DEPTH_TEST)
    r.ctx.depth_func = "<="
    extra = screen_defines(r.screen_ao.occluded)
    return lambda variant, *args: program_for({**variant, **extra}, *args)


def draw_mesh_parts(r, frame: FrameContext, scene, prog, camera: Camera, view_projection: np.ndarray,
                    blend: bool | None = None, parts: list[int] | None = None,
                    image_size: tuple[int, int] | None = None) -> None:
    """ForwardRenderer.draw_mesh_parts, within the scene pass ``frame`` (its impostor)."""
    ctx = r.ctx
    user_maps = user_maps_present(scene)
    user = r.meshes.user_textures(scene)
    tiling = scene.texture_maps or TextureMaps()
    items = []
    size = image_size or tuple(ctx.viewport[2:])
    # The built-in sphere as an impostor (decided once per scene pass in draw_scene), by forward
    # programs only; else its level or the mesh as given.
    proxy_model = frame.impostor_model if callable(prog) and frame.impostor_samples else None
    r.last_sphere_impostor = None
    model = np.eye(4, dtype=np.float32)
    if proxy_model is None:
        drawn, sphere_radius, r.last_sphere_segments = lod_parts(r.meshes, scene.mesh, camera, size,
                                                                 r.sphere_max_error_px)
    else:
        r.last_sphere_segments = None
        drawn = [proxy_part(r.meshes, scene.mesh)]
        sphere_radius = scene.mesh.lod_sphere[0]
        model = np.ascontiguousarray(proxy_model.T, dtype=np.float32)   # GLSL reads columns
        r.last_sphere_impostor = frame.impostor_samples
    if callable(prog) and sphere_radius is None and proxy_model is None:
        drawn = occluded_parts(r, scene, drawn, frame.sun_directions, frame.maps)
    chosen = None if parts is None else set(parts)
    for index, (gpu_part, part) in enumerate(zip(drawn, scene.mesh.parts)):
        if (blend is None or blends(scene, part) == blend) and (chosen is None or index in chosen):
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
                variant = part_defines(scene, gpu_part, part, user_maps)
                if sphere_radius is not None:
                    variant["SPHERE_SURFACE"] = None
                if proxy_model is not None:
                    variant["SPHERE_IMPOSTOR"] = frame.impostor_samples
                alpha_to_coverage(variant, ctx)
                program = prog(variant)
            else:
                program = prog
            if id(program) not in prepared:
                prepared.add(id(program))
                _bind_view(program, ctx, frame, camera, view_projection, model, sphere_radius, proxy_model is not None)
            bind_part(r, scene, program, gpu_part, part, user, tiling, camera, size)
            set_culling(ctx, gpu_part, part)
            gpu_part.vao_for(program).render(moderngl.TRIANGLES)
    finally:
        ctx.disable(moderngl.CULL_FACE)
        if blend:
            ctx.disable(moderngl.BLEND)
            ctx.depth_mask = True


def occluded_parts(r, scene, drawn: list[GpuPart], sun_directions=None, maps: IBLMaps | None = None) -> list[GpuPart]:
    """The mesh's parts refined and baked with visibility where ``scene.occlusion`` wants them
    (alight.render.visibility_parts), else ``drawn``; ``sun_directions``: (K, 3) world, the
    compact sources whose light on the occluders the bake adds (None: none); ``maps``: the
    environment drawn, whose visible sky weight the parts carry (None: none)."""
    textures = r.meshes.textures(scene.mesh)
    sky = None
    if maps is not None:
        sky = (lambda: environment_texels(r.shaders, maps), float(scene.env_rotation_deg))
    return r.visibility_parts.parts_for(scene.mesh, scene.occlusion, drawn,
                                        lambda part: GpuPart(r.ctx, part, textures), light_through(scene),
                                        sun_directions, sky, occluder_materials(scene))


# --- after the scene pass: resolve, reduce, tone map ------------------------------------

def surface_rect(r, frame: FrameContext, scene) -> tuple[int, int, int, int] | None:
    """(x, y, width, height) in pixels of the frame's image holding every pixel the mesh can
    cover: the projected corners of its parts' bounding boxes, a pixel wider each way. None:
    the whole image (the probe view, or a box reaching behind the eye)."""
    if scene.view == "probe":
        return None
    if scene.mesh is None:
        return (0, 0, 0, 0)
    parts = r.meshes.parts(scene.mesh)
    if not parts:
        return (0, 0, 0, 0)
    lo = np.min([p.lo for p in parts], axis=0)
    hi = np.max([p.hi for p in parts], axis=0)
    if scene.ground and frame.shadowed:     # the ground's square is drawn too (draw_ground)
        g = GroundPass.ground_for(scene.mesh)
        lo = np.minimum(lo, g.centre - (g.half_size, 0.0, g.half_size))
        hi = np.maximum(hi, g.centre + (g.half_size, 0.0, g.half_size))
    corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    clip = corners @ np.asarray(frame.view_projection, np.float64)
    if (clip[:, 3] <= 1e-6).any():
        return None
    size = frame.image_size
    pixels = (clip[:, :2] / clip[:, 3:] * 0.5 + 0.5) * np.array(size, np.float64)
    x0, y0 = np.clip(np.floor(pixels.min(axis=0)) - 1, 0, size).astype(int)
    x1, y1 = np.clip(np.ceil(pixels.max(axis=0)) + 1, 0, size).astype(int)
    return (int(x0), int(y0), int(max(x1 - x0, 0)), int(max(y1 - y0, 0)))


def resolve(r, frame: FrameContext, scene, maps: IBLMaps | None, targets: Targets, radiance: bool,
            display: bool) -> None:
    """render/resolve.frag: the multisampled surfaces of the scene pass ``frame`` resolved, the
    background under them, into the radiance and/or the display image (at least one is
    written, so a frame is complete)."""
    radiance = radiance or not display
    mode = background_mode(scene, maps)
    # After the sphere's impostor the surfaces are in the single-sample stand-in, resolved already.
    single = frame.impostor_samples == 4 or frame.vbuffer
    defines = {"BACKGROUND_MODE": int(mode), "SCENE_SAMPLES": 1 if single else targets.samples}
    scene_texture = targets.single()[0] if single else targets.color
    if radiance:
        defines["RADIANCE_OUTPUT"] = None
    if display:
        defines["DISPLAY_OUTPUT"] = 1 if radiance else 0
        defines["TONEMAP_MODE"] = int(glsl_member(Tonemap, scene.display.tonemap))
    w, h = targets.width, targets.height
    rect = surface_rect(r, frame, scene)
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
    r.ctx.viewport = (0, 0, w, h)
    try:
        for pass_defines, scissor in passes:
            prog = r.program("render/background.vert", "render/resolve.frag", pass_defines)
            # The rays of the scene pass just drawn (for a tile, the whole image's projection off centre).
            bind_background(prog, scene, maps, frame.inverse_vp, mode)
            scene_texture.use(UNIT_RADIANCE)
            set_uniform(prog, "u_scene", UNIT_RADIANCE)
            set_uniform(prog, "u_exposure_scale", float(2.0 ** scene.display.exposure))
            set_uniform(prog, "u_opaque", scene.display.background != "transparent")
            r.ctx.scissor = scissor
            r.draws.triangle(prog)
    finally:
        r.ctx.scissor = None


def finish_radiance(r, targets: Targets) -> None:
    """The drawn samples into ``targets.radiance``: the MSAA blit, or the SSAA 2x2 reduction."""
    if targets.aa == "msaa":
        r.ctx.copy_framebuffer(targets.radiance_fbo, targets.draw)  # the resolve
    elif targets.aa == "ssaa":
        prog = r.program("render/fullscreen.vert", "render/downsample.frag")
        targets.color.use(UNIT_RADIANCE)
        prog["u_factor"] = 2
        targets.radiance_fbo.use()
        r.ctx.viewport = (0, 0, targets.width, targets.height)
        r.draws.triangle(prog)


def tonemap(r, radiance: moderngl.Texture, display: Display, fbo: moderngl.Framebuffer, opaque: bool = True) -> None:
    """render/tonemap.frag: ``radiance`` exposed and tone mapped into ``fbo``, sRGB encoded."""
    prog = r.program("render/fullscreen.vert", "render/tonemap.frag",
                     {"TONEMAP_MODE": int(glsl_member(Tonemap, display.tonemap))})
    radiance.use(UNIT_RADIANCE)
    prog["u_exposure_scale"] = float(2.0 ** display.exposure)
    prog["u_opaque"] = opaque
    fbo.use()
    r.ctx.viewport = (0, 0) + fbo.size
    r.draws.triangle(prog)
