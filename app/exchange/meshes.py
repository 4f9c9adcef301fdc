"""Mesh files into ``alight.core.mesh.Mesh``: glTF/GLB by ``alight.exchange.gltf``; OBJ, PLY and
STL by trimesh, with what trimesh leaves out added here: vertex colours (PLY ``red green blue
[alpha]``, OBJ ``v x y z r g b``; sRGB-encoded, decoded to linear) and MTL ``map_Kd`` statements
with options (``alight.exchange.mtl``: ``-o``/``-s`` become the map's texture transform).

trimesh is imported lazily inside the loader so that start-up and the built-in meshes never pay
for it. Every problem with a file becomes a one-line ``AlightError`` naming the file.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable

import numpy as np

from alight.core.mesh import (
    BUILTIN_MESHES,
    FileMaterial,
    Mesh,
    MeshPart,
    _normalize,
    cube,
    far_origin,
    plane,
    rows_times,
    smooth_normals,
    sphere,
)
from alight.core.preview_meshes import drape, rounded_cube, shader_ball
from alight.errors import AlightError

MESH_EXTENSIONS = (".obj", ".gltf", ".glb", ".ply", ".stl")
# What a part without a material of its own is drawn with, in words true for every front end:
# the editor draws the panel's material, 'alight render' its --preset's, the API set_material's.
CURRENT_MATERIAL = "the current material (the default unless one is set)"


_BUILDERS: dict[str, Callable[[], Mesh]] = {"sphere": sphere, "cube": cube, "plane": plane,
                                            "shader_ball": shader_ball, "rounded_cube": rounded_cube,
                                            "drape": drape}


def is_builtin(spec: str) -> bool:
    """Whether ``spec`` names a built-in mesh (not a file)."""
    return spec in _BUILDERS


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def load_mesh(spec: str) -> Mesh:
    """A built-in mesh by name, or a mesh file flattened to world-space parts."""
    if spec in _BUILDERS:
        return _BUILDERS[spec]()
    if not str(spec).strip():   # (Path('') is '.', the current folder: "is a folder" named nothing)
        raise AlightError(f"mesh: the path is empty (a built-in: {', '.join(BUILTIN_MESHES)}; or a mesh file)")
    path = Path(spec)
    ext = path.suffix.lower()
    if path.is_dir():
        raise AlightError(f"{spec}: is a folder, not a mesh file (use {', '.join(MESH_EXTENSIONS)})")
    if ext not in MESH_EXTENSIONS:
        if not ext and not path.exists():
            raise AlightError(f"{spec}: neither a built-in mesh ({', '.join(BUILTIN_MESHES)}) nor a file")
        raise AlightError(
            f"{spec}: unsupported mesh format '{ext or '(none)'}' (use {', '.join(MESH_EXTENSIONS)})"
        )
    if not path.is_file():
        raise AlightError(f"{spec}: no such file")
    if ext in (".gltf", ".glb"):
        from alight.exchange.gltf import load_gltf

        return load_gltf(path, spec)

    import trimesh  # lazily: importing trimesh costs start-up time the built-ins do not need

    faces = _obj_faces(spec, path) if ext == ".obj" else None
    try:
        if faces is not None and faces.rewrite is not None:
            import io

            # The faces made explicit (ear-clipped, normals written): trimesh reads the rewritten
            # text, and the MTL and textures beside the file through the resolver.
            scene = trimesh.load(io.BytesIO(faces.rewrite), file_type="obj", force="scene", process=False,
                                 resolver=trimesh.resolvers.FilePathResolver(str(path)))
        else:
            scene = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # trimesh raises anything from ValueError to KeyError on bad files
        problem = _obj_syntax_problem(path) if ext == ".obj" else None   # what line, where the text can tell
        raise AlightError(f"{spec}: {problem or f'cannot read the file ({_one_line(exc)})'}") from None
    try:
        extras: dict[str, dict] = {}
        textures: dict[int, np.ndarray] = {}
        warnings: list[str] = []
        if ext == ".obj":
            warnings += _unknown_materials(spec, path, faces.usemtl)
            if faces.fan_fallbacks:
                warnings.append(f"{spec}: {faces.fan_fallbacks} polygon(s) that do not lie flat or cross "
                                f"themselves could not be ear-clipped; drawn as fans")
            from alight.exchange.mtl import missing_libraries

            _attach_diffuse_maps(spec, path, extras, textures)
            warnings += [f"{spec}: mtllib '{name}' not found; the parts using its materials are drawn with "
                         f"{CURRENT_MATERIAL}"
                         for name in missing_libraries(path)]
            # What trimesh repairs as it parses without a word: only the text can tell.
            (short, line), (bad_colors, colour_line) = _obj_text_checks(path)
            if short:
                warnings.append(f"{spec}: {short} face{'s' if short > 1 else ''} with fewer than 3 vertices "
                                f"(line {line}) not drawn")
            if bad_colors:
                warnings.append(f"{spec}: {bad_colors} vertex colour{'s' if bad_colors > 1 else ''} NaN or Inf "
                                f"(line {colour_line}); drawn black")
        parts = []
        placed = []
        for node in scene.graph.nodes_geometry:
            transform, geom_name = scene.graph[node]
            geom = scene.geometry.get(geom_name)
            if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
                continue  # point clouds and line paths have no triangles to render
            placed.append((node, np.asarray(transform, np.float64), geom))
        # Far from the origin (a survey's coordinates): moved near it in float64 (Mesh.origin).
        # (From the vertices themselves: trimesh's bounds index them by the faces, checked later.)
        centres = [t[:3, :3] @ (np.nanmin(v, axis=0) + np.nanmax(v, axis=0)) / 2.0 + t[:3, 3]
                   for _, t, g in placed for v in [np.asarray(g.vertices, np.float64)] if len(v)]
        origin = far_origin([c for c in centres if np.isfinite(c).all()])
        for node, transform, geom in placed:
            if ext == ".stl":
                # STL is a list of facets: flat. trimesh's ASCII reader shares the corners of
                # touching facets (the binary one does not), which smoothed across every edge.
                geom.unmerge_vertices()
            transform = transform.copy()
            transform[:3, 3] -= origin
            part = _part_from_trimesh(spec, str(node), geom, transform, textures, extras, warnings)
            if part is not None:
                parts.append(part)
    except AlightError:
        raise
    except Exception as exc:  # e.g. a texture that PIL can only decode lazily and fails on
        raise AlightError(f"{spec}: cannot read the file ({_one_line(exc)})") from None
    if not parts:
        raise AlightError(f"{spec}: no triangles in the file")
    return Mesh(parts, str(spec), warnings=warnings, origin=tuple(float(x) for x in origin))


def _obj_faces(spec: str, path: Path):
    """The OBJ's faces made explicit (alight.exchange.obj_faces); a file that cannot be read is
    an AlightError naming it."""
    from alight.exchange.obj_faces import read_faces

    try:
        data = path.read_bytes()
    except OSError as e:
        raise AlightError(f"{spec}: cannot read the file ({e.strerror or e})") from None
    return read_faces(data)


def _unknown_materials(spec: str, path: Path, usemtl: dict[str, int]) -> list[str]:
    """One line naming the ``usemtl`` materials that no MTL file defines (drawn with the default
    material, which trimesh does silently); none when an mtllib is missing (said already)."""
    from alight.exchange.mtl import material_names, missing_libraries

    if not usemtl or missing_libraries(path):
        return []
    known = material_names(path)
    unknown = [(name, line) for name, line in usemtl.items() if name not in known]
    if not unknown:
        return []
    where = "the MTL files do not define" if known else "no mtllib defines"
    listed = ", ".join(f"'{name}' (line {line})" for name, line in unknown[:5])
    more = f" and {len(unknown) - 5} more" if len(unknown) > 5 else ""
    return [f"{spec}: usemtl {listed}{more}: {where} {'it' if len(unknown) == 1 else 'them'}; drawn with "
            f"{CURRENT_MATERIAL}"]


def _part_from_trimesh(spec: str, name: str, geom, transform: np.ndarray,
                       textures: dict[int, np.ndarray], extras: dict[str, dict],
                       warnings: list[str]) -> MeshPart | None:
    """One trimesh geometry placed by its node transform; None when no face survives. What is
    repaired (non-finite uvs; a PLY's non-finite vertex colours, which trimesh stores as 0) is
    said in ``warnings``, one line each."""
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
    positions = rows_times(positions, m) + t
    if det < 0:
        faces = faces[:, ::-1]
        cof = -cof

    computed, computed_ok = _normalize(smooth_normals(positions, faces))
    normals = computed
    if file_normals is not None and np.shape(file_normals) == positions.shape:
        from_file, file_ok = _normalize(rows_times(file_normals, cof))
        normals = np.where(file_ok[:, None], from_file, computed)
        computed_ok = computed_ok | file_ok
    normals[~computed_ok] = (0.0, 1.0, 0.0)

    uv = getattr(geom.visual, "uv", None)
    if uv is not None and np.shape(uv) == (len(positions), 2):
        uvs = np.asarray(uv, dtype=np.float64)
        bad = ~np.isfinite(uvs).all(axis=1)
        if bad.any():
            warnings.append(f"{spec}: {int(bad.sum())} texture coordinate(s) of '{name}' are NaN or Inf; "
                            f"drawn at (0, 0)")
            uvs = np.where(bad[:, None], 0.0, uvs)
    else:
        uvs = np.zeros((len(positions), 2))

    colors = None
    if getattr(geom.visual, "kind", None) == "vertex":
        from alight.core.shading import srgb_to_linear

        rgba = np.asarray(geom.visual.vertex_colors, dtype=np.float64)
        if rgba.shape == (len(positions), 4):
            bad = _ply_nonfinite_colours(geom)
            if bad:
                warnings.append(f"{spec}: {bad} vertex colour value(s) of '{name}' NaN or Inf; drawn black")
            rgba = np.clip(rgba / 255.0 if rgba.max(initial=0.0) > 1.0 else rgba, 0.0, 1.0)
            colors = np.concatenate([srgb_to_linear(rgba[:, :3]), rgba[:, 3:]], axis=1)

    return MeshPart(
        name=name,
        positions=np.ascontiguousarray(positions, dtype=np.float32),
        normals=np.ascontiguousarray(normals, dtype=np.float32),
        uvs=np.ascontiguousarray(uvs, dtype=np.float32),
        tangents=None,   # made from the uvs if a map needs them (MeshPart.tangents)
        indices=np.ascontiguousarray(faces, dtype=np.uint32),
        material=_file_material(getattr(geom.visual, "material", None), textures, extras),
        colors=None if colors is None else np.ascontiguousarray(colors, dtype=np.float32),
    )


def _obj_text_checks(path: Path) -> tuple[tuple[int, int], tuple[int, int]]:
    """(count, first line number) of an OBJ's ``f`` statements with fewer than 3 vertices
    (Wavefront OBJ: a face has at least three), which trimesh drops, and of its ``v x y z r g b``
    colours that are not finite, which trimesh stores as 0; (0, 0) where there are none. One pass
    over the lines, splitting only face lines (and vertex lines only where the file holds a 'nan'
    or 'inf'): 0.8-0.9 s for a 1M-line file that trimesh parses in 10.6 s."""
    data = path.read_bytes()
    lowered = data.lower()
    colours_to_check = b"nan" in lowered or b"inf" in lowered   # almost never: then no v line is split
    short: list[int] = []
    colours: list[int] = []
    for number, line in enumerate(data.split(b"\n"), 1):
        head = line[:2]
        if head in (b"f ", b"f\t", b"f", b"f\r"):
            if b"#" in line:
                line = line.split(b"#", 1)[0]
            if len(line.split(None, 3)) < 4:
                short.append(number)
        elif colours_to_check and head in (b"v ", b"v\t") and (b"n" in line or b"N" in line):   # nan, inf
            tokens = line.split(b"#", 1)[0].split()
            if len(tokens) >= 7 and not all(_finite_token(t) for t in tokens[4:7]):
                colours.append(number)
    return (len(short), short[0] if short else 0), (len(colours), colours[0] if colours else 0)


# An OBJ vertex statement's numbers (Wavefront OBJ): v x y z [w] or v x y z r g b (a colour,
# alight.exchange.meshes' docstring), vn i j k, vt u [v [w]].
_OBJ_NUMBERS = {b"v": ((3, 4, 6, 7), "a vertex needs 3 coordinates (x y z, or x y z r g b)"),
                b"vn": ((3,), "a normal needs 3 numbers (i j k)"),
                b"vt": ((1, 2, 3), "a texture coordinate needs 1 to 3 numbers (u v)")}


def _obj_syntax_problem(path: Path) -> str | None:
    """The first v/vn/vt line of an OBJ whose numbers are too few, too many or not numbers, as
    'line N: ...' (None: the text looks right and trimesh's own message is all there is). Read
    only after trimesh has failed, whose message names no line."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
    for number, line in enumerate(data.split(b"\n"), 1):
        tokens = line.split(b"#", 1)[0].split()
        if not tokens or tokens[0] not in _OBJ_NUMBERS:
            continue
        counts, need = _OBJ_NUMBERS[tokens[0]]
        values = tokens[1:]
        for token in values:
            try:
                float(token)
            except ValueError:
                return f"line {number}: '{token.decode('utf-8', 'replace')}' is not a number ({need})"
        if len(values) not in counts:
            return f"line {number}: {need}; got {len(values)}"
    return _obj_index_problem(data)


def _obj_index_problem(data: bytes) -> str | None:
    """The first f line of an OBJ naming a vertex, texture coordinate or normal the file does not
    have, as 'line N: ...' (trimesh's IndexError named numpy's 0-based index and no line)."""
    lines = data.split(b"\n")
    totals = {b"v": 0, b"vt": 0, b"vn": 0}
    for line in lines:
        head = line.split(None, 1)[:1]
        if head and head[0] in totals:
            totals[head[0]] += 1
    kinds = ((b"v", "vertex", "vertices"), (b"vt", "texture coordinate", "texture coordinates"),
             (b"vn", "normal", "normals"))
    for number, line in enumerate(lines, 1):
        tokens = line.split(b"#", 1)[0].split()
        if not tokens or tokens[0] != b"f":
            continue
        for corner in tokens[1:]:
            for token, (key, one, many) in zip(corner.split(b"/"), kinds):
                try:
                    index = int(token)
                except ValueError:
                    continue   # empty (v//vn) or not a number: another check's to say
                count = totals[key]
                if index == 0 or abs(index) > count:
                    return (f"line {number}: the face names {one} {index}, but the file has {count} {many} "
                            f"(OBJ counts from 1; negative counts back from the last)")
    return None


def _ply_nonfinite_colours(geom) -> int:
    """How many of a PLY's vertex colour values are NaN or Inf: trimesh hands colours back as
    uint8 with those already 0, and keeps the file's raw values in its metadata (an OBJ's are
    found by _obj_text_checks)."""
    raw = geom.metadata.get("_ply_raw", {}).get("vertex", {}).get("data", {}) if hasattr(geom, "metadata") else {}
    return sum(int((~np.isfinite(np.asarray(raw[k], np.float64))).sum())
               for k in ("red", "green", "blue", "alpha") if k in raw)


def _finite_token(token: bytes) -> bool:
    try:
        return math.isfinite(float(token))
    except ValueError:
        return True   # not a number: trimesh's to judge


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
    if kind == "SimpleMaterial":
        if getattr(mat, "_name", None) is None:
            # trimesh's placeholder (a grey 2x2 image) for an OBJ with uvs but no usable .mtl
            return None
        diffuse = _factor(mat.diffuse, (1.0, 1.0, 1.0, 1.0))
        own_map = extras.get("map_Kd", {}).get(mat.name)
        return FileMaterial(
            # MTL Kd is display-referred in practice; (x/255)**2.2 approximates the sRGB decode.
            base_color=tuple(float(x) ** 2.2 for x in diffuse[:3]),
            metallic=0.0,
            roughness=0.5,
            emissive=(0.0, 0.0, 0.0),
            alpha=float(diffuse[3]) if len(diffuse) > 3 else 1.0,
            base_color_texture=own_map if own_map is not None else _texture(mat.image, textures),
            metallic_roughness_texture=None,
            normal_texture=None,
            normal_scale=1.0,
            emissive_texture=None,
            occlusion_texture=None,
            occlusion_strength=1.0,
        )
    return None


def _attach_diffuse_maps(spec: str, path: Path, extras: dict, cache: dict) -> None:
    """The OBJ's MTL map_Kd statements, read by alight.exchange.mtl (options applied), as
    TextureInfos by material name in ``extras['map_Kd']``; a map that does not read is an error."""
    from alight.core.mesh import TextureInfo, TextureTransform
    from alight.exchange.images import decode_texture
    from alight.exchange.mtl import diffuse_maps

    out = {}
    for name, diffuse in diffuse_maps(path).items():
        key = str(diffuse.path)
        if key not in cache:
            try:
                data = diffuse.path.read_bytes()
            except OSError as e:
                raise AlightError(f"{spec}: material {name}: map_Kd '{diffuse.path.name}' cannot be read "
                                  f"({e.strerror or e})") from None
            cache[key] = decode_texture(data, f"{spec}: material {name}: map_Kd '{diffuse.path.name}'")
        transform = None
        if diffuse.offset != (0.0, 0.0) or diffuse.scale != (1.0, 1.0):
            (ou, ov), (su, sv) = diffuse.offset, diffuse.scale
            # uv' = s uv + o on OpenGL uvs is, in glTF's v-down space, scale s and offset (ou, 1 - sv - ov).
            transform = TextureTransform(offset=(ou, 1.0 - sv - ov), scale=(su, sv))
        out[name] = TextureInfo(cache[key], transform=transform)
    extras["map_Kd"] = out
