"""glTF 2.0 as the specification says: each feature is tested by equivalence, a small
file that uses it against one that does not, rendered linear (no tone mapping) within 1% relMAE;
plus coverage, unlit, refusals and warnings. The tests write their own files (tests/gltf_builder.py).
"""

from __future__ import annotations

import functools
import subprocess
import sys

import numpy as np
import pytest
from tests.gltf_builder import FLOAT, UBYTE, USHORT, Gltf, checker, grid_plane

from alight.accuracy.metrics import relative_mae
from alight.core.scene import Camera, Light, Scene, parse_light
from alight.errors import AlightError
from alight.exchange.meshes import load_mesh

SIZE = 96
CAMERA = Camera(position=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)
LIGHTS = [Light(kind="directional", vector=(-0.4, -0.5, -1.0), intensity=2.0)]


@functools.lru_cache(maxsize=1)
def _maps():
    from tests.gpu import renderer

    from alight.ibl.environment import load_environment

    return renderer().bake(load_environment("studio"), "low")


def render(path, camera: Camera = CAMERA, lights=LIGHTS, background: str = "env", ibl: bool = True,
           aa: str = "none", **scene) -> np.ndarray:
    """(H, W, 4) linear radiance of a mesh file, with its own materials."""
    from tests.gpu import renderer

    from alight.core.scene import Display

    mesh = load_mesh(str(path))
    s = Scene(mesh=mesh, camera=camera, lights=list(lights), display=Display(background=background),
              ibl_enabled=ibl, **scene)
    return renderer().render(s, _maps() if ibl else None, SIZE, SIZE, aa=aa).linear


def assert_equivalent(a: np.ndarray, b: np.ndarray, limit: float = 0.01) -> float:
    covered = (a[..., 3] > 0) | (b[..., 3] > 0)
    assert covered.sum() > 200, "the object must cover part of the image"
    rel = relative_mae(a[..., :3], b[..., :3], covered)
    assert rel < limit, f"relMAE {rel:.4f}"
    return rel


