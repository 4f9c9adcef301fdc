"""Shadow maps (alight.render.shadows, shaders/common/shadows.glsl): a box on a plane seen from
straight above, its shadow where the light's projection of the box along its direction puts
it, under a directional light and under a map with a strong sun; no acne on a lit plane; the
built-in sphere and other convex meshes draw no shadow pass and render as before."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import Mesh, MeshPart, cube, sphere
from alight.core.scene import Camera, Display, Light, Scene
from alight.core.shadow_fit import can_shadow_itself, cube_face, directional_view, point_views
from alight.core.mesh import is_closed

from gpu import renderer

HALF = 3.0            # the top view's half width (world units)
SIZE = 128


def _flat_part(vertices, faces, name: str) -> MeshPart:
    tri = np.asarray(vertices, np.float32)[np.asarray(faces)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = tri.reshape(-1, 3)
    count = len(v)
    return MeshPart(name, v, np.repeat(n, 3, axis=0).astype(np.float32), np.zeros((count, 2), np.float32),
                    np.tile(np.float32([1, 0, 0, 1]), (count, 1)), np.arange(count, dtype=np.uint32).reshape(-1, 3), None)


BOX_CORNERS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (0.0, 1.0) for z in (-0.5, 0.5)], np.float64)
BOX_FACES = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
             [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]


def box_on_plane() -> Mesh:
    """A unit box standing on y = 0 in the middle of a 6 x 6 plane."""
    plane = [[-HALF, 0, -HALF], [HALF, 0, -HALF], [HALF, 0, HALF], [-HALF, 0, HALF]]
    return Mesh([_flat_part(BOX_CORNERS, BOX_FACES, "box"), _flat_part(plane, [[0, 2, 1], [0, 3, 2]], "plane")], "test")


def top_view() -> Camera:
    """Orthographic, straight down: image right is +x, image top is -z."""
    return Camera(position=(0.0, 10.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0),
                  ortho_half_height=HALF, near=1.0, far=20.0)


def pixel_world_xz(size: int = SIZE) -> tuple[np.ndarray, np.ndarray]:
    c = (np.arange(size) + 0.5) / size * 2.0 * HALF - HALF
    return np.meshgrid(c, c)          # x by column, z by row (top row -z)


def _hull_mask(points: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Inside the convex hull of 2-D ``points`` (Andrew's monotone chain, then half-planes)."""
    pts = sorted(map(tuple, points))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]      # counter-clockwise
    inside = np.ones_like(x, bool)
    for a, b in zip(hull, hull[1:] + hull[:1]):
        inside &= (b[0] - a[0]) * (z - a[1]) - (b[1] - a[1]) * (x - a[0]) >= 0
    return inside


def expected_shadow(direction, size: int = SIZE) -> np.ndarray:
    d = np.asarray(direction, np.float64)
    d /= np.linalg.norm(d)
    shadows = BOX_CORNERS - BOX_CORNERS[:, 1:2] / d[1] * d     # each corner along d down to y = 0
    x, z = pixel_world_xz(size)
    footprint = (np.abs(x) <= 0.5) & (np.abs(z) <= 0.5)
    return _hull_mask(shadows[:, [0, 2]], x, z) & ~footprint


def render(scene: Scene, size: int = SIZE, maps=None) -> np.ndarray:
    return renderer().render(scene, maps, size, size).linear


def overlap(shadowed: np.ndarray, expected: np.ndarray) -> float:
    """Intersection over union of two masks."""
    return float((shadowed & expected).sum()) / max(float((shadowed | expected).sum()), 1.0)


def _box_scene(**kw) -> Scene:
    return Scene(mesh=box_on_plane(), material=Material(base_color=(0.8, 0.8, 0.8), roughness=0.6),
                 camera=top_view(), display=Display(background="color"), **kw)


LIGHT = (-0.6, -1.0, -0.4)


