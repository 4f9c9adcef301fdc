"""alight.core.mesh: built-in meshes, tangents, file loading and the refusal of bad files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from alight.core.mesh import (
    BUILTIN_MESHES,
    FileMaterial,
    Mesh,
    MeshPart,
    compute_tangents,
    cube,
    plane,
    sphere,
)
from alight.errors import AlightError
from alight.exchange.meshes import load_mesh

REPO = Path(__file__).resolve().parents[1]


def check_part(part: MeshPart) -> None:
    """Everything the renderer relies on: dtypes, shapes, finite, unit, orthogonal, in range, CCW."""
    n = len(part.positions)
    assert part.positions.dtype == np.float32 and part.positions.shape == (n, 3)
    assert part.normals.dtype == np.float32 and part.normals.shape == (n, 3)
    assert part.uvs.dtype == np.float32 and part.uvs.shape == (n, 2)
    assert part.tangents.dtype == np.float32 and part.tangents.shape == (n, 4)
    assert part.indices.dtype == np.uint32 and part.indices.ndim == 2 and part.indices.shape[1] == 3
    assert len(part.indices) > 0
    for arr in (part.positions, part.normals, part.uvs, part.tangents):
        assert np.isfinite(arr).all()
    assert part.indices.max() < n
    f = part.indices.astype(np.int64)
    assert np.all((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2]))
    np.testing.assert_allclose(np.linalg.norm(part.normals, axis=1), 1.0, atol=1e-5)
    t = part.tangents[:, :3].astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=1e-5)
    assert np.abs(np.sum(t * part.normals, axis=1)).max() < 1e-4
    assert set(np.unique(part.tangents[:, 3])) <= {-1.0, 1.0}


def ccw_fraction(part: MeshPart) -> float:
    """Share of non-degenerate faces whose cross-product normal agrees with the vertex normals."""
    p = part.positions.astype(np.float64)
    f = part.indices.astype(np.int64)
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    area = np.linalg.norm(fn, axis=1)
    keep = area > 1e-12 * max(area.max(), 1e-30)
    vn = part.normals[f].sum(axis=1)
    return float(np.mean(np.sum(fn[keep] * vn[keep], axis=1) > 0))


# --- built-ins ---------------------------------------------------------------------------

@pytest.mark.parametrize("builder", [sphere, cube, plane])
def test_builtin_is_valid_and_ccw(builder):
    mesh = builder()
    assert isinstance(mesh, Mesh) and len(mesh.parts) == 1 and mesh.source == builder.__name__
    part = mesh.parts[0]
    check_part(part)
    assert part.material is None
    assert part.uvs.min() >= 0.0 and part.uvs.max() <= 1.0
    assert ccw_fraction(part) == 1.0
    assert np.all(part.tangents[:, 3] == 1.0)  # no builtin mirrors its texture


def test_builtins_by_name():
    assert BUILTIN_MESHES == ("sphere", "cube", "plane", "shader_ball", "rounded_cube", "drape")
    for name in BUILTIN_MESHES:
        assert load_mesh(name).source == name


def test_sphere_analytic():
    part = sphere(segments=32, rings=16, radius=2.0).parts[0]
    p = part.positions.astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 2.0, atol=1e-5)
    np.testing.assert_allclose(part.normals, p / np.linalg.norm(p, axis=1, keepdims=True), atol=1e-5)
    # v = 1 at the north pole (+Y), 0 at the south pole; u = 0.5 faces the camera on +Z.
    assert np.all(part.uvs[p[:, 1] > 1.999][:, 1] == 1.0)
    assert np.all(part.uvs[p[:, 1] < -1.999][:, 1] == 0.0)
    front = np.argmax(p[:, 2])
    assert part.uvs[front, 0] == pytest.approx(0.5)
    # Analytic tangents agree with the ones derived from the uvs (away from the poles).
    derived = compute_tangents(part.positions, part.normals, part.uvs, part.indices)
    body = np.abs(p[:, 1]) < 1.9
    assert np.sum(derived[body, :3] * part.tangents[body, :3], axis=1).min() > 0.99
    assert np.all(derived[body, 3] == part.tangents[body, 3])


def test_cube_and_plane_layout():
    part = cube(size=3.0).parts[0]
    assert len(part.positions) == 24 and len(part.indices) == 12
    np.testing.assert_allclose(np.abs(part.positions), 1.5)
    # Flat normals: each face's 4 vertices share the outward axis normal.
    for k in range(6):
        n = part.normals[4 * k:4 * k + 4]
        assert np.all(n == n[0]) and np.abs(n[0]).sum() == 1.0
        assert np.all(np.sum(part.positions[4 * k:4 * k + 4] * n[0], axis=1) == pytest.approx(1.5))
        assert {tuple(uv) for uv in part.uvs[4 * k:4 * k + 4]} == {(0, 0), (1, 0), (1, 1), (0, 1)}
    pl = plane(size=4.0).parts[0]
    assert np.all(pl.positions[:, 1] == 0.0) and np.all(pl.normals == (0.0, 1.0, 0.0))
    lo, hi = plane(size=4.0).bounds()
    np.testing.assert_allclose(lo, (-2, 0, -2))
    np.testing.assert_allclose(hi, (2, 0, 2))


# --- compute_tangents --------------------------------------------------------------------

def _quad(uvs):
    positions = np.array([(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)], dtype=np.float32)
    normals = np.tile(np.float32([0, 1, 0]), (4, 1))
    indices = np.array([(0, 1, 2), (0, 2, 3)], dtype=np.uint32)
    return compute_tangents(positions, normals, np.asarray(uvs, dtype=np.float32), indices)


def test_tangents_known_direction_and_handedness():
    # u along +X, v along -Z: tangent +X and cross(n, t) = (0,1,0)x(1,0,0) = -Z = dP/dv, so w = +1.
    t = _quad([(0, 0), (1, 0), (1, 1), (0, 1)])
    np.testing.assert_allclose(t, np.tile([1, 0, 0, 1], (4, 1)), atol=1e-6)
    # Mirrored in v (v along +Z): same tangent, w = -1.
    t = _quad([(0, 1), (1, 1), (1, 0), (0, 0)])
    np.testing.assert_allclose(t, np.tile([1, 0, 0, -1], (4, 1)), atol=1e-6)
    # u along -Z (rotated uvs): tangent -Z.
    t = _quad([(0, 0), (0, 1), (1, 1), (1, 0)])
    np.testing.assert_allclose(t[:, :3], np.tile([0, 0, -1], (4, 1)), atol=1e-6)


@pytest.mark.parametrize("uvs", [np.zeros((4, 2)), np.full((4, 2), 0.3), [(0, 0), (1, 1), (2, 2), (3, 3)]])
def test_tangents_degenerate_uvs(uvs):
    t = _quad(uvs)
    assert np.isfinite(t).all()
    np.testing.assert_allclose(np.linalg.norm(t[:, :3], axis=1), 1.0, atol=1e-6)
    assert np.abs(t[:, 1]).max() < 1e-6  # orthogonal to the +Y normal
    assert np.all(t[:, 3] == 1.0)


def test_tangents_zero_area_triangles_and_bad_normals():
    positions = np.zeros((3, 3), dtype=np.float32)
    normals = np.array([(0, 0, 0), (np.nan, 0, 0), (0, 0, 1)], dtype=np.float32)
    t = compute_tangents(positions, normals, np.zeros((3, 2)), np.array([[0, 1, 2]]))
    assert np.isfinite(t).all()
    np.testing.assert_allclose(np.linalg.norm(t[:, :3], axis=1), 1.0, atol=1e-6)


# --- shared models -------------------------------------------------------------------------

MODELS = [
    "models/DamagedHelmet/DamagedHelmet.gltf",
    "models/Duck.glb",
    "models/BoxTextured.glb",
    "models/CesiumMilkTruck.glb",
    "models/monkey.glb",
    "models/fuze.obj",
    "models/ClearcoatTest.glb",
]


@pytest.mark.parametrize("rel", MODELS)
def test_shared_model_loads(shared_data, rel):
    mesh = load_mesh(str(shared_data / rel))
    assert mesh.source == str(shared_data / rel)
    for part in mesh.parts:
        check_part(part)
        assert ccw_fraction(part) > 0.99
    lo, hi = mesh.bounds()
    assert np.all(lo < hi) and np.isfinite(lo).all() and np.isfinite(hi).all()
    centre, radius = mesh.bounding_sphere()
    assert np.all(centre >= lo) and np.all(centre <= hi)
    half_diag = np.linalg.norm(hi - lo) / 2
    assert half_diag / 2 <= radius <= half_diag + 1e-4
    for part in mesh.parts:
        assert np.linalg.norm(part.positions - centre, axis=1).max() <= radius + 1e-4


def test_damaged_helmet_material(shared_data):
    mesh = load_mesh(str(shared_data / "models/DamagedHelmet/DamagedHelmet.gltf"))
    (part,) = mesh.parts
    m = part.material
    assert isinstance(m, FileMaterial)
    for info in (m.base_color_texture, m.metallic_roughness_texture, m.normal_texture,
                 m.emissive_texture, m.occlusion_texture):
        tex = info.image
        assert tex is not None and tex.dtype == np.uint8 and tex.shape == (2048, 2048, 4)
    # glTF defaults (no factors in the file) and its emissiveFactor [1, 1, 1].
    assert (m.metallic, m.roughness, m.alpha) == (1.0, 1.0, 1.0)
    assert m.base_color == (1.0, 1.0, 1.0) and m.emissive == (1.0, 1.0, 1.0)
    assert m.normal_scale == 1.0 and m.occlusion_strength == 1.0
    # Normal map texels point mostly out of the surface (blue channel high).
    assert m.normal_texture.image[..., 2].mean() > 200
    # Its uvs are stored with v_gltf in [1, 2] (REPEAT wrap); trimesh's flip makes them [-1, 0].
    assert part.uvs[:, 1].max() <= 0.0 and part.uvs[:, 1].min() >= -1.0
    # DamagedHelmet has mirrored uv islands: both handedness signs occur.
    assert 0.2 < np.mean(part.tangents[:, 3] < 0) < 0.8


def test_gltf_factors_are_linear_floats(shared_data):
    mesh = load_mesh(str(shared_data / "models/CesiumMilkTruck.glb"))
    assert len(mesh.parts) == 5  # truck body (3 materials) and two instanced wheels
    glass = [p.material for p in mesh.parts if p.material and p.material.base_color_texture is None]
    colours = {tuple(round(c, 6) for c in m.base_color) for m in glass}
    # Exact values from the file's JSON, not trimesh's uint8 quantisation.
    assert (0.0, 0.040506, 0.021241) in colours
    assert all(m.metallic == 0.0 and m.roughness == 1.0 for m in glass)
    wheels = [p for p in mesh.parts if len(p.indices) == 768]
    assert len(wheels) == 2
    assert not np.allclose(wheels[0].positions, wheels[1].positions)  # each node's transform applied


def test_uv_convention_duck(shared_data):
    """trimesh returns OpenGL uvs (v = 1 - v_gltf): row = (1 - v) * H finds the right texel.

    Checked by the Duck: the vertices at the tip of its beak (+X) sample orange (255, 126, 0)
    with row = (1 - v) * H, and black with row = v * H; its underside samples yellow only with
    the flip.
    """
    (part,) = load_mesh(str(shared_data / "models/Duck.glb")).parts
    tex = part.material.base_color_texture.image
    assert tex.shape == (512, 512, 4)
    h, w = tex.shape[:2]

    def sample(idx, flip=True):
        u, v = part.uvs[idx, 0], part.uvs[idx, 1]
        rows = np.clip(((1 - v) if flip else v) * h, 0, h - 1).astype(int)
        return tex[rows, np.clip(u * w, 0, w - 1).astype(int)].astype(float).mean(axis=0)

    beak = np.argsort(part.positions[:, 0])[-15:]
    r, g, b, _ = sample(beak)
    assert r > 200 and 60 < g < 180 and b < 60  # orange
    assert sample(beak, flip=False)[:3].max() < 50  # the wrong convention lands on black
    belly = np.argsort(part.positions[:, 1])[:15]
    r, g, b, _ = sample(belly)
    assert r > 200 and g > 180 and b < 60  # yellow


def test_box_textured_material(shared_data):
    (part,) = load_mesh(str(shared_data / "models/BoxTextured.glb")).parts
    assert part.material.base_color_texture.image.shape == (256, 256, 4)
    assert part.material.metallic == 0.0


def test_obj_material(tmp_path):
    (tmp_path / "a.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n")
    (tmp_path / "a.obj").write_text(
        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3\n"
    )
    (part,) = load_mesh(str(tmp_path / "a.obj")).parts
    check_part(part)
    m = part.material
    assert m is not None and m.metallic == 0.0 and m.roughness == 0.5
    assert m.base_color[0] == pytest.approx((204 / 255) ** 2.2, abs=1e-6)
    np.testing.assert_allclose(part.normals, np.tile([0, 0, 1], (3, 1)), atol=1e-6)  # computed
    np.testing.assert_allclose(part.tangents, np.tile([1, 0, 0, 1], (3, 1)), atol=1e-6)


def test_ply_and_stl(tmp_path):
    import trimesh

    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    for ext in ("ply", "stl"):
        path = tmp_path / f"box.{ext}"
        box.export(str(path))
        mesh = load_mesh(str(path))
        (part,) = mesh.parts
        check_part(part)
        assert len(part.indices) == 12 and part.material is None
        assert ccw_fraction(part) == 1.0
        lo, hi = mesh.bounds()
        np.testing.assert_allclose(hi - lo, (1, 2, 3), atol=1e-6)


def test_mirroring_node_transform_keeps_ccw(tmp_path):
    """A node with negative determinant (scale -1 in X) must not turn the mesh inside out."""
    import trimesh

    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    scene = trimesh.Scene()
    scene.add_geometry(box, transform=np.diag([-2.0, 1.0, 1.0, 1.0]))
    path = tmp_path / "mirrored.glb"
    scene.export(str(path), include_normals=True)  # file normals go through the normal matrix
    (part,) = load_mesh(str(path)).parts
    check_part(part)
    lo, hi = load_mesh(str(path)).bounds()
    np.testing.assert_allclose(hi - lo, (2, 1, 1), atol=1e-6)
    assert ccw_fraction(part) == 1.0
    assert np.all(np.sum(part.normals * part.positions, axis=1) > 0)  # outward


# --- the bad files -----------------------------------------------------------------------

def _refused(path: Path, what: str) -> None:
    with pytest.raises(AlightError) as info:
        load_mesh(str(path))
    message = str(info.value)
    assert "\n" not in message and path.name in message and what in message


def test_bad_empty_files_are_refused(shared_data):
    _refused(shared_data / "bad/empty.obj", "no triangles")  # only a comment line
    _refused(shared_data / "bad/empty_nodes.glb", "no triangles")  # nodes without meshes


def test_bad_nancolor_loads(shared_data):
    """The positions are a fine cube; the NaN vertex colour (trimesh stores 0: black) is said in
    one warning naming its line."""
    mesh = load_mesh(str(shared_data / "bad/nancolor.obj"))
    (part,) = mesh.parts
    check_part(part)
    assert len(part.positions) == 24 and len(part.indices) == 12   # no vn, no s: flat, 4 corners a side
    assert part.material is None
    (warning,) = [w for w in mesh.warnings if "vertex colour" in w]
    assert "nancolor.obj" in warning and "line 7" in warning and "\n" not in warning


def test_a_ply_with_nan_vertex_colours_says_so(tmp_path):
    """trimesh hands a PLY's colours back as uint8, a NaN already 0 (black): a warning says so."""
    path = tmp_path / "nan_colour.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nproperty float red\nproperty float green\nproperty float blue\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                    "0 0 0 nan 0.5 0.5\n1 0 0 0.5 0.5 0.5\n0 1 0 0.5 0.5 0.5\n3 0 1 2\n")
    mesh = load_mesh(str(path))
    (warning,) = [w for w in mesh.warnings if "vertex colour" in w]
    assert "nan_colour.ply" in warning and "1 vertex colour" in warning
    path.write_text(path.read_text().replace("nan", "0.5"))
    assert not [w for w in load_mesh(str(path)).warnings if "vertex colour" in w]


