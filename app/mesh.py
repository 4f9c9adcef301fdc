"""Meshes as plain numpy arrays ready for GPU buffers (no GL here: the renderer uploads them).

A mesh spec is a built-in name (``sphere``, ``cube``, ``plane``) or a file path (.obj .gltf
.glb .ply .stl). Files are read with trimesh, which is imported lazily inside the loader so
that start-up and the built-in meshes never pay for it. Every problem with a file becomes a
one-line :class:`AlightError` naming the file.

Conventions: world space is right-handed, +Y up (``../shared/CONVENTIONS.md``); faces are
counter-clockwise seen from the front; uvs follow OpenGL (v = 0 is the image's bottom row)
while texture arrays keep PIL's order (row 0 = top row), so a texel is found at
``row = (1 - v) * H``.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from app.errors import AlightError

BUILTIN_MESHES = ("sphere", "cube", "plane")
MESH_EXTENSIONS = (".obj", ".gltf", ".glb", ".ply", ".stl")


@dataclass
class FileMaterial:
    """A glTF/OBJ material as the file gives it (metal-roughness model)."""

    base_color: tuple[float, float, float]  # linear factor
    metallic: float
    roughness: float
    emissive: tuple[float, float, float]  # linear, times KHR_materials_emissive_strength
    alpha: float
    base_color_texture: np.ndarray | None  # (H, W, 4) uint8, sRGB, row 0 = top
    metallic_roughness_texture: np.ndarray | None  # linear; G = roughness, B = metallic
    normal_texture: np.ndarray | None  # tangent-space normal map
    normal_scale: float
    emissive_texture: np.ndarray | None  # sRGB
    occlusion_texture: np.ndarray | None  # R = occlusion
    occlusion_strength: float


@dataclass
class MeshPart:
    """One geometry with one material, in world space."""

    name: str
    positions: np.ndarray  # (N, 3) float32
    normals: np.ndarray  # (N, 3) float32, unit length
    uvs: np.ndarray  # (N, 2) float32, OpenGL convention (v = 0 bottom); zeros when absent
    tangents: np.ndarray  # (N, 4) float32, bitangent = w * cross(n, t)
    indices: np.ndarray  # (M, 3) uint32, counter-clockwise front faces
    material: FileMaterial | None


@dataclass
class Mesh:
    parts: list[MeshPart]
    source: str  # 'sphere' / 'cube' / 'plane' or the file path

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """World-space min and max corners over all parts."""
        allp = np.concatenate([p.positions for p in self.parts]).astype(np.float64)
        return allp.min(axis=0), allp.max(axis=0)

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
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    ok = np.isfinite(length[..., 0]) & (length[..., 0] > 1e-30)
    out = np.where(ok[..., None], v / np.where(ok[..., None], length, 1.0), 0.0)
    return out, ok


def _any_orthogonal(n: np.ndarray) -> np.ndarray:
    """A unit vector orthogonal to each unit normal (the axis least aligned with it, projected)."""
    axis = np.where((np.abs(n[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    t = axis - n * np.sum(n * axis, axis=1, keepdims=True)
    return t / np.linalg.norm(t, axis=1, keepdims=True)


def _scatter_add(index: np.ndarray, values: np.ndarray, count: int) -> np.ndarray:
    """Sum rows of ``values`` into ``count`` bins (faster than np.add.at)."""
    return np.stack(
        [np.bincount(index, weights=values[:, c], minlength=count) for c in range(values.shape[1])],
        axis=1,
    )


def smooth_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (unnormalised; zero where a vertex has no area around it)."""
    p = np.asarray(positions, dtype=np.float64)
    f = np.asarray(indices, dtype=np.int64).reshape(-1, 3)
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    return _scatter_add(f.ravel(), np.repeat(fn, 3, axis=0), len(p))


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
    f = np.asarray(indices, dtype=np.int64).reshape(-1, 3)

    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    d1, d2 = uv[f[:, 1]] - uv[f[:, 0]], uv[f[:, 2]] - uv[f[:, 0]]
    r = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]  # twice the signed UV area
    sign = np.sign(r)[:, None]
    # dP/du and dP/dv times r; multiplying by sign(r) instead of dividing by r keeps direction.
    sdir, s_ok = _normalize((e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * sign)
    tdir, t_ok = _normalize((e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * sign)
    area = np.linalg.norm(np.cross(e1, e2), axis=1)[:, None]
    use = (s_ok & t_ok & (r != 0) & np.isfinite(area[:, 0]))[:, None]
    w_face = np.where(use, area, 0.0)
    acc_t = _scatter_add(f.ravel(), np.repeat(sdir * w_face, 3, axis=0), len(p))
    acc_b = _scatter_add(f.ravel(), np.repeat(tdir * w_face, 3, axis=0), len(p))

    t = acc_t - n * np.sum(n * acc_t, axis=1, keepdims=True)
    t_len = np.linalg.norm(t, axis=1)
    acc_len = np.linalg.norm(acc_t, axis=1)
    good = np.isfinite(t_len) & (acc_len > 0) & (t_len > 1e-6 * acc_len)
    t = np.where(good[:, None], t / np.where(good, t_len, 1.0)[:, None], _any_orthogonal(n))
    w = np.where(good & (np.sum(np.cross(n, t) * acc_b, axis=1) < 0), -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)


# --- built-in meshes -----------------------------------------------------------------------

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
    return Mesh([part], "sphere")


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
    return Mesh([_part("cube", *_quads(_CUBE_FACES, size / 2.0, True))], "cube")


def plane(size: float = 2.0) -> Mesh:
    """Square in the XZ plane facing +Y; u along +X, v along -Z."""
    return Mesh([_part("plane", *_quads([((0, 1, 0), (1, 0, 0))], size / 2.0, False))], "plane")


# --- files ---------------------------------------------------------------------------------

_BUILDERS: dict[str, Callable[[], Mesh]] = {"sphere": sphere, "cube": cube, "plane": plane}


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def load_mesh(spec: str) -> Mesh:
    """A built-in mesh by name, or a mesh file flattened to world-space parts."""
    if spec in _BUILDERS:
        return _BUILDERS[spec]()
    path = Path(spec)
    ext = path.suffix.lower()
    if ext not in MESH_EXTENSIONS:
        if not ext and not path.exists():
            raise AlightError(f"{spec}: neither a built-in mesh ({', '.join(BUILTIN_MESHES)}) nor a file")
        raise AlightError(
            f"{spec}: unsupported mesh format '{ext or '(none)'}' (use {', '.join(MESH_EXTENSIONS)})"
        )
    if not path.is_file():
        raise AlightError(f"{spec}: no such file")

    import trimesh  # lazily: importing trimesh costs start-up time the built-ins do not need

    try:
        scene = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # trimesh raises anything from ValueError to KeyError on bad files
        raise AlightError(f"{spec}: cannot read the file ({_one_line(exc)})") from None
    try:
        extras = _gltf_material_params(path) if ext in (".gltf", ".glb") else {}
        textures: dict[int, np.ndarray] = {}
        parts = []
        for node in scene.graph.nodes_geometry:
            transform, geom_name = scene.graph[node]
            geom = scene.geometry.get(geom_name)
            if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
                continue  # point clouds and line paths have no triangles to render
            part = _part_from_trimesh(spec, str(node), geom, np.asarray(transform), textures, extras)
            if part is not None:
                parts.append(part)
    except AlightError:
        raise
    except Exception as exc:  # e.g. a texture that PIL can only decode lazily and fails on
        raise AlightError(f"{spec}: cannot read the file ({_one_line(exc)})") from None
    if not parts:
        raise AlightError(f"{spec}: no triangles in the file")
    return Mesh(parts, str(spec))


def _part_from_trimesh(spec: str, name: str, geom, transform: np.ndarray,
                       textures: dict[int, np.ndarray], extras: dict[str, dict]) -> MeshPart | None:
    """One trimesh geometry placed by its node transform; None when no face survives."""
    positions = np.asarray(geom.vertices, dtype=np.float64)
    faces = np.asarray(geom.faces, dtype=np.int64).reshape(-1, 3)
    if not np.isfinite(positions).all():
        raise AlightError(f"{spec}: vertex positions contain NaN or Inf")
    if faces.size and (faces.min() < 0 or faces.max() >= len(positions)):
        raise AlightError(f"{spec}: face indices out of range")
    if not np.isfinite(transform).all():
        raise AlightError(f"{spec}: node transform contains NaN or Inf")
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
    if len(faces) == 0:
        return None

    # The file's normals, if trimesh kept them (it stores loaded normals in its cache; reading
    # the public property would silently compute them instead, and we want to know).
    cache = getattr(getattr(geom, "_cache", None), "cache", {})
    file_normals = cache.get("vertex_normals") if isinstance(cache, dict) else None

    # To world space. Normals take the cofactor matrix (= det * inverse transpose) times
    # sign(det); a mirroring transform (det < 0) also reverses the winding to stay CCW.
    m, t = transform[:3, :3].astype(np.float64), transform[:3, 3].astype(np.float64)
    cof = np.stack([np.cross(m[1], m[2]), np.cross(m[2], m[0]), np.cross(m[0], m[1])])
    det = float(np.dot(m[0], cof[0]))
    positions = positions @ m.T + t
    if det < 0:
        faces = faces[:, ::-1]
        cof = -cof

    computed, computed_ok = _normalize(smooth_normals(positions, faces))
    normals = computed
    if file_normals is not None and np.shape(file_normals) == positions.shape:
        from_file, file_ok = _normalize(np.asarray(file_normals, dtype=np.float64) @ cof.T)
        normals = np.where(file_ok[:, None], from_file, computed)
        computed_ok = computed_ok | file_ok
    normals[~computed_ok] = (0.0, 1.0, 0.0)

    uv = getattr(geom.visual, "uv", None)
    if uv is not None and np.shape(uv) == (len(positions), 2):
        uvs = np.nan_to_num(np.asarray(uv, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    else:
        uvs = np.zeros((len(positions), 2))

    return MeshPart(
        name=name,
        positions=np.ascontiguousarray(positions, dtype=np.float32),
        normals=np.ascontiguousarray(normals, dtype=np.float32),
        uvs=np.ascontiguousarray(uvs, dtype=np.float32),
        tangents=compute_tangents(positions, normals, uvs, faces),
        indices=np.ascontiguousarray(faces, dtype=np.uint32),
        material=_file_material(getattr(geom.visual, "material", None), textures, extras),
    )


def _texture(image: Any, cache: dict[int, np.ndarray]) -> np.ndarray | None:
    """A PIL image as (H, W, 4) uint8 RGBA, row 0 = top (PIL's order); shared images converted once."""
    if image is None or not hasattr(image, "convert"):
        return None
    key = id(image)
    if key not in cache:
        cache[key] = np.ascontiguousarray(np.asarray(image.convert("RGBA"), dtype=np.uint8))
    return cache[key]


def _factor(value: Any, default: tuple[float, ...]) -> np.ndarray:
    """A colour factor as floats 0..1: trimesh stores baseColorFactor quantised to uint8 0-255."""
    if value is None:
        return np.array(default, dtype=np.float64)
    arr = np.asarray(value)
    return arr / 255.0 if arr.dtype.kind in "ui" else arr.astype(np.float64)


def _file_material(mat: Any, textures: dict[int, np.ndarray], extras: dict[str, dict]) -> FileMaterial | None:
    """The file's material in our terms; None for vertex colours or trimesh's placeholder."""
    kind = type(mat).__name__
    if kind == "PBRMaterial":
        extra = extras.get(mat.name, {}) if mat.name is not None else {}
        base = _factor(mat.baseColorFactor, (1.0, 1.0, 1.0, 1.0))
        if "base_color_factor" in extra:  # exact linear factor rather than trimesh's uint8
            base = np.asarray(extra["base_color_factor"], dtype=np.float64)
        emissive = _factor(mat.emissiveFactor, (0.0, 0.0, 0.0))[:3] * extra.get("emissive_strength", 1.0)
        return FileMaterial(
            base_color=tuple(float(x) for x in base[:3]),
            metallic=float(1.0 if mat.metallicFactor is None else mat.metallicFactor),
            roughness=float(1.0 if mat.roughnessFactor is None else mat.roughnessFactor),
            emissive=tuple(float(x) for x in emissive),
            alpha=float(base[3]) if len(base) > 3 else 1.0,
            base_color_texture=_texture(mat.baseColorTexture, textures),
            metallic_roughness_texture=_texture(mat.metallicRoughnessTexture, textures),
            normal_texture=_texture(mat.normalTexture, textures),
            normal_scale=float(extra.get("normal_scale", 1.0)),
            emissive_texture=_texture(mat.emissiveTexture, textures),
            occlusion_texture=_texture(mat.occlusionTexture, textures),
            occlusion_strength=float(extra.get("occlusion_strength", 1.0)),
        )
    if kind == "SimpleMaterial":
        if getattr(mat, "_name", None) is None:
            # trimesh's placeholder (a grey 2x2 image) for an OBJ with uvs but no usable .mtl
            return None
        diffuse = _factor(mat.diffuse, (1.0, 1.0, 1.0, 1.0))
        return FileMaterial(
            # MTL Kd is display-referred in practice; (x/255)**2.2 approximates the sRGB decode.
            base_color=tuple(float(x) ** 2.2 for x in diffuse[:3]),
            metallic=0.0,
            roughness=0.5,
            emissive=(0.0, 0.0, 0.0),
            alpha=float(diffuse[3]) if len(diffuse) > 3 else 1.0,
            base_color_texture=_texture(mat.image, textures),
            metallic_roughness_texture=None,
            normal_texture=None,
            normal_scale=1.0,
            emissive_texture=None,
            occlusion_texture=None,
            occlusion_strength=1.0,
        )
    return None


def _gltf_material_params(path: Path) -> dict[str, dict]:
    """Material values trimesh drops, read from the glTF JSON, keyed by (unique) material name.

    trimesh keeps neither normalTexture.scale, occlusionTexture.strength nor
    KHR_materials_emissive_strength, and it quantises baseColorFactor to uint8. Materials are
    matched to trimesh's by name, so nameless or duplicate-named ones keep the defaults.
    Any problem here just means defaults: trimesh has already validated the file.
    """
    try:
        data = path.read_bytes()
        if data[:4] == b"glTF":
            length, kind = struct.unpack("<II", data[12:20])
            if kind != 0x4E4F534A:  # 'JSON'
                return {}
            doc = json.loads(data[20:20 + length])
        else:
            doc = json.loads(data)
        materials = doc.get("materials", [])
        names = [m.get("name") for m in materials]
        out: dict[str, dict] = {}
        for m in materials:
            name = m.get("name")
            if name is None or names.count(name) != 1:
                continue
            params: dict[str, Any] = {}
            bcf = m.get("pbrMetallicRoughness", {}).get("baseColorFactor")
            if isinstance(bcf, list) and len(bcf) == 4:
                params["base_color_factor"] = [float(x) for x in bcf]
            if "scale" in m.get("normalTexture", {}):
                params["normal_scale"] = float(m["normalTexture"]["scale"])
            if "strength" in m.get("occlusionTexture", {}):
                params["occlusion_strength"] = float(m["occlusionTexture"]["strength"])
            strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {})
            if "emissiveStrength" in strength:
                params["emissive_strength"] = float(strength["emissiveStrength"])
            out[name] = params
        return out
    except Exception:
        return {}


def is_closed(positions: np.ndarray, indices: np.ndarray) -> bool:
    """Whether a triangle mesh is closed and consistently wound: after welding vertices at equal
    positions (UV seams duplicate them), every directed edge (a, b) has exactly one (b, a).
    Back faces of such a mesh are never visible from outside, so the renderer culls them; an
    open mesh (a plane, a single-sided shell) is drawn from both sides."""
    if len(indices) == 0:
        return False
    _, weld = np.unique(np.round(np.asarray(positions, np.float64), 6), axis=0, return_inverse=True)
    tri = weld.reshape(-1)[np.asarray(indices, np.int64)]
    tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])]
    if len(tri) == 0:
        return False
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    n = int(weld.max()) + 1
    forward = edges[:, 0] * n + edges[:, 1]
    backward = edges[:, 1] * n + edges[:, 0]
    uniq, counts = np.unique(forward, return_counts=True)
    if (counts != 1).any():
        return False
    return bool(np.isin(backward, uniq, assume_unique=False).all())
