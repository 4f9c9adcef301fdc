"""Meshes as plain numpy arrays ready for GPU buffers (no GL here: the renderer uploads them).

The built-in meshes (``sphere``, ``cube``, ``plane``; the other preview meshes are
``alight.core.preview_meshes``'s), normals and tangents, and the closed-mesh
test live here; files are read by ``alight.exchange.meshes``.

Conventions: world space is right-handed, +Y up (``docs/conventions.md``); faces are
counter-clockwise seen from the front; uvs follow OpenGL (v = 0 is the image's bottom row)
while texture arrays keep PIL's order (row 0 = top row), so a texel is found at
``row = (1 - v) * H``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# The built-in preview meshes, by the name --mesh and the editor's list take.
BUILTIN_MESHES = ("sphere", "cube", "plane", "shader_ball", "rounded_cube", "drape")
# Those that cannot shadow or reflect onto themselves (convex, or flat): a reference needs no paths.
CONVEX_BUILTINS = ("sphere", "cube", "plane", "rounded_cube")
WRAP_MODES = ("repeat", "clamp_to_edge", "mirrored_repeat")   # glTF 2.0 sampler.wrapS/T (10497, 33071, 33648)
ALPHA_MODES = ("OPAQUE", "MASK", "BLEND")                      # glTF 2.0 material.alphaMode


@dataclass(frozen=True)
class Sampler:
    """How a texture is sampled (glTF 2.0 section 3.8.4, "Samplers").

    ``wrap_s``/``wrap_t``: one of WRAP_MODES. ``mag_filter``: 'nearest' or 'linear';
    ``min_filter``: 'nearest', 'linear' or '<nearest|linear>_mipmap_<nearest|linear>'. glTF
    leaves undefined filters to the implementation: alight uses trilinear filtering then.
    """

    wrap_s: str = "repeat"
    wrap_t: str = "repeat"
    mag_filter: str = "linear"
    min_filter: str = "linear_mipmap_linear"

    @property
    def mipmaps(self) -> bool:
        return "mipmap" in self.min_filter


@dataclass(frozen=True)
class TextureTransform:
    """KHR_texture_transform: ``uv' = T(offset) R(rotation) S(scale) uv`` in glTF's texture
    space (u right, v down, origin at the image's top left); ``rotation`` in radians, as the
    extension's specification defines the matrix."""

    offset: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    scale: tuple[float, float] = (1.0, 1.0)

    def matrix(self) -> np.ndarray:
        """(3, 3) float64, acting on glTF uvs as column vectors (u, v, 1)."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        t = np.array([[1.0, 0.0, self.offset[0]], [0.0, 1.0, self.offset[1]], [0.0, 0.0, 1.0]])
        # The extension's GLSL mat3(c, -s, 0, s, c, 0, 0, 0, 1) is column-major: these are its rows
        # (checked against TextureTransformTest's rotation markers).
        r = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        sc = np.diag([self.scale[0], self.scale[1], 1.0])
        return t @ r @ sc

    def gl_matrix(self) -> np.ndarray:
        """The same map on alight's uvs (OpenGL: v_gl = 1 - v_gltf): F M F with F the flip."""
        flip = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, 1.0]])
        return flip @ self.matrix() @ flip


@dataclass
class TextureInfo:
    """One texture slot of a material (glTF 2.0 textureInfo): the decoded image, which uv set it
    reads (``tex_coord``: 0 = TEXCOORD_0, 1 = TEXCOORD_1), KHR_texture_transform and the sampler.

    ``image``: (H, W, 4) uint8 RGBA, row 0 = the image's top row (grey spread to RGB, alpha 255
    where the file has none); sRGB or linear as the slot says, never converted here.
    """

    image: np.ndarray
    tex_coord: int = 0
    transform: TextureTransform | None = None
    sampler: Sampler = field(default_factory=Sampler)
    # The file's PNG or JPEG bytes ``image`` was decoded from (None: another format, or made
    # here), so an export can write the image back as it came instead of a larger PNG. A copy
    # with another image (dataclasses.replace) keeps them: the exporter uses them only where
    # they still decode to ``image`` (alight.exchange.gltf_export).
    encoded: bytes | None = field(default=None, repr=False, compare=False)


