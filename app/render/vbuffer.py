"""Meshes shaded once per pixel from a visibility buffer (``ForwardRenderer.mesh_shading =
"vbuffer"``, or "auto" on dense meshes), instead of once per triangle covering a pixel's samples.

Under 4x MSAA a rasteriser shades a pixel once for every triangle that covers any of its
samples, and llvmpipe shades whole 4x4 blocks per triangle: a mesh of small triangles pays for
each pixel several times. Here (Burns and Hunt 2013, "The Visibility Buffer: A Cache-Friendly
Approach to Deferred Shading"; Schied and Dachsbacher 2015):

    visibility pass: the opaque and alphaMode MASK parts rasterised with 4x MSAA and depth into an
        integer target, (triangle + 1, part + 1) per sample (render/vbuffer.frag; a MASK part
        tests its alpha there, per pixel, as the forward pass does)
    shading pass, one full-screen pass per part (render/vbuffer_shade.frag): each pixel fetches
        the triangles its samples hold from the part's vertex and index buffers (bound as shader
        storage), interpolates them where the view ray meets them, and shades each distinct
        triangle once with the forward pass's material and light functions
        (common/mesh_material.glsl VBUFFER_SHADING), weighted by its samples; the sum is added
        into the single-sample target render/resolve.frag reads with SCENE_SAMPLES 1, as the
        built-in sphere's impostor does (alight.render.sphere_impostor).

The shading pass is quad-coherent: each 2x2 block of pixels shades one triangle at a time at all
four of its pixels (the triangle's plane extended past its edges), as the rasteriser's block does
for the forward pass, so plain ``texture()`` takes the forward pass's derivatives and mip levels
(a block on k visible triangles is shaded k times, as the rasteriser shades it: what is saved is
the forward pass's overdraw and per-triangle work, benchmarks/results/vbuffer.md).
It is drawn as one triangle that nothing clips, over a viewport twice the image's size
(render/vbuffer_shade.vert), under a scissor rectangle with even corners, so its blocks are the
forward pass's, each whole and run once.

Used only where the frame is the fused MSAA resolve with 4 samples, an even width and height,
and nothing but opaque and masked parts (``eligible``): blended, transmissive, the ground, the
built-in sphere and debug views keep the forward pass. Under ``mesh_shading = "auto"`` (the
default) only where the mesh is dense on screen as well (``dense``: fewer than
AUTO_PIXELS_PER_TRIANGLE = 3 estimated covered pixels per triangle, about 1.5 counted on a
sphere, for an untextured material; more where the pixel costs more, ``auto_threshold``), since the visibility pass, the vertex fetches and the id exchange cost about 0.17 s of
CPU time a 1024x1024 frame whatever the mesh: on large triangles that is pure overhead (1.5-1.9x
the forward frame on a sphere of 56-15 pixels per triangle), on small ones it is less than the
forward pass's overshading and per-triangle work (0.66x at 0.44 pixels per triangle). The base
threshold was measured on untextured spheres (benchmarks/results/vbuffer.md); a heavier
pixel moves the crossover toward larger triangles, so textured materials and a sun's soft
shadows raise it (``auto_threshold``, benchmarks/results/vbuffer_cost.md): DamagedHelmet with
its own maps takes the visibility buffer at 512 pixels (0.82x the forward frame) and keeps the
forward pass at 1024 (where the visibility buffer is 1.18x). The visibility bake's per-vertex occlusion
(Scene.occlusion) is read in the shading pass from the baked parts' buffers.
"""

from __future__ import annotations

import moderngl
import numpy as np

from alight.core.shader_names import DEBUG_VIEWS, AlphaMode
from alight.core.texture_maps import TextureMaps
from alight.render.bindings import UNIT_VISIBILITY, set_uniform
from alight.render.part_bindings import _bind_view, bind_part, set_culling
from alight.render.variants import (alpha_to_coverage, has_blending_parts, part_defines, transmissive_parts,
                                    user_maps_present)

