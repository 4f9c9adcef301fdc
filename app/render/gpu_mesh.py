"""The GPU side of meshes: each part's buffers and vertex arrays (GpuPart), a mesh's shared
textures (MeshTextures), the cache of uploaded meshes, the built-in sphere's stand-ins and the
user's maps (GpuMeshes), and the full-screen triangle every full-screen pass draws."""

from __future__ import annotations

import dataclasses

import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary
from alight.core.mesh import is_closed
from alight.core.texture_footprint import anisotropy_for_view, footprints
from alight.render.normal_spread import spread_scale, without_spread
from alight.render.normal_spread_pass import SpreadWriter, level_count

GL_SRGB8_ALPHA8 = 0x8C43
SRGB_MAPS = ("base_color", "emissive", "sheen_color", "specular_color", "diffuse_transmission")
# (diffuse_transmission packs its RGB colour, sRGB, with its A strength: GL_SRGB8_ALPHA8 leaves A linear.)
MAX_UPLOADED_MESHES = 8   # meshes kept on the GPU between frames (GpuMeshes.parts)


# Vertex attributes as the GPU keeps them (GpuPart): normals and tangents as int16, decoded as
# snorm in pbr.vert (PACKED_VERTICES: max(c / 32767, -1), GL 4.2's rule; moderngl's formats have
# no normalized int16, so the shader divides), uvs as half floats where that holds to
# UV_HALF_TEXELS of the textures they address. False: everything float32 (the reference path the
# tests compare the packed one with).
PACK_VERTICES = True
SNORM16 = 32767.0
# Half floats keep 11 significant bits: uvs in [0.5, 1) round by up to 2^-12, a quarter texel of a
# 1024² map. They are used where the rounding stays under this many texels of the largest
# texture the part reads with that uv set; a part with no texture keeps float32 (the user may
# load a map of any size onto it later).
UV_HALF_TEXELS = 1.0 / 8.0


def pack_snorm16(values: np.ndarray) -> np.ndarray:
    """(N, k) values in [-1, 1] as int16 snorm, rounded to nearest (decoded max(c / 32767, -1)):
    at most 1.5e-5 off per component."""
    return np.rint(np.clip(values, -1.0, 1.0) * SNORM16).astype(np.int16)


def unit_directions(values: np.ndarray) -> np.ndarray:
    """(N, 3) directions scaled to unit length (zero rows stay zero), float32: what snorm can
    hold. The shader normalizes after interpolation, so a uniformly scaled normal (a file's normals
    of length 3, or 1e-3) draws as its unit twin; clipped to [-1, 1] or quantized at its own
    length it did not (tests/test_stability.py test_non_unit_mesh_normals_change_nothing)."""
    v = np.asarray(values, np.float32)
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    return v / np.where(length > 0.0, length, 1.0)[:, None]


def unpack_snorm16(packed: np.ndarray) -> np.ndarray:
    """pbr.vert's decode of pack_snorm16, as float32 (its numpy twin)."""
    return np.maximum(packed.astype(np.float32) / np.float32(SNORM16), np.float32(-1.0))


def uvs_hold_as_half(uvs: np.ndarray, texels: int) -> bool:
    """Whether ``uvs`` (N, 2) stored as half floats stay within UV_HALF_TEXELS of a
    ``texels``-wide texture (0: no texture, float32 kept); out of half's range never."""
    if texels <= 0 or not len(uvs):
        return False
    uvs = np.asarray(uvs, np.float32)
    if not np.isfinite(uvs).all() or np.abs(uvs).max() > 60000.0:
        return False
    error = np.abs(uvs.astype(np.float16).astype(np.float32) - uvs).max()
    return bool(error * texels <= UV_HALF_TEXELS)


