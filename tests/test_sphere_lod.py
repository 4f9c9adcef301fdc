"""The built-in sphere drawn at the tessellation its size on screen needs (alight.core.sphere_lod,
ForwardRenderer._drawn_parts): the error model against the mesh itself, the projected radius
against projected points, and pictures of the coarser levels against the finest.

Measured when written (gold r = 0.3 on royal_esplanade, 4x MSAA): the level drawn against the
sphere's own 128 x 64 shaded on the true sphere differs by 0.004-0.03% relMAE, only on outline
pixels (inside it 5e-6); against the 128 x 64 ball as drawn before (normals interpolated over
the facets) by 0.13-0.19%, that ball's own facet error."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import sphere
from alight.core.scene import Camera, Scene, frame_camera, orbit_camera
from alight.core.sphere_lod import (
    MAX_SILHOUETTE_ERROR_PX,
    SPHERE_LOD_SEGMENTS,
    impostor_background_ring,
    impostor_hole_model,
    projected_radius_px,
    silhouette_error,
    sphere_segments,
    ray_meets_sphere,
    sphere_surface_point,
)
from alight.exchange.presets import load_preset
from alight.ibl.environment import load_environment
from tests.gpu import evaluate, renderer


@pytest.mark.parametrize("segments", [16, 48, 128])
def test_the_error_model_bounds_how_far_the_facets_fall_inside_the_sphere(segments):
    part = sphere(segments, segments // 2).parts[0]
    tri = part.positions[part.indices].astype(np.float64)          # (T, 3, 3)
    # Dense barycentric points on every triangle: the facets' nearest approach to the centre.
    w = np.array([(a, b, 1 - a - b) for a in np.linspace(0, 1, 9) for b in np.linspace(0, 1, 9) if a + b <= 1])
    points = np.einsum("kv,tvc->tkc", w, tri)
    depth = 1.0 - np.linalg.norm(points, axis=-1).min()
    model = silhouette_error(segments, 1.0)
    assert depth <= model * 1.0001, (depth, model)
    assert depth >= 0.9 * model, (depth, model)   # the model is the bound, not far above it


def test_the_level_is_the_coarsest_within_the_error():
    for radius_px in (5.0, 40.0, 272.0, 408.0, 1500.0):
        n = sphere_segments(radius_px)
        assert n in SPHERE_LOD_SEGMENTS
        if n != SPHERE_LOD_SEGMENTS[-1]:
            assert silhouette_error(n, radius_px) <= MAX_SILHOUETTE_ERROR_PX
        coarser = [x for x in SPHERE_LOD_SEGMENTS if x < n]
        if coarser:
            assert silhouette_error(coarser[-1], radius_px) > MAX_SILHOUETTE_ERROR_PX
    assert sphere_segments(1e6) == SPHERE_LOD_SEGMENTS[-1]
    for bad in (math.inf, math.nan, 0.0, -3.0):
        assert sphere_segments(bad) == SPHERE_LOD_SEGMENTS[-1]


def _outline_radius(camera: Camera, centre, radius, size) -> float:
    """Half the largest extent of a dense set of the sphere's points, projected to pixels."""
    rng = np.random.default_rng(1)
    d = rng.normal(size=(200000, 3))
    p = np.asarray(centre) + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
    clip = np.hstack([p, np.ones((len(p), 1))]) @ camera.view_projection(size[0] / size[1]).astype(np.float64)
    xy = clip[:, :2] / clip[:, 3:] * np.array(size) / 2.0
    spans = [np.ptp(xy @ np.array([math.cos(a), math.sin(a)])) for a in np.linspace(0, math.pi, 90, endpoint=False)]
    return max(spans) / 2.0