MESH_SHADING = ("auto", "forward", "vbuffer")   # ForwardRenderer.mesh_shading
# "auto" takes the visibility buffer where the mesh has fewer estimated covered pixels per
# triangle than this (pixels_per_triangle, about twice the pixels counted on a sphere).
# Measured (benchmarks/results/vbuffer.md, 2026-12-06: untextured bumpy spheres of 8k-1M
# triangles at 256-1024 pixels, CPU time vbuffer/forward): 1.02-1.06x at 3.6-7.1 estimated
# (1.8-3.5 counted) pixels per triangle, 1.1-1.9x above, 0.81-0.85x at 1.8-2.3 and 0.54-0.66x
# at 0.2-0.9; the ratio follows the density whatever the size. Below 3 only meshes that gain
# take it; a textured, normal-mapped mesh gains at more pixels per triangle (DamagedHelmet 0.71x
# at 9.6 estimated), which this one threshold leaves to the forward pass.
AUTO_PIXELS_PER_TRIANGLE = 3.0
# A heavier pixel moves the crossover toward larger triangles: what the visibility buffer saves
# is shading (overdraw, per-triangle set-up), what it costs is per frame. Measured on
# DamagedHelmet (benchmarks/results/vbuffer_cost.md, CPU time vbuffer/forward, alternated):
# its own five maps 0.74x at 5.4, 0.82x at 9.6, 1.02x at 21.6, 1.18x at 38 estimated pixels per
# triangle; with a sun's soft shadows (PCSS: 20 depth fetches a lit pixel) 0.56x, 0.67x, 0.80x,
# 0.93-1.03x. So auto's threshold is multiplied where a drawn material reads maps and again
# where a compact source's shadow is drawn, each factor about 0.6 of the measured crossover.
AUTO_TEXTURED_FACTOR = 4.0
AUTO_SOFT_SHADOW_FACTOR = 2.0
VBUFFER_SAMPLES = 4                     # render/vbuffer_shade.frag's sample pattern
# render/vbuffer_shade.frag passes triangle ids between a block's pixels as floats (exact below
# 2^24, one id kept for "none"): a part with more triangles keeps the forward pass.
MAX_TRIANGLES = (1 << 24) - 2


def wanted(r, scene, targets, fbo, background: bool, view_projection: np.ndarray | None = None,
           image_size: tuple[int, int] | None = None, maps=None) -> bool:
    """Whether this scene pass shades its mesh from the visibility buffer: ``r.mesh_shading``
    asks for it ("vbuffer"; "auto": where the mesh is dense enough on screen, ``dense``) and the
    pass is the fused MSAA resolve's (4 samples, no background drawn, so no blended parts) of a
    mesh file with no transmissive part, ground or debug view. ``view_projection`` and
    ``image_size``: the whole image's (a tile's pass too), for "auto"."""
    return choose(r, scene, targets, fbo, background, view_projection, image_size, maps)[0]


def choose(r, scene, targets, fbo, background: bool, view_projection: np.ndarray | None = None,
           image_size: tuple[int, int] | None = None, maps=None) -> tuple[bool, str]:
    """``wanted`` and why: (True, why the visibility buffer) or (False, why the forward pass),
    the reason a phrase for a message ("the scene has blended parts"; ForwardRenderer's
    last_mesh_shading_reason, the CLI's warning and --verbose line)."""
    mode = getattr(r, "mesh_shading", "auto")
    if mode not in ("auto", "vbuffer"):
        return False, "asked for"
    reason = ineligible_reason(r, scene, targets, fbo, background, image_size)
    if reason is not None:
        return False, reason
    if mode == "vbuffer":
        return True, "asked for"
    density = None
    if view_projection is not None:
        density = pixels_per_triangle(r, scene, view_projection, image_size)
    if density is None:
        return False, "the camera is at or inside the mesh" if view_projection is not None else \
            "no view to estimate the mesh's density"
    threshold, why = auto_threshold(r, scene, maps)
    if density < threshold:
        return True, f"the mesh is dense on screen, about {density:.1f} pixels per triangle, " \
                     f"below {threshold:g}{why}"
    return False, f"the mesh is not dense on screen, about {density:.1f} pixels per triangle; " \
                  f"auto takes the visibility buffer below {threshold:g}{why}"


def auto_threshold(r, scene, maps=None) -> tuple[float, str]:
    """"auto"'s pixels-per-triangle threshold for this scene's shading and, for a message, what
    raised it ('' or " (textured materials, a sun's soft shadows)"): AUTO_PIXELS_PER_TRIANGLE,
    times AUTO_TEXTURED_FACTOR where a drawn material reads a map, times AUTO_SOFT_SHADOW_FACTOR
    where a compact source's shadow is drawn on the mesh (``maps``' suns, alight.render.shadows)."""
    from alight.render.shadows import shadowed_suns

    threshold, reasons = AUTO_PIXELS_PER_TRIANGLE, []
    if textured(r, scene):
        threshold *= AUTO_TEXTURED_FACTOR
        reasons.append("textured materials")
    if shadowed_suns(scene, maps) and r.shadow_maps.wanted(scene, maps):
        threshold *= AUTO_SOFT_SHADOW_FACTOR
        reasons.append("a sun's soft shadows")
    return threshold, (f" ({', '.join(reasons)})" if reasons else "")


