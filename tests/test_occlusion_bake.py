"""Per-vertex ambient occlusion (alight.render.occlusion): a floor with a wall standing on its
edge, baked on the GPU, against the same cosine-weighted visibility ray-cast by trimesh; the
render darkens the environment light there and only there; convex meshes bake nothing."""

from __future__ import annotations

import numpy as np

from alight.core.material import Material
from alight.core.mesh import Mesh, MeshPart, sphere
from alight.core.occlusion_bake import sphere_directions
from alight.core.scene import Scene
from alight.ibl.environment import constant_environment

from gpu import renderer


def _part(positions, faces, normal, name) -> MeshPart:
    positions = np.asarray(positions, np.float32)
    n = len(positions)
    return MeshPart(name, positions, np.tile(np.float32(normal), (n, 1)), np.zeros((n, 2), np.float32),
                    np.tile(np.float32([1, 0, 0, 1]), (n, 1)), np.asarray(faces, np.uint32), None)


def corner() -> Mesh:
    """A 2x2 floor on y = 0 (a 17 x 17 grid of vertices) and a 2 x 1 wall on x = -1."""
    k = 17
    c = np.linspace(-1.0, 1.0, k)
    x, z = np.meshgrid(c, c)
    floor = np.stack([x.ravel(), np.zeros(k * k), z.ravel()], axis=1)
    faces = []
    for i in range(k - 1):
        for j in range(k - 1):
            a = i * k + j
            faces += [[a, a + k, a + 1], [a + 1, a + k, a + k + 1]]
    wall = [[-1, 0, -1], [-1, 0, 1], [-1, 1, 1], [-1, 1, -1]]
    return Mesh([_part(floor, faces, (0, 1, 0), "floor"), _part(wall, [[0, 1, 2], [0, 2, 3]], (1, 0, 0), "wall")], "corner")


def _hits(origin: np.ndarray, dirs: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(R,) whether each ray from ``origin`` meets any of the triangles (T, 3, 3): Moller-Trumbore."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    pvec = np.cross(dirs[:, None, :], e2[None])                      # (R, T, 3)
    det = np.einsum("rtk,tk->rt", pvec, e1)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    tvec = origin - tri[:, 0]                                          # (T, 3)
    u = np.einsum("rtk,tk->rt", pvec, tvec) * inv
    qvec = np.cross(tvec, e1)                                          # (T, 3)
    v = np.einsum("rk,tk->rt", dirs, qvec) * inv
    t = np.einsum("tk,tk->t", e2, qvec)[None] * inv
    return (ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6)).any(axis=1)


def ray_cast_occlusion(mesh: Mesh, points: np.ndarray, normals: np.ndarray, n: int = 2000) -> np.ndarray:
    """The cosine-weighted share of directions that leave the mesh, ray-cast in numpy."""
    tri = np.concatenate([np.asarray(p.positions, np.float64)[np.asarray(p.indices, np.int64)] for p in mesh.parts])
    dirs = sphere_directions(n)
    out = []
    for p, nrm in zip(points, normals):
        w = np.maximum(dirs @ nrm, 0.0)
        use = w > 0
        hit = _hits(p + nrm * 1e-4, dirs[use], tri)
        out.append(float((w[use] * ~hit).sum() / w[use].sum()))
    return np.array(out)


def test_baked_occlusion_matches_ray_casting():
    r = renderer()
    mesh = corner()
    env = constant_environment(1.0, 64)
    maps = r.bake(env, "low")
    r.render(Scene(mesh=mesh, occlusion="on", material=Material(roughness=1.0)), maps, 32, 32)
    baked = r.occlusion_bake.values(mesh)[0]
    floor = mesh.parts[0].positions.astype(np.float64)
    pick = np.flatnonzero((floor[:, 0] > -0.99) & (np.abs(floor[:, 2]) < 0.6))[::5]     # off the wall's foot
    truth = ray_cast_occlusion(mesh, floor[pick], np.tile([0.0, 1.0, 0.0], (len(pick), 1)))
    assert truth.min() < 0.8 and truth.max() > 0.9          # the wall's shadow is in the sample
    np.testing.assert_allclose(baked[pick], truth, atol=0.05)