def textured_plane(path, uv=None, material_extra=None, texture=None, sampler=None, **attrs) -> Gltf:
    """A 2x2 plane facing +Z with a base-colour checker on TEXCOORD_0 (or the given uvs)."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(4)
    tex = g.image(checker() if texture is None else texture, sampler)
    info = {"index": tex, **(material_extra or {})}
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": info, "metallicFactor": 0.0, "roughnessFactor": 0.6})
    attributes = {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                  "TEXCOORD_0": g.accessor(uvs if uv is None else uv)}
    attributes.update({k: v(g) for k, v in attrs.items()})
    g.mesh([{"attributes": attributes, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    g.save(path)
    return g


# --- equivalence ------------------------------------------------------------------------------

def test_texture_transform_equals_pretransformed_uvs(tmp_path):
    """KHR_texture_transform (offset, rotation, scale) against uvs transformed in the file."""
    from alight.core.mesh import TextureTransform

    t = TextureTransform(offset=(0.1, 0.2), rotation=0.4, scale=(2.0, 1.5))
    _, _, uvs, _ = grid_plane(4)
    moved = (t.matrix() @ np.c_[uvs, np.ones(len(uvs))].T).T[:, :2]
    ext = {"extensions": {"KHR_texture_transform": {"offset": [0.1, 0.2], "rotation": 0.4, "scale": [2.0, 1.5]}}}
    g = textured_plane(tmp_path / "transform.glb", material_extra=ext)
    g.use("KHR_texture_transform")
    g.save(tmp_path / "transform.glb")
    textured_plane(tmp_path / "baked.glb", uv=moved)
    assert_equivalent(render(tmp_path / "transform.glb"), render(tmp_path / "baked.glb"))


def test_texcoord1_equals_texcoord0(tmp_path):
    _, _, uvs, _ = grid_plane(4)
    textured_plane(tmp_path / "uv1.glb", uv=np.zeros_like(uvs), material_extra={"texCoord": 1},
                   TEXCOORD_1=lambda g: g.accessor(uvs))
    textured_plane(tmp_path / "uv0.glb")
    assert load_mesh(str(tmp_path / "uv1.glb")).parts[0].material.base_color_texture.tex_coord == 1
    assert_equivalent(render(tmp_path / "uv1.glb"), render(tmp_path / "uv0.glb"))


def _transform_row(path, baked: bool) -> None:
    """Five quads in a row with a base-colour checker and a white occlusion map (no effect: it
    makes the maps alike); KHR_texture_transform on the checker's TEXCOORD_0, then on the
    occlusion map only, then on the checker's TEXCOORD_1 (TEXCOORD_0 zero), then on the occlusion
    map again, then none and no TEXCOORD_1 at all. ``baked``: the checker's transformed uvs
    written into TEXCOORD_0 instead, no transform and no second set."""
    from alight.core.mesh import TextureTransform

    t = {"offset": [0.1, 0.2], "rotation": 0.4, "scale": [2.0, 1.5]}
    matrix = TextureTransform(offset=(0.1, 0.2), rotation=0.4, scale=(2.0, 1.5)).matrix()
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(4, size=0.9)
    moved = (matrix @ np.c_[uvs, np.ones(len(uvs))].T).T[:, :2]
    tex = g.image(checker())
    white = g.image(np.full((4, 4, 3), 255, np.uint8))
    ext = {"extensions": {"KHR_texture_transform": t}}
    for k, (moved_checker, tex_coord) in enumerate(((True, 0), (False, 0), (True, 1), (False, 0), (False, None))):
        attributes = {"POSITION": g.accessor(positions + [(k - 2) * 1.0, 0.0, 0.0], bounds=True),
                      "NORMAL": g.accessor(normals)}
        if baked or tex_coord is None:
            attributes["TEXCOORD_0"] = g.accessor(moved if moved_checker else uvs)
            base, occlusion = {"index": tex}, {"index": white}
        else:
            attributes["TEXCOORD_0"] = g.accessor(np.zeros_like(uvs) if tex_coord else uvs)
            attributes["TEXCOORD_1"] = g.accessor(uvs)
            base = {"index": tex, "texCoord": tex_coord, **(ext if moved_checker else {})}
            occlusion = {"index": white, **({} if moved_checker else ext)}
        mat = g.material(pbrMetallicRoughness={"baseColorTexture": base, "metallicFactor": 0.0, "roughnessFactor": 0.6},
                         occlusionTexture=occlusion)
        g.mesh([{"attributes": attributes, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    if not baked:
        g.use("KHR_texture_transform")
    g.save(path)


def test_transforms_and_uv_sets_share_one_program(tmp_path, monkeypatch):
    """Parts whose maps differ only in KHR_texture_transform and texCoord, or in having a
    TEXCOORD_1, draw with one program (uniforms, not variants: alight.render.variants.map_uv_uniforms),
    each with its own uvs: a map without a transform drawn after one with a transform must not
    keep its matrix, nor a TEXCOORD_0 map the other's uv set. The same from the visibility buffer
    (a part without TEXCOORD_1 in a HAS_UV1 variant)."""
    from tests.gpu import renderer

    _transform_row(tmp_path / "row.glb", baked=False)
    _transform_row(tmp_path / "baked.glb", baked=True)
    shaders = renderer().shaders
    used = []
    program = shaders.program

    def recording(vertex, fragment, defines=None):
        if fragment == "render/pbr.frag":
            used.append(shaders.program_key(vertex, fragment, defines))
        return program(vertex, fragment, defines)

    monkeypatch.setattr(shaders, "program", recording)
    camera = Camera(position=(0.0, 0.0, 6.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)
    row = render(tmp_path / "row.glb", camera=camera)
    assert len(used) >= 5 and len(set(used)) == 1, set(used)
    baked = render(tmp_path / "baked.glb", camera=camera)
    assert_equivalent(row, baked)
    r = renderer()
    try:
        r.mesh_shading = "vbuffer"
        shaded = render(tmp_path / "row.glb", camera=camera, aa="msaa")
        assert r.last_vbuffer
    finally:
        r.mesh_shading = "forward"
    assert_equivalent(shaded, render(tmp_path / "baked.glb", camera=camera, aa="msaa"))


def test_quantized_uvs_equal_float(tmp_path):
    """KHR_mesh_quantization: TEXCOORD_0 as normalized unsigned short."""
    _, _, uvs, _ = grid_plane(4)
    g = Gltf()
    positions, normals, _, idx = grid_plane(4)
    tex = g.image(checker())
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": tex}, "metallicFactor": 0.0,
                                           "roughnessFactor": 0.6})
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(np.rint(uvs * 65535), USHORT, normalized=True)},
             "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    g.use("KHR_mesh_quantization", required=True)
    g.save(tmp_path / "quantized.glb")
    textured_plane(tmp_path / "float.glb")
    assert_equivalent(render(tmp_path / "quantized.glb"), render(tmp_path / "float.glb"))


def test_sparse_equals_dense(tmp_path):
    positions, normals, _, idx = grid_plane(4)
    lifted = positions.copy()
    ids = np.array([2, 7, 12])
    lifted[ids, 2] += 0.5
    for name, acc in (("sparse", lambda g: g.accessor(positions, bounds=True, sparse=(ids, lifted[ids]))),
                      ("dense", lambda g: g.accessor(lifted, bounds=True))):
        g = Gltf()
        mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.5, 0.2, 1.0], "metallicFactor": 0.0})
        g.mesh([{"attributes": {"POSITION": acc(g)}, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
        g.save(tmp_path / f"{name}.gltf")
    sparse = load_mesh(str(tmp_path / "sparse.gltf")).parts[0]
    assert np.isclose(sparse.positions[:, 2].max(), 0.5)
    assert_equivalent(render(tmp_path / "sparse.gltf"), render(tmp_path / "dense.gltf"))


def _cube_corners():
    faces = [((1, 0, 0), (0, 0, -1)), ((-1, 0, 0), (0, 0, 1)), ((0, 1, 0), (1, 0, 0)),
             ((0, -1, 0), (1, 0, 0)), ((0, 0, 1), (1, 0, 0)), ((0, 0, -1), (-1, 0, 0))]
    out = []
    for n, t in faces:
        n, t = np.array(n, float), np.array(t, float)
        b = np.cross(n, t)
        quad = [n * 0.7 + (cu * t + cv * b) * 0.7 for cu, cv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        out.append((np.array(quad), n))
    return out


COLOURS = [(0.9, 0.1, 0.1), (0.1, 0.8, 0.1), (0.1, 0.2, 0.9), (0.9, 0.9, 0.1), (0.1, 0.9, 0.9), (0.9, 0.1, 0.9)]
TILTED = Camera(position=(2.6, 2.2, 3.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)


def test_color0_equals_per_face_materials(tmp_path):
    """COLOR_0 (here normalized unsigned bytes, RGBA) multiplies the base colour."""
    colours8 = np.rint(np.array(COLOURS) * 255) / 255
    g = Gltf()
    white = g.material(pbrMetallicRoughness={"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0})
    pos, nor, col, idx = [], [], [], []
    for k, (quad, n) in enumerate(_cube_corners()):
        pos += list(quad)
        nor += [n] * 4
        col += [(*colours8[k], 1.0)] * 4
        idx += [4 * k, 4 * k + 1, 4 * k + 2, 4 * k, 4 * k + 2, 4 * k + 3]
    g.mesh([{"attributes": {"POSITION": g.accessor(np.array(pos), bounds=True), "NORMAL": g.accessor(np.array(nor)),
                            "COLOR_0": g.accessor(np.rint(np.array(col) * 255), UBYTE, normalized=True)},
             "indices": g.accessor(np.array(idx), USHORT), "material": white}])
    g.save(tmp_path / "color0.glb")
    g = Gltf()
    prims = []
    for k, (quad, n) in enumerate(_cube_corners()):
        mat = g.material(pbrMetallicRoughness={"baseColorFactor": [*colours8[k], 1.0], "metallicFactor": 0.0})
        prims.append({"attributes": {"POSITION": g.accessor(quad, bounds=True), "NORMAL": g.accessor(np.tile(n, (4, 1)))},
                      "indices": g.accessor(np.array([0, 1, 2, 0, 2, 3]), USHORT), "material": mat})
    g.mesh(prims)
    g.save(tmp_path / "faces.glb")
    assert_equivalent(render(tmp_path / "color0.glb", TILTED), render(tmp_path / "faces.glb", TILTED))


def test_missing_normals_are_flat(tmp_path):
    """No NORMAL: flat normals (section 3.7.2.1), as if the file gave each face its own."""
    shared = np.array([(x, y, z) for x in (-0.7, 0.7) for y in (-0.7, 0.7) for z in (-0.7, 0.7)])
    tris = []
    for quad, _ in _cube_corners():
        k = [int(np.argmin(np.linalg.norm(shared - p, axis=1))) for p in quad]
        tris += [k[0], k[1], k[2], k[0], k[2], k[3]]
    g = Gltf()
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0})
    g.mesh([{"attributes": {"POSITION": g.accessor(shared, bounds=True)},
             "indices": g.accessor(np.array(tris), USHORT), "material": mat}])
    g.save(tmp_path / "shared.glb")
    g = Gltf()
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0})
    pos, nor, idx = [], [], []
    for k, (quad, n) in enumerate(_cube_corners()):
        pos += list(quad)
        nor += [n] * 4
        idx += [4 * k, 4 * k + 1, 4 * k + 2, 4 * k, 4 * k + 2, 4 * k + 3]
    g.mesh([{"attributes": {"POSITION": g.accessor(np.array(pos), bounds=True), "NORMAL": g.accessor(np.array(nor))},
             "indices": g.accessor(np.array(idx), USHORT), "material": mat}])
    g.save(tmp_path / "flat.glb")
    assert_equivalent(render(tmp_path / "shared.glb", TILTED), render(tmp_path / "flat.glb", TILTED))


def _disc(n: int = 12):
    angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    rim = np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], -1)
    return np.vstack([[0.0, 0.0, 0.0], rim])


@pytest.mark.parametrize("mode", [5, 6])
def test_strip_and_fan_equal_triangles(tmp_path, mode):
    """TRIANGLE_STRIP and TRIANGLE_FAN against the same triangles listed."""
    if mode == 6:
        positions = _disc()
        order = np.r_[0, np.arange(1, 13), 1]
        tris = [(0, order[i + 1], order[i + 2]) for i in range(12)]   # fan: {v_i+1, v_i+2, v_0}
    else:
        xs = np.repeat(np.linspace(-1, 1, 6), 2)
        positions = np.stack([xs, np.tile([0.5, -0.5], 6), np.zeros(12)], -1)
        order = np.arange(12)
        tris = [(i, i + 1 + i % 2, i + 2 - i % 2) for i in range(10)]
    for name, prim in (("listed", {"indices": np.array(tris).ravel(), "mode": 4}), ("packed", {"indices": order, "mode": mode})):
        g = Gltf()
        mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.2, 0.7, 0.3, 1], "metallicFactor": 0.0})
        g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True)},
                 "indices": g.accessor(prim["indices"], USHORT), "mode": prim["mode"], "material": mat}])
        g.save(tmp_path / f"{name}.glb")
    assert_equivalent(render(tmp_path / "packed.glb"), render(tmp_path / "listed.glb"))


def _seam_plane(path, split: bool):
    """A 2x1 plane whose uvs mirror at x = 0, with a tilted-normal map and no TANGENT; the seam's
    vertices shared (one position, normal and uv) or split (two vertices each)."""
    n = 4
    xs = np.linspace(-1, 1, 2 * n + 1)
    ys = np.linspace(-1, 1, n + 1)
    cols = []
    for i, x in enumerate(xs):
        cols.append((x, abs(x)))
        if split and i == n:
            cols.append((x, abs(x)))
    pos, uvs = [], []
    for y in ys:
        for x, u in cols:
            pos.append((x, y, 0.0))
            uvs.append((u, (1 - y) / 2))
    w = len(cols)
    idx = []
    for j in range(n):
        for i in range(w - 1):
            if split and i == n:
                continue   # between the two copies of the seam
            a = j * w + i
            idx += [a, a + 1, a + w + 1, a, a + w + 1, a + w]
    g = Gltf()
    tilt = np.zeros((8, 8, 3), np.uint8)
    tilt[...] = (218, 128, 218)   # normal (0.71, 0, 0.71) in tangent space: toward +u
    tex = g.image(tilt)
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0,
                                           "roughnessFactor": 0.5}, normalTexture={"index": tex})
    g.mesh([{"attributes": {"POSITION": g.accessor(np.array(pos), bounds=True),
                            "NORMAL": g.accessor(np.tile([0.0, 0.0, 1.0], (len(pos), 1))),
                            "TEXCOORD_0": g.accessor(np.array(uvs))},
             "indices": g.accessor(np.array(idx), USHORT), "material": mat}])
    return g.save(path)


def test_mirrored_seam_equals_split_seam(tmp_path):
    """MikkTSpace splits a shared vertex at a mirrored uv seam: shared and split seams render
    the same, the halves lit differently (the light comes from +X; +u, where the map tilts the
    normal, points away from the seam on both halves)."""
    light = [Light(kind="directional", vector=(-1.0, 0.0, -0.6), intensity=3.0)]
    shared = render(_seam_plane(tmp_path / "shared.glb", False), lights=light, ibl=False)
    split = render(_seam_plane(tmp_path / "split.glb", True), lights=light, ibl=False)
    assert_equivalent(shared, split)
    row = shared[SIZE // 2, :, 0]
    covered = np.flatnonzero(shared[SIZE // 2, :, 3] > 0)
    left, right = row[covered[: len(covered) // 3]].mean(), row[covered[-len(covered) // 3:]].mean()
    assert right > 3 * left   # tilted toward +u: toward the light on the right half only


# --- alpha, unlit, double-sided -----------------------------------------------------------

def _flat_plane(path, **material):
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    mat = g.material(**material)
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(uvs)}, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g


def test_unlit_pixels_equal_base_colour(tmp_path):
    g = _flat_plane(tmp_path / "u.glb", pbrMetallicRoughness={"baseColorFactor": [0.6, 0.3, 0.1, 1]},
                    extensions={"KHR_materials_unlit": {}})
    g.use("KHR_materials_unlit", required=True)
    image = render(g.save(tmp_path / "u.glb"))
    covered = image[..., 3] == 1
    assert covered.sum() > 1000
    np.testing.assert_allclose(image[covered][:, :3], np.tile([0.6, 0.3, 0.1], (covered.sum(), 1)), atol=1e-5)


def test_blend_coverage_matches_alpha(tmp_path):
    """BLEND over nothing (--background transparent): alpha is the material's, and the radiance
    is the opaque plane's times alpha (premultiplied, as EXR stores it)."""
    g = _flat_plane(tmp_path / "b.glb", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.4, 0.2, 0.3], "metallicFactor": 0.0},
                    alphaMode="BLEND")
    blend = render(g.save(tmp_path / "b.glb"), background="transparent")
    g = _flat_plane(tmp_path / "o.glb", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.4, 0.2, 0.3], "metallicFactor": 0.0})
    opaque = render(g.save(tmp_path / "o.glb"), background="transparent")
    inside = opaque[..., 3] == 1
    np.testing.assert_allclose(blend[inside][:, 3], 0.3, atol=1e-5)
    np.testing.assert_allclose(blend[inside][:, :3], 0.3 * opaque[inside][:, :3], rtol=1e-4, atol=1e-6)