class GpuPart:
    """A mesh part's buffers, uploaded once, and what its shader variant needs to know.

    The vertex buffer holds position (3 float32), normal (4 int16 snorm, the last 0), uv
    (2 half floats where uvs_hold_as_half, else 2 float32), then TEXCOORD_1 (float32) and COLOR_0
    (4 float32) only when the part has them (pbr.vert's HAS_UV1, HAS_VERTEX_COLOR): 28 or 24
    bytes a vertex against 48 with float32 tangents. The tangents (4 int16 snorm) are a buffer of
    their own, made the first time a program reads ``in_tangent`` (a normal or anisotropy map):
    a part drawn without one never computes them (MeshPart.tangents is lazy). Textures come from
    the mesh's shared set (one upload per image and sampler). No array the size of the mesh stays
    on the CPU here; the MeshPart (the caller's) is kept for the tangents, the closedness test
    and the anisotropy level.
    """

    def __init__(self, ctx: moderngl.Context, part, textures: "MeshTextures", packed: bool | None = None):
        self.packed = PACK_VERTICES if packed is None else bool(packed)
        self.has_uv1 = part.uvs1 is not None
        self.has_colors = part.colors is not None
        self.infos: dict = {}
        fm = part.material
        if fm is not None:
            self.infos = dict(fm.textures().items())
        uv_texels = max((max(info.image.shape[:2]) for info in self.infos.values() if info.tex_coord == 0),
                        default=0)
        self.half_uvs = self.packed and uvs_hold_as_half(part.uvs, uv_texels)
        n = len(part.positions)
        # One structured array, each field written straight from the part's (float32) columns:
        # no hstack of float64 copies, and ctx.buffer reads it without a tobytes() copy.
        fields = [("in_position", np.float32, (3,), "3f")]
        fields.append(("in_normal", np.int16, (4,), "4i2") if self.packed else ("in_normal", np.float32, (3,), "3f"))
        fields.append(("in_uv", np.float16, (2,), "2f2") if self.half_uvs else ("in_uv", np.float32, (2,), "2f"))
        if self.has_uv1:
            fields.append(("in_uv1", np.float32, (2,), "2f"))
        if self.has_colors:
            fields.append(("in_color", np.float32, (4,), "4f"))
        vertices = np.empty(n, np.dtype([(name, dtype, shape) for name, dtype, shape, _ in fields]))
        vertices["in_position"] = part.positions
        if self.packed:
            vertices["in_normal"][:, :3] = pack_snorm16(unit_directions(part.normals))
            vertices["in_normal"][:, 3] = 0
        else:
            vertices["in_normal"] = part.normals
        vertices["in_uv"] = part.uvs
        if self.has_uv1:
            vertices["in_uv1"] = part.uvs1
        if self.has_colors:
            vertices["in_color"] = part.colors
        self.layout = [" ".join(f for *_, f in fields), *(name for name, *_ in fields)]
        self.vertex_bytes = vertices.dtype.itemsize
        self.vbo = ctx.buffer(vertices)
        del vertices
        self.ibo = ctx.buffer(np.ascontiguousarray(part.indices, dtype=np.uint32))
        self.tangent_buffer: moderngl.Buffer | None = None
        self.ctx = ctx
        # More per-vertex buffers, (buffer, format, *names), and whether they carry the visibility
        # bake's values (alight.render.visibility_parts: HAS_VISIBILITY).
        self.extra_buffers: list[tuple] = []
        self.has_visibility = False
        self.has_sky_weight = False     # ... and the visible sky weight (HAS_SKY_WEIGHT)
        # A vertex array belongs to one program: one per program this part is drawn with (the
        # shaded pass, a debug view), made on first use.
        self._vaos: dict[int, moderngl.VertexArray] = {}
        self.textures: dict[str, moderngl.Texture] = {}
        self._part = part
        self._closed: bool | None = None
        self._anisotropy_key = None
        self._anisotropy = 1.0
        positions = part.positions
        # Bounding box corners (float32 reductions, exact: min and max pick elements).
        self.lo = positions.min(axis=0).astype(np.float64) if len(positions) else np.zeros(3)
        self.hi = positions.max(axis=0).astype(np.float64) if len(positions) else np.zeros(3)
        self.centre = (self.lo + self.hi) / 2.0
        for name, info in self.infos.items():
            self.textures[name] = textures.get(info, srgb=name in SRGB_MAPS, spread=spread_scale(name, fm))

    @property
    def closed(self) -> bool:
        """Whether the part is closed (alight.core.mesh.is_closed), found on first use: only a
        part without a glTF material's doubleSided needs to know (a 4M-triangle mesh's test
        takes seconds)."""
        if self._closed is None:
            self._closed = is_closed(self._part.positions, self._part.indices)
        return self._closed

    def anisotropy(self, view_projection: np.ndarray, image_size: tuple[int, int],
                   texture_size: tuple[int, int]) -> float:
        """The anisotropic filtering level this view of the part gains from
        (alight.core.texture_footprint), remembered for the last view asked."""
        key = (np.asarray(view_projection, np.float32).tobytes(), tuple(image_size), tuple(texture_size))
        if self._anisotropy_key != key:
            part = self._part
            uvs = part.uvs
            # The uvs the maps read: KHR_texture_transform's scale (gltfpack's dequantization of
            # quantized uvs among them) multiplies the footprint. The transform that stretches
            # the most sets it.
            mats = [np.asarray(info.transform.gl_matrix(), np.float64) for info in self.infos.values()
                    if info.transform is not None and info.tex_coord == 0]
            if mats:
                m = max(mats, key=lambda m: abs(np.linalg.det(m[:2, :2])))
                uvs = np.asarray(uvs, np.float64) @ m[:2, :2].T + m[:2, 2]
            area, p_max, p_min = footprints(part.positions, uvs, part.indices, view_projection,
                                            image_size, texture_size)
            self._anisotropy = anisotropy_for_view(area, p_max, p_min)
            self._anisotropy_key = key
        return self._anisotropy

    def vao_for(self, program: moderngl.Program) -> moderngl.VertexArray:
        vao = self._vaos.get(id(program))
        if vao is None:
            buffers = [(self.vbo, *self.layout), *self.extra_buffers]
            if program.get("in_tangent", None) is not None:   # active: the variant reads the tangent frame
                buffers.append(self._tangents())
            vao = self._vaos[id(program)] = self.ctx.vertex_array(
                program, buffers, self.ibo, index_element_size=4,
                skip_errors=True)  # a debug view may not read every attribute
        return vao

    def _tangents(self) -> tuple:
        """The tangent buffer and its format, uploaded on first use."""
        if self.tangent_buffer is None:
            tangents = np.asarray(self._part.tangents, np.float32)
            if self.packed:
                tangents = np.concatenate([unit_directions(tangents[:, :3]), tangents[:, 3:]], axis=1)
            data = pack_snorm16(tangents) if self.packed else np.ascontiguousarray(tangents)
            self.tangent_buffer = self.ctx.buffer(data)
        return (self.tangent_buffer, "4i2" if self.packed else "4f", "in_tangent")

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self.vbo.release()
        self.ibo.release()
        if self.tangent_buffer is not None:
            self.tangent_buffer.release()


