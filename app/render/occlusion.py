"""Per-vertex ambient occlusion of the environment light, baked once per mesh on the GPU
(``Scene.occlusion``; alight.core.occlusion_bake has the maths and its numpy twin): the mesh's
depth seen from DIRECTIONS directions spread over the sphere, every vertex tested against each
map in a compute shader.
The result is one float per vertex in a storage buffer per part, which pbr.vert reads by
gl_VertexID (HAS_VERTEX_OCCLUSION) so the vertex layout is unchanged; mesh_material.glsl takes
the minimum with the glTF occlusion texture.

The bake is for still renders and the editor alike: DamagedHelmet's took the time
docs/shadows_notes.md gives, once per mesh: kept in memory by mesh, and on disk in the IBL bake's
store (alight.ibl.bake_cache) under the hash of the mesh's geometry, the bake's settings, its
shaders and code and the GL renderer, so a later process loads it."""

from __future__ import annotations

import hashlib
import importlib.util
import json
from pathlib import Path

import moderngl
import numpy as np

from alight.core.occlusion_bake import occlusion, sphere_directions
from alight.core.shadow_fit import directional_view

DIRECTIONS = 96
RESOLUTION = 512


class OcclusionBake:
    def __init__(self, ctx: moderngl.Context, shaders, cache=None):
        self.ctx = ctx
        self.shaders = shaders     # alight.core.gpu.ShaderLibrary
        self.cache = cache         # alight.ibl.bake_cache.BakeCache, or None: memory only
        self.bakes_run = 0
        self.bakes_loaded = 0
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
        values = self._load(mesh)
        if values is None:
            values = self._bake(mesh, gpu_parts, draw_parts)
            self._save(mesh, values)
        buffers = [self.ctx.buffer(np.ascontiguousarray(v, np.float32).tobytes()) for v in values]
        self._cache[id(mesh)] = (mesh, buffers, values)
        return buffers

    def _bake(self, mesh, gpu_parts, draw_parts) -> list[np.ndarray]:
        """Each direction: its depth map drawn, then every vertex tested in a compute shader
        (render/occlusion_accumulate.comp) that adds to per-vertex sums kept on the GPU, read
        back once at the end (a read back per direction cost 60 ms of llvmpipe's time each)."""
        ctx = self.ctx
        if self._depth is None:
            self._depth = ctx.depth_texture((RESOLUTION, RESOLUTION))
            self._depth.compare_func = ""             # read as depths (texelFetch)
            self._fbo = ctx.framebuffer(depth_attachment=self._depth)
        prog = self.shaders.compute("render/occlusion_accumulate.comp")
        centre, radius = mesh.bounding_sphere()
        parts = []
        for p in mesh.parts:
            n = len(p.positions)
            parts.append((n, ctx.buffer(np.ascontiguousarray(p.positions, np.float32).tobytes()),
                          ctx.buffer(np.ascontiguousarray(p.normals, np.float32).tobytes()),
                          ctx.buffer(np.zeros((max(n, 1), 2), np.float32).tobytes())))
        self._fbo.use()
        ctx.viewport = (0, 0, RESOLUTION, RESOLUTION)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        ctx.disable(moderngl.CULL_FACE)
        try:
            for toward in sphere_directions(DIRECTIONS):
                view = directional_view(-toward, centre, radius, RESOLUTION)
                self._fbo.use()
                self._fbo.clear(depth=1.0)
                draw_parts(np.ascontiguousarray(view.matrix.T, np.float32).tobytes(), gpu_parts)
                self._depth.use(0)
                prog["u_depth"] = 0
                prog["u_matrix"].write(np.ascontiguousarray(view.matrix.T, np.float32).tobytes())
                prog["u_toward"] = tuple(float(x) for x in toward)
                prog["u_texel"] = float(view.texel)
                prog["u_depth_range"] = float(view.far - view.near)
                for n, positions, normals, sums in parts:
                    if n == 0:
                        continue
                    positions.bind_to_storage_buffer(0)
                    normals.bind_to_storage_buffer(1)
                    sums.bind_to_storage_buffer(2)
                    prog["u_count"] = n
                    prog.run((n + 63) // 64)
                ctx.memory_barrier()
            out = []
            for n, *_, sums in parts:
                s = np.frombuffer(sums.read(), np.float32).reshape(-1, 2)[:n].astype(np.float64)
                out.append(occlusion(s[:, 0], s[:, 1]))
        finally:
            ctx.disable(moderngl.DEPTH_TEST)
            for _, *buffers in parts:
                for buf in buffers:
                    buf.release()
        self.bakes_run += 1
        return out

    def _key(self, mesh) -> tuple[str, dict]:
        from alight.core.gpu import describe

        geometry = hashlib.sha256()
        for p in mesh.parts:
            for a in (p.positions, p.normals, p.indices):
                a = np.ascontiguousarray(a)
                geometry.update(str((a.dtype.str, a.shape)).encode())
                geometry.update(a.tobytes())
        code = hashlib.sha256()
        for name in ("alight.render.occlusion", "alight.core.occlusion_bake", "alight.core.shadow_fit"):
            code.update(Path(importlib.util.find_spec(name).origin).read_bytes())
        description = {
            "what": "vertex occlusion", "geometry": geometry.hexdigest(), "directions": DIRECTIONS,
            "resolution": RESOLUTION, "code": code.hexdigest(), "renderer": describe(self.ctx),
            "shaders": {name: self.shaders.digest(name) for name in
                        ("render/occlusion_accumulate.comp", "render/shadow_depth.vert", "render/shadow_depth.frag")},
        }
        text = json.dumps(description, sort_keys=True)
        return "alight-occlusion-" + hashlib.sha256(text.encode()).hexdigest(), description

    def _load(self, mesh) -> list[np.ndarray] | None:
        if self.cache is None:
            return None
        key, description = self._key(mesh)
        arrays = self.cache.load(key, description, f"{mesh.source}'s occlusion")
        if arrays is None:
            return None
        values = [arrays.get(f"part{i}") for i in range(len(mesh.parts))]
        if any(v is None or v.shape != (len(p.positions),) for v, p in zip(values, mesh.parts)):
            self.cache.reject(key, f"{mesh.source}'s occlusion", "not a bake of this mesh")
            return None
        self.bakes_loaded += 1
        return [np.asarray(v, np.float32) for v in values]

    def _save(self, mesh, values: list[np.ndarray]) -> None:
        if self.cache is None:
            return
        from alight.ibl.bake_cache import encode_entry

        key, description = self._key(mesh)
        self.cache.save(key, encode_entry(description, {f"part{i}": v for i, v in enumerate(values)}))

    def release(self) -> None:
        for entry in self._cache.values():
            for buf in entry[1]:
                buf.release()
        self._cache.clear()
        for obj in (self._fbo, self._depth):
            if obj is not None:
                obj.release()
        self._fbo = self._depth = None
