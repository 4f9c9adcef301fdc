"""The visibility bake (alight.core.visibility) and the forward pass's occlusion (--occlusion):
analytic visibility at the foot of a wall, the corner darker than the open floor, the shader's
functions against their numpy twins, the render against the bake's values, the cache, the
built-in sphere untouched, and the command line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("embreex")
trimesh = pytest.importorskip("trimesh")

from alight.core import visibility as vis  # noqa: E402
from alight.core.material import Material  # noqa: E402
from alight.core.scene import Camera, Scene  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.ibl.environment import constant_environment  # noqa: E402
from tests.gpu import evaluate, renderer  # noqa: E402
from tests.warned import alight_warnings  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def _quad(a, b, c, d):
    return np.array([a, b, c, d], np.float64), np.array([[0, 1, 2], [0, 2, 3]])


def _flat_obj(quads, path: Path) -> Path:
    """Quads (counter-clockwise seen from the front) as an OBJ with face normals, written by trimesh."""
    verts, faces, normals, base = [], [], [], 0
    for v, f in quads:
        n = np.cross(v[1] - v[0], v[2] - v[0])
        verts.append(v)
        faces.append(f + base)
        normals.append(np.repeat((n / np.linalg.norm(n))[None], len(v), axis=0))
        base += len(v)
    mesh = trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), vertex_normals=np.concatenate(normals),
                           process=False)
    path.write_text(mesh.export(file_type="obj", include_normals=True, include_texture=False))
    return path


def _box_quads(lo, hi):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    return [_quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
            _quad((x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)),
            _quad((x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)),
            _quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
            _quad((x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0))]


@pytest.fixture(scope="module")
def corner_obj(tmp_path_factory) -> Path:
    """Floor y = 0 over [-1, 1]^2, walls at z = -1 and x = -1 (1.2 high), a 0.6 box near the corner."""
    quads = [_quad((-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)),
             _quad((-1, 0, -1), (1, 0, -1), (1, 1.2, -1), (-1, 1.2, -1)),
             _quad((-1, 0, 1), (-1, 0, -1), (-1, 1.2, -1), (-1, 1.2, 1)),
             *_box_quads((-0.55, 0.0, -0.55), (0.05, 0.7, 0.05))]
    return _flat_obj(quads, tmp_path_factory.mktemp("corner") / "corner.obj")


@pytest.fixture(scope="module")
def corner_bake(corner_obj):
    mesh = load_mesh(str(corner_obj))
    return mesh, vis.bake_visibility(mesh)


def test_foot_of_an_infinite_wall_matches_the_form_factor(tmp_path):
    """A floor point at distance d from a wall of height H (infinitely long) sees the wall with
    form factor (1 - d / sqrt(d^2 + H^2)) / 2 (the 2D strip rule F = (sin a2 - sin a1) / 2 with the
    wall's edges at 90 degrees and atan(d / H) from the normal), so its cosine-weighted visibility
    is 1/2 + d / (2 sqrt(d^2 + H^2)): 1/2 at the foot for any height. The wall here is 40 long, so
    the missing ends change V by under 0.002 at d <= 1."""
    height = 1.0
    quads = [_quad((0, 0, 1), (2, 0, 1), (2, 0, -1), (0, 0, -1)),                   # floor, x >= 0
             _quad((0, 0, 20), (0, 0, -20), (0, height, -20), (0, height, 20))]     # wall x = 0, facing +x
    mesh = load_mesh(str(_flat_obj(quads, tmp_path / "wall.obj")))
    assert vis.self_occludes(mesh.parts)
    baked = vis.bake_visibility(mesh, rays=256, coarse_fraction=1.0 / 500.0, threshold=1.0)
    floor = baked.parts[0]
    p = floor.positions
    on_floor = (np.abs(p[:, 1]) < 1e-6) & (np.abs(p[:, 2]) < 0.8)
    for d in (0.0, 0.25, 0.5, 1.0):
        near = on_floor & (np.abs(p[:, 0] - d) < 0.02)
        assert near.sum() >= 10
        expected = 0.5 + 0.5 * d / np.hypot(d, height)
        got = float(floor.visibility[near].mean())
        assert abs(got - expected) < 0.02, (d, got, expected)
    # The bent normal leans away from the wall, toward +x.
    at_foot = on_floor & (p[:, 0] < 0.02)
    assert (floor.bent_normal[at_foot, 0] > 0.3).all()


def test_the_inner_corner_is_darker_than_the_open_floor(corner_bake):
    mesh, baked = corner_bake
    assert vis.self_occludes(mesh.parts)
    p = np.concatenate([part.positions for part in baked.parts])
    v = np.concatenate([part.visibility for part in baked.parts])
    floor = np.abs(p[:, 1]) < 1e-6
    corner = floor & (np.linalg.norm(p[:, [0, 2]] - (-1.0, -1.0), axis=1) < 0.05)
    open_floor = floor & (np.linalg.norm(p[:, [0, 2]] - (0.95, 0.95), axis=1) < 0.1)
    assert corner.any() and open_floor.any()
    # Two infinite walls would leave a quarter of the hemisphere (V = 0.25) at the corner.
    assert v[corner].max() < 0.3
    assert v[open_floor].min() > 0.8
    w = np.concatenate([part.bounce_weight for part in baked.parts])
    assert w[corner].mean() > w[open_floor].mean()
    # Refinement kept the geometry: the same area.
    def area(pos, idx):
        t = pos[idx]
        return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    before = sum(area(np.asarray(q.positions, np.float64), q.indices) for q in mesh.parts)
    after = sum(area(np.asarray(q.positions, np.float64), q.indices) for q in baked.parts)
    assert after == pytest.approx(before, rel=1e-5)


def test_convex_and_flat_meshes_need_no_bake():
    for name in ("sphere", "cube", "plane"):
        mesh = load_mesh(name)
        assert not vis.self_occludes(mesh.parts), name
        assert not vis.wants_occlusion(mesh, "auto"), name
    assert not vis.wants_occlusion(load_mesh("sphere"), "on")   # the built-in sphere never
    assert vis.wants_occlusion(load_mesh("cube"), "on")
    assert not vis.wants_occlusion(load_mesh("cube"), "off")


def test_shader_functions_match_their_numpy_twins():
    rng = np.random.default_rng(3)
    n = 600
    caps = np.column_stack([rng.uniform(-0.2, 1, n), rng.uniform(0, 1, n), rng.uniform(-1, 1, n)])
    gpu = evaluate(0, caps, shader="accuracy/evaluate_occlusion.comp")[:, 0]
    np.testing.assert_allclose(gpu, vis.spherical_caps_intersection(caps[:, 0], caps[:, 1], caps[:, 2]),
                               atol=2e-4)
    v = rng.uniform(0, 1, n)
    gpu = evaluate(1, v[:, None], shader="accuracy/evaluate_occlusion.comp")[:, 0]
    np.testing.assert_allclose(gpu, vis.cone_aperture_cos(v), atol=1e-5)
    so_in = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(0, 1, n), rng.uniform(0, 1, n), rng.uniform(0, 1, n)])
    gpu = evaluate(2, so_in, shader="accuracy/evaluate_occlusion.comp")[:, 0]
    np.testing.assert_allclose(gpu, vis.specular_occlusion(*so_in.T), atol=2e-3)
    # An unoccluded point (V = 1, bent = n) keeps its whole reflection at every angle.
    r = np.linspace(0.0, 1.0, 11)
    assert np.allclose(vis.specular_occlusion(r, r, 1.0, 0.6), 1.0)


def _floor_values(baked, x, z):
    """V and the bounce weight interpolated on the refined floor at points (x, z)."""
    part = baked.parts[0]
    p = part.positions.astype(np.float64)
    tri = part.indices.astype(np.int64)
    tri = tri[(np.abs(p[tri][:, :, 1]) < 1e-6).all(axis=1)]
    a, b, c = (p[tri[:, k]][:, [0, 2]] for k in range(3))
    q = np.column_stack([x, z])[:, None, :]
    det = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    l1 = ((b[:, 1] - c[:, 1]) * (q[..., 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (q[..., 1] - c[:, 1])) / det
    l2 = ((c[:, 1] - a[:, 1]) * (q[..., 0] - c[:, 0]) + (a[:, 0] - c[:, 0]) * (q[..., 1] - c[:, 1])) / det
    l3 = 1.0 - l1 - l2
    inside = (l1 >= -1e-6) & (l2 >= -1e-6) & (l3 >= -1e-6)
    k = inside.argmax(axis=1)
    rows = np.arange(len(x))
    weights = np.column_stack([l1[rows, k], l2[rows, k], l3[rows, k]])
    corners = tri[k]
    return ((part.visibility[corners] * weights).sum(axis=1), (part.bounce_weight[corners] * weights).sum(axis=1))


def test_the_render_reads_the_bake(corner_obj, corner_bake):
    """Seen from straight above (orthographic) under a uniform white environment, a diffuse floor's
    radiance with occlusion over without it is what occluded_diffuse gives for the baked V and
    bounce weight interpolated there: V + albedo w (the environment's E/pi is 1 everywhere)."""
    mesh, baked = corner_bake
    r = renderer()
    maps = r.bake(constant_environment(1.0), "low")
    camera = Camera(position=(0.0, 5.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0), near=1.0, far=10.0,
                    ortho_half_height=1.0)
    albedo = 0.8
    material = Material(base_color=(albedo,) * 3, metallic=0.0, roughness=1.0, specular_f0=(0.0, 0.0, 0.0))
    size = 96
    images = {}
    for mode in ("off", "on"):
        scene = Scene(mesh=mesh, material=material, camera=camera, occlusion=mode)
        images[mode] = r.render(scene, maps, size, size, aa="none", read_linear=True, read_srgb=False).linear
    assert r.visibility_parts.wanted(mesh, "on")
    j, i = np.mgrid[0:size, 0:size]
    x = (2.0 * (i + 0.5) / size - 1.0).ravel()
    z = (2.0 * (j + 0.5) / size - 1.0).ravel()      # row 0 at the top: up is -z
    open_floor = (np.abs(x) < 0.97) & (np.abs(z) < 0.97) & ~((x > -0.6) & (x < 0.1) & (z > -0.6) & (z < 0.1))
    v, w = _floor_values(baked, x[open_floor], z[open_floor])
    ratio = (images["on"][..., 0] / images["off"][..., 0]).ravel()[open_floor]
    ones = np.ones((len(v), 3))
    expected = vis.occluded_environment(v, v, w, ones, ones, albedo, np.ones(len(v)), ones)[0][:, 0]
    # The remainder: the small specular bias B (f0 = 0), in the hit's albedo and in the lobe.
    assert np.abs(ratio - expected).max() < 0.03
    assert expected.min() < 0.6 and ratio.min() < 0.6   # the corners are in the picture


def test_the_bake_is_cached(corner_obj, tmp_path):
    from alight.ibl.bake_cache import BakeCache
    from alight.render.visibility_parts import cached_visibility

    mesh = load_mesh(str(corner_obj))
    cache = BakeCache(tmp_path / "cache")
    first = cached_visibility(mesh, cache, rays=32)
    second = cached_visibility(mesh, cache, rays=32)
    assert not first.from_cache and second.from_cache
    for a, b in zip(first.parts, second.parts):
        np.testing.assert_array_equal(a.visibility, b.visibility)
        np.testing.assert_array_equal(a.indices, b.indices)
    third = cached_visibility(mesh, cache, rays=48)   # other settings: another key
    assert not third.from_cache
    cache.close()


def test_the_built_in_sphere_is_drawn_as_before():
    r = renderer()
    maps = r.bake(constant_environment(0.7), "low")
    runs = r.visibility_parts.bakes_run
    mesh = load_mesh("sphere")
    frames = {}
    for mode in ("off", "auto", "on"):
        scene = Scene(mesh=mesh, material=Material(roughness=0.4), occlusion=mode)
        frames[mode] = r.render(scene, maps, 64, 64, read_linear=True, read_srgb=False).linear
    assert r.visibility_parts.bakes_run == runs
    np.testing.assert_array_equal(frames["off"], frames["auto"])
    np.testing.assert_array_equal(frames["off"], frames["on"])


def _cli(*args, cache: Path):
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(cache))
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)