def test_mask_coverage_matches_alpha(tmp_path):
    """MASK: texels below alphaCutoff are discarded (alpha 0 behind them), the rest opaque."""
    tex = np.zeros((16, 16, 4), np.uint8)
    tex[..., :3] = 200
    tex[:, :8, 3] = 40      # left half alpha 0.16 < 0.5
    tex[:, 8:, 3] = 255
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    t = g.image(tex, {"magFilter": 9728, "minFilter": 9728})
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t}, "metallicFactor": 0.0}, alphaMode="MASK")
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                            "TEXCOORD_0": g.accessor(uvs)}, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    image = render(g.save(tmp_path / "m.glb"), background="transparent")
    row = image[SIZE // 2, :, 3]
    covered = np.flatnonzero(row > 0)
    assert covered.size > 10 and set(np.unique(row)) <= {0.0, 1.0}
    # the plane spans columns of the image; only its right half (u >= 0.5, x >= 0) is left
    assert covered.min() >= SIZE // 2 - 1


def test_transparent_png_keeps_blend_alpha(tmp_path):
    out = tmp_path / "b.png"
    g = _flat_plane(tmp_path / "b.glb", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.4, 0.2, 0.3], "metallicFactor": 0.0},
                    alphaMode="BLEND")
    g.save(tmp_path / "b.glb")
    run = subprocess.run([sys.executable, "-m", "alight", "render", "--mesh", str(tmp_path / "b.glb"), "--size", "64",
                          "--quality", "low", "--background", "transparent", "--aa", "none", "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    from PIL import Image

    alpha = np.asarray(Image.open(out))[..., 3]
    assert abs(int(alpha[32, 32]) - round(0.3 * 255)) <= 1
    assert alpha[0, 0] == 0


def test_double_sided_back_equals_front(tmp_path):
    """doubleSided true: the back is lit with the flipped normal, as a plane facing the other
    way; false: the back face is culled."""
    behind = Camera(position=(0.0, 0.0, -4.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)
    g = _flat_plane(tmp_path / "d.glb", pbrMetallicRoughness={"baseColorFactor": [0.7, 0.7, 0.2, 1], "metallicFactor": 0.0},
                    doubleSided=True)
    back = render(g.save(tmp_path / "d.glb"), behind)
    g = _flat_plane(tmp_path / "turned.glb", pbrMetallicRoughness={"baseColorFactor": [0.7, 0.7, 0.2, 1], "metallicFactor": 0.0})
    g.doc["nodes"][0]["rotation"] = [0.0, 1.0, 0.0, 0.0]   # 180 degrees about Y: faces -Z
    front = render(g.save(tmp_path / "turned.glb"), behind)
    assert_equivalent(back, front, 1e-3)
    g = _flat_plane(tmp_path / "s.glb", pbrMetallicRoughness={"baseColorFactor": [0.7, 0.7, 0.2, 1]})
    assert render(g.save(tmp_path / "s.glb"), behind)[..., 3].max() == 0.0


def test_mirrored_repeat_equals_mirrored_uvs(tmp_path):
    """MIRRORED_REPEAT with u in [0, 2] against u folded back in the file (CLAMP_TO_EDGE)."""
    _, _, uvs, _ = grid_plane(4)
    wide = uvs * [2.0, 1.0]
    folded = wide.copy()
    folded[:, 0] = 1.0 - np.abs(wide[:, 0] - 1.0)
    clamp = {"wrapS": 33071, "wrapT": 33071}
    textured_plane(tmp_path / "mirror.glb", uv=wide, sampler={"wrapS": 33648, "wrapT": 33071})
    textured_plane(tmp_path / "folded.glb", uv=folded, sampler=clamp)
    assert_equivalent(render(tmp_path / "mirror.glb"), render(tmp_path / "folded.glb"))


# --- lights and cameras from the file -----------------------------------------------------

def test_spot_light_from_file_equals_cli_spot(tmp_path):
    g = _flat_plane(tmp_path / "l.glb", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0})
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "spot", "intensity": 20.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}}]}}
    g.node(translation=[0.3, 0.0, 2.0], extensions={"KHR_lights_punctual": {"light": 0}})
    g.use("KHR_lights_punctual")
    mesh = load_mesh(str(g.save(tmp_path / "l.glb")))
    (light,) = mesh.lights
    assert light.kind == "spot" and np.allclose(light.vector, (0.3, 0.0, 2.0)) and np.allclose(light.direction, (0, 0, -1))
    spec = parse_light(f"spot:pos=0.3,0,2:dir=0,0,-1:inner={np.degrees(0.2)}:outer={np.degrees(0.4)}:intensity=20")
    a = render(tmp_path / "l.glb", lights=mesh.lights, ibl=False)
    b = render(tmp_path / "l.glb", lights=[spec], ibl=False)
    np.testing.assert_allclose(a, b, atol=1e-6)
    row = a[SIZE // 2, :, 0]
    assert row[SIZE // 2 + 5] > 0.1 and row[2:8].max() == 0.0   # lit inside the cone, dark outside


def test_gltf_camera(tmp_path):
    g = _flat_plane(tmp_path / "c.glb", pbrMetallicRoughness={})
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1}}]
    g.node(camera=0, translation=[0.0, 0.0, 5.0])
    mesh = load_mesh(str(g.save(tmp_path / "c.glb")))
    (cam,) = mesh.cameras
    assert np.allclose(cam.position, (0, 0, 5)) and np.allclose(cam.target, (0, 0, 4))
    assert cam.fov_y_deg == pytest.approx(np.degrees(0.6))