def test_directional_shadow_lies_where_the_box_projects():
    light = Light(kind="directional", vector=LIGHT, intensity=3.0)
    lit = render(_box_scene(lights=[light], ibl_enabled=False, shadows="off"))
    shadowed_img = render(_box_scene(lights=[light], ibl_enabled=False, shadows="on"))
    x, z = pixel_world_xz()
    plane = ~((np.abs(x) <= 0.5) & (np.abs(z) <= 0.5))
    ratio = shadowed_img[..., :3].mean(axis=2) / np.maximum(lit[..., :3].mean(axis=2), 1e-6)
    shadowed = (ratio < 0.5) & plane
    expected = expected_shadow(LIGHT)
    assert expected.sum() > 300
    assert overlap(shadowed, expected) >= 0.9
    # Outside the shadow the plane is as lit as without shadows (no acne, no darkening).
    away = plane & ~expected & ~_dilate(expected, 3)
    assert np.abs(ratio[away] - 1.0).max() < 1e-3
    # 'auto' draws shadows here: the box on the plane is not one convex solid.
    auto = render(_box_scene(lights=[light], ibl_enabled=False))
    np.testing.assert_array_equal(auto, shadowed_img)


def _dilate(mask: np.ndarray, n: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(n):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def test_lit_plane_has_no_acne_at_grazing_light():
    """A plane alone under a low light (75 degrees from its normal) with shadows forced on: every
    pixel as without shadows."""
    plane = Mesh([_flat_part([[-HALF, 0, -HALF], [HALF, 0, -HALF], [HALF, 0, HALF], [-HALF, 0, HALF]],
                             [[0, 2, 1], [0, 3, 2]], "plane")], "plane")
    d = (-np.sin(np.radians(75.0)), -np.cos(np.radians(75.0)), 0.0)
    scene = Scene(mesh=plane, lights=[Light(kind="directional", vector=d, intensity=3.0)], camera=top_view(),
                  ibl_enabled=False, shadows="on")
    on = render(scene)
    assert renderer().shadow_maps.last_active
    scene.shadows = "off"
    off = render(scene)
    np.testing.assert_allclose(on, off, rtol=1e-4, atol=1e-6)


def test_convexity_decides():
    s = sphere()
    assert not can_shadow_itself([(s.parts[0].positions, s.parts[0].indices)], [True])
    c = cube()
    assert not can_shadow_itself([(p.positions, p.indices) for p in c.parts],
                                 [is_closed(p.positions, p.indices) for p in c.parts])
    m = box_on_plane()
    assert can_shadow_itself([(p.positions, p.indices) for p in m.parts], [False, False])
    # A closed concave solid: an L of two boxes.
    corners = BOX_CORNERS * (2.0, 1.0, 1.0)
    positions = np.concatenate([BOX_CORNERS, corners + (0.0, 1.0, 0.0)])
    faces = np.concatenate([np.array(BOX_FACES), np.array(BOX_FACES) + 8])
    assert can_shadow_itself([(positions, faces)], [True])


def test_convexity_of_big_meshes_without_testing_every_face_against_every_vertex():
    """Beyond 2000 faces the edges decide (a concave edge anywhere), then a sample of faces
    against a sample of vertices (several solids): a 330k-triangle sphere was every face against
    every vertex before (minutes at 1.3M)."""
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=7)          # 327,680 faces
    pos, idx = np.asarray(ball.vertices, np.float32), np.asarray(ball.faces, np.uint32)
    assert not can_shadow_itself([(pos, idx)], [True])
    # Pushing one vertex in makes its edges concave: found among 327k faces.
    dented = pos.copy()
    dented[12345] *= 0.97
    assert can_shadow_itself([(dented, idx)], [True])
    # Two convex solids side by side shadow each other; every edge is convex.
    small = trimesh.creation.icosphere(subdivisions=5)
    p2, i2 = np.asarray(small.vertices), np.asarray(small.faces)
    assert can_shadow_itself([(np.concatenate([p2, p2 + (3.0, 0.0, 0.0)]), np.concatenate([i2, i2 + len(p2)]))], [True])
    # Wound inside out, a convex solid is still convex.
    assert not can_shadow_itself([(p2, i2[:, ::-1])], [True])