def test_bad_negative_indices_load(shared_data):
    """OBJ relative indices (-1 = last vertex so far) are legal: 6 quads -> 12 triangles.

    Compared with resolving the indices and fan-triangulating ourselves.
    """
    path = shared_data / "bad/negative_indices.obj"
    (part,) = load_mesh(str(path)).parts
    check_part(part)
    assert len(part.indices) == 12
    verts, expected = [], []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            verts.append(tuple(float(x) for x in line.split()[1:4]))
        elif line.startswith("f "):
            idx = [len(verts) + int(c.split("/")[0]) for c in line.split()[1:]]
            expected += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]

    def canonical(tris):
        out = set()
        for tri in tris:  # rotation-invariant, winding-preserving key
            k = int(np.argmin([hash(t) for t in tri]))
            out.add(tri[k:] + tri[:k])
        return out

    got = [tuple(tuple(float(x) for x in part.positions[i]) for i in f) for f in part.indices]
    want = [tuple(verts[i] for i in f) for f in expected]
    assert canonical(got) == canonical(want)
    assert ccw_fraction(part) == 1.0  # windings agree with the file's vn


def test_bad_no_indices_glb_loads(shared_data):
    """glTF primitives without indices are legal (consecutive vertex triples); node rotation applied."""
    mesh = load_mesh(str(shared_data / "bad/no_indices_3storybuilding.glb"))
    assert len(mesh.parts) == 3
    for part in mesh.parts:
        check_part(part)
        assert len(part.positions) == 72 and len(part.indices) == 24
        np.testing.assert_array_equal(np.sort(part.indices.ravel()), np.arange(72))
    lo, hi = mesh.bounds()
    # The -90 degree rotation about X turns the file's Z-up floors (z 0..9) into Y-up.
    assert lo[1] == pytest.approx(0.0, abs=1e-4) and hi[1] == pytest.approx(9.0, abs=1e-4)
    assert hi[2] == pytest.approx(63.3614, abs=1e-3)


