"""Meshes shaded from the visibility buffer (ForwardRenderer.mesh_shading = "vbuffer",
alight.render.vbuffer) against the forward pass, 4x MSAA: the same pictures within a stated
tolerance (relMAE of the linear radiance), the same coverage, and the scenes it leaves to the
forward pass."""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest
from tests.gltf_builder import USHORT, Gltf, checker, grid_plane

from alight.core.scene import Camera, Display, Light, Scene
from alight.exchange.meshes import load_mesh

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
HELMET = SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
NORMAL_TANGENT = SHARED / "models" / "khronos" / "NormalTangentTest" / "glTF-Binary" / "NormalTangentTest.glb"
CAMERA = Camera(position=(0.3, 0.4, 4.0), target=(0.0, 0.0, 0.0), fov_y_deg=35.0, near=0.1, far=20.0)
LIGHTS = [Light(kind="directional", vector=(-0.4, -0.5, -1.0), intensity=2.0)]
# Every pixel is shaded at the same point as the forward pass, and each 2x2 block evaluates one
# triangle at all four pixels as the rasteriser's block does (render/vbuffer_shade.frag), so the
# maps' implicit derivatives, and with them their mip levels, are the forward pass's: what is
# left is float rounding (the barycentrics from the view ray, not the rasteriser's planes).
# Measured (llvmpipe, Mesa 22.3): the helmet 6.8e-6 at 256x256 (7.2e-6 with occlusion 'auto' at
# 192), NormalTangentTest 5.7e-6 at 192, the masked planes 3.5e-6, the checker grids 5.4e-6 (4x4
# cells) and 5.0e-6 (40x40) at 160. Before the quad-coherent shading (textureGrad on derivatives
# one pixel over) these were 1.3e-4, 3.8e-3, -, 2.0e-3 and 5.8e-3.
REL_LIMIT = 2e-5
REL_LIMIT_GRID = 1e-4


@functools.lru_cache(maxsize=1)
def _maps():
    from tests.gpu import renderer

    from alight.ibl.environment import load_environment

    return renderer().bake(load_environment("studio"), "low")


def both(scene: Scene, size: int = 128, **kwargs):
    """(forward, vbuffer) frames of ``scene``, and whether the second used the visibility buffer."""
    from tests.gpu import renderer

    r = renderer()
    frames = []
    try:
        for mode in ("forward", "vbuffer"):
            r.mesh_shading = mode
            frames.append(r.render(scene, _maps(), size, size, aa="msaa", **kwargs))
        used = r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)
    return frames[0], frames[1], used


def rel_mae(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a[..., :3] - b[..., :3]).sum() / np.abs(a[..., :3]).sum())


def assert_same(forward, vbuffer, used: bool, limit: float = REL_LIMIT) -> float:
    assert used, "the scene was expected to take the visibility buffer"
    covered = forward.linear[..., 3] > 0
    assert covered.sum() > 500, "the mesh must cover part of the image"
    # Coverage comes from the same rasteriser: equal sample for sample.
    np.testing.assert_array_equal(forward.linear[..., 3], vbuffer.linear[..., 3])
    rel = rel_mae(forward.linear, vbuffer.linear)
    assert rel < limit, rel
    return rel


def test_textured_normal_mapped_helmet():
    """DamagedHelmet: base colour, metal-roughness, normal, emissive and occlusion maps."""
    scene = Scene(mesh=load_mesh(str(HELMET)))
    assert_same(*both(scene, 256))


def test_normal_tangent_model():
    """Khronos NormalTangentTest: normal maps on the file's tangents, both handednesses."""
    scene = Scene(mesh=load_mesh(str(NORMAL_TANGENT)), lights=list(LIGHTS))
    assert_same(*both(scene, 192))


