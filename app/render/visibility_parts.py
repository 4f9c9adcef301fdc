"""The forward pass's side of the visibility bake (alight.core.visibility): which meshes get one,
and their refined parts on the GPU with the baked values as two more vertex attributes
(pbr.vert's in_visibility, in_bounce; HAS_VISIBILITY in shaders/common/occlusion.glsl), and the
suns' light on the occluders (in_sun_bounce: alight.core.visibility.bake_sun_bounce, for the
environment's compact sources in world space; a new map or rotation reruns that pass only).

One ``OcclusionParts`` per renderer keeps, per mesh, the decision (``Scene.occlusion``: 'auto'
bakes where the mean occlusion of the surface, ``occlusion_statistic``, is above
AUTO_MIN_OCCLUSION and the mesh has at most AUTO_MAX_VERTICES vertices; 'on' wherever it is
not the built-in sphere; 'off' never) and the uploaded parts; the bake itself is cached on disk
with the IBL bakes (the renderer's ``bake_cache``), keyed by the mesh's content and the bake's
settings; the sun pass beside it, keyed by the bake's key and the suns' directions.
"""

from __future__ import annotations

import numpy as np

from alight.core.visibility import (AUTO_MAX_VERTICES, DEFAULT_EDGE_FRACTION, DEFAULT_MAX_VERTICES, DEFAULT_RAYS,
                                    VISIBILITY_FIELDS, MeshVisibility, PartVisibility, auto_too_big, bake_sun_bounce,
                                    bake_visibility, embree_available, refined_mesh_part, sun_bounce_key,
                                    visibility_key, wants_occlusion)
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


def cached_sun_bounce(mesh, baked: MeshVisibility, directions, cache=None, rays: int = DEFAULT_RAYS,
                      edge_fraction: float = DEFAULT_EDGE_FRACTION, max_vertices: int = DEFAULT_MAX_VERTICES,
                      light_through=None) -> tuple[list[np.ndarray], bool]:
    """``bake_sun_bounce`` of ``baked`` (the bake of ``mesh`` with these settings) for the suns'
    world ``directions`` (K, 3), through ``cache`` (``sun_bounce_key``); (per part (N, 8)
    float32, whether it came from the cache). No sun: zeros, nothing cast or cached."""
    directions = np.asarray(directions if directions is not None else np.zeros((0, 3)), np.float64).reshape(-1, 3)
    if not len(directions):
        return [np.zeros((len(p.positions), 8), np.float32) for p in baked.parts], False
    bake_key, _ = visibility_key(mesh, rays, edge_fraction, max_vertices, light_through)
    key, description = sun_bounce_key(bake_key, directions, light_through=light_through)
    if cache is not None:
        arrays = cache.load(key, description, "sun bounce bake")
        if arrays is not None:
            values = [arrays.get(f"{i}.sun_bounce") for i in range(len(baked.parts))]
            if all(v is not None and v.shape == (len(p.positions), 8) for v, p in zip(values, baked.parts)):
                return [np.asarray(v, np.float32) for v in values], True
            cache.reject(key, "sun bounce bake", "a part's arrays are missing or of another size")
    values = bake_sun_bounce(baked.parts, directions, light_through=light_through)
    if cache is not None:
        cache.save(key, encode_entry(description, {f"{i}.sun_bounce": v for i, v in enumerate(values)}))
    return values, False


class OcclusionParts:
    """Baked GPU parts per mesh, made on first use; ``cache``: a BakeCache or None.
    Counters: ``bakes_run`` (ray-traced here), ``bakes_loaded`` (from the cache), ``last_seconds``
    (the last bake's wall time); ``sun_bakes_run``, ``sun_bakes_loaded``: the same for the sun pass."""

    def __init__(self, ctx, cache=None, rays: int = DEFAULT_RAYS,
                 edge_fraction: float = DEFAULT_EDGE_FRACTION, max_vertices: int = DEFAULT_MAX_VERTICES):
        self.ctx = ctx
        self.cache = cache
        self.rays, self.edge_fraction, self.max_vertices = rays, edge_fraction, max_vertices
        self._wanted: dict[tuple[int, str], tuple[object, bool]] = {}
        self._parts: dict[int, tuple[object, list]] = {}
        self.bakes_run = 0
        self.bakes_loaded = 0
        self.sun_bakes_run = 0      # the suns' light on the occluders (bake_sun_bounce), per new set of suns
        self.sun_bakes_loaded = 0
        self.sun_bounce = True      # False: the occluders see the map without its suns (the benchmarks' before)
        self.last_seconds = 0.0

    def wanted(self, mesh, mode: str) -> bool:
        """Whether ``mesh`` is drawn with occlusion under ``mode`` (decided once per mesh)."""
        entry = self._wanted.get((id(mesh), mode))
        if entry is None or entry[0] is not mesh:
            entry = self._wanted[(id(mesh), mode)] = (mesh, wants_occlusion(mesh, mode))
        return entry[1]

    def parts_for(self, mesh, mode: str, drawn: list, make_part, through=None, sun_directions=None) -> list:
        """The GPU parts to draw for ``mesh``: its baked ones where it is wanted, else ``drawn``.
        ``make_part(part)`` uploads a MeshPart (alight.render.gpu_mesh.GpuPart, the mesh's
        textures shared); ``through``: the parts' light_through (None: all opaque);
        ``sun_directions``: (K, 3) world directions of the environment's compact sources (None:
        none), whose light on the occluders is baked (``cached_sun_bounce``) when they change."""
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
                # Written in place when the suns change (the vertex arrays keep the buffer).
                g.extra_buffers.append((self.ctx.buffer(reserve=len(vis.positions) * 32), "4f 4f", "in_sun_bounce",
                                        "in_sun_bounce2"))
                g.has_visibility = True
                gpu.append(g)
            entry = self._parts[id(mesh)] = [mesh, gpu, through, baked, None]
        suns = np.zeros((0, 3)) if sun_directions is None or not self.sun_bounce else np.asarray(sun_directions, np.float64).reshape(-1, 3)
        sun_key = tuple(np.round(suns, 5).ravel())
        if entry[4] != sun_key:
            values, loaded = cached_sun_bounce(mesh, entry[3], suns, self.cache, self.rays, self.edge_fraction,
                                               self.max_vertices, through)
            if len(suns):
                self.sun_bakes_loaded += int(loaded)
                self.sun_bakes_run += int(not loaded)
            for g, v in zip(entry[1], values):
                g.extra_buffers[-1][0].write(np.ascontiguousarray(v, np.float32).tobytes())
            entry[4] = sun_key
        return entry[1]

    @staticmethod
    def _release(parts) -> None:
        for g in parts:
            for extra in g.extra_buffers:
                extra[0].release()
            g.release()

    def release(self) -> None:
        for entry in self._parts.values():
            self._release(entry[1])
        self._parts.clear()
        self._wanted.clear()