def textured(r, scene) -> bool:
    """Whether a material the mesh is drawn with reads a texture map: a file material's own maps
    (where the view shows them) or the user's loaded maps on the panel's material."""
    if user_maps_present(scene):
        return True
    if not scene.use_file_materials:
        return False
    return any(part.material is not None and gpu_part.infos
               for gpu_part, part in zip(r.meshes.parts(scene.mesh), scene.mesh.parts))


def eligible(r, scene, targets, fbo, background: bool) -> bool:
    """Whether the visibility buffer can draw this pass as the forward pass would (``wanted``'s
    conditions but the density): ``ineligible_reason`` finds none."""
    return ineligible_reason(r, scene, targets, fbo, background) is None


def ineligible_reason(r, scene, targets, fbo, background: bool,
                      image_size: tuple[int, int] | None = None) -> str | None:
    """Why the visibility buffer cannot draw this pass as the forward pass would, as a phrase
    ("the scene has blended parts"), or None where it can. The first reason found, the user's
    choices (view, mesh, ground, materials) before the frame's (anti-aliasing, size).
    ``image_size``: the whole image's, where the pass draws a tile of it (named in the reason)."""
    mesh = scene.mesh
    width, height = targets.draw_size
    if scene.view == "probe":
        return "the probe view draws no mesh"
    if mesh is None or not mesh.parts:
        return "there is no mesh"
    if mesh.lod_sphere is not None:
        return "the built-in sphere has its own impostor"
    if scene.debug_view:
        view = DEBUG_VIEWS[scene.debug_view] if 0 <= scene.debug_view < len(DEBUG_VIEWS) else scene.debug_view
        return f"the debug view '{view}' is drawn by the forward pass"
    if scene.ground:
        return "the scene has a ground"
    if has_blending_parts(scene):
        return "the scene has blended parts"
    if transmissive_parts(scene):
        return "the scene has transmissive parts"
    if targets.aa != "msaa" or targets.samples != VBUFFER_SAMPLES:
        aa = f"{targets.samples}x msaa" if targets.aa == "msaa" else f"anti-aliasing {targets.aa}"
        return f"the visibility buffer needs {VBUFFER_SAMPLES}x msaa, not {aa}"
    if fbo is not targets.draw or background:
        return "the pass draws the background (not the fused MSAA resolve)"
    # An odd width or height keeps the forward pass: the shading pass's 2x2 blocks must be the
    # forward pass's, and along an odd edge the last column or row of blocks would reach past the
    # image, where their other pixels have no samples to share.
    tiled = image_size is not None and tuple(image_size) != (targets.width, targets.height)
    size = f"the tile {width}x{height} of the {image_size[0]}x{image_size[1]} image" if tiled \
        else f"the size {width}x{height}"
    if width % 2 or height % 2:
        return f"{size} is odd; the visibility buffer needs an even width and height"
    if 2 * max(width, height) > max_viewport(r.ctx):
        return f"{size} is over half of GL_MAX_VIEWPORT_DIMS ({max_viewport(r.ctx)})"
    big = max(len(part.indices) for part in mesh.parts)
    if big > MAX_TRIANGLES:
        return f"a part has {big} triangles, over the visibility buffer's {MAX_TRIANGLES}"
    return None


def pixels_per_triangle(r, scene, view_projection: np.ndarray, image_size: tuple[int, int]) -> float | None:
    """An estimate of the pixels the mesh covers per triangle it has: the areas of its parts'
    bounding boxes projected to the image (the rectangle holding a box's 8 projected corners,
    not clipped to the image), over all of its triangles (front- and back-facing). None where a
    box reaches behind the eye (the camera in or at the mesh: near triangles are large on
    screen, so the forward pass).

    Why this is good enough: the rectangle holds everything the box's contents project to, so
    the estimate is an upper bound of the pixels covered (2.0x on the benchmark's spheres, 2.2x on
    DamagedHelmet), and it errs only toward the forward pass (the old default) by that factor; the
    threshold is calibrated on this same estimate (AUTO_PIXELS_PER_TRIANGLE), and the measured
    ratio moves slowly with the density. It costs 8 corners a part, nothing per triangle. Not
    clipping to the image keeps the density of a mesh that the camera is close to (part of it
    off screen) at the density of its visible part: its triangles spread over the whole
    unclipped area."""
    size = np.array(image_size, np.float64)
    area, triangles = 0.0, 0
    for gpu_part, part in zip(r.meshes.parts(scene.mesh), scene.mesh.parts):
        lo, hi = gpu_part.lo, gpu_part.hi
        corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        clip = corners @ np.asarray(view_projection, np.float64)
        if (clip[:, 3] <= 1e-6).any():
            return None
        pixels = clip[:, :2] / clip[:, 3:] * 0.5 * size
        extent = pixels.max(axis=0) - pixels.min(axis=0)
        area += float(extent[0] * extent[1])
        triangles += len(part.indices)
    return area / triangles if triangles else None