# --- MikkTSpace against the reference files ----------------------------------------------

def test_mikktspace_matches_supplied_tangents(shared_data):
    """NormalTangentMirrorTest's TANGENTs were made by MikkTSpace (Blender's exporter): ours,
    generated from its positions, normals and uvs, agree in direction and sign."""
    from pathlib import Path

    from alight.core.mikktspace import generate_tangents
    from alight.exchange.gltf import read_document
    from alight.exchange.gltf_accessors import Accessors

    path = shared_data / "models/khronos/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb"
    doc, blob = read_document(path, str(path))
    acc = Accessors(doc, str(path), Path(path).parent, blob)
    prim = doc.meshes[0].primitives[0]
    a = prim.attributes
    pos, nor, uv, tan = (acc.read(a[k]) for k in ("POSITION", "NORMAL", "TEXCOORD_0", "TANGENT"))
    uv = uv.copy()
    uv[:, 1] = 1.0 - uv[:, 1]
    faces = acc.indices(prim.indices, "x", len(pos)).reshape(-1, 3)
    ours = generate_tangents(pos, nor / np.linalg.norm(nor, axis=1, keepdims=True), uv, faces).reshape(-1, 4)
    theirs = tan[faces.reshape(-1)]
    assert np.all(ours[:, 3] == np.sign(theirs[:, 3]))
    dots = np.sum(ours[:, :3] * theirs[:, :3] / np.linalg.norm(theirs[:, :3], axis=1, keepdims=True), axis=1)
    assert np.degrees(np.arccos(np.clip(dots, -1.0, 1.0))).max() < 0.1   # measured: 0.028 degrees


