"""What blotched the Duck, NormalTangentMirrorTest and TextureSettingsTest with --occlusion, by
equivalence: a mesh that cannot occlude itself renders with the bake as without it.

- A coarse convex mesh (the Duck's kind: a round body of large flat triangles): the rays of a
  vertex started behind the planes of its own faces and left through them, V ~ 0 on convex patches.
- A normal-mapped plane (NormalTangentMirrorTest's tiles): the per-vertex bent normal replaced the
  normal map in the diffuse lookup, the relief went flat.
- The occluders' radiance w / (1 - V) (a bright ring where the occlusion texture is dark and the
  bake saw almost nothing): at most 1.
The test writes its own files (trimesh) and reads them with alight's loader."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("embreex")
trimesh = pytest.importorskip("trimesh")

from alight.core import visibility as vis  # noqa: E402
from alight.core.material import Material  # noqa: E402
from alight.core.scene import Camera, Scene  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.ibl.environment import studio_environment  # noqa: E402
from tests.gpu import renderer  # noqa: E402


def _coarse_ball(path: Path) -> Path:
    """An icosphere of 80 faces with its exact (radial) normals, as OBJ."""
    ball = trimesh.creation.icosphere(subdivisions=1)
    normals = ball.vertices / np.linalg.norm(ball.vertices, axis=1, keepdims=True)
    mesh = trimesh.Trimesh(ball.vertices, ball.faces, vertex_normals=normals, process=False)
    path.write_text(mesh.export(file_type="obj", include_normals=True, include_texture=False))
    return path


def _bumpy_plane(path: Path) -> Path:
    """A 2 x 2 plane facing +Z with a tangent-space normal map of ridges (slopes up to 45 degrees)
    as glTF binary."""
    from PIL import Image

    size = 64
    u = (np.arange(size) + 0.5) / size
    slope = np.tile(np.sin(2.0 * np.pi * 4.0 * u), (size, 1))          # dh/du of the ridges
    n = np.stack([-slope, np.zeros_like(slope), np.ones_like(slope)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    image = Image.fromarray(np.round((n * 0.5 + 0.5) * 255).astype(np.uint8))
    vertices = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[200, 200, 200, 255], metallicFactor=0.0,
                                                   roughnessFactor=0.6, normalTexture=image)
    mesh = trimesh.Trimesh(vertices, faces, vertex_normals=np.tile([0.0, 0.0, 1.0], (4, 1)), process=False,
                           visual=trimesh.visual.TextureVisuals(uv=uv, material=material))
    path.write_bytes(trimesh.Scene(mesh).export(file_type="glb"))
    return path


def _on_and_off(mesh, camera):
    r = renderer()
    maps = r.bake(studio_environment(256), "low")
    images = {}
    for mode in ("off", "on"):
        scene = Scene(mesh=mesh, material=Material(base_color=(0.8, 0.8, 0.8), roughness=0.5), camera=camera,
                      occlusion=mode)
        images[mode] = r.render(scene, maps, 96, 96, aa="none", read_linear=True, read_srgb=False).linear[..., :3]
    assert r.visibility_parts.wanted(mesh, "on")
    return images["off"], images["on"]


def test_a_coarse_convex_mesh_does_not_occlude_itself(tmp_path):
    mesh = load_mesh(str(_coarse_ball(tmp_path / "ball.obj")))
    baked = vis.bake_visibility(mesh)
    v = np.concatenate([p.visibility for p in baked.parts])
    # Convex: every ray reaches the sky (the old origins gave V = 0 at some vertices, mean 0.89).
    assert v.min() > 0.97, v.min()
    off, on = _on_and_off(mesh, Camera(position=(0.0, 0.6, 3.5)))
    lit = off.sum(axis=-1) > 1e-3
    assert lit.mean() > 0.2
    relative = np.abs(on - off).sum(axis=-1)[lit] / off.sum(axis=-1)[lit]
    assert np.percentile(relative, 99) < 0.03 and relative.mean() < 0.01, (relative.mean(), relative.max())


def test_a_normal_map_keeps_its_relief_with_occlusion(tmp_path):
    mesh = load_mesh(str(_bumpy_plane(tmp_path / "plane.glb")))
    assert mesh.parts[0].material.normal_texture is not None
    camera = Camera(position=(0.0, -1.5, 3.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    off, on = _on_and_off(mesh, camera)
    lit = off.sum(axis=-1) > 1e-3
    assert lit.mean() > 0.3
    luminance = off.sum(axis=-1)[lit]
    assert luminance.std() / luminance.mean() > 0.05           # the ridges show
    relative = np.abs(on - off).sum(axis=-1)[lit] / luminance
    assert np.percentile(relative, 99) < 0.03, np.percentile(relative, 99)


def test_the_occluders_visibility_is_at_most_one():
    """w / (1 - V) is the mean visibility of what the occluded rays hit; w and V come from
    different rays, so where V is near 1 their noise must not make the occluders brighter than lit."""
    w = np.array([0.0, 0.02, 0.3, 0.5])
    v = np.array([1.0, 0.999, 0.5, 0.2])
    got = vis.occluder_visibility(w, v)
    np.testing.assert_allclose(got, [0.0, 1.0, 0.6, 0.625])
    ones = np.ones((4, 3))
    diffuse, _ = vis.occluded_environment(np.zeros(4), v, w, ones, ones, 1.0, np.ones(4), ones)
    assert diffuse.max() <= 1.0 + 1e-9


def test_the_bent_normal_follows_the_normal_map():
    rng = np.random.default_rng(1)
    n = rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n[:, 2] = np.abs(n[:, 2])
    vertex = np.tile([0.0, 0.0, 1.0], (50, 1))
    # Open (bent = vertex normal): the mapped normal itself.
    np.testing.assert_allclose(vis.mapped_bent_normal(n, vertex, vertex), n, atol=1e-12)
    # Unmapped (n = vertex normal): the baked bent normal.
    bent = np.tile(np.array([0.3, 0.0, 0.9]) / np.linalg.norm([0.3, 0.0, 0.9]), (50, 1))
    np.testing.assert_allclose(vis.mapped_bent_normal(vertex, bent, vertex), bent, atol=1e-12)


def _polar(theta, phi):
    return np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


def test_the_new_shader_terms_match_their_numpy_twins():
    from tests.gpu import evaluate

    rng = np.random.default_rng(4)
    count = 400
    angles = np.column_stack([rng.uniform(0, 1.5, count), rng.uniform(0, 6.3, count),
                              rng.uniform(0, 1.5, count), rng.uniform(0, 6.3, count)])
    gpu = evaluate(3, angles, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    vertex = np.tile([0.0, 0.0, 1.0], (count, 1))
    want = vis.mapped_bent_normal(_polar(angles[:, 0], angles[:, 1]), _polar(angles[:, 2], angles[:, 3]), vertex)
    np.testing.assert_allclose(gpu, want, atol=2e-5)
    wv = np.column_stack([rng.uniform(0, 1, count), rng.uniform(0, 1, count)])
    gpu = evaluate(4, wv, shader="accuracy/evaluate_occlusion.comp")[:, 0]
    np.testing.assert_allclose(gpu, vis.occluder_visibility(wv[:, 0], wv[:, 1]), rtol=1e-5, atol=1e-6)
    rows = np.column_stack([rng.uniform(0, 1, (count, 3)), rng.uniform(0, 1, count)])
    gpu = evaluate(5, rows, shader="accuracy/evaluate_occlusion.comp")[:, :3]
    np.testing.assert_allclose(gpu, vis.occluders_reflectance(rows[:, :3], rows[:, 3]), rtol=1e-4, atol=1e-6)


def test_the_occluders_reflect_every_bounce():
    """a V / (1 - a (1 - V)): one bounce (a V) where the occluders are open; the sum of the
    geometric series a^k where they are closed in (V -> 0 with a V / (1 - a) per unit)."""
    a = np.array([[0.7, 0.7, 0.7]])
    np.testing.assert_allclose(vis.occluders_reflectance(a, np.array([1.0])), a)
    v = np.array([0.5])
    np.testing.assert_allclose(vis.occluders_reflectance(a, v), 0.35 / (1.0 - 0.35))
    assert (vis.occluders_reflectance(a, np.array([0.3])) > a * 0.3).all()


def _revolved_bowl(path: Path) -> Path:
    """A bowl (a spherical shell's lower half, 0.1 thick; 20k faces) revolved by trimesh and
    written as OBJ without normals, as a user's file often is: alight's loader then makes the
    normals and keeps a copy of each vertex per face around it (59k vertices at 10k positions),
    their normals a degree or two apart."""
    t = np.linspace(0.0, np.pi / 2.0, 40)
    arc = np.column_stack([np.sin(t), -np.cos(t)])
    bowl = trimesh.creation.revolve(np.vstack([arc, 0.9 * arc[::-1]]), sections=128)
    path.write_text(bowl.export(file_type="obj", include_normals=False, include_texture=False))
    return path


def _speckle(linear: np.ndarray) -> float:
    """Mean |Laplacian| of the covered pixels' luminance over its mean: the triangle-sized
    speckle a noisy per-vertex term draws."""
    x = linear[..., :3].mean(-1)
    covered = linear[..., 3] > 0.99
    lap = np.abs(4 * x[1:-1, 1:-1] - x[:-2, 1:-1] - x[2:, 1:-1] - x[1:-1, :-2] - x[1:-1, 2:])
    inner = covered[1:-1, 1:-1] & covered[:-2, 1:-1] & covered[2:, 1:-1] & covered[1:-1, :-2] & covered[1:-1, 2:]
    return float(lap[inner].mean() / x[covered].mean())


def test_copies_of_a_vertex_share_their_occlusion(tmp_path, shared_data):
    """The revolved bowl under royal_esplanade (its bright sky makes the visible sky weight
    vary most), 256 px from 45 degrees up: with the bake the inside is as smooth as without it.
    Each copy of a vertex cast rays of its own and the faces connected no copy to its
    neighbours, so the smoothing stayed inside each triangle (visibility.welded). Measured when
    written: the speckle 1.10x the unoccluded frame's, 1.68x before."""
    from alight.core.scene import orbit_camera
    from alight.ibl.environment import load_environment

    mesh = load_mesh(str(_revolved_bowl(tmp_path / "bowl.obj")))
    assert sum(len(p.positions) for p in mesh.parts) > 3 * 9986   # the copies this test is about
    centre, radius = mesh.bounding_sphere()
    camera = orbit_camera(centre, radius, 1.0, 0.0, 45.0, None, 35.0, None, corners=mesh.corners())
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "medium")
    speckle = {}
    for occlusion in ("off", "on"):
        scene = Scene(mesh=mesh, material=Material(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5),
                      use_file_materials=False, camera=camera, occlusion=occlusion, shadows="off")
        speckle[occlusion] = _speckle(r.render(scene, maps, 256, 256, read_linear=True, read_srgb=False).linear)
    assert speckle["on"] < 1.3 * speckle["off"], speckle


def test_welded_keeps_creases_apart():
    """Copies at one position within 10 degrees of their mean normal share an index; a cube's
    corner (three faces' copies, 55 degrees from their mean) keeps three, and so does an authored
    hard edge of 30 degrees (DamagedHelmet's split normals: merged, they lit specks under spot1Lux)."""
    from alight.core.visibility import welded

    smooth = welded([[0, 0, 0], [0, 0, 0], [1, 0, 0]], [[0, 0, 1], [0.02, 0, 1], [0, 0, 1]])
    assert smooth[0] == smooth[1] != smooth[2]
    corner = welded([[0, 0, 0]] * 3, [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
    assert len(set(corner.tolist())) == 3
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    edge = welded([[0, 0, 0]] * 2, [[0, 0, 1], [s, 0, c]])
    assert edge[0] != edge[1]
