"""OBJ and STL as modellers write them: concave polygons ear-clipped, no `vn` drawn flat unless a
smoothing group says otherwise, ASCII STL with several solids flat, unknown `usemtl` warned.
Each through the real command, against its control (the shared cases) or against an equivalent
file the test writes itself."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from tests.files_cases import CONTROLS, rel_mae, render_exr, run

ORBIT = ("--orbit", "35", "--elevation", "25", "--target", "0,0,0", "--distance", "6")


# --- the shared cases --------------------------------------------------------------------------

@pytest.mark.parametrize("feature, control, flags", [
    ("obj_concave_hexagon.obj", "obj_concave_ctrl_triangles.obj", ()),
    ("obj_cube_s_off_no_vn.obj", "obj_cube_ctrl_flat_vn.obj", ORBIT),
    ("stl_ascii_two_solids_crlf.stl", "stl_ctrl_binary.stl", ORBIT),
])
def test_case_renders_like_its_control(tmp_path, feature, control, flags):
    a, warn_a = render_exr(tmp_path / "a.exr", "--mesh", CONTROLS / feature, *flags)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", CONTROLS / control, *flags)
    assert rel_mae(a, b) < 0.01
    assert np.array_equal(a[..., 3] > 0, b[..., 3] > 0)   # the same coverage: the L's notch open
    assert warn_a == []


# --- files the tests write -------------------------------------------------------------------

def _l_shape(notches: str = "L") -> list[tuple[float, float]]:
    if notches == "L":
        return [(1, 0), (0, 0), (0, 1), (-1, 1), (-1, -1), (1, -1)]
    if notches == "dart":   # a concave quad, its reflex corner second: a-c runs outside it
        return [(-1, -1), (0, -0.3), (1, -1), (0, 1)]
    # a U: two notches' worth of reflex corners
    return [(-1, 1), (-1, -1), (1, -1), (1, 1), (0.5, 1), (0.5, -0.4), (-0.5, -0.4), (-0.5, 1)]


def _triangles_by_hand(poly):
    """A correct triangulation of the shapes above, written out (the control)."""
    if len(poly) == 6:   # the L: the square (-1..0, -1..1) and the square (0..1, -1..0)
        return [(4, 5, 0), (4, 0, 1), (4, 1, 2), (4, 2, 3)]
    if len(poly) == 4:   # the dart, cut from its reflex corner
        return [(1, 2, 3), (1, 3, 0)]
    return [(0, 1, 7), (1, 6, 7), (1, 2, 6), (2, 5, 6), (2, 3, 5), (3, 4, 5)]


@pytest.mark.parametrize("shape", ["L", "U", "dart"])
def test_concave_polygon_renders_like_its_triangles(tmp_path, shape):
    poly = _l_shape(shape)
    verts = "".join(f"v {x} {y} 0\n" for x, y in poly) + "vn 0 0 1\n"
    (tmp_path / "poly.obj").write_text(verts + "f " + " ".join(f"{i + 1}//1" for i in range(len(poly))) + "\n")
    (tmp_path / "tris.obj").write_text(verts + "".join(
        "f " + " ".join(f"{i + 1}//1" for i in t) + "\n" for t in _triangles_by_hand(poly)))
    a, _ = render_exr(tmp_path / "a.exr", "--mesh", tmp_path / "poly.obj")
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", tmp_path / "tris.obj")
    assert np.array_equal(a[..., 3] > 0, b[..., 3] > 0)
    assert rel_mae(a, b) < 0.01


CUBE_V = "".join(f"v {x} {y} {z}\n" for x in (-1, 1) for y in (-1, 1) for z in (-1, 1))
CUBE_F = ["1 2 4 3", "5 7 8 6", "1 5 6 2", "3 4 8 7", "1 3 7 5", "2 6 8 4"]   # outward, CCW


def _cube_obj(path, smoothing: str | None, normals: bool = False):
    lines = [CUBE_V]
    face_normals = [(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1)]
    if normals:
        lines += [f"vn {x} {y} {z}\n" for x, y, z in face_normals]
    if smoothing is not None:
        lines.append(f"s {smoothing}\n")
    for k, f in enumerate(CUBE_F):
        corners = f.split()
        lines.append("f " + " ".join(f"{c}//{k + 1}" if normals else c for c in corners) + "\n")
    path.write_text("".join(lines))
    return path


@pytest.mark.parametrize("smoothing", [None, "off", "0"])
def test_obj_without_normals_is_flat(tmp_path, smoothing):
    a, _ = render_exr(tmp_path / "a.exr", "--mesh", _cube_obj(tmp_path / "a.obj", smoothing), *ORBIT)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", _cube_obj(tmp_path / "b.obj", None, normals=True), *ORBIT)
    assert rel_mae(a, b) < 0.01


def test_obj_smoothing_group_is_smooth():
    """`s 1` over the shared corners: each corner's normal is the mean of its three faces'."""
    import tempfile
    from pathlib import Path

    from alight.exchange.meshes import load_mesh

    with tempfile.TemporaryDirectory() as d:
        mesh = load_mesh(str(_cube_obj(Path(d) / "s.obj", "1")))
        flat = load_mesh(str(_cube_obj(Path(d) / "f.obj", "off")))
    normals = np.concatenate([p.normals for p in mesh.parts])
    np.testing.assert_allclose(np.abs(normals), 1 / np.sqrt(3), atol=1e-5)
    flat_normals = np.concatenate([p.normals for p in flat.parts])
    assert np.allclose(np.sort(np.abs(flat_normals), axis=1), [0, 0, 1], atol=1e-6)


def test_obj_smoothing_groups_per_face(tmp_path):
    """Two groups on one cube: group 1 (top faces) smooth among themselves, `s off` faces flat."""
    from alight.exchange.meshes import load_mesh

    lines = [CUBE_V, "s off\n"] + [f"f {f}\n" for f in CUBE_F[:3]] + ["s 2\n"] + [f"f {f}\n" for f in CUBE_F[3:]]
    (tmp_path / "g.obj").write_text("".join(lines))
    mesh = load_mesh(str(tmp_path / "g.obj"))
    normals = np.concatenate([p.normals for p in mesh.parts])
    axis_aligned = np.isclose(np.sort(np.abs(normals), axis=1), [0, 0, 1], atol=1e-6).all(axis=1)
    # the 3 flat quads' 12 corners; of group 2's 8 distinct corners, the 4 on two of its faces
    # (+y with -z or +z) blend, the 4 on one face only keep that face's normal
    assert axis_aligned.sum() == 16 and (~axis_aligned).sum() == 4


def test_unknown_usemtl_is_warned_once(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n")
    (tmp_path / "m.obj").write_text("mtllib m.mtl\n" + CUBE_V + "usemtl red\n" + "".join(
        f"f {f}\n" for f in CUBE_F[:3]) + "usemtl blue\n" + "".join(f"f {f}\n" for f in CUBE_F[3:]))
    out = tmp_path / "m.png"
    proc = run("render", "--size", "32", "--quality", "low", "--aa", "none", "--mesh", tmp_path / "m.obj",
               *ORBIT, "--out", out)
    assert proc.returncode == 0, proc.stderr
    warnings = [ln for ln in proc.stderr.splitlines() if ln.startswith("alight: warning:")]
    assert len(warnings) == 1, warnings
    assert "'blue'" in warnings[0] and "line 14" in warnings[0] and "'red'" not in warnings[0]


def test_known_usemtl_is_silent(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n")
    (tmp_path / "m.obj").write_text("mtllib m.mtl\n" + CUBE_V + "usemtl red\n" + "".join(f"f {f}\n" for f in CUBE_F))
    proc = run("render", "--size", "16", "--quality", "low", "--aa", "none", "--mesh", tmp_path / "m.obj",
               "--out", tmp_path / "m.png")
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr


def _cube_triangles() -> np.ndarray:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
    tris = []
    for f in CUBE_F:
        a, b, c, d = (int(i) - 1 for i in f.split())
        tris += [(a, b, c), (a, c, d)]
    return corners[np.array(tris)]          # (12, 3, 3)


def test_ascii_stl_with_several_solids_is_flat_like_binary(tmp_path):
    tris = _cube_triangles()
    text = []
    for name, part in (("first", tris[:6]), ("second", tris[6:])):
        text.append(f"solid {name}\r\n")
        for t in part:
            text.append("\tfacet normal 0 0 0\r\n\t\touter loop\r\n")
            text += [f"\t\t\tvertex {x:e} {y:e} {z:e}\r\n" for x, y, z in t]
            text.append("\t\tendloop\r\n\tendfacet\r\n")
        text.append(f"endsolid {name}\r\n")
    (tmp_path / "a.stl").write_text("".join(text))
    body = b"".join(struct.pack("<3f", 0, 0, 0) + t.astype("<f4").tobytes() + b"\0\0" for t in tris)
    (tmp_path / "b.stl").write_bytes(b"\0" * 80 + struct.pack("<I", len(tris)) + body)
    a, _ = render_exr(tmp_path / "a.exr", "--mesh", tmp_path / "a.stl", *ORBIT)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", tmp_path / "b.stl", *ORBIT)
    assert rel_mae(a, b) < 0.01


def test_ear_clip_covers_the_polygon_area():
    from alight.exchange.obj_faces import ear_clip

    for shape in ("L", "U"):
        poly = np.array([(x, y, 0.0) for x, y in _l_shape(shape)])
        tris = ear_clip(poly)
        assert tris is not None and len(tris) == len(poly) - 2
        p = poly[tris]
        area = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])[:, 2]
        assert (area > 0).all()                                    # every triangle CCW, as the polygon
        x, y = poly[:, 0], poly[:, 1]
        assert area.sum() == pytest.approx(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