def test_normal_tangent_test_renders_like_supplied(shared_data):
    """NormalTangentTest (no TANGENT): every normal-mapped cell equals its geometry twin's
    shading closely enough; checked as the generated tangents being orthogonal unit vectors
    with both signs where its mirrored cells are."""
    mesh = load_mesh(str(shared_data / "models/khronos/NormalTangentTest/glTF-Binary/NormalTangentTest.glb"))
    (part,) = mesh.parts
    t = part.tangents.astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(t[:, :3], axis=1), 1.0, atol=1e-5)
    assert np.abs(np.sum(t[:, :3] * part.normals, axis=1)).max() < 1e-4


# --- refusals and warnings ---------------------------------------------------------------

def _cli(*args):
    return subprocess.run([sys.executable, "-m", "alight", "render", "--size", "32", "--quality", "low", *args],
                          capture_output=True, text=True)


def test_required_extension_refused_in_one_line(tmp_path):
    g = _flat_plane(tmp_path / "r.glb", pbrMetallicRoughness={})
    g.use("KHR_materials_made_up", required=True)
    out = tmp_path / "r.png"
    run = _cli("--mesh", str(g.save(tmp_path / "r.glb")), "--out", str(out))
    assert run.returncode == 2 and not out.exists()
    (line,) = run.stderr.strip().splitlines()
    assert line.startswith("alight: error:") and "r.glb" in line and "extensionsRequired" in line
    assert "KHR_materials_made_up" in line and "Traceback" not in run.stderr