@pytest.mark.parametrize("case", ["centred", "off_axis", "close", "portrait"])
def test_the_projected_radius_is_the_outlines_within_a_few_percent_and_never_below(case):
    size = (860, 720)
    centre = (0.0, 0.0, 0.0)
    camera = frame_camera(centre, 1.0, aspect=size[0] / size[1])
    if case == "off_axis":
        centre = (1.2, -0.6, 0.0)
    elif case == "close":
        camera = orbit_camera(centre, 1.0, size[0] / size[1], orbit_deg=30.0, elevation_deg=20.0, distance=1.6)
    elif case == "portrait":
        size = (300, 900)
        camera = frame_camera(centre, 1.0, aspect=size[0] / size[1])
    got = projected_radius_px(camera.view_projection(size[0] / size[1]), centre, 1.0, size)
    outline = _outline_radius(camera, centre, 1.0, size)
    assert outline * 0.999 <= got <= outline * 1.1, (got, outline)
    ortho = Camera(ortho_half_height=2.0)
    got = projected_radius_px(ortho.view_projection(1.0), centre, 1.0, (400, 400))
    assert got == pytest.approx(100.0)
    inside = Camera(position=(0.0, 0.0, 0.5))
    assert projected_radius_px(inside.view_projection(1.0), (0.0, 0.0, 0.0), 1.0, (64, 64)) == math.inf


def _ball(r, maps, mesh, size, aa="msaa", max_error=MAX_SILHOUETTE_ERROR_PX, impostor=False, **scene_fields):
    """The gold ball, tessellated (the level for ``max_error``) or as the impostor."""
    scene = Scene(mesh=mesh, material=dataclasses.replace(load_preset("gold"), roughness=0.3), **scene_fields)
    r.sphere_max_error_px, r.sphere_impostor = max_error, impostor
    try:
        frame = r.render(scene, maps, *size, aa=aa)
    finally:
        r.sphere_max_error_px, r.sphere_impostor = MAX_SILHOUETTE_ERROR_PX, True
    assert r.last_sphere_impostor == ({"msaa": 4, "none": 1, "ssaa": 1}[aa] if impostor else None)
    return frame, r.last_sphere_segments


def _inside(*alphas, shrink=2):
    m = np.logical_and.reduce([a == 1.0 for a in alphas])
    for _ in range(shrink):
        m = m & np.roll(m, 1, 0) & np.roll(m, -1, 0) & np.roll(m, 1, 1) & np.roll(m, -1, 1)
    return m


def _rel(a, b, mask=None):
    a, b = a[..., :3].astype(np.float64), b[..., :3].astype(np.float64)
    if mask is not None:
        a, b = a[mask], b[mask]
    return float(np.abs(a - b).sum() / np.abs(b).sum())