TEXTURE_SLOTS = ("base_color", "metallic_roughness", "normal", "emissive", "occlusion")
# The layers' textures (KHR_materials_clearcoat, KHR_materials_sheen): clearcoat R and
# clearcoat_roughness G multiply their factors (linear); clearcoat_normal is the coat's own
# tangent-space normal map (scaled by clearcoat_normal_scale); sheen_color RGB (sRGB) and
# sheen_roughness A multiply theirs.
# anisotropy (KHR_materials_anisotropy's anisotropyTexture, linear): RG a direction in the tangent
# frame (2x - 1), B a factor on anisotropy_strength. KHR_materials_transmission's R multiplies
# transmission and KHR_materials_volume's thickness G multiplies thickness (linear).
LAYER_TEXTURE_SLOTS = ("clearcoat", "clearcoat_roughness", "clearcoat_normal", "sheen_color", "sheen_roughness",
                       "anisotropy", "transmission", "thickness", "iridescence", "iridescence_thickness",
                       "diffuse_transmission")
# KHR_materials_iridescence (linear): iridescence R multiplies iridescence, iridescence_thickness G
# mixes the film's thickness from iridescence_thickness_minimum to _maximum.
# KHR_materials_diffuse_transmission's two textures packed in one (one sampler unit: the fragment
# shader with every layer and map on needs 32 of llvmpipe's 32 otherwise 33;
# alight.exchange.packed_textures): A (linear) multiplies diffuse_transmission (the
# diffuseTransmissionTexture's A), RGB (sRGB) multiplies diffuse_transmission_color (the
# diffuseTransmissionColorTexture's RGB).
# KHR_materials_specular's textures: specular A multiplies specularFactor, specular_color RGB
# (sRGB) multiplies specularColorFactor, before the extension's min(..., 1) (FileMaterial).
SPECULAR_TEXTURE_SLOTS = ("specular", "specular_color")


@dataclass
class FileMaterial:
    """A glTF/OBJ material as the file gives it (glTF 2.0 metal-roughness, section 3.9).

    Factors are linear. A ``*_texture`` is a TextureInfo (an (H, W, 4) uint8 array is accepted
    and wrapped with TEXCOORD_0 and the default sampler). ``specular_f0`` is the dielectric F0
    that KHR_materials_ior and KHR_materials_specular give (0.04 without them).
    """

    base_color: tuple[float, float, float] = (1.0, 1.0, 1.0)  # linear factor
    metallic: float = 1.0
    roughness: float = 1.0
    emissive: tuple[float, float, float] = (0.0, 0.0, 0.0)  # linear, times KHR_materials_emissive_strength
    alpha: float = 1.0                                       # baseColorFactor's alpha
    base_color_texture: TextureInfo | None = None            # sRGB; A = alpha
    metallic_roughness_texture: TextureInfo | None = None    # linear; G = roughness, B = metallic
    normal_texture: TextureInfo | None = None                # tangent-space normal map
    normal_scale: float = 1.0
    emissive_texture: TextureInfo | None = None              # sRGB
    occlusion_texture: TextureInfo | None = None             # R = occlusion
    occlusion_strength: float = 1.0
    alpha_mode: str = "OPAQUE"                               # ALPHA_MODES
    alpha_cutoff: float = 0.5                                # MASK only
    double_sided: bool = False
    unlit: bool = False                                      # KHR_materials_unlit
    specular_f0: tuple[float, float, float] = (0.04, 0.04, 0.04)
    name: str = ""
    # The ior and the layers' factors the file gives (alight.core.material field names, e.g.
    # {"clearcoat": 1.0}; alight.exchange.gltf_material.layer_fields_from_gltf); empty: none.
    layers: dict = field(default_factory=dict)
    clearcoat_texture: TextureInfo | None = None
    clearcoat_roughness_texture: TextureInfo | None = None
    clearcoat_normal_texture: TextureInfo | None = None
    clearcoat_normal_scale: float = 1.0
    sheen_color_texture: TextureInfo | None = None
    sheen_roughness_texture: TextureInfo | None = None
    anisotropy_texture: TextureInfo | None = None
    transmission_texture: TextureInfo | None = None
    thickness_texture: TextureInfo | None = None
    iridescence_texture: TextureInfo | None = None
    iridescence_thickness_texture: TextureInfo | None = None
    diffuse_transmission_texture: TextureInfo | None = None   # packed: RGB colour (sRGB), A strength
    # KHR_materials_specular with textures: specular_f0 per texel is
    # min(specular_color_f0 * specular_color, 1) * specular_factor * specular (the textures'
    # values), where specular_color_f0 = F0(ior) * specularColorFactor, not clamped.
    specular_texture: TextureInfo | None = None
    specular_color_texture: TextureInfo | None = None
    specular_factor: float = 1.0
    specular_color_f0: tuple[float, float, float] = (0.04, 0.04, 0.04)
    # KHR_materials_specular's F90 of the dielectric part: its specularFactor (the extension
    # scales the Fresnel at grazing incidence too; a metal's F90 stays 1). 1 without it.
    specular_f90: float = 1.0

    def __post_init__(self) -> None:
        for slot in TEXTURE_SLOTS + LAYER_TEXTURE_SLOTS + SPECULAR_TEXTURE_SLOTS:
            value = getattr(self, f"{slot}_texture")
            if isinstance(value, np.ndarray):
                setattr(self, f"{slot}_texture", TextureInfo(value))

    def textures(self) -> dict[str, TextureInfo]:
        """The slots that have a texture, by slot name (TEXTURE_SLOTS, LAYER_TEXTURE_SLOTS, SPECULAR_TEXTURE_SLOTS)."""
        out = {}
        for slot in TEXTURE_SLOTS + LAYER_TEXTURE_SLOTS + SPECULAR_TEXTURE_SLOTS:
            info = getattr(self, f"{slot}_texture")
            if info is not None:
                out[slot] = info
        return out