def dense(r, scene, view_projection: np.ndarray, image_size: tuple[int, int], maps=None) -> bool:
    """"auto"'s choice: the visibility buffer where the mesh has fewer estimated covered pixels
    per triangle (``pixels_per_triangle``) than ``auto_threshold`` for its shading."""
    density = pixels_per_triangle(r, scene, view_projection, image_size)
    return density is not None and density < auto_threshold(r, scene, maps)[0]


def max_viewport(ctx) -> int:
    """GL_MAX_VIEWPORT_DIMS's smaller side: the shading pass's viewport is twice the image's."""
    return int(min(ctx.info["GL_MAX_VIEWPORT_DIMS"]))


_FORMAT_BYTES = {"f": 4, "f2": 2, "i2": 2, "i": 4, "u": 4}


def vertex_layout(gpu_part) -> dict:
    """render/vbuffer_shade.frag's defines for ``gpu_part.vbo``'s layout (GpuPart.layout, e.g.
    '3f 4i2 2f2 2f'): each attribute's offset in 32-bit words, the vertex's size in words, and
    which attributes are packed (int16 snorm normals and tangents, half-float uvs)."""
    fields, names = gpu_part.layout[0].split(), gpu_part.layout[1:]
    defines, at = {}, 0
    for field, name in zip(fields, names):
        count = int(field[0])
        kind = field[1:]
        if name == "in_normal":
            defines["NORMAL_AT"] = at // 4
            if kind == "i2":
                defines["NORMAL_SNORM16"] = None
        elif name == "in_uv":
            defines["UV_AT"] = at // 4
            if kind == "f2":
                defines["UV_HALF"] = None
        elif name == "in_uv1":
            defines["UV1_AT"] = at // 4
        elif name == "in_color":
            defines["COLOR_AT"] = at // 4
        at += count * _FORMAT_BYTES[kind]
    if at % 4:
        raise ValueError(f"vertex layout {gpu_part.layout[0]!r} is not whole 32-bit words")
    defines["VERTEX_WORDS"] = at // 4
    if gpu_part.packed:
        defines["TANGENT_SNORM16"] = None
    return defines