def test_occlusion_darkens_the_environment_light_only_where_occluded():
    r = renderer()
    mesh = corner()
    maps = r.bake(constant_environment(1.0, 64), "low")
    scene = Scene(mesh=mesh, material=Material(base_color=(0.8, 0.8, 0.8), roughness=1.0))
    off = r.render(scene, maps, 64, 64).linear
    scene.occlusion = "on"
    on = r.render(scene, maps, 64, 64).linear
    covered = off[..., 3] > 0.99
    ratio = on[..., :3].mean(axis=2)[covered] / off[..., :3].mean(axis=2)[covered]
    assert ratio.max() <= 1.0 + 1e-4 and ratio.min() < 0.75


def test_convex_meshes_bake_nothing():
    r = renderer()
    maps = r.bake(constant_environment(1.0, 64), "low")
    before = r.occlusion_bake.bakes_run
    scene = Scene(mesh=sphere(), occlusion="on")
    on = r.render(scene, maps, 48, 48).linear
    assert r.occlusion_bake.bakes_run == before
    scene.occlusion = "off"
    np.testing.assert_array_equal(r.render(scene, maps, 48, 48).linear, on)


def test_compute_shader_matches_its_numpy_twin():
    """render/occlusion_accumulate.comp against alight.core.occlusion_bake's visible_from and
    accumulate, on the same depth maps read back."""
    import moderngl

    from alight.core.occlusion_bake import accumulate, occlusion, visible_from
    from alight.core.shadow_fit import directional_view
    from alight.render.occlusion import DIRECTIONS, RESOLUTION

    r = renderer()
    mesh = corner()
    maps = r.bake(constant_environment(1.0, 64), "low")
    r.render(Scene(mesh=mesh, occlusion="on"), maps, 16, 16)
    gpu = r.occlusion_bake.values(mesh)
    ctx = r.ctx
    depth = ctx.depth_texture((RESOLUTION, RESOLUTION))
    fbo = ctx.framebuffer(depth_attachment=depth)
    prog = r.program("render/shadow_depth.vert", "render/shadow_depth.frag")
    centre, radius = mesh.bounding_sphere()
    sums = [(np.zeros(len(p.positions)), np.zeros(len(p.positions))) for p in mesh.parts]
    try:
        for toward in sphere_directions(DIRECTIONS):
            view = directional_view(-toward, centre, radius, RESOLUTION)
            fbo.use()
            ctx.viewport = (0, 0, RESOLUTION, RESOLUTION)
            fbo.clear(depth=1.0)
            ctx.enable(moderngl.DEPTH_TEST)
            prog["u_view_projection"].write(np.ascontiguousarray(view.matrix.T, np.float32).tobytes())
            for g in r._gpu_mesh(mesh):
                g.vao_for(prog).render(moderngl.TRIANGLES)
            ctx.disable(moderngl.DEPTH_TEST)
            d = np.frombuffer(depth.read(), np.float32).reshape(RESOLUTION, RESOLUTION)
            for (w, s), p in zip(sums, mesh.parts):
                nrm = np.asarray(p.normals, np.float64)
                accumulate(w, s, nrm, toward, visible_from(view, d, np.asarray(p.positions, np.float64), nrm, toward))
    finally:
        fbo.release()
        depth.release()
    for (w, s), g in zip(sums, gpu):
        np.testing.assert_allclose(g, occlusion(w, s), atol=0.03)


def test_bake_is_kept_on_disk_for_the_next_process(tmp_path):
    """A second renderer on the same store loads the bake instead of running it; values equal."""
    from alight.ibl.bake_cache import BakeCache
    from alight.render.renderer import ForwardRenderer

    mesh = corner()
    env = constant_environment(1.0, 16)
    values = []
    for _ in range(2):
        with ForwardRenderer(bake_cache=BakeCache(tmp_path)) as r:
            r.render(Scene(mesh=mesh, occlusion="on"), r.bake(env, "low"), 16, 16)
            values.append((r.occlusion_bake.bakes_run, r.occlusion_bake.bakes_loaded, r.occlusion_bake.values(mesh)))
    assert values[0][:2] == (1, 0) and values[1][:2] == (0, 1)
    for a, b in zip(values[0][2], values[1][2]):
        np.testing.assert_array_equal(a, b)
