"""The forward pass's side of the visibility bake (alight.core.visibility): which meshes get one,
and their refined parts on the GPU with the baked values as two more vertex attributes
(pbr.vert's in_visibility, in_bounce; HAS_VISIBILITY in shaders/common/occlusion.glsl), what the
bounce rays hit by material (in_hit_albedo, in_hit_emission: alight.core.visibility.
bake_occluder_materials, keyed by the parts' materials too, so a colour edit reruns that pass
only), and the suns' light on the occluders (in_sun_bounce: alight.core.visibility.bake_sun_bounce, for the
environment's compact sources in world space; a new map or rotation reruns that pass only), and
the visible sky weight (in_sky_weight: alight.core.sky_weight, HAS_SKY_WEIGHT): its rays cast and
cached once per bake (``cached_sky_rays``), the weight read along them from the environment drawn
(``cached_sky_weight``, keyed by the read-back texels and the rotation too).

One ``OcclusionParts`` per renderer keeps, per mesh, the decision (``Scene.occlusion``: 'auto'
bakes where the mean occlusion of the surface, ``occlusion_statistic``, is above
AUTO_MIN_OCCLUSION and the mesh has at most AUTO_MAX_VERTICES vertices; 'on' wherever it is
not the built-in sphere; 'off' never) and the uploaded parts; the bake itself is cached on disk
with the IBL bakes (the renderer's ``bake_cache``), keyed by the mesh's content and the bake's
settings; the sun pass beside it, keyed by the bake's key and the suns' directions.
"""

from __future__ import annotations

import math

import numpy as np