def _masked_plane(path: Path) -> Path:
    """A tilted plane whose base colour texture's alpha is a checker of 0.16 and 1 (alphaMode
    MASK, cutoff 0.5), in front of a second, opaque plane of another material (two parts)."""
    tex = np.zeros((64, 64, 4), np.uint8)
    tex[..., :3] = checker(8, 64)
    tex[..., 3] = np.where(checker(4, 64, colours=((40, 40, 40), (255, 255, 255)))[..., 0] > 100, 255, 40)
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(6)
    t = g.image(tex)
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t}, "metallicFactor": 0.0,
                                           "roughnessFactor": 0.4}, alphaMode="MASK", doubleSided=True)
    back = g.material(pbrMetallicRoughness={"baseColorFactor": [0.2, 0.5, 0.9, 1.0], "metallicFactor": 1.0,
                                            "roughnessFactor": 0.3})
    tilted = positions @ np.array([[1.0, 0.0, 0.0], [0.0, 0.8, 0.6], [0.0, -0.6, 0.8]]).T
    g.mesh([{"attributes": {"POSITION": g.accessor(tilted, bounds=True), "NORMAL": g.accessor(normals @ np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.8, 0.6], [0.0, -0.6, 0.8]]).T), "TEXCOORD_0": g.accessor(uvs)},
        "indices": g.accessor(idx.ravel(), USHORT), "material": mat},
        {"attributes": {"POSITION": g.accessor(positions * 1.3 - [0.0, 0.0, 0.8], bounds=True),
                        "NORMAL": g.accessor(normals), "TEXCOORD_0": g.accessor(uvs)},
         "indices": g.accessor(idx.ravel(), USHORT), "material": back}])
    return g.save(path / "masked.glb")


def test_alpha_mask_and_two_parts(tmp_path):
    """MASK parts are tested in the visibility pass as the forward pass tests them; the part
    behind shows through their holes, and both parts' shares of an edge pixel add up."""
    scene = Scene(mesh=load_mesh(str(_masked_plane(tmp_path))), camera=CAMERA, lights=list(LIGHTS),
                  display=Display(background="transparent"))
    forward, vbuffer, used = both(scene, 160)
    assert_same(forward, vbuffer, used)
    alpha = forward.linear[..., 3]
    assert ((alpha > 0) & (alpha < 1)).sum() > 20   # edge pixels, where the two parts share samples


def test_tiles_match_one_framebuffer():
    """A tiled image (each tile's off-centre projection) equals the untiled one."""
    from tests.gpu import renderer

    scene = Scene(mesh=load_mesh(str(HELMET)))
    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        whole = r.render(scene, _maps(), 160, 160, aa="msaa").linear
        tiled = r.render(scene, _maps(), 160, 160, aa="msaa", tile=(64, 64)).linear
        assert r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)
    np.testing.assert_allclose(tiled, whole, atol=2e-3)


@pytest.mark.parametrize("kind", ["blend", "sphere", "ssaa"])
def test_forward_where_not_eligible(tmp_path, kind):
    """Blended parts, the built-in sphere (its impostor) and SSAA keep the forward pass."""
    from tests.gpu import renderer

    if kind == "blend":
        g = Gltf()
        positions, normals, uvs, idx = grid_plane(2)
        mat = g.material(pbrMetallicRoughness={"baseColorFactor": [1.0, 1.0, 1.0, 0.5]}, alphaMode="BLEND")
        g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals)},
                 "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
        scene = Scene(mesh=load_mesh(str(g.save(tmp_path / "b.glb"))), camera=CAMERA)
    else:
        scene = Scene() if kind == "sphere" else Scene(mesh=load_mesh(str(HELMET)))
    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        r.render(scene, _maps(), 64, 64, aa="ssaa" if kind == "ssaa" else "msaa")
        assert not r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)