@dataclass
class MeshPart:
    """One glTF primitive (or OBJ/PLY group) with one material, in world space.

    ``uvs`` and ``uvs1`` follow OpenGL (v = 0 bottom, i.e. 1 - v of glTF); ``colors`` is COLOR_0
    (or PLY/OBJ vertex colours) as linear RGBA that multiplies the base colour and alpha.
    ``element`` names where it came from in the file (``meshes[2].primitives[0]``).
    """

    name: str
    positions: np.ndarray  # (N, 3) float32
    normals: np.ndarray  # (N, 3) float32, unit length
    uvs: np.ndarray  # (N, 2) float32, OpenGL convention (v = 0 bottom); zeros when absent
    # (N, 4) float32, bitangent = w * cross(n, t). None: made from the uvs by compute_tangents
    # when first read (MeshPart.tangents below), so a part no normal map is drawn on never pays
    # for them (seconds and hundreds of MiB for millions of vertices).
    tangents: np.ndarray | None
    indices: np.ndarray  # (M, 3) uint32, counter-clockwise front faces
    material: FileMaterial | None
    uvs1: np.ndarray | None = None  # (N, 2) float32, TEXCOORD_1
    colors: np.ndarray | None = None  # (N, 4) float32, linear RGBA
    element: str = ""
    # KHR_materials_variants: {variant index: the material that variant gives this part}, and
    # None: the part's own material (the file's, drawn without a variant). Empty for parts of a
    # file without variants. select_variant swaps ``material`` from it.
    variant_materials: dict = field(default_factory=dict)


def single_sided(part) -> bool:
    """Whether ``part`` exists from its front side only (counter-clockwise winding): a glTF
    primitive whose material is not doubleSided (the default material is single-sided). The
    camera pass culls its back faces; a shadow map draws only the faces whose front faces the
    light; the occlusion bake and the path tracer let light through it where the light would
    meet its back. Parts from other files (OBJ, PLY, the built-ins) are two-sided."""
    if not str(getattr(part, "element", "")).startswith("meshes["):
        return False
    material = getattr(part, "material", None)
    return not (material is not None and material.double_sided)


def _part_tangents(part: MeshPart) -> np.ndarray:
    tangents = part.__dict__.get("_tangents")
    if tangents is None:
        tangents = compute_tangents(part.positions, part.normals, part.uvs, part.indices)
        part.__dict__["_tangents"] = tangents
    return tangents


def _set_part_tangents(part: MeshPart, tangents) -> None:
    part.__dict__["_tangents"] = None if tangents is None else np.ascontiguousarray(tangents, dtype=np.float32)


# After the dataclass is made: its __init__ assigns through the property's setter.
MeshPart.tangents = property(_part_tangents, _set_part_tangents,
                             doc="(N, 4) float32 tangents, made by compute_tangents on first read where the "
                                 "part was given None")
MeshPart.has_tangents = property(lambda part: part.__dict__.get("_tangents") is not None,
                                 doc="Whether the tangents exist yet (given, or made by a read).")