@pytest.mark.parametrize("ext", ["EXT_meshopt_compression", "KHR_texture_basisu", "KHR_draco_mesh_compression"])
def test_undecodable_compression_refused(tmp_path, ext, monkeypatch):
    """Without its decoder installed (each is a dependency; here made to look missing), a file
    requiring the compression is refused in one line."""
    from alight.exchange import gltf

    for name in ("meshopt_available", "_ktx2_available", "_draco_available"):
        monkeypatch.setattr(gltf, name, lambda: False)
    g = _flat_plane(tmp_path / "c.glb", pbrMetallicRoughness={})
    g.use(ext, required=True)
    with pytest.raises(AlightError, match=f"extensionsRequired: {ext} is required and no library"):
        load_mesh(str(g.save(tmp_path / "c.glb")))


def test_bad_accessor_names_the_primitive(tmp_path):
    g = _flat_plane(tmp_path / "b.glb", pbrMetallicRoughness={})
    g.mesh([{"attributes": {"POSITION": g.accessor(np.zeros((3, 3)))}, "indices": g.accessor(np.array([0, 1, 9]), USHORT)}])
    out = tmp_path / "b.png"
    run = _cli("--mesh", str(g.save(tmp_path / "b.glb")), "--out", str(out))
    assert run.returncode == 2 and not out.exists()
    (line,) = run.stderr.strip().splitlines()
    assert "b.glb: meshes[1].primitives[0]" in line and "out of range" in line