def _reference_locally_convex(positions, indices, eps: float) -> bool:
    """shadow_fit._locally_convex as it was before it shared closed_edges' weld and edge sort
    (its own column weld, an argsort of undirected edge keys, (M, 3) float32 rows)."""
    from alight.core.mesh import _weld_by_columns

    p = np.asarray(positions, np.float64).reshape(-1, 3)
    tri = np.asarray(indices, np.int64).reshape(-1, 3)
    welded = _weld_by_columns(p)[tri]
    good = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 2] != welded[:, 0])
    tri, welded = tri[good], welded[good]
    if len(tri) == 0:
        return True
    p32 = (p - p.mean(axis=0)).astype(np.float32)
    p0 = p32[tri[:, 0]]
    normals = np.cross(p32[tri[:, 1]] - p0, p32[tri[:, 2]] - p0)
    normals /= np.maximum(np.linalg.norm(normals, axis=1), 1e-30)[:, None]
    offsets = np.einsum("ij,ij->i", normals, p0)
    n = int(welded.max()) + 1
    count = len(tri)
    keys = np.empty(3 * count, np.int64)
    opposite = np.empty(3 * count, np.int64)
    for k in range(3):
        a, b = welded[:, k], welded[:, (k + 1) % 3]
        keys[k * count:(k + 1) * count] = np.minimum(a, b) * n + np.maximum(a, b)
        opposite[k * count:(k + 1) * count] = tri[:, (k + 2) % 3]
    order = np.argsort(keys)
    keys = keys[order]
    paired = keys[0::2] == keys[1::2]
    face = order[0::2][paired] % count
    across = opposite[order[1::2][paired]]
    d = np.einsum("ij,ij->i", normals[face], p32[across]) - offsets[face]
    return bool(d.max() <= eps or d.min() >= -eps)


def test_shared_edges_give_the_former_convexity_answers():
    """can_shadow_itself's local test on closed_edges' pairing (the closedness test's weld and
    sort, as alight.render.shadows passes it) answers as the former test with its own weld and
    sort, on the convex and concave closed meshes above and on dents of growing depth, some
    within the 1e-5 tolerance, the deeper ones past it."""
    import trimesh

    from alight.core.mesh import closed_edges
    from alight.core.shadow_fit import _locally_convex

    ball = trimesh.creation.icosphere(subdivisions=4)
    pos, idx = np.asarray(ball.vertices, np.float32), np.asarray(ball.faces, np.uint32)
    s = sphere().parts[0]
    corners = BOX_CORNERS * (2.0, 1.0, 1.0)
    l_shape = (np.concatenate([BOX_CORNERS, corners + (0.0, 1.0, 0.0)]),
               np.concatenate([np.array(BOX_FACES), np.array(BOX_FACES) + 8]))
    cases = [(s.positions, s.indices), (pos, idx), (pos, idx[:, ::-1]), l_shape,
             (BOX_CORNERS, np.array(BOX_FACES))]
    for depth in (1e-7, 1e-6, 1e-4, 1e-2):
        dented = pos.copy()
        dented[100] *= 1.0 - depth
        cases.append((dented, idx))
    answers = []
    for positions, indices in cases:
        size = float(np.abs(positions - np.asarray(positions, np.float64).mean(axis=0)).max())
        edges = closed_edges(positions, indices)
        assert edges is not None
        for e in (edges, closed_edges(positions, indices, pack=False), None):
            got = _locally_convex(positions, indices, 1e-5 * size, e)
            assert got == _reference_locally_convex(positions, indices, 1e-5 * size)
        answers.append(got)
        assert can_shadow_itself([(positions, indices)], [True], edges=[edges]) == \
            can_shadow_itself([(positions, indices)], [True])
    assert set(answers) == {True, False}