@pytest.mark.parametrize("size,aa", [((96, 96), "msaa"), ((320, 240), "none"), ((200, 150), "ssaa")])
def test_a_coarser_level_changes_only_the_outline(shared_data, size, aa):
    """Against the finest sphere (256 x 128) shaded on the true sphere: the level drawn differs
    within the equivalence bound, and inside the outline only by interpolated uvs."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    lod, n = _ball(r, maps, sphere(), size, aa)
    exact, n_exact = _ball(r, maps, sphere(256, 128), size, aa, max_error=0.0)
    assert n < 64 and n_exact == 256
    assert lod.srgb[:, :, :3].std() > 5.0                     # a real picture
    assert _rel(lod.linear, exact.linear) < 0.01
    inside = _inside(lod.linear[..., 3], exact.linear[..., 3])
    assert inside.sum() > 0.2 * size[0] * size[1]
    assert _rel(lod.linear, exact.linear, inside) < 1e-4
    # the 128 x 64 ball with normals interpolated over its facets, as drawn before the levels
    before = sphere()
    before.lod_sphere = None
    old, _ = _ball(r, maps, before, size, aa)
    assert _rel(lod.linear, old.linear) < 0.01


def test_a_large_picture_draws_the_spheres_own_tessellation(shared_data):
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    ball = sphere(32, 16)                 # never finer than the mesh asked for
    _, n = _ball(r, maps, ball, (400, 400))
    assert n == 32
    _, n = _ball(r, maps, sphere(), (96, 96))
    assert n < 128


def test_tiles_draw_the_level_of_the_whole_image(shared_data):
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    scene = Scene(mesh=sphere(), material=Material(base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5))
    r.sphere_impostor = False     # the levels (the impostor's tiles: below)
    try:
        whole = r.render(scene, maps, 160, 120, aa="msaa", read_linear=True, read_srgb=False)
        n = r.last_sphere_segments
        tiled = r.render(scene, maps, 160, 120, aa="msaa", read_linear=True, read_srgb=False, tile=(64, 64))
    finally:
        r.sphere_impostor = True
    assert n is not None and r.last_sphere_segments == n
    assert _rel(tiled.linear, whole.linear) < 1e-5


def test_orthographic_and_inside_views_draw_the_mesh_as_given(shared_data):
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    for camera in (Camera(ortho_half_height=1.5), Camera(position=(0.0, 0.0, 0.5), near=0.01)):
        scene = Scene(mesh=sphere(), material=Material(), camera=camera)
        frame = r.render(scene, maps, 64, 64, aa="none")
        assert r.last_sphere_segments is None
        assert np.isfinite(frame.linear).all()


def test_the_shaded_point_is_the_rays_hit_on_the_true_sphere_and_the_glsl_matches_its_twin():
    """Facet points of a coarse ball (grazing ones near its outline included) seen from the
    default camera's distance: the twin's point lies on the sphere, on the ray, before the facet;
    common/sphere_surface.glsl gives the same point."""
    rng = np.random.default_rng(3)
    part = sphere(16, 8).parts[0]
    tri = part.positions[part.indices].astype(np.float64)
    w = rng.dirichlet(np.ones(3), size=len(tri))
    points = np.einsum("tv,tvc->tc", w, tri)
    eye = np.array([0.0, 0.0, 4.323162])
    hit = sphere_surface_point(eye, points, 1.0)
    np.testing.assert_allclose(np.linalg.norm(hit, axis=1), 1.0, atol=1e-9)
    ray = (points - eye) / np.linalg.norm(points - eye, axis=1, keepdims=True)
    along = hit - eye
    np.testing.assert_allclose(np.cross(along, ray), 0.0, atol=1e-9)               # on the ray
    assert (np.sum(along * ray, axis=1) <= np.linalg.norm(points - eye, axis=1) + 1e-12).all()   # not beyond
    glsl = evaluate("SPHERE_SURFACE", np.hstack([points, np.full((len(points), 1), eye[2])]))[:, :3]
    np.testing.assert_allclose(glsl, hit, atol=2e-5)


# ---- the impostor (ForwardRenderer._sphere_impostor) -------------------------------------------

STANDARD_4X = np.array([(-0.125, -0.375), (0.375, -0.125), (-0.375, 0.125), (0.125, 0.375)])


def _coverage(camera: Camera, size, offsets, radius=1.0) -> np.ndarray:
    """The fraction of each pixel's sample rays (``offsets`` from its centre, in pixels) that
    meet the sphere, by the numpy twin; (H, W), row 0 at the top."""
    w, h = size
    inverse = np.linalg.inv(camera.view_projection(w / h).astype(np.float64))
    y, x = np.mgrid[0:h, 0:w]
    eye = np.asarray(camera.position, np.float64)
    hits = np.zeros((h, w))
    for ox, oy in offsets:
        ndc = np.stack([(x + 0.5 + ox) / w * 2 - 1, (y + 0.5 + oy) / h * 2 - 1, np.ones_like(x, float),
                        np.ones_like(x, float)], axis=-1).reshape(-1, 4)
        far = ndc @ inverse
        hits += ray_meets_sphere(eye, far[:, :3] / far[:, 3:] - eye, radius).reshape(h, w)
    return (hits / len(offsets))[::-1]


@pytest.mark.parametrize("size,aa", [((96, 96), "msaa"), ((320, 240), "none"), ((200, 150), "ssaa"),
                                     ((256, 160), "msaa")])
def test_the_impostor_is_the_finest_ball_inside_and_the_true_sphere_at_the_outline(shared_data, size, aa):
    """Against the finest tessellated ball (256 x 128, shaded on the true sphere): the same
    pixels inside the outline; over the whole picture within the levels' bound. Its coverage is
    the true sphere's at the samples, by the numpy twin (ray_meets_sphere)."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    impostor, _ = _ball(r, maps, sphere(), size, aa, impostor=True)
    finest, n = _ball(r, maps, sphere(256, 128), size, aa, max_error=0.0)
    assert n == 256
    assert impostor.srgb[:, :, :3].std() > 5.0                     # a real picture
    assert _rel(impostor.linear, finest.linear) < 0.01
    inside = _inside(impostor.linear[..., 3], finest.linear[..., 3])
    assert inside.sum() > 0.2 * size[0] * size[1]
    assert _rel(impostor.linear, finest.linear, inside) < 1e-5
    if aa == "ssaa":
        return    # (its alpha is the mean of 2x2 sub-pixels: the msaa and none cases test the coverage)
    camera = r.camera_for(Scene(mesh=sphere()), size[0] / size[1])
    want = _coverage(camera, size, STANDARD_4X if aa == "msaa" else [(0.0, 0.0)])
    got = impostor.linear[..., 3]
    # Rays within float rounding of the tangent may go either way.
    assert (got != want).sum() <= max(2, 0.02 * ((want > 0) & (want < 1)).sum()), (got != want).sum()
    assert np.abs(got - want).max() <= 1.0 / len(STANDARD_4X) if aa == "msaa" else True