def _checker_grid(path: Path, cells: int) -> Path:
    """A grid plane of cells x cells quads (two triangles each) with a 256x256 checker texture
    repeated 6 times across it, tilted away from the camera: every 2x2 block on a triangle edge
    straddles two triangles, and the minified checker's mip level shows any wrong derivative."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(cells, size=3.0)
    t = g.image(np.concatenate([checker(32, 256), np.full((256, 256, 1), 255, np.uint8)], axis=2))
    mat = g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t}, "metallicFactor": 0.0,
                                           "roughnessFactor": 0.5}, doubleSided=True)
    turn = np.array([[1.0, 0.0, 0.0], [0.0, 0.35, -0.94], [0.0, 0.94, 0.35]])
    turn = turn @ np.array([[0.94, 0.0, 0.34], [0.0, 1.0, 0.0], [-0.34, 0.0, 0.94]])
    g.mesh([{"attributes": {"POSITION": g.accessor(positions @ turn.T, bounds=True),
                            "NORMAL": g.accessor(normals @ turn.T), "TEXCOORD_0": g.accessor(uvs * 6.0)},
             "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g.save(path / f"grid{cells}.glb")


@pytest.mark.parametrize("cells", [4, 40])
def test_tilted_checker_grid(tmp_path, cells):
    """Triangle edges across a minified, tilted checker: each block's mip level is the forward
    pass's, where its pixels lie on two triangles too."""
    scene = Scene(mesh=load_mesh(str(_checker_grid(tmp_path, cells))), camera=CAMERA, lights=list(LIGHTS))
    assert_same(*both(scene, 160), limit=REL_LIMIT_GRID)


def test_odd_size_keeps_forward():
    """An odd width or height keeps the forward pass: the shading pass's 2x2 blocks could not all
    lie inside the image, as the forward pass's do (alight.render.vbuffer.wanted)."""
    from tests.gpu import renderer

    scene = Scene(mesh=load_mesh(str(HELMET)))
    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        for width, height in ((65, 64), (64, 65), (65, 65)):
            r.render(scene, _maps(), width, height, aa="msaa")
            assert not r.last_vbuffer, (width, height)
        r.render(scene, _maps(), 64, 64, aa="msaa")
        assert r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)


def test_per_vertex_occlusion():
    """The visibility bake's per-vertex occlusion (Scene.occlusion 'auto': the helmet is baked)
    is read in the shading pass as the forward pass reads it; the scene takes the visibility buffer."""
    scene = Scene(mesh=load_mesh(str(HELMET)), occlusion="auto")
    forward, vbuffer, used = both(scene, 192)
    assert_same(forward, vbuffer, used)
    # (and the occlusion is there: the picture differs from the helmet's without it well beyond that)
    plain = both(Scene(mesh=load_mesh(str(HELMET))), 192)[0]
    assert rel_mae(forward.linear, plain.linear) > 1e-3


def test_tangents_only_where_read(tmp_path):
    """A part whose material reads no tangent frame (no normal map, no anisotropy) is shaded
    without its tangents ever being made (common/mesh_material.glsl READS_TANGENT); the helmet's
    normal-mapped part has them."""
    from tests.gpu import renderer

    r = renderer()
    grid = load_mesh(str(_checker_grid(tmp_path, 4)))
    helmet = load_mesh(str(HELMET))
    r.mesh_shading = "vbuffer"
    try:
        for mesh in (grid, helmet):
            r.render(Scene(mesh=mesh, camera=CAMERA), _maps(), 64, 64, aa="msaa")
            assert r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)
    assert all(g.tangent_buffer is None for g in r.meshes.parts(grid))
    assert all(g.tangent_buffer is not None for g in r.meshes.parts(helmet))


def test_scissor_rectangle_has_even_corners():
    """The shading pass's rectangle is made of whole 2x2 blocks, inside the image."""
    from alight.render.vbuffer import box_rect

    vp = np.eye(4)
    for lo, hi in (((-0.31, -0.52, 0.0), (0.47, 0.13, 0.0)), ((-2.0, -2.0, 0.0), (0.011, 2.0, 0.0))):
        x, y, w, h = box_rect(np.array(lo), np.array(hi), vp, (64, 48))
        assert x % 2 == 0 and y % 2 == 0 and w % 2 == 0 and h % 2 == 0, (x, y, w, h)
        assert 0 <= x and 0 <= y and x + w <= 64 and y + h <= 48