@dataclass
class Mesh:
    """Parts in world space, and what else the file brought: its cameras (``alight.core.scene.Camera``,
    in the file's order), its punctual lights (``alight.core.scene.Light``) and one-line warnings
    about what alight renders without."""

    parts: list[MeshPart]
    source: str  # 'sphere' / 'cube' / 'plane' or the file path
    cameras: list = field(default_factory=list)
    lights: list = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    animations: int = 0   # the file's animations (not played: the rest pose is drawn)
    # The built-in UV sphere's (radius, segments), centred at the origin, its part's geometry as
    # ``sphere`` made it: a renderer may draw it with fewer segments where its size on screen
    # allows (alight.core.sphere_lod), never more. None for every other mesh: drawn as given.
    lod_sphere: tuple[float, int] | None = None
    # Where the file's origin went: every position, camera and light here is the file's minus
    # this (float64). A model far from its origin (1e6) is moved near it before positions become
    # float32, whose spacing there (0.06) faceted a unit sphere and broke its reflections.
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    # The direction a built-in is best seen from, (orbit, elevation) in degrees as
    # alight.core.scene.orbit_camera takes them: a 3/4 view, so a cube is not a square and a
    # plane not an edge. None: from +Z, the default camera (docs/conventions.md).
    view: tuple[float, float] | None = None
    # KHR_materials_variants: the file's variant names, in its order ([] without the extension),
    # and the one whose materials the parts hold (None: each part's own; select_variant).
    variants: list[str] = field(default_factory=list)
    variant: str | None = None

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """World-space min and max corners over all parts."""
        allp = np.concatenate([p.positions for p in self.parts]).astype(np.float64)
        return allp.min(axis=0), allp.max(axis=0)

    def corners(self) -> np.ndarray:
        """The bounding box's 8 world-space corners (8, 3) (camera framing)."""
        lo, hi = self.bounds()
        pick = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
        return np.where(pick, hi, lo)

    def flat_normal(self) -> np.ndarray | None:
        """The unit normal of the plane every vertex lies in (to 1e-5 of the mesh's size), or
        None for a mesh with depth: the smallest principal axis of the vertices."""
        points = np.concatenate([p.positions for p in self.parts]).astype(np.float64)
        centred = points - points.mean(axis=0)
        values, vectors = np.linalg.eigh(centred.T @ centred)
        if values[-1] <= 0.0 or values[0] > 1e-10 * values[-1]:
            return None
        return vectors[:, 0]

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre of the bounding box and the distance to the farthest vertex (camera framing)."""
        lo, hi = self.bounds()
        centre = (lo + hi) / 2.0
        radius = max(float(np.linalg.norm(p.positions - centre, axis=1).max()) for p in self.parts)
        return centre, radius


# --- vector helpers ------------------------------------------------------------------------

def _normalize(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors and a mask of the rows that could be normalised (finite, non-zero)."""
    v = np.asarray(v, dtype=np.float64)
    # einsum's row sums: np.linalg.norm(axis=-1) reduces along a 3-wide axis several times slower.
    length = np.sqrt(np.einsum("...i,...i->...", v, v))
    ok = np.isfinite(length) & (length > 1e-30)
    out = v / np.where(ok, length, 1.0)[..., None]
    out[~ok] = 0.0
    return out, ok