def test_the_impostors_outline_is_nearer_the_true_one_than_the_tessellated_balls(shared_data):
    """Coverage against the sphere's exact area per pixel (16 x 16 sample rays): the impostor's
    4 samples of the true sphere err less than 4 samples of the level drawn, whose facets fall
    inside the outline by up to half a pixel."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    size = (200, 150)
    camera = r.camera_for(Scene(mesh=sphere()), size[0] / size[1])
    grid = (np.arange(16) + 0.5) / 16 - 0.5
    exact = _coverage(camera, size, [(gx, gy) for gx in grid for gy in grid])
    impostor, _ = _ball(r, maps, sphere(), size, impostor=True)
    level, n = _ball(r, maps, sphere(), size)
    assert n < 128
    edge = (exact > 0) & (exact < 1)
    err_impostor = float(np.abs(impostor.linear[..., 3] - exact)[edge].mean())
    err_level = float(np.abs(level.linear[..., 3] - exact)[edge].mean())
    bias_impostor = float((impostor.linear[..., 3] - exact)[edge].mean())
    bias_level = float((level.linear[..., 3] - exact)[edge].mean())
    assert err_impostor < err_level, (err_impostor, err_level)
    assert abs(bias_impostor) < abs(bias_level), (bias_impostor, bias_level)


@pytest.mark.parametrize("aa", ["msaa", "none"])
def test_the_impostor_seen_from_close_and_off_centre_is_the_finest_ball(shared_data, aa):
    """An eye 1.3 radii from the centre (the outline circle far from the sphere's equator) looking
    past the sphere, which sits off the image centre: the proxy still covers the outline."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    camera = Camera(position=(0.3, 0.2, 1.3), target=(0.6, 0.1, 0.0), near=0.05, fov_y_deg=60.0)
    size = (160, 120)
    impostor, _ = _ball(r, maps, sphere(), size, aa, impostor=True, camera=camera)
    finest, _ = _ball(r, maps, sphere(256, 128), size, aa, max_error=0.0, camera=camera)
    alpha = impostor.linear[..., 3]
    assert 0.1 < (alpha > 0).mean() < 0.9                          # the outline is in the picture
    assert _rel(impostor.linear, finest.linear) < 0.01
    inside = _inside(alpha, finest.linear[..., 3])
    assert _rel(impostor.linear, finest.linear, inside) < 1e-4
    want = _coverage(camera, size, STANDARD_4X if aa == "msaa" else [(0.0, 0.0)])
    assert (alpha != want).sum() <= max(2, 0.02 * ((want > 0) & (want < 1)).sum())


def test_tiles_draw_the_impostor_as_the_whole_image(shared_data):
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    scene = Scene(mesh=sphere(), material=Material(base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5))
    whole = r.render(scene, maps, 160, 120, aa="msaa", read_linear=True, read_srgb=False)
    assert r.last_sphere_impostor == 4
    tiled = r.render(scene, maps, 160, 120, aa="msaa", read_linear=True, read_srgb=False, tile=(64, 64))
    assert r.last_sphere_impostor == 4
    np.testing.assert_array_equal(tiled.linear[..., 3], whole.linear[..., 3])
    assert _rel(tiled.linear, whole.linear) < 1e-5


RING_CAMERAS = {
    "default": Camera(),
    "orbit": Camera(position=(1.5, 0.7, 2.2)),
    "from above": Camera(position=(0.0, 3.9, 0.3)),
    "close, off centre": Camera(position=(0.3, 0.2, 1.3), target=(0.6, 0.1, 0.0), near=0.05, fov_y_deg=60.0),
}


@pytest.mark.parametrize("name", list(RING_CAMERAS))
def test_the_background_ring_covers_the_view_once_but_a_hole_the_sphere_fills(name):
    """impostor_background_ring's triangles, at 200 x 200 points over the NDC square: each point
    lies in at most one triangle, and a point in none is one whose ray meets the sphere (the
    impostor draws it). Counter-clockwise, as every pass's triangles."""
    camera = RING_CAMERAS[name]
    size = (860, 720)
    vp = camera.view_projection(size[0] / size[1]).astype(np.float64)
    radius_px = projected_radius_px(vp, (0.0, 0.0, 0.0), 1.0, size)
    triangles = impostor_background_ring(impostor_hole_model(camera.position, 1.0, radius_px), vp)
    assert triangles is not None and triangles.shape == (6 * 16, 2)
    tri = triangles.astype(np.float64).reshape(-1, 3, 2)
    edge_a, edge_b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    assert (edge_a[:, 0] * edge_b[:, 1] - edge_a[:, 1] * edge_b[:, 0] > 0).all()
    g = np.linspace(-0.9975, 0.9975, 200)
    points = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    count = np.zeros(len(points), int)
    for t in tri:
        sides = np.stack([(t[(i + 1) % 3, 0] - t[i, 0]) * (points[:, 1] - t[i, 1])
                          - (t[(i + 1) % 3, 1] - t[i, 1]) * (points[:, 0] - t[i, 0]) for i in range(3)], axis=1)
        count += (sides > 0).all(axis=1)
    assert count.max() == 1
    far = np.hstack([points, np.ones((len(points), 2))]) @ np.linalg.inv(vp)
    hit = ray_meets_sphere(camera.position, far[:, :3] / far[:, 3:] - np.asarray(camera.position), 1.0)
    hole = count == 0
    assert hole.sum() > 100 and hit[hole].all()
    assert hole.sum() > 0.9 * hit.sum()                # the hole is most of the sphere


@pytest.mark.parametrize("aa", ["none", "ssaa"])
@pytest.mark.parametrize("name", ["default", "close, off centre"])
def test_the_background_around_the_impostor_is_the_depth_tested_one(shared_data, aa, name):
    """With one sample a pixel the background is drawn first around the impostor's hole, without
    a depth buffer (ForwardRenderer.background_ring); against the depth-tested background after
    it: the same radiance and coverage, and the same display bytes but for float rounding of the
    rays (at most 1 LSB on a few pixels)."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    scene = Scene(mesh=sphere(), material=dataclasses.replace(load_preset("gold"), roughness=0.3),
                  camera=RING_CAMERAS[name])
    frames = {}
    for ring in (True, False):
        r.background_ring = ring
        try:
            frames[ring] = r.render(scene, maps, 240, 180, aa=aa, read_linear=True, read_srgb=True)
        finally:
            r.background_ring = True
        assert r.last_sphere_impostor == 1 and r.last_background_ring == ring
    ring, depth = frames[True], frames[False]
    assert 0.05 < (depth.linear[..., 3] > 0).mean() < 0.95           # ball and background both in view
    np.testing.assert_array_equal(ring.linear[..., 3], depth.linear[..., 3])
    # The rays interpolate over other triangles: float rounding moves the texel weights (2e-6 here).
    assert _rel(ring.linear, depth.linear) < 1e-5
    inside = _inside(ring.linear[..., 3], depth.linear[..., 3])
    np.testing.assert_array_equal(ring.linear[inside], depth.linear[inside])   # the ball: the same pass
    difference = np.abs(ring.srgb.astype(int) - depth.srgb.astype(int))
    assert difference.max() <= 1 and (difference > 0).mean() < 1e-3


def test_the_background_ring_is_not_used_where_the_depth_is_needed(shared_data):
    """A transparent background (nothing drawn around the hole), 4x MSAA (the fused resolve
    composites the background) and a transmissive ball (the scene behind it is read before the
    background) keep the depth-tested path."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    base = Scene(mesh=sphere(), material=load_preset("gold"))
    r.render(base, maps, 64, 48, aa="none")
    assert r.last_background_ring
    from alight.core.scene import Display
    for scene, aa in ((dataclasses.replace(base, display=Display(background="transparent")), "none"), (base, "msaa"),
                      (dataclasses.replace(base, material=dataclasses.replace(load_preset("gold"), metallic=0.0,
                                                                              transmission=1.0)), "none")):
        r.render(scene, maps, 64, 48, aa=aa)
        assert not r.last_background_ring


def _checker_maps(n: int = 128):
    """A base colour checker with colour ramps and a striped normal map: sharp edges and fine
    detail, so a wrong uv, tangent or mip level shows."""
    y, x = np.mgrid[0:n, 0:n]
    color = np.zeros((n, n, 4), np.uint8)
    color[..., 0] = 40 + 200 * ((x // 8 + y // 8) % 2)
    color[..., 1] = x * 255 // n
    color[..., 2] = y * 255 // n
    color[..., 3] = 255
    normal = np.zeros((n, n, 4), np.uint8)
    normal[...] = (128, 128, 255, 255)
    normal[..., 0] = (128 + 60 * np.sin(x / 3.0)).astype(np.uint8)
    from alight.core.texture_maps import TextureMaps
    return TextureMaps(base_color="c.png", normal="n.png", uv_scale=(2.0, 2.0)), {"c.png": color, "n.png": normal}


@pytest.mark.parametrize("aa,from_behind", [("msaa", False), ("none", True)])
def test_the_textured_impostor_reads_the_spheres_own_uvs_and_tangents(shared_data, aa, from_behind):
    """A base colour and a normal map on the impostor (the sphere's uv and tangent at the shaded
    point, mesh_material.glsl surface_uv, surface_tangent) against the finest tessellated ball,
    whose uvs and tangents are interpolated over its facets. From behind, the seam (u = 0/1)
    faces the camera: no line of the smallest mip there."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    texture_maps, images = _checker_maps()
    camera = r.camera_for(Scene(mesh=sphere()), 1.0)
    if from_behind:
        camera = dataclasses.replace(camera, position=(0.0, 0.0, -float(np.linalg.norm(camera.position))))
    fields = dict(material=Material(base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=0.4),
                  texture_maps=texture_maps, texture_images=images, camera=camera)
    size = (240, 240)
    pictures = {}
    for impostor, mesh, max_error in ((True, sphere(), MAX_SILHOUETTE_ERROR_PX), (False, sphere(256, 128), 0.0)):
        r.sphere_max_error_px, r.sphere_impostor = max_error, impostor
        try:
            pictures[impostor] = r.render(Scene(mesh=mesh, **fields), maps, *size, aa=aa)
            assert r.last_sphere_impostor == ({"msaa": 4, "none": 1}[aa] if impostor else None)
        finally:
            r.sphere_max_error_px, r.sphere_impostor = MAX_SILHOUETTE_ERROR_PX, True
    a, b = pictures[True], pictures[False]
    assert a.srgb[..., :3].std() > 20.0
    inside = _inside(a.linear[..., 3], b.linear[..., 3])
    # (Measured when written: 1.2-1.4e-3, the checker's edges and the stripes moving by the
    # finest ball's facet interpolation; a uv, tangent or mip level gone wrong is far above.)
    assert _rel(a.linear, b.linear, inside) < 4e-3
    seam = np.zeros(size[::-1], bool)
    seam[:, size[0] // 2 - 2:size[0] // 2 + 2] = True      # the middle columns: the seam from behind
    d = np.abs(a.srgb[..., :3].astype(int) - b.srgb[..., :3].astype(int)).max(axis=2)
    assert np.percentile(d[inside & seam], 99) <= 40, np.percentile(d[inside & seam], 99)


def test_the_impostor_is_not_used_where_the_shading_needs_more_than_the_ray(shared_data):
    """An orthographic camera, an eye inside the sphere: the tessellated ball. Texture maps,
    anisotropy, transmission and the debug views: the impostor."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    base = Scene(mesh=sphere(), material=Material())
    r.render(base, maps, 64, 64, aa="msaa")
    assert r.last_sphere_impostor == 4
    r.render(base, maps, 64, 64, aa="none")
    assert r.last_sphere_impostor == 1
    texture_maps, images = _checker_maps(16)
    for scene in (dataclasses.replace(base, texture_maps=texture_maps, texture_images=images),
                  dataclasses.replace(base, material=Material(anisotropy_strength=0.5)),
                  dataclasses.replace(base, material=Material(transmission=1.0)),
                  dataclasses.replace(base, debug_view=1)):
        r.render(scene, maps, 64, 64, aa="msaa")
        assert r.last_sphere_impostor == 4
    cases = [
        dataclasses.replace(base, camera=Camera(ortho_half_height=1.5)),
        dataclasses.replace(base, camera=Camera(position=(0.0, 0.0, 0.5), near=0.01)),   # inside
    ]
    for scene in cases:
        frame = r.render(scene, maps, 64, 64, aa="msaa")
        assert r.last_sphere_impostor is None, scene
        assert np.isfinite(frame.linear).all()


def test_the_impostors_uv_and_tangent_are_the_meshs():
    """common/sphere_surface.glsl's sphere_uv and sphere_tangent at the built-in sphere's vertices
    give the uvs and tangents alight.core.mesh.sphere stores there (u modulo 1: the seam's two
    columns; the poles, where u and the tangent are undefined, left out)."""
    part = sphere(32, 16, 2.0).parts[0]
    keep = np.abs(part.normals[:, 1]) < 0.999
    got = evaluate("SPHERE_UV", part.positions[keep])
    du = (got[:, 0] - part.uvs[keep, 0] + 0.5) % 1.0 - 0.5
    np.testing.assert_allclose(du, 0.0, atol=2e-6)
    np.testing.assert_allclose(got[:, 1], part.uvs[keep, 1], atol=2e-6)
    np.testing.assert_allclose(got[:, 2:], part.tangents[keep][:, [0, 2]], atol=2e-6)
    assert (part.tangents[keep, 3] == 1.0).all()       # (the GLSL's handedness is +1)
