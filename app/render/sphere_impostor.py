"""The built-in sphere's stand-ins (alight.core.sphere_lod): the coarsest tessellation whose
outline stays within a pixel budget, and the impostor, a flat proxy polygon whose pixels test
their sample rays against the true sphere (mesh_material.glsl SPHERE_IMPOSTOR)."""

from __future__ import annotations

import math

import numpy as np

from alight.core.mesh import MeshPart, sphere
from alight.core.sphere_lod import (
    SPHERE_LOD_SEGMENTS,
    impostor_proxy_model,
    impostor_proxy_polygon,
    projected_radius_px,
    sphere_segments,
)
from alight.render.gpu_mesh import GpuMeshes, GpuPart
from alight.render.variants import part_defines, user_maps_present

# The impostor's proxy polygon as homogeneous points (rows), for impostor_placement's clipping check.
_PROXY_POINTS = np.hstack([impostor_proxy_polygon()[0],
                           np.ones((len(impostor_proxy_polygon()[0]), 1))]).astype(np.float64)
# What a file's material could ask of a part and the built-in sphere's cannot.
_REFUSED = ("ALPHA_MODE", "UNLIT", "HAS_VERTEX_COLOR", "HAS_UV1", "HAS_TEXTURE_TRANSFORM")
_REFUSED_MASKS = ("MAP_MIRROR_S_MASK", "MAP_MIRROR_T_MASK")


def lod_parts(meshes: GpuMeshes, mesh, camera, image_size: tuple[int, int],
              max_error_px: float) -> tuple[list[GpuPart], float | None, int | None]:
    """The GPU parts a pass draws for ``mesh``, the radius of the true sphere they stand for
    where ``mesh`` is the built-in sphere (else None), and the level's segments (else None).

    The built-in sphere (``Mesh.lod_sphere``) seen by a perspective camera from outside is
    drawn at the coarsest level whose outline stays within ``max_error_px`` at ``image_size``
    (the whole image's pixels; alight.core.sphere_lod), never finer than its own, and its
    fragments are shaded on the true sphere (mesh_material.glsl SPHERE_SURFACE), so the level
    moves the outline only. Every pass of a frame, every tile, picks the same."""
    own = meshes.parts(mesh)
    if mesh.lod_sphere is None or len(mesh.parts) != 1 or camera.ortho_half_height is not None:
        return own, None, None
    radius, segments = mesh.lod_sphere
    vp = camera.view_projection(image_size[0] / image_size[1])
    radius_px = projected_radius_px(vp, (0.0, 0.0, 0.0), radius, image_size)
    if not math.isfinite(radius_px):    # the eye at or inside the sphere: drawn as given
        return own, None, None
    n = sphere_segments(radius_px, max_error_px,
                        levels=tuple(x for x in SPHERE_LOD_SEGMENTS if x < segments) + (segments,))
    if n == segments:
        return own, radius, n
    return [meshes.stand_in(mesh, n, lambda: sphere(n, n // 2, radius).parts[0])], radius, n


def impostor_placement(meshes: GpuMeshes, scene, camera, image_size: tuple[int, int],
                       view_projection: np.ndarray | None = None) -> tuple[np.ndarray, float] | None:
    """Where the built-in sphere can be drawn as an impostor, the (4, 4) matrix that places its
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
    if (scene.view == "probe" or mesh is None or scene.ground or mesh.lod_sphere is None
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
    defines = part_defines(scene, meshes.parts(mesh)[0], mesh.parts[0], user_maps_present(scene))
    if any(k in defines for k in _REFUSED) or any(defines.get(k) for k in _REFUSED_MASKS):
        return None
    return model, radius_px


def proxy_part(meshes: GpuMeshes, mesh) -> GpuPart:
    """The impostor's proxy polygon (alight.core.sphere_lod.impostor_proxy_polygon), placed by
    the model matrix of impostor_placement; its normals, uvs and tangents are never read."""
    def make_part() -> MeshPart:
        positions, indices = impostor_proxy_polygon()
        n = len(positions)
        return MeshPart("", positions, np.tile(np.float32([0.0, 0.0, 1.0]), (n, 1)), np.zeros((n, 2), np.float32),
                        np.tile(np.float32([1.0, 0.0, 0.0, 1.0]), (n, 1)), indices, None)

    return meshes.stand_in(mesh, "proxy", make_part)