def test_missing_buffer_names_it(tmp_path):
    g = _flat_plane(tmp_path / "x.gltf", pbrMetallicRoughness={})
    path = g.save(tmp_path / "x.gltf", embedded=False)
    (tmp_path / "x.bin").unlink()
    with pytest.raises(AlightError, match=r"x\.gltf: buffers\[0\]: 'x\.bin' not found"):
        load_mesh(str(path))


def test_percent_encoded_uri(tmp_path):
    g = _flat_plane(tmp_path / "p.gltf", pbrMetallicRoughness={})
    path = g.save(tmp_path / "p.gltf", embedded=False)
    (tmp_path / "p.bin").rename(tmp_path / "my data.bin")
    text = path.read_text().replace('"uri": "p.bin"', '"uri": "my%20data.bin"')
    path.write_text(text)
    assert len(load_mesh(str(path)).parts) == 1


def test_points_and_unknown_extensions_warn_once(tmp_path):
    g = _flat_plane(tmp_path / "w.glb", pbrMetallicRoughness={})
    pts = g.accessor(np.zeros((4, 3)) + [0, 0, 0.1])
    g.mesh([{"attributes": {"POSITION": pts}, "mode": 0}, {"attributes": {"POSITION": pts}, "mode": 0}])
    g.use("KHR_materials_volume_scatter", "KHR_animation_pointer")   # not drawn by alight
    run = _cli("--mesh", str(g.save(tmp_path / "w.glb")), "--out", str(tmp_path / "w.png"))
    assert run.returncode == 0, run.stderr
    lines = [x for x in run.stderr.splitlines() if x.startswith("alight: warning:")]
    assert len(lines) == 3 and len(set(lines)) == 3
    assert sum("POINTS" in x for x in lines) == 1
    assert sum("KHR_materials_volume_scatter" in x for x in lines) == 1


def test_ior_and_specular_reach_the_renderer(tmp_path):
    """KHR_materials_ior, _specular and _emissive_strength as gltf_material imports them."""
    from alight.exchange.gltf_material import dielectric_f0

    g = _flat_plane(tmp_path / "s.glb", pbrMetallicRoughness={"metallicFactor": 0.0}, emissiveFactor=[0.5, 0.25, 0.0],
                    extensions={"KHR_materials_ior": {"ior": 1.8},
                                "KHR_materials_specular": {"specularFactor": 0.7, "specularColorFactor": [1.0, 0.5, 0.5]},
                                "KHR_materials_emissive_strength": {"emissiveStrength": 4.0}})
    g.use("KHR_materials_ior", "KHR_materials_specular", "KHR_materials_emissive_strength")
    fm = load_mesh(str(g.save(tmp_path / "s.glb"))).parts[0].material
    np.testing.assert_allclose(fm.specular_f0, dielectric_f0(1.8, 0.7, (1.0, 0.5, 0.5)))
    np.testing.assert_allclose(fm.emissive, (2.0, 1.0, 0.0))
    from tests.gpu import renderer

    from alight.core.material import Material

    material, maps_used = renderer()._part_material(Scene(), load_mesh(str(tmp_path / "s.glb")).parts[0])
    assert maps_used and np.allclose(material.specular_f0, fm.specular_f0) and isinstance(material, Material)


