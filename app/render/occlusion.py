"""Per-vertex ambient occlusion of the environment light, baked once per mesh on the GPU
(``Scene.occlusion``; alight.core.occlusion_bake has the maths): the mesh's depth seen from
DIRECTIONS directions spread over the sphere, each read back and tested against every vertex.
The result is one float per vertex in a storage buffer per part, which pbr.vert reads by
gl_VertexID (HAS_VERTEX_OCCLUSION) so the vertex layout is unchanged; mesh_material.glsl takes
the minimum with the glTF occlusion texture.

The bake is for still renders and the editor alike: DamagedHelmet's took the time
docs/shadows_notes.md gives, once per mesh and process (kept in memory by mesh)."""

from __future__ import annotations

import moderngl
import numpy as np

from alight.core.occlusion_bake import accumulate, occlusion, sphere_directions, visible_from
from alight.core.shadow_fit import directional_view

DIRECTIONS = 96
RESOLUTION = 512


class OcclusionBake:
    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.bakes_run = 0
        self._cache: dict[int, tuple[object, list[moderngl.Buffer], list[np.ndarray]]] = {}
        self._depth: moderngl.Texture | None = None
        self._fbo: moderngl.Framebuffer | None = None

    def values(self, mesh) -> list[np.ndarray] | None:
        """The baked (N,) occlusion of each part of ``mesh``, or None if not baked."""
        entry = self._cache.get(id(mesh))
        return entry[2] if entry is not None and entry[0] is mesh else None

    def buffers(self, mesh, gpu_parts, draw_parts) -> list[moderngl.Buffer]:
        """One storage buffer per part of ``mesh`` (its vertices' occlusion, float32), baked on
        first use. ``draw_parts(matrix_bytes, parts)`` draws the casters (alight.render.shadows)."""
        entry = self._cache.get(id(mesh))
        if entry is not None and entry[0] is mesh:
            return entry[1]
        for old in [k for k, e in self._cache.items() if e[0] is not mesh]:
            for buf in self._cache.pop(old)[1]:
                buf.release()
        values = self._bake(mesh, gpu_parts, draw_parts)
        buffers = [self.ctx.buffer(np.ascontiguousarray(v, np.float32).tobytes()) for v in values]
        self._cache[id(mesh)] = (mesh, buffers, values)
        return buffers

    def _bake(self, mesh, gpu_parts, draw_parts) -> list[np.ndarray]:
        ctx = self.ctx
        if self._depth is None:
            self._depth = ctx.depth_texture((RESOLUTION, RESOLUTION))
            self._fbo = ctx.framebuffer(depth_attachment=self._depth)
        centre, radius = mesh.bounding_sphere()
        positions = [np.asarray(p.positions, np.float64) for p in mesh.parts]
        normals = [np.asarray(p.normals, np.float64) for p in mesh.parts]
        weights = [np.zeros(len(p)) for p in positions]
        seen = [np.zeros(len(p)) for p in positions]
        self._fbo.use()
        ctx.viewport = (0, 0, RESOLUTION, RESOLUTION)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        ctx.disable(moderngl.CULL_FACE)
        try:
            for toward in sphere_directions(DIRECTIONS):
                view = directional_view(-toward, centre, radius, RESOLUTION)
                self._fbo.clear(depth=1.0)
                draw_parts(np.ascontiguousarray(view.matrix.T, np.float32).tobytes(), gpu_parts)
                depth = np.frombuffer(self._depth.read(), np.float32).reshape(RESOLUTION, RESOLUTION)
                for i in range(len(positions)):
                    visible = visible_from(view, depth, positions[i], normals[i], toward)
                    accumulate(weights[i], seen[i], normals[i], toward, visible)
        finally:
            ctx.disable(moderngl.DEPTH_TEST)
        self.bakes_run += 1
        return [occlusion(w, s) for w, s in zip(weights, seen)]

    def release(self) -> None:
        for entry in self._cache.values():
            for buf in entry[1]:
                buf.release()
        self._cache.clear()
        for obj in (self._fbo, self._depth):
            if obj is not None:
                obj.release()
        self._fbo = self._depth = None
