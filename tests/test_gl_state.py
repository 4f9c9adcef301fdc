"""What one frame leaves behind for the next: no GL error, a bounded set of uploaded meshes and
(in the editor) of bakes.

A renderer lives as long as an editor session or a test run, drawing many scenes at many sizes;
a framebuffer released while bound used to leave moderngl restoring a deleted name
(GL_INVALID_OPERATION, and once the name was reused, the wrong framebuffer bound), and every
mesh ever drawn stayed on the GPU."""

from __future__ import annotations

import numpy as np

from alight.accuracy.reference import ReferenceRenderer
from alight.core.material import Material
from alight.core.mesh import cube, sphere
from alight.core.scene import Light, Scene
from alight.ibl.environment import load_environment
from alight.render.gpu_mesh import MAX_UPLOADED_MESHES
from alight.render.renderer import ForwardRenderer


def test_frames_that_change_targets_leave_no_gl_error():
    with ForwardRenderer(bake_cache=None) as r:
        maps = r.bake(load_environment("studio"), "low")
        lit_cube = Scene(mesh=cube(), lights=[Light(kind="directional", vector=(-0.3, -1.0, -0.4), intensity=3.0)],
                         ground=True, shadows="on")
        steps = [
            ("probe, no anti-aliasing", lambda: r.render(Scene(view="probe"), maps, 32, 32, aa="none")),
            ("sphere, MSAA", lambda: r.render(Scene(mesh=sphere(48, 24)), maps, 48, 32)),
            ("reference G-buffer", lambda: ReferenceRenderer(r).render(Scene(mesh=sphere(48, 24)), None, 40, 24)),
            ("shadowed cube on the ground", lambda: r.render(lit_cube, maps, 64, 48)),
            ("probe again, another size", lambda: r.render(Scene(view="probe"), maps, 24, 24, aa="none")),
            ("sphere, SSAA", lambda: r.render(Scene(mesh=sphere(48, 24)), maps, 40, 40, aa="ssaa")),
        ]
        assert r.ctx.error == "GL_NO_ERROR"
        for name, step in steps:
            step()
            assert r.ctx.error == "GL_NO_ERROR", name


def test_the_least_recently_drawn_meshes_leave_the_gpu_and_come_back_the_same():
    with ForwardRenderer(bake_cache=None) as r:
        maps = r.bake(load_environment("studio"), "low")
        first = sphere(40, 20)
        scene = Scene(mesh=first, material=Material(base_color=(0.8, 0.2, 0.1), roughness=0.4))
        before = r.render(scene, maps, 32, 32).linear
        for i in range(MAX_UPLOADED_MESHES + 4):
            r.render(Scene(mesh=sphere(24 + i, 12)), maps, 16, 16)
            assert len(r.meshes) <= MAX_UPLOADED_MESHES
        after = r.render(scene, maps, 32, 32).linear    # uploaded again: the same pixels
        assert np.array_equal(before, after)
        assert r.ctx.error == "GL_NO_ERROR"


def test_bakes_beyond_max_bakes_leave_the_gpu_and_load_back_from_the_disk_cache(tmp_path):
    """An editor visiting environment after environment keeps the last ``max_bakes`` bakes on the
    GPU; an older one asked for again is read from the disk cache, not baked, and lights the
    same pixels."""
    from alight.ibl.bake_cache import BakeCache
    from alight.ibl.environment import constant_environment

    with ForwardRenderer(bake_cache=BakeCache(tmp_path)) as r:
        r.max_bakes = 2
        envs = [load_environment("studio")] + [constant_environment(v, 32) for v in (0.5, 2.0)]
        scene = Scene(mesh=sphere(40, 20), material=Material(base_color=(0.8, 0.2, 0.1), roughness=0.4))
        first = r.bake(envs[0], "low")
        before = r.render(scene, first, 32, 32).linear
        for env in envs[1:]:
            r.bake(env, "low")
        assert len(r._bakes) == 2 and r.bakes_run == 3
        assert type(first.irradiance.mglo).__name__ == "InvalidObject"    # released (moderngl's mark)
        again = r.bake(envs[0], "low")
        assert r.bakes_run == 3 and r.bakes_loaded == 1
        assert np.array_equal(before, r.render(scene, again, 32, 32).linear)
        assert r.ctx.error == "GL_NO_ERROR"


def test_an_older_renderer_draws_in_its_own_context_after_a_newer_one_was_made():
    """Every ForwardRenderer() makes an EGL context of its own, and making one makes it current:
    the older renderer's next bake and frame must still go to its own context, with its own
    programs (they went to the newer one's, where the same names are other programs or none:
    GL_INVALID_OPERATION in glUseProgram, and black maps, late in one test process)."""
    from alight.ibl.bake import read_cube
    from alight.ibl.environment import constant_environment

    first, env = constant_environment(2.0, 32), constant_environment(0.5, 32)
    scene = Scene(mesh=sphere(40, 20), material=Material(base_color=(0.8, 0.2, 0.1), roughness=0.4))
    with ForwardRenderer(bake_cache=None) as alone:
        alone_maps = alone.bake(env, "low")
        expected_irradiance = read_cube(alone.shaders, alone_maps.irradiance)[..., :3]
        expected = alone.render(scene, alone_maps, 32, 32).linear
    older = ForwardRenderer(bake_cache=None)
    try:
        older.render(scene, older.bake(first, "low"), 32, 32)   # its programs exist, in its context
        with ForwardRenderer(bake_cache=None) as newer:
            newer.render(Scene(view="probe"), newer.bake(first, "low"), 16, 16)
            maps = older.bake(env, "low")
            irradiance = read_cube(older.shaders, maps.irradiance)[..., :3]
            frame = older.render(scene, maps, 32, 32).linear
            assert older.ctx.error == "GL_NO_ERROR"
        assert abs(irradiance.mean() - 0.5) < 0.01      # a constant L: E/pi = L, not black
        np.testing.assert_array_equal(irradiance, expected_irradiance)
        np.testing.assert_array_equal(frame, expected)
        np.testing.assert_array_equal(older.render(scene, maps, 32, 32).linear, expected)  # and after
    finally:
        older.release()