def box_rect(lo, hi, view_projection: np.ndarray, size: tuple[int, int]) -> tuple[int, int, int, int] | None:
    """(x, y, width, height) in pixels holding the projection of the box ``lo``..``hi``, a pixel
    wider each way and out to even corners (whole 2x2 blocks, ``size`` being even); None where
    the box reaches behind the eye."""
    corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    clip = corners @ np.asarray(view_projection, np.float64)
    if (clip[:, 3] <= 1e-6).any():
        return None
    pixels = (clip[:, :2] / clip[:, 3:] * 0.5 + 0.5) * np.array(size, np.float64)
    x0, y0 = np.clip(np.floor(pixels.min(axis=0)) - 1, 0, size).astype(int) // 2 * 2
    x1, y1 = np.minimum((np.clip(np.ceil(pixels.max(axis=0)) + 1, 0, size).astype(int) + 1) // 2 * 2, size)
    return (int(x0), int(y0), int(max(x1 - x0, 0)), int(max(y1 - y0, 0)))


def draw(r, frame, scene, camera, view_projection: np.ndarray, targets, program_for, image_size,
         drawn: list | None = None) -> None:
    """The mesh's parts into ``targets.single()`` (cleared by the scene pass): the visibility
    pass, then one shading pass per part. ``program_for(variant, vertex, fragment)``: draw_mesh's
    program with the scene's defines and bindings (IBL, shadows, layer tables). ``drawn``: the
    GPU parts to draw (passes.occluded_parts: the baked parts, with the bake's per-vertex buffers,
    where Scene.occlusion wants them); None: the mesh's own."""

    ctx = r.ctx
    width, height = targets.draw_size
    size = image_size or (width, height)
    parts = list(zip(r.meshes.parts(scene.mesh) if drawn is None else drawn, scene.mesh.parts))
    user_maps = user_maps_present(scene)
    user = r.meshes.user_textures(scene)
    tiling = scene.texture_maps or TextureMaps()
    model = np.eye(4, dtype=np.float32)
    variants = [part_defines(scene, g, part, user_maps) for g, part in parts]

    visibility, visibility_fbo = targets.visibility()
    visibility_fbo.use()
    ctx.viewport = (0, 0, width, height)
    visibility_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
    ctx.enable(moderngl.DEPTH_TEST)
    ctx.depth_func = "<="
    prepared: set[int] = set()
    try:
        for index, ((gpu_part, part), variant) in enumerate(zip(parts, variants)):
            masked = variant.get("ALPHA_MODE") == int(AlphaMode.MASK)
            # An opaque part needs nothing of its material here: one program for all of them.
            program = r.program("render/pbr.vert", "render/vbuffer.frag",
                                alpha_to_coverage(dict(variant), ctx) if masked else None)
            if id(program) not in prepared:
                prepared.add(id(program))
                _bind_view(program, ctx, frame, camera, view_projection, model, None, False)
            if masked:
                bind_part(r, scene, program, gpu_part, part, user, tiling, camera, size)
            set_uniform(program, "u_part", index + 1)
            set_culling(ctx, gpu_part, part)
            gpu_part.vao_for(program).render(moderngl.TRIANGLES)
    finally:
        ctx.disable(moderngl.CULL_FACE)
        ctx.disable(moderngl.DEPTH_TEST)

    targets.single()[1].use()
    ctx.viewport = (0, 0, width, height)
    ctx.enable(moderngl.BLEND)
    ctx.blend_func = (moderngl.ONE, moderngl.ONE)   # each part adds its share of the pixel's mean
    try:
        for index, ((gpu_part, part), variant) in enumerate(zip(parts, variants)):
            rect = box_rect(gpu_part.lo, gpu_part.hi, frame.view_projection, (width, height))
            if rect is not None and (rect[2] == 0 or rect[3] == 0):
                continue   # off screen
            variant = {**variant, "VBUFFER_SHADING": None, **vertex_layout(gpu_part)}
            variant.pop("ALPHA_MODE", None)   # (tested in the visibility pass; the samples are opaque)
            program = program_for(variant, "render/vbuffer_shade.vert", "render/vbuffer_shade.frag")
            set_uniform(program, "u_model", model.tobytes(), write=True)
            set_uniform(program, "u_normal_matrix", np.eye(3, dtype=np.float32).tobytes(), write=True)
            set_uniform(program, "u_camera_position", tuple(float(x) for x in camera.position))
            set_uniform(program, "u_inverse_view_projection", frame.inverse_vp.tobytes(), write=True)
            set_uniform(program, "u_viewport_size", (float(width), float(height)))
            set_uniform(program, "u_part", index + 1)
            bind_part(r, scene, program, gpu_part, part, user, tiling, camera, size)
            visibility.use(UNIT_VISIBILITY)
            gpu_part.vbo.bind_to_storage_buffer(0)
            gpu_part.ibo.bind_to_storage_buffer(1)
            # The tangents only where the variant reads them (common/mesh_material.glsl
            # READS_TANGENT, under which alone the Tangents block is declared), as the forward
            # pass's in_tangent.
            if _active(program, "Tangents"):
                gpu_part._tangents()[0].bind_to_storage_buffer(2)
            if gpu_part.has_visibility:
                for buffer, _format, *names in gpu_part.extra_buffers:
                    if "in_visibility" in names:
                        buffer.bind_to_storage_buffer(3)
                    elif "in_sun_bounce" in names:
                        buffer.bind_to_storage_buffer(4)
                    elif "in_sky_weight" in names and gpu_part.has_sky_weight:
                        buffer.bind_to_storage_buffer(5)
                    elif "in_hit_albedo" in names:
                        buffer.bind_to_storage_buffer(6)
            ctx.scissor = (0, 0, width, height) if rect is None else rect
            # One unclipped triangle over a viewport twice the image's size (render/vbuffer_shade.vert):
            # every 2x2 block inside the scissor is whole, and runs once.
            ctx.viewport = (0, 0, 2 * width, 2 * height)
            r.draws.triangle(program)
    finally:
        ctx.scissor = None
        ctx.viewport = (0, 0, width, height)
        ctx.disable(moderngl.BLEND)


def _active(program: moderngl.Program, name: str) -> bool:
    """Whether ``program`` has the member ``name`` (a storage block among them; llvmpipe lists a
    declared block even where nothing reads it)."""
    try:
        program[name]
    except KeyError:
        return False
    return True