ANISOTROPIC_FILTERS = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR_MIPMAP_NEAREST,
                        moderngl.NEAREST_MIPMAP_LINEAR, moderngl.NEAREST_MIPMAP_NEAREST)
MIN_FILTERS = {"nearest": moderngl.NEAREST, "linear": moderngl.LINEAR,
                "nearest_mipmap_nearest": moderngl.NEAREST_MIPMAP_NEAREST,
                "linear_mipmap_nearest": moderngl.LINEAR_MIPMAP_NEAREST,
                "nearest_mipmap_linear": moderngl.NEAREST_MIPMAP_LINEAR,
                "linear_mipmap_linear": moderngl.LINEAR_MIPMAP_LINEAR}


class MeshTextures:
    """A mesh's textures, one per (image, colour space, sampler): parts sharing an image share
    its upload. REPEAT and CLAMP_TO_EDGE are the texture's wrap state; MIRRORED_REPEAT is folded
    in the shader (mesh_material.glsl), so its axis is clamped here. ``shaders``: the renderer's
    library, which compiles a normal map's spread pass (upload_normal_map)."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary):
        self.ctx, self.shaders = ctx, shaders
        self._textures: dict[tuple, moderngl.Texture] = {}

    def get(self, info, srgb: bool, spread: float | None = None) -> moderngl.Texture:
        """``spread``: a normal map's scale, whose levels then carry their spread in A
        (alight.render.normal_spread; keyed by it too)."""
        sampler = info.sampler
        key = texture_key(info, srgb, spread)
        tex = self._textures.get(key)
        if tex is None:
            if spread is None:
                tex = upload_image(self.ctx, info.image, srgb, mipmaps=sampler.mipmaps)
            else:
                tex = upload_normal_map(self.ctx, self.shaders, info.image, spread, mipmaps=sampler.mipmaps)
            tex = self._textures[key] = self.sampled(tex, sampler)
        return tex

    @staticmethod
    def sampled(tex: moderngl.Texture, sampler) -> moderngl.Texture:
        """``tex`` (as upload_image leaves it) with the glTF sampler's filters and wrap."""
        tex.filter = (MIN_FILTERS.get(sampler.min_filter, moderngl.LINEAR_MIPMAP_LINEAR),
                      moderngl.NEAREST if sampler.mag_filter == "nearest" else moderngl.LINEAR)
        tex.repeat_x = sampler.wrap_s == "repeat"
        tex.repeat_y = sampler.wrap_t == "repeat"
        if not sampler.mipmaps or sampler.mag_filter == "nearest":
            tex.anisotropy = 1.0
        return tex

    def adopt(self, key: tuple, tex: moderngl.Texture) -> None:
        """A texture uploaded beforehand (alight.render.mesh_upload) under ``get``'s key."""
        self._textures[key] = tex

    def release(self) -> None:
        for tex in self._textures.values():
            tex.release()
        self._textures.clear()


