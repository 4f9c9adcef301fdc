"""The forward pass's side of the visibility bake (alight.core.visibility): which meshes get one,
and their refined parts on the GPU with the baked values as two more vertex attributes
(pbr.vert's in_visibility, in_bounce; HAS_VISIBILITY in shaders/common/occlusion.glsl).

One ``OcclusionParts`` per renderer keeps, per mesh, the decision (``Scene.occlusion``: 'auto'
bakes where the mean occlusion of the surface, ``occlusion_statistic``, is above
AUTO_MIN_OCCLUSION and the mesh has at most AUTO_MAX_VERTICES vertices; 'on' wherever it is
not the built-in sphere; 'off' never) and the uploaded parts; the bake itself is cached on disk
with the IBL bakes (the renderer's ``bake_cache``), keyed by the mesh's content and the bake's
settings.
"""

from __future__ import annotations

import numpy as np

from alight.core.visibility import (AUTO_MAX_VERTICES, DEFAULT_EDGE_FRACTION, DEFAULT_MAX_VERTICES, DEFAULT_RAYS,
                                    VISIBILITY_FIELDS, MeshVisibility, PartVisibility, auto_too_big, bake_visibility,
                                    embree_available, refined_mesh_part, visibility_key, wants_occlusion)
from alight.errors import warn
from alight.ibl.bake_cache import BadEntry, encode_entry


def light_through(scene) -> tuple[float, ...] | None:
    """Per part of ``scene.mesh``, the share of light it lets through to what lies behind it (the
    bake's and the shadow maps' casters): transmission (KHR_materials_transmission's factor) times
    (1 - metallic), or 1 - alpha for a part drawn blended; None where every part is opaque.
    The factors only: a transmission texture is not read (one number per part)."""
    from alight.render.variants import blends, part_material

    values = []
    for part in scene.mesh.parts:
        m, _ = part_material(scene, part)
        t = float(m.transmission) * (1.0 - float(m.metallic))
        if blends(scene, part):
            t = max(t, 1.0 - float(part.material.alpha))
        values.append(min(max(t, 0.0), 1.0))
    return tuple(values) if any(v > 0.0 for v in values) else None


def cached_visibility(mesh, cache=None, rays: int = DEFAULT_RAYS, edge_fraction: float = DEFAULT_EDGE_FRACTION,
                      max_vertices: int = DEFAULT_MAX_VERTICES, light_through=None) -> MeshVisibility:
    """``bake_visibility``, through ``cache`` (an ``alight.ibl.bake_cache.BakeCache``; None: no
    cache) keyed by the mesh's content, the parts' ``light_through`` and the bake settings
    (``visibility_key``)."""
    key, description = visibility_key(mesh, rays, edge_fraction, max_vertices, light_through)
    if cache is not None:
        arrays = cache.load(key, description, "visibility bake")
        if arrays is not None:
            try:
                parts = []
                for i in range(len(mesh.parts)):
                    values = {f: arrays.get(f"{i}.{f}") for f in VISIBILITY_FIELDS}
                    if any(values[f] is None for f in VISIBILITY_FIELDS if f not in ("uvs1", "colors")):
                        raise BadEntry("a part's arrays are missing")
                    parts.append(PartVisibility(**values))
                return MeshVisibility(parts, from_cache=True)
            except BadEntry as exc:
                cache.reject(key, "visibility bake", str(exc))
    result = bake_visibility(mesh, rays, edge_fraction, max_vertices, light_through=light_through)
    if cache is not None:
        arrays = {f"{i}.{f}": getattr(p, f) for i, p in enumerate(result.parts) for f in VISIBILITY_FIELDS
                  if getattr(p, f) is not None}
        cache.save(key, encode_entry(description, arrays))
    return result


class OcclusionParts:
    """Baked GPU parts per mesh, made on first use; ``cache``: a BakeCache or None.
    Counters: ``bakes_run`` (ray-traced here), ``bakes_loaded`` (from the cache), ``last_seconds``
    (the last bake's wall time)."""

    def __init__(self, ctx, cache=None, rays: int = DEFAULT_RAYS,
                 edge_fraction: float = DEFAULT_EDGE_FRACTION, max_vertices: int = DEFAULT_MAX_VERTICES):
        self.ctx = ctx
        self.cache = cache
        self.rays, self.edge_fraction, self.max_vertices = rays, edge_fraction, max_vertices
        self._wanted: dict[tuple[int, str], tuple[object, bool]] = {}
        self._parts: dict[int, tuple[object, list]] = {}
        self.bakes_run = 0
        self.bakes_loaded = 0
        self.last_seconds = 0.0

    def wanted(self, mesh, mode: str) -> bool:
        """Whether ``mesh`` is drawn with occlusion under ``mode`` (decided once per mesh)."""
        entry = self._wanted.get((id(mesh), mode))
        if entry is None or entry[0] is not mesh:
            entry = self._wanted[(id(mesh), mode)] = (mesh, wants_occlusion(mesh, mode))
        return entry[1]

    def parts_for(self, mesh, mode: str, drawn: list, make_part, through=None) -> list:
        """The GPU parts to draw for ``mesh``: its baked ones where it is wanted, else ``drawn``.
        ``make_part(part)`` uploads a MeshPart (alight.render.gpu_mesh.GpuPart, the mesh's
        textures shared); ``through``: the parts' light_through (None: all opaque)."""
        if not self.wanted(mesh, mode):
            return drawn
        if mode == "auto" and not embree_available():
            # 'auto' never stops a render: it says once what it drew without ('on' raises).
            warn(f"{mesh.source}: rendered without occlusion of the environment light: the visibility bake "
                 f"needs embreex (pip install embreex)")
            return drawn
        if mode == "auto" and auto_too_big(mesh):
            warn(f"{mesh.source}: rendered without occlusion of the environment light: "
                 f"{sum(len(p.positions) for p in mesh.parts)} vertices are more than --occlusion auto bakes "
                 f"({AUTO_MAX_VERTICES}); --occlusion on bakes it")
            return drawn
        entry = self._parts.get(id(mesh))
        if entry is None or entry[0] is not mesh or entry[2] != through:
            if entry is not None:
                self._release(entry[1])
            baked = cached_visibility(mesh, self.cache, self.rays, self.edge_fraction, self.max_vertices, through)
            if baked.from_cache:
                self.bakes_loaded += 1
            else:
                self.bakes_run += 1
                self.last_seconds = baked.seconds
            gpu = []
            for part, vis in zip(mesh.parts, baked.parts):
                g = make_part(refined_mesh_part(part, vis))
                buffer = self.ctx.buffer(np.ascontiguousarray(vis.vertex_data()).tobytes())
                g.extra_buffers.append((buffer, "4f 4f", "in_visibility", "in_bounce"))
                g.has_visibility = True
                gpu.append(g)
            entry = self._parts[id(mesh)] = (mesh, gpu, through)
        return entry[1]

    @staticmethod
    def _release(parts) -> None:
        for g in parts:
            for extra in g.extra_buffers:
                extra[0].release()
            g.release()

    def release(self) -> None:
        for _, parts, _ in self._parts.values():
            self._release(parts)
        self._parts.clear()
        self._wanted.clear()