def rows_times(a: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``a @ m.T`` for (N, 3) rows and a (3, 3) matrix, in float64, by broadcasting: numpy hands
    the matmul to a threaded BLAS, which on a loaded 2-core machine measured 20-35x slower
    (0.42-0.48 s against 0.013-0.023 s for 500k rows) than this."""
    a = np.asarray(a, np.float64)
    m = np.asarray(m, np.float64)
    if np.array_equal(m, np.eye(3)):
        return a.copy()   # the same values: x * 1 + y * 0 + z * 0 is x exactly for finite rows
    return a[:, 0:1] * m[:, 0] + a[:, 1:2] * m[:, 1] + a[:, 2:3] * m[:, 2]


def row_norms(v: np.ndarray) -> np.ndarray:
    """(N,) lengths of (N, k) rows (einsum: faster than np.linalg.norm's reduction on 3 columns)."""
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N, 3) row-wise cross products, written out: np.cross transposes and copies its inputs."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), np.result_type(a, b))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _any_orthogonal(n: np.ndarray) -> np.ndarray:
    """A unit vector orthogonal to each unit normal (the axis least aligned with it, projected)."""
    axis = np.where((np.abs(n[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    t = axis - n * np.sum(n * axis, axis=1, keepdims=True)
    return t / row_norms(t)[:, None]


def _scatter_faces(faces: np.ndarray, values: np.ndarray, count: int) -> np.ndarray:
    """(count, k): each face's row of ``values`` (T, k) summed into its three vertices' bins.
    One np.bincount over (vertex, column) bins with every corner's copy of the row (faster than
    np.add.at, and than a bincount per column, which copies each strided column first)."""
    k = values.shape[1]
    bins = (np.asarray(faces, np.int64)[:, :, None] * k + np.arange(k)).reshape(-1)
    weights = np.broadcast_to(np.asarray(values, np.float64)[:, None, :], (len(values), 3, k)).reshape(-1)
    return np.bincount(bins, weights=weights, minlength=count * k).reshape(count, k)


# Faces per step of the per-face passes below: their float64 temporaries (a dozen (T, 3) arrays)
# then stay near 150 MiB at any triangle count instead of growing with it.
FACE_CHUNK = 1 << 19


def smooth_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (unnormalised; zero where a vertex has no area around it)."""
    p = np.asarray(positions, dtype=np.float64)
    faces = np.asarray(indices).reshape(-1, 3)
    out = np.zeros((len(p), 3))
    for start in range(0, len(faces), FACE_CHUNK):
        f = faces[start:start + FACE_CHUNK].astype(np.int64)
        p0 = p[f[:, 0]]
        out += _scatter_faces(f, cross_rows(p[f[:, 1]] - p0, p[f[:, 2]] - p0), len(p))
    return out


def compute_tangents(positions, normals, uvs, indices) -> np.ndarray:
    """Per-vertex tangents (N, 4) from per-triangle UV derivatives.

    Each triangle's dP/du and dP/dv are normalised and accumulated per vertex weighted by the
    triangle's area (so a near-degenerate UV triangle cannot dominate its neighbours), then the
    tangent is Gram-Schmidt orthogonalised against the normal, and w = sign of
    dot(cross(n, t), dP/dv) so that bitangent = w * cross(n, t). Where UVs are missing or
    degenerate the tangent is any unit vector orthogonal to the normal with w = 1. Never NaN.
    """
    p = np.asarray(positions, dtype=np.float64)
    n, n_ok = _normalize(normals)
    n[~n_ok] = (0.0, 1.0, 0.0)
    uv = np.nan_to_num(np.asarray(uvs, dtype=np.float64).reshape(len(p), 2))
    faces = np.asarray(indices).reshape(-1, 3)
    acc_t, acc_b = np.zeros((len(p), 3)), np.zeros((len(p), 3))
    # Without uvs (a scan, most PLY and STL files) every triangle's uv area is 0, no face adds
    # anything and every vertex takes the fallback below: skip the per-face passes.
    for start in range(0, len(faces) if uv.any() else 0, FACE_CHUNK):
        f = faces[start:start + FACE_CHUNK].astype(np.int64)
        p0, uv0 = p[f[:, 0]], uv[f[:, 0]]
        e1, e2 = p[f[:, 1]] - p0, p[f[:, 2]] - p0
        d1, d2 = uv[f[:, 1]] - uv0, uv[f[:, 2]] - uv0
        del p0, uv0
        r = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]  # twice the signed UV area
        sign = np.sign(r)[:, None]
        # dP/du and dP/dv times r; multiplying by sign(r) instead of dividing by r keeps direction.
        sdir, s_ok = _normalize((e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * sign)
        tdir, t_ok = _normalize((e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * sign)
        area = row_norms(cross_rows(e1, e2))[:, None]
        use = (s_ok & t_ok & (r != 0) & np.isfinite(area[:, 0]))[:, None]
        w_face = np.where(use, area, 0.0)
        acc_t += _scatter_faces(f, sdir * w_face, len(p))
        acc_b += _scatter_faces(f, tdir * w_face, len(p))

    t = acc_t - n * np.einsum("ij,ij->i", n, acc_t)[:, None]
    t_len = row_norms(t)
    acc_len = row_norms(acc_t)
    good = np.isfinite(t_len) & (acc_len > 0) & (t_len > 1e-6 * acc_len)
    t /= np.where(good, t_len, 1.0)[:, None]
    if not good.all():
        t[~good] = _any_orthogonal(n[~good])
    w = np.where(good & (np.einsum("ij,ij->i", cross_rows(n, t), acc_b) < 0), -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)


# --- built-in meshes -----------------------------------------------------------------------

THREE_QUARTER = (35.0, 25.0)   # Mesh.view: turned 35 degrees, raised 25 (an object with depth)
FROM_ABOVE = (30.0, 45.0)      # Mesh.view: a flat or nearly flat object, seen from above at an angle

def _part(name: str, positions, normals, uvs, tangents, indices) -> MeshPart:
    return MeshPart(
        name=name,
        positions=np.ascontiguousarray(positions, dtype=np.float32),
        normals=np.ascontiguousarray(normals, dtype=np.float32),
        uvs=np.ascontiguousarray(uvs, dtype=np.float32),
        tangents=np.ascontiguousarray(tangents, dtype=np.float32),
        indices=np.ascontiguousarray(np.asarray(indices).reshape(-1, 3), dtype=np.uint32),
        material=None,
    )


def sphere(segments: int = 128, rings: int = 64, radius: float = 1.0) -> Mesh:
    """UV sphere at the origin with analytic normals and tangents.

    u runs counter-clockwise about +Y (east on a globe), so a texture reads un-mirrored from
    outside (w = +1); the seam u = 0/1 is at -Z, away from the default camera on +Z, and u = 0.5
    faces +Z. v = 1 at the north pole (+Y). Pole triangles of zero area are left out.
    """
    i, j = np.meshgrid(np.arange(rings + 1), np.arange(segments + 1), indexing="ij")
    u, v = j / segments, 1.0 - i / rings
    theta, phi = np.pi * i / rings, 2.0 * np.pi * u
    normals = np.stack([-np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1)
    tangents = np.stack([-np.cos(phi), np.zeros_like(phi), np.sin(phi), np.ones_like(phi)], -1)
    a = (i[:-1, :-1] * (segments + 1) + j[:-1, :-1]).ravel()
    row = np.repeat(np.arange(rings), segments)
    b, c = a + 1, a + segments + 1
    d = c + 1
    upper = np.stack([a, c, d], -1)[row != rings - 1]  # degenerate on the south pole row
    lower = np.stack([a, d, b], -1)[row != 0]  # degenerate on the north pole row
    part = _part(
        "sphere",
        (normals * radius).reshape(-1, 3),
        normals.reshape(-1, 3),
        np.stack([u, v], -1).reshape(-1, 2),
        tangents.reshape(-1, 4),
        np.concatenate([upper, lower]),
    )
    return Mesh([part], "sphere", lod_sphere=(float(radius), int(segments)) if rings * 2 == segments else None)


# (normal, tangent = +u direction); bitangent (+v) = cross(normal, tangent), so w = +1.
_CUBE_FACES = (
    ((1, 0, 0), (0, 0, -1)),
    ((-1, 0, 0), (0, 0, 1)),
    ((0, 1, 0), (1, 0, 0)),
    ((0, -1, 0), (1, 0, 0)),
    ((0, 0, 1), (1, 0, 0)),
    ((0, 0, -1), (-1, 0, 0)),
)


def _quads(faces, half: float, offset: bool) -> tuple[np.ndarray, ...]:
    """Square faces (normal, tangent): 4 vertices each, uvs (0,0)..(1,1), two CCW triangles."""
    pos, nor, uvs, tan, idx = [], [], [], [], []
    corners = ((-1, -1), (1, -1), (1, 1), (-1, 1))
    for k, (n, t) in enumerate(faces):
        n, t = np.array(n, float), np.array(t, float)
        b = np.cross(n, t)
        for cu, cv in corners:
            pos.append((n if offset else 0.0) * half + (cu * t + cv * b) * half)
            nor.append(n)
            uvs.append(((cu + 1) / 2, (cv + 1) / 2))
            tan.append((*t, 1.0))
        idx += [(4 * k, 4 * k + 1, 4 * k + 2), (4 * k, 4 * k + 2, 4 * k + 3)]
    return tuple(np.array(x) for x in (pos, nor, uvs, tan, idx))


def cube(size: float = 2.0) -> Mesh:
    """Axis-aligned cube centred at the origin: 24 vertices, flat normals, a full uv square per face."""
    return Mesh([_part("cube", *_quads(_CUBE_FACES, size / 2.0, True))], "cube", view=THREE_QUARTER)


def plane(size: float = 2.0) -> Mesh:
    """Square in the XZ plane facing +Y; u along +X, v along -Z."""
    return Mesh([_part("plane", *_quads([((0, 1, 0), (1, 0, 0))], size / 2.0, False))], "plane", view=FROM_ABOVE)


# --- topology ------------------------------------------------------------------------------

def _weld(positions: np.ndarray) -> np.ndarray:
    """(N,) int64: one id per distinct position rounded to 1e-6 (UV seams and flat-shaded corners
    duplicate a position); the ids are labels, in no particular order.

    One 1-D ``np.unique`` of a 64-bit hash of the rounded position, checked exactly: every
    position must equal its group's first one, so a hash collision (two positions, one id) is
    found, and the column-by-column weld (``_weld_by_columns``) answers instead. A single sort of
    N keys instead of five: 4x faster on a 500k-vertex mesh."""
    p = np.asarray(positions, np.float64).reshape(-1, 3)
    if not len(p):
        return np.zeros(0, np.int64)
    # np.round(p, 6) is rint(p * 1e6) / 1e6, so equal rounded floats are equal integers here
    # (-0.0 and 0.0 both become 0). Past 9e12 the integers would overflow int64.
    if not np.isfinite(p).all() or np.abs(p).max() > 1e12:
        return _weld_by_columns(p)
    q = np.rint(p * 1e6).astype(np.int64).view(np.uint64)
    h = _mix64(_mix64(_mix64(q[:, 0]) + q[:, 1]) + q[:, 2])
    _, first, ids = np.unique(h, return_index=True, return_inverse=True)
    ids = ids.reshape(-1).astype(np.int64)
    if not (q[first[ids]] == q).all():
        return _weld_by_columns(p)
    return ids


def _mix64(v: np.ndarray) -> np.ndarray:
    """SplitMix64's finaliser (Steele et al. 2014), wrapping uint64 arithmetic: every input bit
    reaches every output bit, so symmetric positions ((x, y, z) and (-x, y, -z) on a sphere)
    do not collide as they did under a plain multiply-xor of the three integers."""
    v = (v ^ (v >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    v = (v ^ (v >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return v ^ (v >> np.uint64(31))


def _weld_by_columns(p: np.ndarray) -> np.ndarray:
    """_weld without hashing: three 1-D ``np.unique`` calls and two more on integer pairs (a 1-D
    sort is an order of magnitude faster than ``np.unique(axis=0)``'s row sort, which compares
    rows field by field), so it stays close to linear in the vertex count."""
    p = np.round(np.asarray(p, np.float64).reshape(-1, 3), 6)
    ids = None
    for column in range(3):
        _, rank = np.unique(p[:, column], return_inverse=True)   # -0.0 and 0.0 compare equal: one id
        rank = rank.reshape(-1).astype(np.int64)
        if ids is None:
            ids = rank
        else:
            _, ids = np.unique(ids * (int(rank.max()) + 1) + rank, return_inverse=True)
            ids = ids.reshape(-1).astype(np.int64)
    return ids


def _welded_faces(positions, indices) -> tuple[np.ndarray, np.ndarray, int]:
    """(rows, welded, n): the faces whose three corners stay distinct after the weld, as original
    indices (rows) and as weld ids (welded), and the number of weld ids."""
    weld = _weld(positions)
    rows = np.asarray(indices, np.int64).reshape(-1, 3)
    welded = weld[rows]
    good = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 2] != welded[:, 0])
    if not good.all():
        rows, welded = rows[good], welded[good]
    return rows, welded, (int(weld.max()) + 1 if len(weld) else 0)


def _edge_keys(welded: np.ndarray, n: int) -> np.ndarray:
    """(3 M,) int64: edge (corner k, corner k + 1) of every face, corner by corner (entry
    k M + f is face f's edge k), keyed ``2 (min n + max) + (a < b)``: sorted, a closed and
    consistently wound mesh's keys come in pairs (2k, 2k + 1), the edge once each way."""
    count = len(welded)
    keys = np.empty(3 * count, np.int64)
    for k in range(3):
        a, b = welded[:, k], welded[:, (k + 1) % 3]
        keys[k * count:(k + 1) * count] = (np.minimum(a, b) * n + np.maximum(a, b)) * 2 + (a < b)
    return keys


def _welded_edge_keys(positions, indices) -> tuple[np.ndarray, np.ndarray] | None:
    """(rows, keys): the faces left after the weld as original indices (_welded_faces) and their
    edges' keys (_edge_keys); None where no face is left (or none was given). The welded faces,
    as long as ``rows``, are dropped before returning: the keys are the caller's largest array."""
    if len(indices) == 0:
        return None
    rows, welded, n = _welded_faces(positions, indices)
    if len(welded) == 0:
        return None
    return rows, _edge_keys(welded, n)


def _paired(keys: np.ndarray) -> bool:
    """Whether sorted edge keys (_edge_keys) are all in pairs (2k, 2k + 1): once forward, once
    backward; a third use of an edge or a repeated direction breaks the pattern of some pair."""
    first, second = keys[0::2], keys[1::2]
    return bool(len(keys) % 2 == 0 and not (first & 1).any() and np.array_equal(second, first + 1))


def is_closed(positions: np.ndarray, indices: np.ndarray) -> bool:
    """Whether a triangle mesh is closed and consistently wound: after welding vertices at equal
    positions (UV seams duplicate them), every directed edge (a, b) has exactly one (b, a).
    Back faces of such a mesh are never visible from outside, so the renderer culls them; an
    open mesh (a plane, a single-sided shell) is drawn from both sides.

    Equivalently, every undirected edge {a, b} occurs exactly twice, once each way: one sort of
    the edges keyed ``2 (min n + max) + (a < b)`` checks both at once, so the test costs a few
    1-D sorts (about a second for 4M triangles) instead of row-wise uniques and set lookups.
    ``closed_edges`` answers the same with the faces at each edge, for the shadow test."""
    found = _welded_edge_keys(positions, indices)
    if found is None:
        return False
    # The keys array is the only one as long as all the edges (a 4M-triangle mesh's peak stays
    # near 100 MiB here): sorted in place, no permutation kept.
    keys = found[1]
    del found
    keys.sort()
    return _paired(keys)


def _sorted_with_positions(keys: np.ndarray, pack: bool = True) -> np.ndarray | None:
    """The permutation that sorts edge keys (_edge_keys), or None where they are not paired
    (_paired). Where a key and its index fit in 63 bits together (meshes up to about 1.8M
    faces), both are packed into one int64 and sorted in place: the positions come out in the
    low bits, and the sort of values is about twice as fast as ``np.argsort`` here (AVX-512
    quicksort for values; 0.27 s against 0.53 s for 3M keys). Beyond that, ``np.argsort``."""
    index_bits = max(int(len(keys) - 1).bit_length(), 1)
    if pack and len(keys) and int(keys.max()).bit_length() + index_bits <= 63:
        keys <<= index_bits
        keys |= np.arange(len(keys), dtype=np.int64)
        keys.sort()
        order = keys & ((1 << index_bits) - 1)
        keys >>= index_bits
    else:
        order = np.argsort(keys)
        keys = keys[order]
    return order if _paired(keys) else None


@dataclass(frozen=True)
class ClosedEdges:
    """A closed, consistently wound part's faces at each edge (``closed_edges``). ``faces``:
    (M, 3) int64, the faces with three distinct corners after the weld (original vertex
    indices); per edge, ``face`` the row of one face holding it and ``across`` the original
    index of the other face's corner that is not on the edge."""

    faces: np.ndarray
    face: np.ndarray
    across: np.ndarray


def closed_edges(positions: np.ndarray, indices: np.ndarray, pack: bool = True) -> ClosedEdges | None:
    """is_closed's verdict with its edge pairing kept: None where the part is open (or wound
    inconsistently), else which faces meet at each edge. One weld and one sort serve both the
    closedness and the shadow test's local convexity (alight.core.shadow_fit.can_shadow_itself),
    which welded and sorted the edges again (1.5 s of a 1M-triangle cold render). It needs the
    sort's permutation where is_closed sorts the keys in place (8 bytes more an edge), so the
    culling decision alone keeps is_closed. ``pack``: False always takes the argsort
    (_sorted_with_positions; tests)."""
    found = _welded_edge_keys(positions, indices)
    if found is None:
        return None
    rows, keys = found
    count = len(rows)
    order = _sorted_with_positions(keys, pack)
    if order is None:
        return None
    # order // count is the edge's corner k in its face, order % count the face; the corner
    # across from edge (k, k + 1) is k + 2.
    face = order[0::2] % count
    other = order[1::2]
    across = rows[other % count, (other // count + 2) % 3]
    return ClosedEdges(rows, face, across)


# A model whose nodes lie farther than this from the file's origin is moved near it before its
# positions become float32 (spacing 6e-5 here, 0.06 at 1e6).
FAR_FROM_ORIGIN = 1.0e3


def far_origin(translations) -> np.ndarray:
    """Where to put the origin for models placed at ``translations`` ((3,) each, float64): their
    mean when it is farther than FAR_FROM_ORIGIN from (0, 0, 0), else (0, 0, 0), so ordinary
    files keep their coordinates exactly."""
    if not len(translations):
        return np.zeros(3)
    centre = np.mean(np.asarray(translations, np.float64), axis=0)
    return centre if np.isfinite(centre).all() and np.abs(centre).max() > FAR_FROM_ORIGIN else np.zeros(3)


def select_variant(mesh: Mesh, name: str | None) -> Mesh:
    """``mesh`` with KHR_materials_variants' variant ``name`` active: a Mesh whose parts hold the
    materials that variant maps them to, and their own material where it maps none (the
    extension's rule); ``name`` None: every part's own material. The geometry is shared, not
    copied; ``mesh`` is left as it is (the same mesh comes back when nothing changes). Raises
    AlightError of one line for a mesh without variants or a name it does not have (listing the
    names it has)."""
    import copy

    from alight.errors import AlightError

    if name == mesh.variant:
        return mesh
    if name is not None:
        if not mesh.variants:
            raise AlightError(f"{mesh.source}: has no material variants (KHR_materials_variants) to choose "
                              f"{name!r} from")
        if name not in mesh.variants:
            raise AlightError(f"{mesh.source}: no material variant named {name!r}; the file's variants: "
                              + ", ".join(repr(v) for v in mesh.variants))
    index = None if name is None else mesh.variants.index(name)
    parts = []
    for part in mesh.parts:
        choices = part.variant_materials
        material = choices.get(index, choices.get(None, part.material)) if choices else part.material
        if material is part.material:
            parts.append(part)
            continue
        moved = copy.copy(part)   # (not dataclasses.replace: it would read, so make, lazy tangents)
        moved.material = material
        parts.append(moved)
    out = copy.copy(mesh)
    out.parts, out.variant = parts, name
    return out