def test_bad_notenoughindices_keeps_the_triangle(shared_data):
    """The two-vertex face `f 1// 2//` is no polygon and is dropped, with a warning naming its
    line; the triangle after it loads."""
    mesh = load_mesh(str(shared_data / "bad/notenoughindices.obj"))
    (warning,) = [w for w in mesh.warnings if "fewer than 3" in w]
    assert "notenoughindices.obj" in warning and "line 9" in warning
    (part,) = mesh.parts
    check_part(part)
    assert len(part.indices) == 1
    np.testing.assert_allclose(part.positions[part.indices[0]], [(-500, 0, 500), (500, 0, 500), (500, 500, 500)])


def test_bad_polygonfaces_triangulated(shared_data):
    """One pentagon -> a fan of 3 triangles covering it, winding kept."""
    (part,) = load_mesh(str(shared_data / "bad/polygonfaces.obj")).parts
    check_part(part)
    assert part.indices.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]


def test_bad_singlevn_loads(shared_data):
    """Every corner uses the one `vn`: all normals are +Y and the faces wind CCW about it."""
    (part,) = load_mesh(str(shared_data / "bad/singlevn.obj")).parts
    check_part(part)
    assert len(part.indices) == 2
    np.testing.assert_allclose(part.normals, np.tile([0, 1, 0], (4, 1)))
    assert ccw_fraction(part) == 1.0
    assert part.material is None  # surface.mtl does not exist: trimesh's placeholder is not a material
    np.testing.assert_allclose(np.abs(load_mesh(str(shared_data / "bad/singlevn.obj")).flat_normal()), [0, 1, 0],
                               atol=1e-9)   # flat: 'alight render' warns that +Z sees it edge-on
    # u along +X and v along -Z: tangent +X, cross(n, t) = -Z = dP/dv, so w = +1.
    np.testing.assert_allclose(part.tangents, np.tile([1, 0, 0, 1], (4, 1)), atol=1e-6)