# --- mesh_shading "auto" (the default): the visibility buffer only on a dense mesh ----------

def _auto(scene: Scene, size: int):
    """The "auto" frame of ``scene`` and whether it took the visibility buffer."""
    from tests.gpu import renderer

    r = renderer()
    r.mesh_shading = "auto"
    frame = r.render(scene, _maps(), size, size, aa="msaa")
    return frame, r.last_vbuffer


def _estimate(scene: Scene, size: int) -> float:
    from tests.gpu import renderer

    from alight.render.vbuffer import pixels_per_triangle

    r = renderer()
    return pixels_per_triangle(r, scene, r.camera_for(scene, 1.0).view_projection(1.0), (size, size))


def test_auto_takes_the_visibility_buffer_on_a_dense_mesh_only(tmp_path):
    """A grid of 28,800 triangles over a few thousand pixels takes the visibility buffer, with
    the forward pass's picture; a grid of 32 triangles in the same place keeps the forward pass."""
    from alight.render.vbuffer import auto_threshold
    from tests.gpu import renderer

    dense = Scene(mesh=load_mesh(str(_checker_grid(tmp_path, 120))), camera=CAMERA, lights=list(LIGHTS))
    sparse = Scene(mesh=load_mesh(str(_checker_grid(tmp_path, 4))), camera=CAMERA, lights=list(LIGHTS))
    threshold = auto_threshold(renderer(), sparse, _maps())[0]
    assert _estimate(dense, 160) < threshold < _estimate(sparse, 160)
    frame, used = _auto(dense, 160)
    forward = both(dense, 160)[0]
    assert_same(forward, frame, used, limit=REL_LIMIT_GRID)
    frame, used = _auto(sparse, 160)
    assert not used
    np.testing.assert_array_equal(frame.linear, both(sparse, 160)[0].linear)


def test_auto_follows_the_pixels_cost_on_the_helmet():
    """DamagedHelmet at 512 pixels (about 9.6 estimated pixels per triangle): with its own five
    maps the pixel is heavy enough for the visibility buffer to pay (auto_threshold's textured
    factor; measured 0.82x the forward frame), in the grey panel material it is not (the
    untextured threshold, 3); at 1024 (about 38) both keep the forward pass."""
    from alight.core.material import Material

    textured = Scene(mesh=load_mesh(str(HELMET)))
    assert _auto(textured, 512)[1]
    grey = Scene(mesh=load_mesh(str(HELMET)), use_file_materials=False, material=Material())
    assert not _auto(grey, 512)[1]
    assert not _auto(textured, 1024)[1]


def test_auto_counts_a_suns_soft_shadows():
    """A sun's shadow (PCSS) doubles the threshold: the helmet's density at 768 pixels (about 21.6)
    is above the textured threshold (12) and below it with the sun's shadows (24)."""
    from alight.render.vbuffer import auto_threshold, pixels_per_triangle
    from tests.gpu import renderer

    from alight.ibl.environment import load_environment

    r = renderer()
    quarry = r.bake(load_environment(str(SHARED / "env" / "quarry_01_1k.hdr")), "low")
    assert quarry.suns, "quarry_01 has a sun"
    scene = Scene(mesh=load_mesh(str(HELMET)))
    r.render(scene, quarry, 64, 64)      # the parts uploaded, as a frame has them
    density = pixels_per_triangle(r, scene, r.camera_for(scene, 1.0).view_projection(1.0), (768, 768))
    plain, _ = auto_threshold(r, scene, None)
    with_sun, why = auto_threshold(r, scene, quarry)
    assert plain < density < with_sun and "soft shadows" in why
    no_shadows, _ = auto_threshold(r, dataclasses.replace(scene, shadows="off"), quarry)
    assert no_shadows == plain