def texture_key(info, srgb: bool, spread: float | None = None) -> tuple:
    """MeshTextures' key of a map: one upload per image, colour space and sampler, and for a
    normal map with its spread in A (``spread``: its scale) per scale too."""
    key = (id(info.image), srgb, info.sampler)
    return key if spread is None else (*key, "spread", float(spread))


def spread_of(key: tuple) -> float | None:
    """The scale a texture's spread is measured at, from its ``texture_key`` (its "spread"
    entry), or None for a texture without."""
    return key[4] if len(key) > 3 and key[3] == "spread" else None


def upload_normal_map(ctx: moderngl.Context, shaders: ShaderLibrary, image: np.ndarray, scale: float,
                      mipmaps: bool = True) -> moderngl.Texture:
    """A normal map as ``upload_image`` makes it (RGB the same: level 0 as the file has it with
    A = 0, GL's generate_mipmap), then the spread of its normals at ``scale`` written into A of
    each level from 1 on, on the GPU by the pass ``shaders`` compiles (the renderer's library;
    alight.render.normal_spread_pass; its numpy twin alight.render.normal_spread). A side that is
    not a power of two: GL's mips with A = 0 (no widening), as before. GL work: the thread that
    owns ``ctx``. Raises ShaderCompileError where the pass's source does not compile."""
    tex = upload_image(ctx, without_spread(image), False, mipmaps)
    h, w = image.shape[:2]
    if mipmaps and not (h & (h - 1) or w & (w - 1)):
        SpreadWriter(ctx, shaders, tex, (w, h), level_count((w, h)), scale).write_all()
    return tex


def level_texture(ctx: moderngl.Context, size: tuple[int, int], levels: int, srgb: bool) -> moderngl.Texture:
    """``upload_image``'s texture (format, filter, anisotropy) with its ``levels`` allocated and
    not yet written: levels made beforehand (alight.render.mesh_upload) are written into it."""
    from alight.core.gpu import rgba8_texture

    tex = rgba8_texture(ctx, size, levels, srgb)
    if levels > 1:
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        tex.anisotropy = 8.0
    else:
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return tex


def upload_image(ctx: moderngl.Context, image: np.ndarray, srgb: bool, mipmaps: bool = True) -> moderngl.Texture:
    """An RGBA uint8 image (alight.core.mesh gives RGBA) as a texture, mipmapped unless told not."""
    image = np.asarray(image, dtype=np.uint8)
    if image.shape[2] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
    # Images arrive top row first; texture coordinate v = 0 is the bottom row (OpenGL, trimesh).
    data = np.ascontiguousarray(image[::-1, :, :4])
    h, w = data.shape[:2]
    tex = ctx.texture((w, h), 4, data.tobytes(), internal_format=GL_SRGB8_ALPHA8 if srgb else None)
    if mipmaps:
        tex.build_mipmaps()
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        tex.anisotropy = 8.0
    else:
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return tex


