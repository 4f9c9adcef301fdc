"""../shared/data/cases: every glTF, OBJ and PLY file renders as cases/README.md says (the
environment files there are another test's). Renders are linear, compared with a control where
the README names one."""

from __future__ import annotations

import numpy as np
import pytest
from tests.test_gltf import SIZE, assert_equivalent, render

from alight.core.scene import Camera, Light
from alight.exchange.meshes import load_mesh

MESH_CASES = {
    "gltf_no_normals_cube.glb", "gltf_vertex_colors.glb", "gltf_alpha_mask.glb", "gltf_alpha_blend.glb",
    "gltf_texcoord1.glb", "gltf_texture_transform.glb", "gltf_sparse.gltf", "gltf_quantized_uv.glb",
    "gltf_png16_grey_ramp.glb", "gltf_mirrored_uv_seam.glb", "gltf_mirrored_uv_seam_split.glb",
    "gltf_triangle_fan.glb", "gltf_sampler_clamp.glb", "gltf_uri_space", "obj_mtl_options",
    "ply_vertex_colors.ply", "obj_vertex_colors.obj",
}
TILTED = Camera(position=(3.0, 2.5, 3.5), target=(0.0, 0.0, 0.0), fov_y_deg=40.0, near=0.1, far=30.0)


def case(shared_data, name):
    return shared_data / "cases" / name


def test_every_mesh_case_has_a_test(shared_data):
    names = {p.name for p in (shared_data / "cases").iterdir()}
    mesh_like = {n for n in names if n.startswith(("gltf_", "obj_", "ply_"))}
    assert mesh_like == MESH_CASES


def test_no_normals_cube_is_flat(shared_data):
    (part,) = load_mesh(str(case(shared_data, "gltf_no_normals_cube.glb"))).parts
    p = part.positions[part.indices].astype(np.float64)
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    np.testing.assert_allclose(part.normals[part.indices], np.repeat(face[:, None], 3, axis=1), atol=1e-6)


def test_vertex_colours_colour_the_faces(shared_data):
    image = render(case(shared_data, "gltf_vertex_colors.glb"), TILTED)
    covered = image[..., 3] == 1
    pixels = image[covered][:, :3]
    hue = np.argmax(pixels, axis=1)
    assert len(np.unique(hue)) >= 2   # the white material shows coloured faces
    chroma = (pixels.max(axis=1) - pixels.min(axis=1)) / np.maximum(pixels.max(axis=1), 1e-6)
    assert np.median(chroma) > 0.5