from alight.core import sky_weight as sw
from alight.core.mesh import single_sided
from alight.core.visibility import (AUTO_MAX_VERTICES, DEFAULT_EDGE_FRACTION, DEFAULT_MAX_VERTICES, DEFAULT_RAYS,
                                    VISIBILITY_FIELDS, MeshVisibility, OccluderMaterial, PartVisibility, auto_too_big,
                                    bake_occluder_materials, bake_sun_bounce, bake_visibility, embree_available,
                                    occluder_materials_key, refined_mesh_part, screen_occlusion, sun_bounce_key,
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


# id(image) -> (image, its mean colour): a texture's mean is read once, not per frame.
_TEXTURE_MEANS: dict[int, tuple] = {}


def texture_mean(image: np.ndarray, srgb: bool) -> np.ndarray:
    """The mean RGB of an (H, W, 4) uint8 texture, linear (decoded first where ``srgb``)."""
    kept = _TEXTURE_MEANS.get(id(image))
    if kept is not None and kept[0] is image:
        return kept[1]
    from alight.core.shading import srgb_to_linear

    rgb = np.asarray(image)[..., :3].reshape(-1, 3)
    table = np.arange(256) / 255.0
    table = srgb_to_linear(table) if srgb else table
    mean = np.array([np.bincount(rgb[:, c], minlength=256) @ table for c in range(3)]) / max(len(rgb), 1)
    if len(_TEXTURE_MEANS) > 256:
        _TEXTURE_MEANS.clear()
    _TEXTURE_MEANS[id(image)] = (image, mean)
    return mean


def occluder_materials(scene) -> tuple[OccluderMaterial, ...]:
    """Per part of ``scene.mesh``, its material as the occluders' pass reads it
    (alight.core.visibility.bake_occluder_materials): the factors the part draws with
    (alight.render.variants.part_material) and, where the file's maps apply, the mean colour of
    its base colour, metallic-roughness (B) and emissive textures multiplied in (one colour per
    map: the hit's uv is not looked up), and its vertex colours."""
    from alight.render.variants import part_material

    out = []
    for part in scene.mesh.parts:
        m, textured = part_material(scene, part)
        base = np.asarray(m.base_color, np.float64)
        metallic = float(m.metallic)
        emission = np.asarray(m.emissive, np.float64)
        fm = part.material if textured else None
        if fm is not None and fm.base_color_texture is not None:
            base = base * texture_mean(fm.base_color_texture.image, True)
        if fm is not None and fm.metallic_roughness_texture is not None:
            metallic *= float(texture_mean(fm.metallic_roughness_texture.image, False)[2])
        if fm is not None and fm.emissive_texture is not None:
            emission = emission * texture_mean(fm.emissive_texture.image, True)
        f0 = np.broadcast_to(np.asarray(m.specular_f0, np.float64), (3,))
        out.append(OccluderMaterial(tuple(float(x) for x in base), metallic, tuple(float(x) for x in f0),
                                    tuple(float(x) for x in emission), bool(textured and part.colors is not None)))
    return tuple(out)


def cached_occluder_materials(mesh, baked: MeshVisibility, materials, cache=None, rays: int = DEFAULT_RAYS,
                              edge_fraction: float = DEFAULT_EDGE_FRACTION, max_vertices: int = DEFAULT_MAX_VERTICES,
                              light_through=None) -> tuple[list[np.ndarray], bool]:
    """``bake_occluder_materials`` of ``baked`` (the bake of ``mesh`` with these settings) for
    ``materials`` (one OccluderMaterial per part), through ``cache`` (``occluder_materials_key``):
    (per part (N, 8) float32, whether it came from the cache)."""
    bake_key, _ = visibility_key(mesh, rays, edge_fraction, max_vertices, light_through)
    key, description = occluder_materials_key(bake_key, materials)
    return _cached_per_vertex(cache, key, description, "occluder materials", "occluders", baked.parts,
                              lambda: bake_occluder_materials(baked.parts, materials))


def _cached_per_vertex(cache, key: str, description, what: str, name: str, parts, compute):
    """Per part an (N, 8) float32 array (N: the part's vertices) from ``cache`` under ``key``
    (entries ``{i}.{name}``), else ``compute()``'s, saved there: (the arrays, whether they came
    from the cache). An entry whose arrays are missing or of another size is rejected (``what``
    names it in the line) and made again."""
    if cache is not None:
        arrays = cache.load(key, description, what)
        if arrays is not None:
            values = [arrays.get(f"{i}.{name}") for i in range(len(parts))]
            if all(v is not None and v.shape == (len(p.positions), 8) for v, p in zip(values, parts)):
                return [np.asarray(v, np.float32) for v in values], True
            cache.reject(key, what, "a part's arrays are missing or of another size")
    values = compute()
    if cache is not None:
        cache.save(key, encode_entry(description, {f"{i}.{name}": v for i, v in enumerate(values)}))
    return values, False


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
                    parts.append(PartVisibility(**values, one_way=single_sided(mesh.parts[i])))
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
    return _cached_per_vertex(cache, key, description, "sun bounce bake", "sun_bounce", baked.parts,
                              lambda: bake_sun_bounce(baked.parts, directions, light_through=light_through))


def environment_texels(shaders, maps, size: int = sw.SKY_TEXELS) -> tuple[np.ndarray, str]:
    """The environment's light as the sky weight reads it: the box mip of ``size`` texels a face
    of the IBL's source cube without its compact sources (``maps.lighting_environment``, else
    ``maps.environment``: the cube the irradiance map is made from), (6, size, size, 3) float32
    in map space, and its digest; read back once per ``maps``."""
    from alight.ibl.bake import read_cube

    kept = getattr(maps, "_sky_texels", None)
    if kept is not None and kept[0].shape[1] == size:
        return kept
    cube = maps.lighting_environment if maps.lighting_environment is not None else maps.environment
    level = max(0, int(round(math.log2(max(cube.size[0], 1) / size))))
    texels = np.ascontiguousarray(read_cube(shaders, cube, level)[..., :3], np.float32)
    kept = (texels, sw.texels_digest(texels))
    maps._sky_texels = kept
    return kept


def cached_sky_rays(mesh, baked: MeshVisibility, cache=None, rays: int = DEFAULT_RAYS,
                    edge_fraction: float = DEFAULT_EDGE_FRACTION, max_vertices: int = DEFAULT_MAX_VERTICES,
                    light_through=None) -> tuple[list[tuple[np.ndarray, np.ndarray]], bool]:
    """``sky_weight.sky_rays`` of ``baked`` through ``cache`` (``sky_rays_key``): (per part (free
    (N, R) uint8, angle (N,) float32), whether it came from the cache)."""
    bake_key, _ = visibility_key(mesh, rays, edge_fraction, max_vertices, light_through)
    key, description = sw.sky_rays_key(bake_key, rays, light_through)
    if cache is not None:
        arrays = cache.load(key, description, "sky rays")
        if arrays is not None:
            values = [(arrays.get(f"{i}.free"), arrays.get(f"{i}.angle")) for i in range(len(baked.parts))]
            if all(f is not None and a is not None and f.shape == (len(p.positions), rays) and a.shape == (len(p.positions),)
                   for (f, a), p in zip(values, baked.parts)):
                return [(np.asarray(f, np.uint8), np.asarray(a, np.float32)) for f, a in values], True
            cache.reject(key, "sky rays", "a part's arrays are missing or of another size")
    values = sw.sky_rays(baked.parts, rays, light_through=light_through)
    if cache is not None:
        arrays = {}
        for i, (f, a) in enumerate(values):
            arrays[f"{i}.free"], arrays[f"{i}.angle"] = f, a
        cache.save(key, encode_entry(description, arrays))
    return values, False


class OcclusionParts:
    """Baked GPU parts per mesh, made on first use; ``cache``: a BakeCache or None.
    Counters: ``bakes_run`` (ray-traced here), ``bakes_loaded`` (from the cache), ``last_seconds``
    (the last bake's wall time); ``sun_bakes_run``, ``sun_bakes_loaded``: the same for the sun pass;
    ``sky_rays_run``, ``sky_rays_loaded`` for the sky weight's rays and ``sky_weights_run``,
    ``sky_weights_loaded`` for the weight (``last_sky_seconds``: the last weight's wall time, its
    rays included when they were cast)."""

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
        self.sky_weight = True      # False: no visible sky weight (HAS_SKY_WEIGHT off: the benchmarks' before)
        self.sky_rays_run = 0
        self.sky_rays_loaded = 0
        self.sky_weights_run = 0
        self.sky_weights_loaded = 0
        self.last_sky_seconds = 0.0
        self.occluder_bakes_run = 0      # the occluders' materials (bake_occluder_materials)
        self.occluder_bakes_loaded = 0
        # True: a mesh already drawn baked keeps its suns' and sky's values (a few degrees of
        # rotation stale) instead of making new ones in this draw: the editor sets it while its
        # child process makes them (alight.frontends.editor.occlusion_bake), as each takes seconds.
        self.hold_lighting = False

    def decide(self, mesh, mode: str, wanted: bool) -> None:
        """Record ``wants_occlusion(mesh, mode)`` decided elsewhere (the editor's child process
        casts its rays), so ``wanted`` casts none."""
        self._wanted[(id(mesh), mode)] = (mesh, bool(wanted))

    def wanted(self, mesh, mode: str) -> bool:
        """Whether ``mesh`` is drawn with occlusion under ``mode`` (decided once per mesh)."""
        entry = self._wanted.get((id(mesh), mode))
        if entry is None or entry[0] is not mesh:
            entry = self._wanted[(id(mesh), mode)] = (mesh, wants_occlusion(mesh, mode))
        return entry[1]

    def screen_wanted(self, mesh, mode: str) -> bool:
        """Whether ``mesh`` is drawn with screen-space GTAO under ``mode``
        (alight.core.visibility.screen_occlusion; 'auto' decides as ``wanted`` does, once)."""
        if mode == "gtao":
            return screen_occlusion(mesh, mode)
        if mode != "auto" or mesh is None or not auto_too_big(mesh):
            return False
        return screen_occlusion(mesh, mode, self.wanted(mesh, mode))

    def parts_for(self, mesh, mode: str, drawn: list, make_part, through=None, sun_directions=None, sky=None,
                  materials=None) -> list:
        """The GPU parts to draw for ``mesh``: its baked ones where it is wanted, else ``drawn``.
        ``make_part(part)`` uploads a MeshPart (alight.render.gpu_mesh.GpuPart, the mesh's
        textures shared); ``through``: the parts' light_through (None: all opaque);
        ``sun_directions``: (K, 3) world directions of the environment's compact sources (None:
        none), whose light on the occluders is baked (``cached_sun_bounce``) when they change;
        ``sky``: (a callable giving the environment's read-back texels and their digest,
        ``environment_texels``; the rotation in degrees) or None: the parts' visible sky weight,
        made (``cached_sky_weight``) when they change; ``materials``: the parts' OccluderMaterial
        (``occluder_materials``; None: every occluder taken as the surface's own material), what
        the bounce rays hit made of them (``cached_occluder_materials``) when they change."""
        if not self.wanted(mesh, mode):
            return drawn
        if mode == "auto" and not embree_available():
            # 'auto' never stops a render: it says once what it drew without ('on' raises).
            warn(f"{mesh.source}: rendered without occlusion of the environment light: the visibility bake "
                 f"needs embreex (pip install embreex)")
            return drawn
        if mode == "auto" and auto_too_big(mesh):
            # (the scene pass draws it with screen-space GTAO instead: screen_wanted). Worded as
            # the value, not a flag, so it reads right from the CLI (--occlusion on) and the API
            # (set_occlusion('on')) alike.
            warn(f"{mesh.source}: occlusion of the environment light in screen space (gtao) instead of the "
                 f"visibility bake: {sum(len(p.positions) for p in mesh.parts)} vertices are more than "
                 f"occlusion 'auto' bakes ({AUTO_MAX_VERTICES}); occlusion 'on' bakes it")
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
                g.extra_buffers.append((self.ctx.buffer(reserve=len(vis.positions) * 16), "4f", "in_sky_weight"))
                # The occluders' materials (zeros until written: this surface's own albedo, no emission).
                g.extra_buffers.append((self.ctx.buffer(reserve=len(vis.positions) * 32), "4f 4f", "in_hit_albedo",
                                        "in_hit_emission"))
                g.has_visibility = True
                gpu.append(g)
            entry = self._parts[id(mesh)] = [mesh, gpu, through, baked, None, None, None]
        if materials is not None and entry[6] != materials and not self.hold_lighting:
            values, loaded = cached_occluder_materials(mesh, entry[3], materials, self.cache, self.rays,
                                                       self.edge_fraction, self.max_vertices, through)
            self.occluder_bakes_loaded += int(loaded)
            self.occluder_bakes_run += int(not loaded)
            for g, v in zip(entry[1], values):
                g.extra_buffers[3][0].write(np.ascontiguousarray(v, np.float32).tobytes())
            entry[6] = materials
        suns = np.zeros((0, 3)) if sun_directions is None or not self.sun_bounce else np.asarray(sun_directions, np.float64).reshape(-1, 3)
        sun_key = tuple(np.round(suns, 5).ravel())
        if self.hold_lighting and entry[4] is not None:
            sun_key = entry[4]       # the last suns' values stay until the new ones are made
        elif self.hold_lighting:
            suns, sun_key = np.zeros((0, 3)), ()   # none made yet: the occluders without suns (no ray)
        if entry[4] != sun_key:
            values, loaded = cached_sun_bounce(mesh, entry[3], suns, self.cache, self.rays, self.edge_fraction,
                                               self.max_vertices, through)
            if len(suns):
                self.sun_bakes_loaded += int(loaded)
                self.sun_bakes_run += int(not loaded)
            for g, v in zip(entry[1], values):
                g.extra_buffers[1][0].write(np.ascontiguousarray(v, np.float32).tobytes())
            entry[4] = sun_key
        if sky is None or not self.sky_weight or (self.hold_lighting and entry[5] is None):
            for g in entry[1]:       # the buffer keeps the weight of entry[5] for the next frame
                g.has_sky_weight = False
        elif self.hold_lighting:
            for g in entry[1]:       # the last weight, read along the last rotation
                g.has_sky_weight = True
        else:
            texels, digest = sky[0]()
            sky_key = (digest, round(float(sky[1]) % 360.0, 6))
            if entry[5] != sky_key:
                values = self.cached_sky_weight(mesh, entry[3], texels, digest, sky[1], through)
                for g, v in zip(entry[1], values):
                    g.extra_buffers[2][0].write(np.ascontiguousarray(v, np.float32).tobytes())
                entry[5] = sky_key
            for g in entry[1]:
                g.has_sky_weight = True
        return entry[1]

    def cached_sky_weight(self, mesh, baked: MeshVisibility, texels, digest: str, rotation_deg: float,
                          through=None) -> list[np.ndarray]:
        """Per part (N, 4) float32, the visible sky weight of ``baked`` under the environment
        ``texels`` (digest ``digest``) turned by ``rotation_deg``, through the cache
        (``sky_weight_key``): a hit casts nothing and reads no rays; a miss reads the rays from the
        cache (``cached_sky_rays``; cast on a miss) and weighs them (numpy)."""
        import time

        bake_key, _ = visibility_key(mesh, self.rays, self.edge_fraction, self.max_vertices, through)
        key, description = sw.sky_weight_key(bake_key, digest, rotation_deg, self.rays)
        if self.cache is not None:
            arrays = self.cache.load(key, description, "sky weight")
            if arrays is not None:
                values = [arrays.get(f"{i}.sky_weight") for i in range(len(baked.parts))]
                if all(v is not None and v.shape == (len(p.positions), 4) for v, p in zip(values, baked.parts)):
                    self.sky_weights_loaded += 1
                    return [np.asarray(v, np.float32) for v in values]
                self.cache.reject(key, "sky weight", "a part's arrays are missing or of another size")
        start = time.perf_counter()
        rays, loaded = cached_sky_rays(mesh, baked, self.cache, self.rays, self.edge_fraction, self.max_vertices,
                                       through)
        self.sky_rays_loaded += int(loaded)
        self.sky_rays_run += int(not loaded)
        values = [sw.sky_weight(free, angle, p.normals, p.indices.reshape(-1, 3), texels, rotation_deg,
                                positions=p.positions)
                  for (free, angle), p in zip(rays, baked.parts)]
        self.last_sky_seconds = time.perf_counter() - start
        self.sky_weights_run += 1
        if self.cache is not None:
            self.cache.save(key, encode_entry(description, {f"{i}.sky_weight": v for i, v in enumerate(values)}))
        return values

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