def test_cli_occlusion_flag(corner_obj, tmp_path):
    cache = tmp_path / "cache"
    outs = {}
    for mode in ("off", "on"):
        out = tmp_path / f"{mode}.exr"
        p = _cli("render", "--mesh", corner_obj, "--size", "48", "--quality", "low", "--occlusion", mode,
                 "--out", out, cache=cache)
        assert p.returncode == 0, p.stderr
        import OpenImageIO as oiio

        outs[mode] = oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)
    # The occluded corner is darker on the surface (the background is the same), though the
    # bounces give part of it back; the inner corner most.
    surface = (outs["off"][..., 3] >= 1.0) & (outs["on"][..., 3] >= 1.0)
    on, off = outs["on"][..., :3].sum(axis=-1)[surface], outs["off"][..., :3].sum(axis=-1)[surface]
    assert on.sum() < 0.97 * off.sum()
    assert (on / off).min() < 0.7
    bad = _cli("render", "--mesh", corner_obj, "--occlusion", "sometimes", "--out", tmp_path / "x.png", cache=cache)
    assert bad.returncode == 2
    assert len(bad.stderr.strip().splitlines()) == 1 and "--occlusion" in bad.stderr


def test_auto_without_embree_renders_and_says_so(corner_obj, monkeypatch):
    """'auto' never stops a render: without embreex it draws without occlusion and warns once."""
    import alight.render.visibility_parts as occlusion

    monkeypatch.setattr(occlusion, "embree_available", lambda: False)
    r = renderer()
    maps = r.bake(constant_environment(1.0), "low")
    mesh = load_mesh(str(corner_obj))
    runs = r.visibility_parts.bakes_run + r.visibility_parts.bakes_loaded
    scene = Scene(mesh=mesh, material=Material(), occlusion="auto")
    with alight_warnings() as said:
        r.render(scene, maps, 32, 32)
    assert r.visibility_parts.bakes_run + r.visibility_parts.bakes_loaded == runs
    assert len(said) == 1 and "without occlusion" in said[0] and "embreex" in said[0], said