def release_mesh(entry) -> None:
    for part in entry[1]:
        part.release()
    entry[2].release()


def mark_mesh_uv_features(parts: list["GpuPart"]) -> None:
    """Whether any map of the mesh reads TEXCOORD_1 (``mesh_reads_uv1``) and whether any has
    KHR_texture_transform (``mesh_transforms``), on each of its parts: alight.render.variants
    compiles these in for every textured part of such a mesh, so that its parts share programs."""
    infos = [(gp, info) for gp in parts for info in gp.infos.values()]
    reads_uv1 = any(info.tex_coord == 1 and gp.has_uv1 for gp, info in infos)
    transforms = any(info.transform is not None for _, info in infos)
    for gp in parts:
        gp.mesh_reads_uv1 = reads_uv1
        gp.mesh_transforms = transforms


class GpuMeshes:
    """The uploaded meshes (by the mesh's id, kept while that mesh is the one asked for), the
    built-in sphere's stand-ins (coarser levels, the impostor's proxy: alight.render.sphere_impostor)
    and the user-loaded texture maps (Scene.texture_maps), uploaded once per decoded image."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary):
        self.ctx = ctx
        self.shaders = shaders   # the renderer's library (``use_shaders``): its normal maps' spread pass
        self._meshes: dict[int, tuple[object, list[GpuPart], MeshTextures]] = {}
        # The built-in sphere's stand-ins, by the mesh's id and a key (segments, "proxy").
        self._stand_ins: dict[tuple[int, object], tuple[object, list[GpuPart], MeshTextures]] = {}
        # (path, sRGB) -> (image, texture)
        self._map_textures: dict[tuple[str, bool], tuple[np.ndarray, moderngl.Texture]] = {}

    def parts(self, mesh) -> list[GpuPart]:
        """``mesh``'s parts on the GPU, uploaded on first use (a new mesh object replaces the old)."""
        entry = self._meshes.pop(id(mesh), None)
        if entry is None or entry[0] is not mesh:
            if entry is not None:
                release_mesh(entry)
            # The least recently drawn meshes leave the GPU first (a long editor session or test
            # run draws many; an evicted one uploads again when next drawn).
            while len(self._meshes) >= MAX_UPLOADED_MESHES:
                release_mesh(self._meshes.pop(next(iter(self._meshes))))
            textures = MeshTextures(self.ctx, self.shaders)
            entry = (mesh, [GpuPart(self.ctx, part, textures) for part in mesh.parts], textures)
            mark_mesh_uv_features(entry[1])
        self._meshes[id(mesh)] = entry    # last: the most recently drawn
        return entry[1]

    def adopt(self, mesh, textures: "MeshTextures") -> list[GpuPart]:
        """``mesh`` uploaded with ``textures`` filled beforehand (alight.render.mesh_upload): its
        parts' buffers made now; drawn from here on as if ``parts`` had uploaded it."""
        entry = self._meshes.pop(id(mesh), None)
        if entry is not None:
            release_mesh(entry)
        while len(self._meshes) >= MAX_UPLOADED_MESHES:
            release_mesh(self._meshes.pop(next(iter(self._meshes))))
        parts = [GpuPart(self.ctx, part, textures) for part in mesh.parts]
        mark_mesh_uv_features(parts)
        self._meshes[id(mesh)] = (mesh, parts, textures)
        return parts

    def __len__(self) -> int:
        """How many meshes are uploaded (at most MAX_UPLOADED_MESHES)."""
        return len(self._meshes)

    def textures(self, mesh) -> MeshTextures:
        """The shared textures of a mesh ``parts`` uploaded."""
        return self._meshes[id(mesh)][2]

    def stand_in(self, mesh, key, make_part) -> GpuPart:
        """A part drawn in place of the built-in sphere ``mesh``'s own (a coarser level, the
        impostor's proxy), kept by ``key`` while ``mesh`` is the one drawn; ``make_part`` builds
        its MeshPart, which takes the sphere's material, name and element."""
        for old in [k for k, e in self._stand_ins.items() if e[0] is not mesh]:   # another mesh's
            release_mesh(self._stand_ins.pop(old))
        entry = self._stand_ins.get((id(mesh), key))
        if entry is None:
            part = mesh.parts[0]
            stand_in = dataclasses.replace(make_part(), material=part.material, name=part.name, element=part.element)
            textures = MeshTextures(self.ctx, self.shaders)
            entry = self._stand_ins[(id(mesh), key)] = (mesh, [GpuPart(self.ctx, stand_in, textures)], textures)
        return entry[1][0]

    def user_textures(self, scene) -> dict[str, moderngl.Texture]:
        """The scene's user-loaded maps as textures by slot, uploaded on first use of an image."""
        if scene.texture_maps is None:
            return {}
        out = {}
        for slot, path in scene.texture_maps.paths().items():
            image = scene.texture_images.get(path)
            if image is None:
                continue
            spread = spread_scale(slot, None)
            key = (path, slot in SRGB_MAPS) if spread is None else (path, False, "spread")
            entry = self._map_textures.get(key)
            if entry is None or entry[0] is not image:
                if entry is not None:
                    entry[1].release()
                tex = (upload_image(self.ctx, image, srgb=key[1]) if spread is None
                       else upload_normal_map(self.ctx, self.shaders, image, spread))
                entry = self._map_textures[key] = (image, tex)
            out[slot] = entry[1]
        return out

    def forget_map_textures(self, keep_paths) -> None:
        """Release the uploaded maps whose path is not in ``keep_paths``."""
        for key in [k for k in self._map_textures if k[0] not in keep_paths]:
            self._map_textures.pop(key)[1].release()

    def use_shaders(self, shaders: ShaderLibrary) -> None:
        """Upload with ``shaders`` from now on (the renderer switched libraries); the meshes are
        released (``release_meshes``), the user's maps stay."""
        self.shaders = shaders
        self.release_meshes()

    def release_meshes(self) -> None:
        """Release every uploaded mesh and stand-in (their vertex arrays belong to programs that a
        shader reload replaces); the user's maps stay."""
        for entry in [*self._meshes.values(), *self._stand_ins.values()]:
            release_mesh(entry)
        self._meshes.clear()
        self._stand_ins.clear()

    def release(self) -> None:
        self.forget_map_textures(())
        self.release_meshes()