def test_every_bad_file_has_a_decision(shared_data):
    decided = {
        "empty.obj", "empty_nodes.glb", "nancolor.obj", "negative_indices.obj",
        "no_indices_3storybuilding.glb", "notenoughindices.obj", "polygonfaces.obj", "singlevn.obj",
    }
    assert {p.name for p in (shared_data / "bad").iterdir()} == decided


# --- errors ----------------------------------------------------------------------------------

def test_missing_and_unknown(tmp_path):
    _refused(tmp_path / "nothere.obj", "no such file")
    xyz = tmp_path / "points.xyz"
    xyz.write_text("0 0 0\n1 0 0\n0 1 0\n")
    _refused(xyz, "unsupported mesh format")
    with pytest.raises(AlightError, match="shpere: neither a built-in mesh"):
        load_mesh("shpere")


def test_corrupt_and_truncated(tmp_path, shared_data):
    junk = tmp_path / "junk.glb"
    junk.write_bytes(np.random.default_rng(1).integers(0, 256, 4096, dtype=np.uint8).tobytes())
    _refused(junk, "cannot read")
    data = (shared_data / "models/Duck.glb").read_bytes()
    truncated = tmp_path / "truncated.glb"
    truncated.write_bytes(data[: len(data) // 2])
    _refused(truncated, "cannot read")


def test_nan_positions_and_bad_indices_refused(tmp_path):
    nan = tmp_path / "nan.obj"
    nan.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    _refused(nan, "NaN")
    oor_obj = tmp_path / "oor.obj"  # trimesh itself fails on this one
    oor_obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    _refused(oor_obj, "line 4: the face names vertex 7, but the file has 3 vertices")
    oor_ply = tmp_path / "oor.ply"  # trimesh passes this one through; our check refuses it
    oor_ply.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"
    )
    _refused(oor_ply, "face indices out of range")
    degenerate = tmp_path / "degenerate.obj"
    degenerate.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\nf 2 3 3\n")
    _refused(degenerate, "no triangles")


def test_degenerate_faces_dropped(tmp_path):
    path = tmp_path / "mixed.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n")
    (part,) = load_mesh(str(path)).parts
    check_part(part)
    assert part.indices.tolist() == [[0, 1, 2]]