def test_auto_bakes_the_concave_scenes_only(corner_obj, tmp_path):
    """--occlusion auto: by the mean occlusion of the surface (occlusion_statistic) above
    AUTO_MIN_OCCLUSION; convex meshes are decided without a ray."""
    from alight.accuracy.scenes import write_scene

    ball = trimesh.creation.icosphere(subdivisions=2)
    (tmp_path / "ball.obj").write_text(ball.export(file_type="obj", include_normals=True))
    for spec in ("sphere", "cube", "rounded_cube", str(tmp_path / "ball.obj")):
        mesh = load_mesh(spec)
        assert vis.occlusion_statistic(mesh.parts) == 0.0, spec
        assert not vis.wants_occlusion(mesh, "auto"), spec
    corner = load_mesh(str(corner_obj))
    bowl = load_mesh(str(write_scene("bowl", tmp_path)))
    assert vis.occlusion_statistic(corner.parts) > 0.2
    assert vis.occlusion_statistic(bowl.parts) > 0.1
    assert vis.wants_occlusion(corner, "auto") and vis.wants_occlusion(bowl, "auto")


def test_auto_leaves_a_huge_mesh_unbaked_and_says_so(corner_obj, monkeypatch):
    import alight.render.visibility_parts as occlusion

    monkeypatch.setattr(vis, "AUTO_MAX_VERTICES", 10)
    monkeypatch.setattr(occlusion, "AUTO_MAX_VERTICES", 10)
    r = renderer()
    maps = r.bake(constant_environment(1.0), "low")
    mesh = load_mesh(str(corner_obj))
    runs = r.visibility_parts.bakes_run + r.visibility_parts.bakes_loaded
    with alight_warnings() as said:
        r.render(Scene(mesh=mesh, material=Material(), occlusion="auto"), maps, 32, 32)
    assert r.visibility_parts.bakes_run + r.visibility_parts.bakes_loaded == runs
    # (since GTAO: drawn with screen-space occlusion instead of none, in one warning line; worded
    # as the value, so it fits the CLI's --occlusion and the API's set_occlusion alike)
    assert len(said) == 1 and "in screen space (gtao) instead of the visibility bake" in said[0] \
        and "occlusion 'on' bakes it" in said[0] and "--occlusion" not in said[0], said
    assert r.last_occlusion_reason.startswith("gtao (auto")


