"""What a mesh part binds before it is drawn, shared by the forward pass (passes.py) and the
visibility buffer's shading pass (vbuffer.py): the material, its factors, map transforms and
maps with this view's anisotropy, the culling, and pbr.vert's view transforms."""

from __future__ import annotations

import moderngl
import numpy as np

from alight.core.mesh import single_sided
from alight.core.scene import Camera
from alight.core.shader_names import MATERIAL_MAPS
from alight.core.texture_maps import TextureMaps
from alight.render.bindings import UNIT_MATERIAL, set_material, set_uniform
from alight.render.gpu_mesh import ANISOTROPIC_FILTERS, GpuPart
from alight.render.variants import map_uv_uniforms, part_material


def bind_part(r, scene, program, gpu_part: GpuPart, part, user: dict, tiling: TextureMaps, camera: Camera,
              size: tuple[int, int]) -> None:
    """A part's material, factors, map transforms and maps (with their anisotropy for this view)
    on ``program``; ``user``: the user's maps (GpuMeshes.user_textures)."""
    material, maps_used = part_material(scene, part)
    set_material(program, material)
    _bind_part_factors(program, part.material if maps_used else None, material, maps_used, tiling)
    # Every part: parts whose maps differ only in uv set or transform share a program (variants.py).
    _bind_map_uvs(program, gpu_part, maps_used)
    bound_maps = []
    for name in MATERIAL_MAPS:
        tex = gpu_part.textures.get(name) if maps_used else user.get(name)
        set_uniform(program, f"u_has_{name}_map", tex is not None)
        if tex is not None:
            tex.use(UNIT_MATERIAL[name])
            if tex.filter[0] in ANISOTROPIC_FILTERS and tex.filter[1] != moderngl.NEAREST:
                bound_maps.append(tex)   # (a sampler's nearest magnification keeps 1: MeshTextures)
    if bound_maps:
        _set_anisotropy(r, scene, camera, gpu_part, part, bound_maps, size)


def set_culling(ctx, gpu_part: GpuPart, part) -> None:
    """Back-face culling for the part, as its file or its closedness decides."""
    if part.element.startswith("meshes["):
        # A glTF primitive: the file decides (the default material is single-sided).
        cull = single_sided(part)
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


def _bind_view(program, ctx, frame: FrameContext, camera: Camera, view_projection: np.ndarray, model: np.ndarray,
               sphere_radius: float | None, impostor: bool) -> None:
    """pbr.vert's transforms and the camera, once per program in a draw_mesh_parts call."""
    set_uniform(program, "u_model", model.tobytes(), write=True)
    set_uniform(program, "u_normal_matrix", np.eye(3, dtype=np.float32).tobytes(), write=True)
    set_uniform(program, "u_view_projection", view_projection.astype(np.float32).tobytes(), write=True)
    set_uniform(program, "u_camera_position", tuple(float(x) for x in camera.position))
    set_uniform(program, "u_sphere_radius", float(sphere_radius or 0.0))
    if impostor:   # (the inverse of this pass's view_projection)
        set_uniform(program, "u_inverse_view_projection", frame.inverse_vp.tobytes(), write=True)
        set_uniform(program, "u_viewport_size", tuple(float(x) for x in ctx.viewport[2:]))


def _bind_part_factors(program, fm, material, maps_used: bool, tiling: TextureMaps) -> None:
    """A part's file factors beside its material's (``fm``: its FileMaterial where its maps
    apply, else None) and the uv tiling: a file's maps use its own uvs, the user's are tiled."""
    set_uniform(program, "u_normal_scale", float(fm.normal_scale) if fm else 1.0)
    set_uniform(program, "u_clearcoat_normal_scale", float(fm.clearcoat_normal_scale) if fm else 1.0)
    set_uniform(program, "u_occlusion_strength", float(fm.occlusion_strength) if fm else 1.0)
    set_uniform(program, "u_alpha", float(fm.alpha) if fm else 1.0)
    set_uniform(program, "u_alpha_cutoff", float(fm.alpha_cutoff) if fm else 0.5)
    set_uniform(program, "u_specular_factor", float(fm.specular_factor) if fm else 1.0)
    set_uniform(program, "u_specular_f90", float(fm.specular_f90) if fm else 1.0)
    set_uniform(program, "u_specular_color_f0", tuple(float(x) for x in fm.specular_color_f0) if fm
                else tuple(float(x) for x in material.specular_f0))
    set_uniform(program, "u_uv_scale", (1.0, 1.0) if maps_used else tuple(map(float, tiling.uv_scale)))
    set_uniform(program, "u_uv_offset", (0.0, 0.0) if maps_used else tuple(map(float, tiling.uv_offset)))


def _bind_map_uvs(program, gpu_part: GpuPart, file_maps: bool) -> None:
    """Each map's uv set and KHR_texture_transform matrix (variants.map_uv_uniforms), where the
    variant reads them (HAS_UV1, HAS_TEXTURE_TRANSFORM): nothing to do for most files' parts."""
    member = program.get("u_map_transform", None)
    if member is None and program.get("u_map_uv1", None) is None:
        return
    uv1, transforms = map_uv_uniforms(gpu_part, file_maps)
    set_uniform(program, "u_map_uv1", uv1)
    if member is not None:
        # GLSL mat3 is column-major: upload the transposes. The compiler trims the array after
        # the last slot the variant reads.
        used = transforms.transpose(0, 2, 1)[:member.array_length]
        member.write(np.ascontiguousarray(used, dtype=np.float32).tobytes())


def _set_anisotropy(r, scene, camera: Camera, gpu_part: GpuPart, part, bound_maps, size) -> None:
    """Anisotropic filtering where this view gains from it (alight.core.texture_footprint), not
    everywhere: on llvmpipe 8x costs a textured frame 2-5x. Measured on TEXCOORD_0 as the file
    gives it (not a TEXCOORD_1 map's uvs, nor the user maps' tiling)."""
    finest = max((t.size for t in bound_maps), key=lambda wh: wh[0] * wh[1])
    if scene.mesh is not None and scene.mesh.lod_sphere is not None:
        # The built-in sphere: its stand-ins (the impostor's proxy, coarser levels) have other
        # uvs than the ball they stand for, whose shading they draw: the level is the ball's.
        gpu_part = r.meshes.parts(scene.mesh)[0]
    level = gpu_part.anisotropy(camera.view_projection(size[0] / size[1]), size, finest)
    r.last_anisotropy[part.name] = level
    for tex in bound_maps:
        if tex.anisotropy != level:
            tex.anisotropy = level