class FullscreenDraws:
    """The vertex arrays of full-screen passes (one triangle, no buffer), one per program, and of
    the background's ring (alight.render.sphere_impostor), whose buffer is rewritten per draw."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._vaos: dict = {}
        self._ring_buffer: moderngl.Buffer | None = None

    def triangle(self, prog: moderngl.Program) -> None:
        """One full-screen triangle with ``prog`` (render/fullscreen.vert, render/background.vert)."""
        vao = self._vaos.get(id(prog))
        if vao is None:
            vao = self._vaos[id(prog)] = self.ctx.vertex_array(prog, [])
        vao.render(moderngl.TRIANGLES, vertices=3)

    def ring(self, prog: moderngl.Program, ring: np.ndarray) -> None:
        """``ring``'s triangles ((n, 2) float32 NDC points) with ``prog``."""
        if self._ring_buffer is None:
            self._ring_buffer = self.ctx.buffer(reserve=ring.nbytes)
        self._ring_buffer.write(ring.tobytes())
        vao = self._vaos.get((id(prog), "ring"))
        if vao is None:
            vao = self._vaos[(id(prog), "ring")] = self.ctx.vertex_array(prog, [(self._ring_buffer, "2f", "in_ndc")])
        vao.render(moderngl.TRIANGLES, vertices=len(ring))

    def release_vaos(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()

    def release(self) -> None:
        self.release_vaos()
        if self._ring_buffer is not None:
            self._ring_buffer.release()
            self._ring_buffer = None