def test_alpha_mask_hole(shared_data):
    image = render(case(shared_data, "gltf_alpha_mask.glb"), background="transparent")
    covered = image[..., 3] > 0
    assert covered.sum() > 500 and image[SIZE // 2, SIZE // 2, 3] == 0.0   # the round hole


def test_alpha_blend_see_through(shared_data):
    image = render(case(shared_data, "gltf_alpha_blend.glb"), background="transparent")
    assert image[SIZE // 2, SIZE // 2, 3] == pytest.approx(0.2, abs=1e-4)


@pytest.mark.parametrize("name", ["gltf_texcoord1.glb", "gltf_quantized_uv.glb", "gltf_texture_transform.glb",
                                  "gltf_uri_space/plane.gltf"])
def test_checkers_have_8x8_cells(shared_data, name):
    """texCoord 1, quantized uvs, a scale-4 transform of a 2x2 checker and a percent-encoded image
    URI all show an 8x8 checker: count the colour changes along the middle row."""
    image = render(case(shared_data, name), lights=[], aa="none")
    row = image[SIZE // 2 + 3, :, :3].sum(axis=1)
    covered = image[SIZE // 2 + 3, :, 3] > 0
    values = row[covered]
    dark = values < (values.min() + values.max()) / 2
    changes = np.count_nonzero(dark[1:] != dark[:-1])
    assert changes == 7


def test_texcoord1_equals_quantized(shared_data):
    a = render(case(shared_data, "gltf_texcoord1.glb"))
    b = render(case(shared_data, "gltf_quantized_uv.glb"))
    assert_equivalent(a, b, 0.02)


def test_sparse_three_teeth(shared_data):
    (part,) = load_mesh(str(case(shared_data, "gltf_sparse.gltf"))).parts
    top = part.positions[:, 1].max()
    assert np.count_nonzero(np.isclose(part.positions[:, 1], top)) == 3


def test_png16_grey_ramp(shared_data):
    image = render(case(shared_data, "gltf_png16_grey_ramp.glb"), ibl=False, aa="none")
    row = image[SIZE // 2, :, 0]
    values = row[image[SIZE // 2, :, 3] > 0]
    assert values[-1] > 4 * values[0]                    # dark to white, the dark end lit by specular only
    image16 = load_mesh(str(case(shared_data, "gltf_png16_grey_ramp.glb"))).parts[0].material.base_color_texture.image
    assert image16[0, 0, 0] == 0 and image16[0, -1, 0] == 255   # 16 bits rescaled, not clipped
    assert np.all(np.diff(values[2:-2]) >= -1e-4)        # monotonic: no wrap, no clipping


def test_mirrored_seam_like_split(shared_data):
    light = [Light(kind="directional", vector=(-1.0, 0.0, -0.6), intensity=3.0)]
    a = render(case(shared_data, "gltf_mirrored_uv_seam.glb"), lights=light, ibl=False)
    b = render(case(shared_data, "gltf_mirrored_uv_seam_split.glb"), lights=light, ibl=False)
    assert_equivalent(a, b)
    row = a[SIZE // 2, :, 0]
    assert row[SIZE // 2 - 8] > 5 * max(row[SIZE // 2 + 8], 1e-3)   # left lit, right dark, a sharp edge


def test_triangle_fan_green_disc(shared_data):
    image = render(case(shared_data, "gltf_triangle_fan.glb"))
    covered = image[..., 3] == 1
    assert covered.sum() > 1000
    rgb = image[covered][:, :3].mean(axis=0)
    assert rgb[1] > 1.5 * rgb[0] and rgb[1] > 1.5 * rgb[2]


def test_sampler_clamp(shared_data):
    (part,) = load_mesh(str(case(shared_data, "gltf_sampler_clamp.glb"))).parts
    sampler = part.material.base_color_texture.sampler
    assert (sampler.wrap_s, sampler.wrap_t) == ("clamp_to_edge", "clamp_to_edge")
    image = render(case(shared_data, "gltf_sampler_clamp.glb"), lights=[], aa="none")
    covered = np.argwhere(image[..., 3] > 0)
    (r0, c0), (r1, c1) = covered.min(axis=0), covered.max(axis=0)
    # The outer thirds repeat the edge texels: constant along the stretched direction.
    corner = image[r0 + 2:r0 + (r1 - r0) // 4, c0 + 2:c0 + (c1 - c0) // 4, :3]
    assert np.ptp(corner, axis=(0, 1)).max() < 0.05 * corner.max()


@pytest.mark.parametrize("name", ["map_kd_with_option.obj", "map_kd_space.obj"])
def test_mtl_map_kd_like_plain(shared_data, name):
    plain = render(case(shared_data, "obj_mtl_options/map_kd_plain.obj"), TILTED)
    assert_equivalent(render(case(shared_data, f"obj_mtl_options/{name}"), TILTED), plain)


def test_mtl_scalar_ka_red(shared_data):
    image = render(case(shared_data, "obj_mtl_options/mtl_scalar_ka.obj"), TILTED)
    rgb = image[image[..., 3] == 1][:, :3].mean(axis=0)
    assert rgb[0] > 5 * rgb[1] and rgb[0] > 5 * rgb[2]


@pytest.mark.parametrize("name", ["ply_vertex_colors.ply", "obj_vertex_colors.obj"])
def test_ply_obj_vertex_colours(shared_data, name):
    (part,) = load_mesh(str(case(shared_data, name))).parts
    assert part.colors is not None and part.colors.shape == (len(part.positions), 4)
    image = render(case(shared_data, name), TILTED)
    hue = np.argmax(image[image[..., 3] == 1][:, :3], axis=1)
    assert len(np.unique(hue)) >= 2


def test_mtl_offset_and_scale_equal_moved_uvs(tmp_path):
    """map_Kd -o/-s: the map read at s * uv + o, against an OBJ whose uvs are moved in the file."""
    from PIL import Image

    from tests.gltf_builder import checker

    Image.fromarray(checker(4, 32)).save(tmp_path / "c.png")
    quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n"
    faces = "usemtl m\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n"
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], float)
    moved = uv * (1.5, 0.75) + (0.25, 0.1)
    (tmp_path / "opt.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd -blendu on -s 1.5 0.75 1 -o 0.25 0.1 c.png\n")
    (tmp_path / "plain.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd c.png\n")
    (tmp_path / "opt.obj").write_text("mtllib opt.mtl\n" + quad + "".join(f"vt {u} {v}\n" for u, v in uv) + faces)
    (tmp_path / "plain.obj").write_text("mtllib plain.mtl\n" + quad + "".join(f"vt {u} {v}\n" for u, v in moved) + faces)
    assert_equivalent(render(tmp_path / "opt.obj"), render(tmp_path / "plain.obj"))