def test_cli_default_is_auto(corner_obj, tmp_path):
    """`alight render` without --occlusion bakes the corner (auto) and leaves the sphere alone."""
    import OpenImageIO as oiio

    cache = tmp_path / "cache"
    outs = {}
    for mode in (None, "on"):
        out = tmp_path / f"{mode}.exr"
        flag = () if mode is None else ("--occlusion", mode)
        p = _cli("render", "--mesh", corner_obj, "--size", "48", "--quality", "low", *flag, "--out", out, cache=cache)
        assert p.returncode == 0, p.stderr
        outs[mode] = oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)
    np.testing.assert_array_equal(outs[None], outs["on"])


def test_splits_are_kept_only_where_interpolation_misses(tmp_path, monkeypatch):
    """The refinement keeps a split only where the midpoint's V (or bent normal) is not what the
    edge interpolates to: fewer triangles (llvmpipe pays per triangle), while the floor by a wall
    interpolates the analytic V (the form factor of the test above) at its triangles' centroids
    at most 0.025 worse than with every split (the threshold allows 0.1 at a midpoint)."""
    height = 1.0
    quads = [_quad((0, 0, 1), (2, 0, 1), (2, 0, -1), (0, 0, -1)),
             _quad((0, 0, 3), (0, 0, -3), (0, height, -3), (0, height, 3))]     # short: the refinement's
    mesh = load_mesh(str(_flat_obj(quads, tmp_path / "wall.obj")))                   # scale is the diagonal

    def centroid_error(baked):
        floor = baked.parts[0]
        tri = floor.indices.reshape(-1, 3)
        centre = floor.positions[tri].mean(axis=1)
        inner = np.abs(centre[:, 2]) < 0.5     # the wall's ends (3 away) change V by under 0.02 here
        d = centre[inner, 0]
        expected = 0.5 + 0.5 * d / np.hypot(d, height)
        return float(np.abs(floor.visibility[tri[inner]].mean(axis=1) - expected).mean()), len(tri)

    monkeypatch.setattr(vis, "INTERPOLATION_TEST", False)
    every, every_count = centroid_error(vis.bake_visibility(mesh, rays=256))
    monkeypatch.setattr(vis, "INTERPOLATION_TEST", True)
    kept, kept_count = centroid_error(vis.bake_visibility(mesh, rays=256))
    # measured: every split 474 triangles, 0.067; splits kept 306 triangles, 0.085
    assert kept_count < 0.8 * every_count
    assert kept < every + 0.025