def test_closedness_found_by_the_test_gives_the_callers_answers(monkeypatch):
    """Without ``closed`` (as alight.render.shadows calls it) the test answers as with the
    caller's is_closed, open and closed, convex and not; and where its sample of faces against
    vertices finds a splitting plane it answers before welding or sorting anything."""
    import trimesh

    from alight.core import mesh as mesh_module

    ball = trimesh.creation.icosphere(subdivisions=4)
    pos, idx = np.asarray(ball.vertices, np.float32), np.asarray(ball.faces, np.uint32)
    corners = BOX_CORNERS * (2.0, 1.0, 1.0)
    l_shape = [(np.concatenate([BOX_CORNERS, corners + (0.0, 1.0, 0.0)]),
                np.concatenate([np.array(BOX_FACES), np.array(BOX_FACES) + 8]))]
    dented = pos.copy()
    dented[100] *= 0.97
    cases = {
        "built-in sphere": [(p.positions, p.indices) for p in sphere().parts],
        "cube": [(p.positions, p.indices) for p in cube().parts],
        "box on a plane": [(p.positions, p.indices) for p in box_on_plane().parts],
        "L of two boxes": l_shape,
        "icosphere": [(pos, idx)],
        "icosphere, a face missing (open, convex)": [(pos, idx[1:])],
        "icosphere, one vertex pushed in by 3%": [(dented, idx)],
        "two icospheres": [(np.concatenate([pos, pos + (3.0, 0.0, 0.0)]), np.concatenate([idx, idx + len(pos)]))],
    }
    answers = {}
    for name, parts in cases.items():
        closed = [is_closed(p, i) for p, i in parts]
        answers[name] = can_shadow_itself(parts)
        assert answers[name] == can_shadow_itself(parts, closed), name
    assert answers == {"built-in sphere": False, "cube": False, "box on a plane": True, "L of two boxes": True,
                       "icosphere": False, "icosphere, a face missing (open, convex)": True,
                       "icosphere, one vertex pushed in by 3%": True, "two icospheres": True}

    def no_sort(*args, **kwargs):
        raise AssertionError("welded and sorted although the sample had answered")

    monkeypatch.setattr(mesh_module, "closed_edges", no_sort)
    assert can_shadow_itself(l_shape)
    assert can_shadow_itself(cases["two icospheres"])


def test_sphere_draws_no_shadow_pass_and_is_unchanged():
    r = renderer()
    light = Light(kind="directional", vector=(-0.3, -1.0, -0.5), intensity=3.0)
    scene = Scene(mesh=sphere(), lights=[light], ibl_enabled=False)
    before = r.shadow_maps.passes_run
    auto = r.render(scene, None, 64, 64).linear
    assert r.shadow_maps.passes_run == before and not r.shadow_maps.last_active
    scene.shadows = "off"
    np.testing.assert_array_equal(r.render(scene, None, 64, 64).linear, auto)
    # Forced on, a convex solid's shadow changes nothing it can see (within the PCF's edge).
    scene.shadows = "on"
    on = r.render(scene, None, 64, 64).linear
    assert r.shadow_maps.passes_run == before + 1
    assert np.abs(on - auto).max() < 0.02 * auto.max()


def test_maps_are_reused_when_only_the_camera_moves():
    r = renderer()
    light = Light(kind="directional", vector=LIGHT, intensity=3.0)
    scene = _box_scene(lights=[light], ibl_enabled=False, shadows="on")
    r.render(scene, None, 32, 32)
    before = r.shadow_maps.passes_run
    scene.camera = Camera(position=(3.0, 4.0, 5.0), target=(0.0, 0.3, 0.0))
    r.render(scene, None, 32, 32)
    assert r.shadow_maps.passes_run == before
    scene.lights = [Light(kind="directional", vector=(0.6, -1.0, 0.4), intensity=3.0)]
    r.render(scene, None, 32, 32)
    assert r.shadow_maps.passes_run == before + 1


def test_directional_fit_is_snapped_to_texels():
    """Moving the bounds by less than a texel moves the map by whole texels only."""
    a = directional_view(LIGHT, (0.0, 0.0, 0.0), 2.0, 512)
    b = directional_view(LIGHT, (0.001, 0.0, 0.0), 2.0, 512)
    p = np.array([0.3, 0.2, 0.1, 1.0])
    shift = ((b.matrix @ p)[:2] - (a.matrix @ p)[:2]) / 2.0 * 512     # in texels
    np.testing.assert_allclose(shift, np.round(shift), atol=1e-6)