def test_auto_keeps_the_builtin_sphere_forward():
    assert not _auto(Scene(), 128)[1]


def test_estimate_bounds_the_covered_pixels(tmp_path):
    """pixels_per_triangle's projected boxes hold every pixel the mesh covers (an upper bound,
    so that "auto" errs toward the forward pass): on the helmet within 3x (2.2x at the sizes of
    benchmarks/results/vbuffer.md); the tilted grid reaches past the image, whose pixels the
    estimate counts and the frame cannot."""
    for mesh, camera, most in ((load_mesh(str(HELMET)), None, 3.0),
                               (load_mesh(str(_checker_grid(tmp_path, 40))), CAMERA, None)):
        scene = Scene(mesh=mesh, camera=camera)
        frame = both(scene, 192)[0]
        covered = float((frame.linear[..., 3] > 0).sum())
        estimate = _estimate(scene, 192) * sum(len(part.indices) for part in mesh.parts)
        assert covered <= estimate, (covered, estimate)
        assert most is None or estimate < most * covered, (covered, estimate)


def _grid_file(path: Path, cells: int) -> Path:
    """A plain grid plane of cells x cells quads facing the default camera (+Z)."""
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(cells)
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.5, 0.2, 1.0], "roughnessFactor": 0.5})
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals)},
             "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g.save(path / f"plain{cells}.glb")


def test_cli_mesh_shading_flag(tmp_path):
    """``alight render --mesh-shading`` (default auto) through the command line: --verbose says
    which shading ran; auto takes the visibility buffer on the dense grid, not on the sparse one,
    and its picture is the forward one's."""
    import os
    import subprocess
    import sys

    import OpenImageIO as oiio

    def render(mesh: Path, *flags) -> tuple[str, np.ndarray]:
        out = tmp_path / f"{mesh.stem}_{'_'.join(flags) or 'default'}.exr"
        proc = subprocess.run([sys.executable, "-m", "alight", "render", "--size", "64", "--quality", "low",
                               "--mesh", str(mesh), "--verbose", *flags, "--out", str(out)],
                              capture_output=True, text=True, env=dict(os.environ), timeout=300)
        assert proc.returncode == 0, proc.stderr
        line = next(x for x in proc.stderr.splitlines() if x.startswith("mesh shading:"))
        return line, np.asarray(oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT))

    dense, sparse = _grid_file(tmp_path, 80), _grid_file(tmp_path, 2)
    line, auto = render(dense)
    assert line.startswith("mesh shading: vbuffer (--mesh-shading auto: the mesh is dense on screen")
    line, forward = render(dense, "--mesh-shading", "forward")
    assert line == "mesh shading: forward (--mesh-shading forward: asked for)"
    assert rel_mae(forward, auto) < REL_LIMIT_GRID
    assert render(sparse)[0].startswith("mesh shading: forward (--mesh-shading auto: the mesh is not dense")
    assert render(sparse, "--mesh-shading", "vbuffer")[0] == "mesh shading: vbuffer (--mesh-shading vbuffer: asked for)"


def test_api_and_batch_check_the_mode(tmp_path):
    from alight.errors import AlightError
    from alight.frontends.api import Renderer
    from alight.frontends.batch import plan

    assert Renderer(32).mesh_shading == "auto"
    assert Renderer(32, mesh_shading="forward").mesh_shading == "forward"
    with pytest.raises(AlightError, match="mesh_shading"):
        Renderer(32, mesh_shading="deferred")
    spec = tmp_path / "spec.toml"
    spec.write_text('size = 32\nmeshes = ["sphere"]\nmesh_shading = "vbuffer"\n')
    assert {item.mesh_shading for item in plan(spec).stills} == {"vbuffer"}
    spec.write_text('size = 32\nmeshes = ["sphere"]\nmesh_shading = "deferred"\n')
    with pytest.raises(AlightError, match="mesh_shading"):
        plan(spec)