def test_draco_equals_plain(tmp_path):
    """KHR_draco_mesh_compression, decoded with DracoPy (Google's Draco), against the same plane
    stored plainly."""
    DracoPy = pytest.importorskip("DracoPy")
    positions, normals, uvs, idx = grid_plane(4)
    textured_plane(tmp_path / "plain.glb")
    data = DracoPy.encode(positions.astype(np.float32), idx.astype(np.uint32), normals=normals, tex_coord=uvs,
                          preserve_order=True, quantization_bits=16)
    ids = {a["attribute_type"]: a["unique_id"] for a in DracoPy.decode(data).attributes}   # 0 position, 1 normal, 3 uv
    g = Gltf()
    tex = g.image(checker())
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": tex}, "metallicFactor": 0.0, "roughnessFactor": 0.6})
    view = g._view(data)
    count = len(positions)
    for array in (positions, normals, uvs):
        g.doc["accessors"].append({"componentType": FLOAT, "count": count, "type": "VEC3" if array.shape[1] == 3 else "VEC2",
                                   **({"min": positions.min(0).tolist(), "max": positions.max(0).tolist()} if array is positions else {})})
    g.doc["accessors"].append({"componentType": USHORT, "count": idx.size, "type": "SCALAR"})
    g.mesh([{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": mat,
             "extensions": {"KHR_draco_mesh_compression": {"bufferView": view, "attributes": {
                 "POSITION": ids[0], "NORMAL": ids[1], "TEXCOORD_0": ids[3]}}}}])
    g.use("KHR_draco_mesh_compression", required=True)
    g.save(tmp_path / "draco.glb")
    assert_equivalent(render(tmp_path / "draco.glb"), render(tmp_path / "plain.glb"))


def _specular_plane(path, specular: dict, textures: dict | None = None) -> Path:
    """A grey dielectric plane with KHR_materials_specular ``specular`` and constant textures
    (``textures``: specularTexture / specularColorTexture -> an RGBA texel)."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(4)
    ext = dict(specular)
    for key, texel in (textures or {}).items():
        ext[key] = {"index": g.image(np.tile(np.asarray(texel, np.uint8), (8, 8, 1)))}
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.2, 0.2, 0.2, 1.0], "metallicFactor": 0.0,
                                           "roughnessFactor": 0.3},
                     extensions={"KHR_materials_specular": ext})
    g.use("KHR_materials_specular")
    attributes = {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals),
                  "TEXCOORD_0": g.accessor(uvs)}
    g.mesh([{"attributes": attributes, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g.save(path)


@pytest.mark.parametrize("color_factor", [1.0, 30.0], ids=["white", "f0_above_1"])
def test_specular_textures_equal_their_factors(tmp_path, color_factor):
    """KHR_materials_specular's specularTexture (A) and specularColorTexture (RGB, sRGB) multiply
    specularFactor and specularColorFactor before the extension's min(..., 1): constant textures
    render as the products of the factors (color_factor 30: F0 1.2 before the texel, so the min
    must come after it)."""
    from alight.core.shading import srgb_to_linear

    texel_a, texel_rgb = 153, (255, 128, 64)
    with_maps = _specular_plane(tmp_path / "maps.glb",
                                {"specularFactor": 0.9, "specularColorFactor": [color_factor] * 3},
                                {"specularTexture": (255, 0, 255, texel_a), "specularColorTexture": (*texel_rgb, 255)})
    colour = [color_factor * float(srgb_to_linear(c / 255.0)) for c in texel_rgb]
    factors = _specular_plane(tmp_path / "factors.glb",
                              {"specularFactor": 0.9 * texel_a / 255.0, "specularColorFactor": colour})
    a, b = render(with_maps), render(factors)
    assert_equivalent(a, b)
    # and the textures do something: without them the plane differs
    plain = render(_specular_plane(tmp_path / "plain.glb", {"specularFactor": 0.9,
                                                            "specularColorFactor": [color_factor] * 3}))
    covered = b[..., 3] > 0
    assert relative_mae(plain[..., :3], b[..., :3], covered) > 0.02