def test_point_light_faces_cover_every_direction():
    views = point_views((0.0, 2.0, 0.0), (0.0, 0.0, 0.0), 1.0, 64)
    rng = np.random.default_rng(1)
    for v in rng.normal(size=(200, 3)):
        clip = views[cube_face(v)].matrix @ np.append(np.array([0.0, 2.0, 0.0]) + v / np.linalg.norm(v) * 1.5, 1.0)
        ndc = clip[:3] / clip[3]
        assert clip[3] > 0 and np.abs(ndc[:2]).max() <= 1.0


def synthetic_sun_map(toward, radiance=2.0e4, radius_deg=0.6, sky=0.5, size=512) -> np.ndarray:
    """An equirect map: a uniform sky and a small disk of the sun toward ``toward``."""
    from alight.core.shading import texel_directions

    dirs, _ = texel_directions(size // 2, size)
    d = np.asarray(toward, float) / np.linalg.norm(toward)
    env = np.full((size // 2, size, 3), sky, np.float32)
    env[dirs @ d > np.cos(np.radians(radius_deg))] = radiance
    return env


@pytest.mark.parametrize("rotation", [0.0, 90.0])
def test_sun_of_the_map_casts_the_box_shadow(rotation):
    """The compact source alight takes out of the map (alight.ibl.sun) casts the same shadow as a
    directional light along it; the environment turned by 90 degrees turns the shadow with it."""
    from alight.core.shading import rotate_world_to_map
    from alight.ibl.environment import Environment

    # The map texel toward m lights world direction R_y(+deg) m: put the sun where the world's
    # light must come from.
    toward_world = -np.asarray(LIGHT, float)
    toward_map = rotate_world_to_map(toward_world, rotation)
    env = Environment(radiance=synthetic_sun_map(toward_map), name="synthetic sun", warnings=[])
    r = renderer()
    maps = r.bake(env, "low")
    assert len(maps.suns) == 1
    scene = _box_scene(env_rotation_deg=rotation, shadows="off")
    lit = render(scene, maps=maps)
    scene.shadows = "auto"
    shadowed_img = render(scene, maps=maps)
    assert r.shadow_maps.last_active
    x, z = pixel_world_xz()
    plane = ~((np.abs(x) <= 0.5) & (np.abs(z) <= 0.5))
    ratio = shadowed_img[..., :3].mean(axis=2) / np.maximum(lit[..., :3].mean(axis=2), 1e-6)
    shadowed = (ratio < 0.6) & plane
    expected = expected_shadow(LIGHT)
    assert overlap(shadowed, expected) >= 0.9
    # In the shadow only the sky is left: the sun's share is gone.
    assert np.median(ratio[expected & ~_dilate(~expected, 2)]) < 0.4


def test_glsl_taps_are_vogel_disks():
    """The 4-tap table, and the 8 and 12 taps the soft shadows' loops walk (a turn by the golden
    angle per step, radius sqrt((k + 0.5) / n)), against their numpy twin."""
    import re

    from alight.core.shadow_fit import vogel_disk
    from alight.paths import shader_dir

    text = (shader_dir() / "common" / "shadows.glsl").read_text()
    body = re.search(r"SHADOW_TAPS_4\[4\] = vec2\[\]\((.*?)\);", text, re.S).group(1)
    values = np.array([float(x) for x in re.findall(r"-?\d+\.\d+", body)]).reshape(-1, 2)
    np.testing.assert_allclose(values, vogel_disk(4), atol=1e-6)
    turn = [float(x) for x in re.search(r"SHADOW_GOLDEN_TURN = vec2\((\S+), (\S+)\);", text).groups()]
    for n in (8, 12):
        assert f"sqrt((float(k) + 0.5) / {n}.0)" in text
        d, walked = np.array([1.0, 0.0], np.float32), []
        for k in range(n):
            walked.append(d * np.sqrt((k + 0.5) / n))
            d = np.array([d[0] * turn[0] - d[1] * turn[1], d[0] * turn[1] + d[1] * turn[0]], np.float32)
        np.testing.assert_allclose(walked, vogel_disk(n), atol=1e-5)


def test_ground_catches_the_sphere_shadow_where_it_falls():
    """The built-in sphere (radius 1) on --ground under a light at 45 degrees: seen from above, the
    shadow in alpha (transparent background) is the ellipse the light's projection puts on the
    plane y = -1 (centre x = -1, semi-axes sqrt(2) along x and 1 along z), outside the ball."""
    light = Light(kind="directional", vector=(-1.0, -1.0, 0.0), intensity=3.0)
    scene = Scene(mesh=sphere(), lights=[light], ibl_enabled=False, ground=True, camera=top_view(),
                  display=Display(background="transparent"))
    r = renderer()
    frame = r.render(scene, None, SIZE, SIZE)
    assert r.shadow_maps.last_active     # the ground needs the pass the convex sphere alone does not
    x, z = pixel_world_xz()
    ball = x * x + z * z <= 1.0
    near = x * x + z * z < 1.7 ** 2      # inside the fade (alight.core.ground)
    expected = (((x + 1.0) / np.sqrt(2.0)) ** 2 + z * z <= 1.0) & ~ball & near
    alpha = frame.linear[..., 3]
    shadowed = (alpha > 0.5) & ~ball & near
    assert overlap(shadowed, expected) >= 0.9
    assert alpha[~_dilate(ball, 2) & ~_dilate(expected, 3) & near].max() < 0.02     # lit ground: transparent
    # Without the ground the same scene has no shadow pass and nothing off the ball.
    scene.ground = False
    before = r.shadow_maps.passes_run
    plain = r.render(scene, None, SIZE, SIZE)
    assert r.shadow_maps.passes_run == before and plain.linear[..., 3][~_dilate(ball, 2)].max() == 0.0


@pytest.mark.parametrize("aa", ["none", "msaa", "ssaa"])
def test_cli_ground_over_background_is_the_background_darkened_by_the_alpha(tmp_path, aa):
    """alight render --ground: over a colour background each pixel off the ball is the colour
    times (1 - the shadow's alpha) of the same render over a transparent background."""
    from PIL import Image

    common = [sys.executable, "-m", "alight", "render", "--mesh", "sphere", "--no-ibl", "--ground", "--size", "96",
              "--elevation", "35", "--light", "directional:dir=-1,-1,-0.3:intensity=3", "--tonemap", "none", "--aa", aa]
    a, b = tmp_path / "t.png", tmp_path / "c.png"
    subprocess.run(common + ["--background", "transparent", "--out", str(a)], check=True, capture_output=True)
    subprocess.run(common + ["--background", "color", "--background-color", "0.5,0.5,0.5", "--out", str(b)],
                   check=True, capture_output=True)
    t = np.asarray(Image.open(a), np.float64) / 255.0
    c = np.asarray(Image.open(b), np.float64) / 255.0
    off_ball = t[..., 3] < 0.999
    shadow = off_ball & (t[..., 3] > 0.2)
    assert shadow.sum() > 50
    # sRGB of linear 0.5 times (1 - alpha), against the colour render (8-bit rounding).
    expected = 0.5 * (1.0 - t[..., 3])
    srgb = np.where(expected <= 0.0031308, 12.92 * expected, 1.055 * expected ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(c[..., 0][off_ball & ~_dilate(~off_ball, 1)], srgb[off_ball & ~_dilate(~off_ball, 1)], atol=3 / 255)


@pytest.mark.parametrize("kind", ["point", "spot"])
def test_point_and_spot_shadows_lie_where_the_box_projects(kind):
    """From a light at P the box's shadow on y = 0 is the hull of its corners projected from P."""
    p = np.array([1.3, 2.2, 0.9])
    if kind == "point":
        light = Light(kind="point", vector=tuple(p), intensity=8.0)
    else:
        light = Light(kind="spot", vector=tuple(p), direction=tuple(-p), inner_cone_deg=60.0, outer_cone_deg=70.0,
                      intensity=8.0)
    lit = render(_box_scene(lights=[light], ibl_enabled=False, shadows="off"))
    shadowed_img = render(_box_scene(lights=[light], ibl_enabled=False, shadows="on"))
    x, z = pixel_world_xz()
    plane = ~((np.abs(x) <= 0.5) & (np.abs(z) <= 0.5))
    ratio = shadowed_img[..., :3].mean(axis=2) / np.maximum(lit[..., :3].mean(axis=2), 1e-9)
    valid = lit[..., :3].mean(axis=2) > 1e-4 * lit[..., :3].max()        # inside the spot's cone
    shadowed = (ratio < 0.5) & plane & valid
    t = p[1] / (p[1] - BOX_CORNERS[:, 1])
    projected = p + (BOX_CORNERS - p) * t[:, None]
    expected = _hull_mask(projected[:, [0, 2]], x, z) & plane & valid
    assert expected.sum() > 300
    assert overlap(shadowed, expected) >= 0.9


def test_batch_spec_takes_shadows_and_ground(tmp_path):
    """A batch spec's 'ground' under a map with a sun darkens the background where the ball's
    shadow falls; a bad 'shadows' value is one error naming the spec."""
    import io

    from PIL import Image

    from alight.errors import AlightError
    from alight.exchange.output import write_image
    from alight.frontends.batch import plan, run

    write_image(tmp_path / "sun.exr", synthetic_sun_map((0.5, 1.0, 0.3), size=256), linear=True)
    base = 'size = 48\nquality = "low"\nmeshes = ["sphere"]\nenvironments = ["sun.exr"]\nmaterials = ["gold"]\n' \
           'camera_angles = [0]\ncontact_sheet = false\nbackground = "color"\n'
    images = {}
    for name, extra in (("plain", ""), ("ground", "ground = true\n")):
        spec = tmp_path / f"{name}.toml"
        spec.write_text(base + extra)
        result = run(plan(spec), executor="inline", log=io.StringIO())
        (png,) = (tmp_path / name).glob("*.png")
        images[name] = np.asarray(Image.open(png), np.float64)
        assert result is not None
    darker = images["ground"][..., :3].mean(axis=2) < images["plain"][..., :3].mean(axis=2) - 5
    assert darker.sum() > 20
    assert not (images["ground"][..., :3].mean(axis=2) > images["plain"][..., :3].mean(axis=2) + 1).any()
    bad = tmp_path / "bad.toml"
    bad.write_text(base + 'shadows = "sometimes"\n')
    with pytest.raises(AlightError, match="bad.toml: 'shadows' must be auto, on or off"):
        plan(bad)


def test_api_set_shadows():
    """alight.Renderer.set_shadows: the ground's shadow over a transparent background is in alpha;
    bad modes are one-line errors."""
    from alight import Renderer
    from alight.errors import AlightError

    with Renderer(48, quality="low", background="transparent") as r:
        r.set_environment(None).set_lights(["directional:dir=-1,-1,-0.2:intensity=3"])
        plain = r.render()
        shadowed = r.set_shadows("auto", ground=True).render()
        assert (plain[..., 3] == 0).sum() > (shadowed[..., 3] == 0).sum() + 20
        with pytest.raises(AlightError, match="shadows: 'sometimes'"):
            r.set_shadows("sometimes")
        with pytest.raises(AlightError, match="occlusion: 'x'"):
            r.set_shadows(occlusion="x")


def test_ground_views_are_as_wide_as_the_casters():
    """On --ground the sun's and a directional light's views cover the model across the light
    (its shadow lies in its own footprint there) and reach the ground only in depth."""
    from alight.core.ground import ground_under
    from alight.ibl.sun import Sun
    from alight.render.shadows import RESOLUTION, plan_views

    mesh = cube()
    lo, hi = mesh.bounds()
    centre, radius = mesh.bounding_sphere()
    ground = ground_under(lo, hi, centre, radius)
    low_sun = Sun(direction=np.array([0.0, np.sin(np.radians(10.0)), -np.cos(np.radians(10.0))]),
                  power=np.ones(3), fraction=0.5, texels=10, spread=0.004)
    plan = plan_views([Light(kind="directional", vector=(0.3, -0.2, 0.9))], [low_sun], *ground.bounds,
                      casters=(centre, radius))
    travel = [np.array([0.3, -0.2, 0.9]), -low_sun.direction]      # where each source's light goes
    for view, d in zip(plan.views, travel):
        assert view.texel == pytest.approx(2.0 * radius * 1.02 / view.resolution)
        assert view.resolution == RESOLUTION["directional"]
        # the ground's rim down the light, where the longest shadow fades out, lies inside the
        # view's depth range (the rim toward the light lies before the casters: nothing shadows it)
        away = np.array([d[0], 0.0, d[2]]) / np.hypot(d[0], d[2])
        depth = (view.matrix @ np.append(ground.centre + ground.fade * away, 1.0))[2]
        assert -1.0 <= depth <= 1.0


def test_ground_shadow_of_a_low_sun_matches_traced_visibility():
    """A cube on --ground under a map's sun 10 degrees high (0.5 degrees wide), seen from above:
    the ground's shadow (alpha over a transparent background, divided by the sun's share of the
    ground's light) against the hidden share of the sun's disk from Embree shadow rays. With the
    sun's view as wide as the ground's sphere a texel was stretched along the light into streaks."""
    pytest.importorskip("embreex", reason="the traced visibility needs embreex (pip install 'alight[reference]')")
    from alight.accuracy.path_trace import _Rays, scene_geometry
    from alight.core.shading import rotate_world_to_map
    from alight.ibl.environment import Environment
    from alight.render.shadows import SPREAD_TO_RADIUS

    toward = np.array([0.6, np.sin(np.radians(10.0)), -0.8])
    toward[[0, 2]] *= np.cos(np.radians(10.0)) / np.hypot(0.6, 0.8)
    env = Environment(radiance=synthetic_sun_map(toward, radiance=4.0e4, radius_deg=0.5, size=1024),
                      name="low sun", warnings=[])
    r = renderer()
    maps = r.bake(env, "low")
    sun = maps.suns[0]
    size = 384
    scene = Scene(mesh=cube(), ground=True, camera=top_view(), display=Display(background="transparent"))
    alpha = r.render(scene, maps, size, size).linear[..., 3].astype(np.float64)
    x, z = pixel_world_xz(size)
    y0 = float(cube().bounds()[0][1])
    pts = np.stack([x, np.full_like(x, y0 + 1e-4), z], axis=-1).reshape(-1, 3)
    rays = _Rays(scene_geometry(scene)[0])
    d0 = np.asarray(rotate_world_to_map(np.asarray(sun.direction, float), 0.0))
    a = np.cross(d0, (0.0, 1.0, 0.0))
    a /= np.linalg.norm(a)
    b = np.cross(d0, a)
    disk = np.tan(sun.spread * SPREAD_TO_RADIUS)
    hidden = np.zeros(len(pts))
    for k in range(32):
        rho, phi = np.sqrt((k + 0.5) / 32), k * 2.39996323
        d = d0 + disk * rho * (np.cos(phi) * a + np.sin(phi) * b)
        hidden += rays.blocked(pts, np.broadcast_to(d / np.linalg.norm(d), pts.shape), np.full(len(pts), np.inf))
    hidden = (hidden / 32).reshape(size, size)
    ground = ~_dilate((np.abs(x) <= 1.0) & (np.abs(z) <= 1.0), 2) & (np.hypot(x, z) < 2.5)
    share = np.median(alpha[ground & (hidden > 0.999)])
    estimate = alpha / share
    penumbra = ground & (hidden > 0.02) & (hidden < 0.98)
    assert penumbra.sum() > 100
    # now 0.056 and 0.00027; with the views as wide as the ground 0.090 and 0.00074
    assert np.abs(estimate - hidden)[penumbra].mean() < 0.075
    assert np.abs(estimate - hidden)[ground].mean() < 0.0005