def _warnings(stderr: str) -> list[str]:
    return [x for x in stderr.splitlines() if x.startswith("alight: warning:")]


def _cli(tmp_path, mesh, *flags, size="64"):
    import os
    import subprocess
    import sys

    out = tmp_path / f"w_{len(list(tmp_path.iterdir()))}.png"
    proc = subprocess.run([sys.executable, "-m", "alight", "render", "--size", size, "--quality", "low",
                           *(["--mesh", str(mesh)] if mesh else []), *flags, "--out", str(out)],
                          capture_output=True, text=True, env=dict(os.environ), timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc.stderr


def _blended_file(path: Path) -> Path:
    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2)
    mat = g.material(pbrMetallicRoughness={"baseColorFactor": [1.0, 1.0, 1.0, 0.5]}, alphaMode="BLEND")
    g.mesh([{"attributes": {"POSITION": g.accessor(positions, bounds=True), "NORMAL": g.accessor(normals)},
             "indices": g.accessor(idx.ravel(), USHORT), "material": mat}])
    return g.save(path / "blended.glb")


# (--view probe with --mesh-shading is refused, not warned: test_cli's "probe-mesh-shading")
@pytest.mark.parametrize("case", ["blend", "odd", "ground", "aa", "sphere"])
def test_cli_says_why_vbuffer_was_not_used(tmp_path, case):
    """``alight render --mesh-shading vbuffer`` where the visibility buffer cannot draw the pass:
    one warning line naming the reason (vbuffer.ineligible_reason), not a silent forward pass;
    the same scene under auto says nothing."""
    mesh, flags, size, reason = {
        "blend": (_blended_file(tmp_path), [], "64", "the scene has blended parts"),
        "odd": (_grid_file(tmp_path, 8), [], "65x64", "the size 65x64 is odd"),
        # (a light, so that the ground has a shadow to catch: without one it says so in a line of its own)
        "ground": (_grid_file(tmp_path, 8), ["--ground", "--light", "directional:dir=-0.5,-1,-0.3"], "64",
                   "the scene has a ground"),
        "aa": (_grid_file(tmp_path, 8), ["--aa", "ssaa"], "64", "needs 4x msaa, not anti-aliasing ssaa"),
        "sphere": (None, [], "64", "the built-in sphere"),
    }[case]
    lines = _warnings(_cli(tmp_path, mesh, *flags, "--mesh-shading", "vbuffer", size=size))
    assert len(lines) == 1, lines
    assert lines[0].startswith("alight: warning: --mesh-shading vbuffer: drawn with the forward pass (")
    assert reason in lines[0], lines[0]
    assert not [x for x in _warnings(_cli(tmp_path, mesh, *flags, size=size)) if "mesh-shading" in x]


def test_cli_vbuffer_used_says_nothing(tmp_path):
    assert not _warnings(_cli(tmp_path, _grid_file(tmp_path, 8), "--mesh-shading", "vbuffer"))


def test_one_warning_per_render_not_per_tile():
    """Tiles of an odd width (an even image cut in two): the forward pass in each tile, one
    warning for the render, naming the tile."""
    from tests.gpu import renderer
    from tests.warned import alight_warnings

    r = renderer()
    r.mesh_shading = "vbuffer"
    try:
        with alight_warnings() as lines:
            r.render(Scene(mesh=load_mesh(str(HELMET))), _maps(), 66, 64, aa="msaa", tile=(33, 64))
        assert not r.last_vbuffer
    finally:
        r.mesh_shading = "auto"   # (the renderer's default)
    assert len(lines) == 1, lines
    assert "2 of its 2 tiles" not in lines[0] and "the tile 33x64 of the 66x64 image is odd" in lines[0], lines[0]