def _big_sphere_ply(path: Path, bump) -> Path:
    """A latitude-longitude sphere of 512x512 vertices (over --occlusion auto's AUTO_MAX_VERTICES)
    whose radius is ``bump(theta, phi)``, as a binary PLY (counter-clockwise from outside)."""
    n = 512
    theta, phi = np.meshgrid(np.linspace(0.0, np.pi, n), np.linspace(0.0, 2.0 * np.pi, n, endpoint=False),
                             indexing="ij")
    radius = bump(theta, phi)
    points = np.stack([radius * np.sin(theta) * np.cos(phi), radius * np.cos(theta),
                       radius * np.sin(theta) * np.sin(phi)], axis=-1).reshape(-1, 3).astype("<f4")
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n), indexing="ij")
    a, b = i * n + j, i * n + (j + 1) % n
    c, d = a + n, b + n
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([b, d, c], -1).reshape(-1, 3)])
    rows = np.empty(len(faces), [("n", "u1"), ("i", "<i4", (3,))])
    rows["n"], rows["i"] = 3, faces
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\nproperty float x\n"
              f"property float y\nproperty float z\nelement face {len(faces)}\n"
              f"property list uchar int vertex_indices\nend_header\n")
    out = path / "big.ply"
    out.write_bytes(header.encode() + points.tobytes() + rows.tobytes())
    return out


@pytest.mark.parametrize("shape", ["bumpy", "lobed"])
def test_cli_warns_of_a_huge_mesh_only_where_it_would_need_occlusion(tmp_path, shape):
    """--occlusion auto on a mesh over AUTO_MAX_VERTICES: drawn with screen-space GTAO, said in
    one warning line and the --verbose reason, only where the mesh would plausibly need occlusion (occlusion_estimate above
    AUTO_MIN_OCCLUSION), not for a nearly convex sphere whose bumps of 0.2% of its radius made
    self_occludes true."""
    bump = {"bumpy": lambda t, p: 1.0 + 0.002 * np.sin(40.0 * t) * np.sin(40.0 * p),
            "lobed": lambda t, p: 1.0 + 0.45 * np.sin(5.0 * t) * np.sin(5.0 * p)}[shape]
    mesh = _big_sphere_ply(tmp_path, bump)
    p = _cli("render", "--mesh", mesh, "--size", "32", "--quality", "low", "--occlusion", "auto", "--verbose",
             "--out", tmp_path / "x.png", cache=tmp_path / "cache")
    assert p.returncode == 0, p.stderr
    # (since GTAO: drawn with screen-space occlusion instead of none, and said so)
    warned = [x for x in p.stderr.splitlines() if "in screen space (gtao) instead of the visibility bake" in x]
    if shape == "bumpy":
        assert not warned, p.stderr
        assert "occlusion: gtao" not in p.stderr
    else:
        assert len(warned) == 1 and "occlusion 'on' bakes it" in warned[0], p.stderr
        assert "occlusion: gtao (auto: the mesh has more vertices than auto bakes" in p.stderr, p.stderr