def test_import_does_not_import_trimesh():
    code = "import sys, alight.exchange.meshes as m; m.sphere(); m.load_mesh('cube'); print('trimesh' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_obj_with_a_missing_mtllib_says_so_once(tmp_path):
    from alight.exchange.meshes import load_mesh

    obj = "mtllib gone.mtl\nmtllib here.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"
    (tmp_path / "tri.obj").write_text(obj)
    (tmp_path / "here.mtl").write_text("newmtl red\nKd 1 0 0\n")
    mesh = load_mesh(str(tmp_path / "tri.obj"))
    assert [w for w in mesh.warnings if "mtllib" in w] == [
        f"{tmp_path / 'tri.obj'}: mtllib 'gone.mtl' not found; the parts using its materials are drawn with "
        "the current material (the default unless one is set)"]
    (tmp_path / "gone.mtl").write_text("newmtl blue\nKd 0 0 1\n")
    assert load_mesh(str(tmp_path / "tri.obj")).warnings == []


def test_framing_fits_a_long_object_in_a_wide_image():
    """fit_distance: the bounding box's corners, where nearer than the sphere fit, all project
    inside both fields of view with the margin; a ball keeps the sphere fit."""
    import math

    from alight.core.mesh import sphere
    from alight.core.scene import frame_camera, orbit_camera

    lo, hi = np.array([-4.0, -0.5, -0.3]), np.array([4.0, 0.5, 0.3])
    pick = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
    corners = np.where(pick, hi, lo)
    radius = float(np.linalg.norm(hi))
    for aspect, orbit in ((2.5, 0.0), (2.5, 30.0), (0.75, 0.0)):
        sphere_fit = orbit_camera((0, 0, 0), radius, aspect, orbit, 10.0)
        box_fit = orbit_camera((0, 0, 0), radius, aspect, orbit, 10.0, corners=corners)
        d_sphere = np.linalg.norm(sphere_fit.position)
        d_box = np.linalg.norm(box_fit.position)
        assert d_box < d_sphere
        vp = box_fit.view_projection(aspect).astype(np.float64)
        clip = np.c_[corners, np.ones(8)] @ vp
        ndc = clip[:, :2] / clip[:, 3:4]
        assert np.abs(ndc).max() <= 1.0 / 1.3 + 1e-6       # inside, with the margin to spare
        assert np.abs(ndc).max() >= 1.0 / 1.3 - 1e-6       # and no further than needed
    ball = sphere()
    cam = frame_camera(*ball.bounding_sphere(), aspect=1.0, corners=ball.corners())
    plain = frame_camera(*ball.bounding_sphere(), aspect=1.0)
    assert cam.position == plain.position and math.isclose(cam.far, plain.far)
