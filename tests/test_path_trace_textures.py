"""The path tracer's texture maps (app/accuracy/path_trace_maps.py), by equivalence: a glTF quad
with a map traces as its twin that says the same with factors, uv sets or geometry, the same
seed on both (the maps change no random draw, so the twins agree to rounding)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("embreex", reason="the path tracer needs embreex (pip install 'alight[reference]')")

from alight.accuracy.path_trace import TraceSettings, trace  # noqa: E402
from alight.accuracy.path_trace_maps import sample_texture  # noqa: E402
from alight.core.mesh import TextureTransform  # noqa: E402
from alight.core.scene import Camera, Scene, parse_light  # noqa: E402
from alight.core.shading import srgb_to_linear  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from tests.gltf_builder import USHORT, Gltf, grid_plane  # noqa: E402

SIZE = 24
# Straight on, the quad (2 x 2 at z = 0) filling the frame but for a border of background.
FRONT = Camera(position=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), ortho_half_height=1.2)
SKY = np.ones((16, 32, 3))   # a uniform environment of radiance 1


def _quad(path, material, uvs=None, uvs1=None, colors=None, normals=None, extra=None):
    """A 2 x 2 quad facing +Z (gltf_builder.grid_plane(2)); ``material(g)`` returns the glTF
    material dict (it may add images to g); ``uvs`` glTF uvs (default the grid's);
    ``extra``: (positions, normals, indices, material dict) of a second primitive."""
    g = Gltf()
    positions, nrm, grid_uvs, idx = grid_plane(2)
    attributes = {"POSITION": g.accessor(positions, bounds=True),
                  "NORMAL": g.accessor(nrm if normals is None else normals),
                  "TEXCOORD_0": g.accessor(grid_uvs if uvs is None else uvs)}
    if uvs1 is not None:
        attributes["TEXCOORD_1"] = g.accessor(uvs1)
    if colors is not None:
        attributes["COLOR_0"] = g.accessor(colors)
    prims = [{"attributes": attributes, "indices": g.accessor(idx.ravel(), USHORT),
              "material": g.material(**material(g))}]
    if extra is not None:
        p2, n2, i2, m2 = extra
        prims.append({"attributes": {"POSITION": g.accessor(p2, bounds=True), "NORMAL": g.accessor(n2)},
                      "indices": g.accessor(np.asarray(i2).ravel(), USHORT), "material": g.material(**m2)})
    g.mesh(prims)
    return g.save(path)


def _pbr(base=(1.0, 1.0, 1.0, 1.0), metallic=0.0, roughness=0.5, **more):
    return {"baseColorFactor": list(base), "metallicFactor": metallic, "roughnessFactor": roughness, **more}


def _trace(path, samples=16, camera=FRONT, radiance=SKY, lights=(), **settings):
    scene = Scene(mesh=load_mesh(str(path)), view="camera", camera=camera, lights=list(lights),
                  ibl_enabled=radiance is not None)
    result = trace(scene, radiance, SIZE, SIZE, TraceSettings(samples=samples, max_bounces=3, seed=7, **settings))
    return result.linear.astype(np.float64), result.warnings


def _rel(a, b):
    return np.abs(a[..., :3] - b[..., :3]).sum() / max(np.abs(b[..., :3]).sum(), 1e-30)


def _solid(rgba, size=4):
    return np.broadcast_to(np.asarray(rgba, np.uint8), (size, size, 4)).copy()


def test_sampling_is_bilinear_between_texel_centres_in_srgb_decoded_values():
    image = np.zeros((1, 2, 4), np.uint8)
    image[0, 1] = 255
    at = np.array([[0.25, 0.5], [0.5, 0.5], [0.75, 0.5], [0.0, 0.5]])
    got = sample_texture(image, at, srgb=True, wrap_s="clamp_to_edge")
    assert np.allclose(got[:, 0], [0.0, 0.5, 1.0, 0.0])     # centres, halfway, clamped at the edge
    assert np.allclose(sample_texture(image, at, srgb=True)[3, 0], 0.5)   # repeat: the edge blends the far texel
    half = np.full((1, 1, 4), 128, np.uint8)
    assert np.allclose(sample_texture(half, at[:1], srgb=True)[0, :3], srgb_to_linear(128 / 255))
    assert np.allclose(sample_texture(half, at[:1], srgb=False)[0], 128 / 255)   # A and linear maps as stored
    mirrored = sample_texture(image, np.array([[1.25, 0.5]]), srgb=False, wrap_s="mirrored_repeat")
    assert np.allclose(mirrored[0, 0], 1.0)   # 1.25 folds to 0.75: the right texel's centre


def test_uniform_base_colour_texture_is_its_factor(tmp_path):
    texel = (200, 90, 30, 255)
    c = [float(x) for x in srgb_to_linear(np.array(texel[:3]) / 255.0)]

    def textured(g):
        return {"pbrMetallicRoughness": _pbr(baseColorTexture={"index": g.image(_solid(texel))})}
    maps, warnings = _trace(_quad(tmp_path / "t.glb", textured))
    factors, _ = _trace(_quad(tmp_path / "f.glb", lambda g: {"pbrMetallicRoughness": _pbr(base=(*c, 1.0))}))
    assert not warnings, warnings
    assert _rel(maps, factors) < 1e-6
    white, _ = _trace(_quad(tmp_path / "w.glb", lambda g: {"pbrMetallicRoughness": _pbr()}))
    assert _rel(white, factors) > 0.2   # the texture did something


def test_vertex_colours_multiply_the_base_colour(tmp_path):
    c = (0.7, 0.3, 0.1, 1.0)
    colored, _ = _trace(_quad(tmp_path / "c.glb", lambda g: {"pbrMetallicRoughness": _pbr()},
                              colors=np.tile(c, (9, 1))))
    factors, _ = _trace(_quad(tmp_path / "f.glb", lambda g: {"pbrMetallicRoughness": _pbr(base=c)}))
    assert _rel(colored, factors) < 1e-6


def test_two_colour_texture_gives_each_half_its_colour(tmp_path):
    # Left half (u < 0.5) one colour, right half the other; away from the split (bilinear blends
    # within half a texel of it) each half traces as the quad with that colour's factor. Clamped
    # (REPEAT would blend the far edge's colour into the quad's outer half texel).
    a, b = (230, 40, 40, 255), (40, 60, 220, 255)
    image = np.empty((8, 8, 4), np.uint8)
    image[:, :4], image[:, 4:] = a, b
    clamp = {"wrapS": 33071, "wrapT": 33071}
    split, _ = _trace(_quad(tmp_path / "s.glb", lambda g: {"pbrMetallicRoughness": _pbr(
        baseColorTexture={"index": g.image(image, clamp)})}), samples=32)
    twins = [_trace(_quad(tmp_path / f"{i}.glb", lambda g, c=c: {"pbrMetallicRoughness": _pbr(
        base=(*srgb_to_linear(np.array(c[:3]) / 255.0), 1.0))}), samples=32)[0] for i, c in enumerate((a, b))]
    inside = slice(3, SIZE - 3)   # off the background border
    left, right = slice(3, SIZE // 2 - 2), slice(SIZE // 2 + 2, SIZE - 3)
    assert _rel(split[inside, left], twins[0][inside, left]) < 1e-6
    assert _rel(split[inside, right], twins[1][inside, right]) < 1e-6
    assert split[inside, left, 0].mean() > 3 * split[inside, right, 0].mean()


def test_texture_transform_reads_as_pre_transformed_uvs(tmp_path):
    # KHR_texture_transform (offset, rotation, scale) on the grid's uvs against the same texture
    # without it on uvs the transform was applied to (glTF's uv space); repeat and mirrored wraps.
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, (8, 8, 4), dtype=np.uint8)
    image[..., 3] = 255
    transform = {"offset": [0.3, -0.2], "rotation": 0.4, "scale": [1.7, 0.8]}
    _, _, uvs, _ = grid_plane(2)
    m = TextureTransform(tuple(transform["offset"]), transform["rotation"], tuple(transform["scale"])).matrix()
    moved = (np.c_[uvs, np.ones(len(uvs))] @ m.T)[:, :2]
    for wrap in (10497, 33648):
        sampler = {"wrapS": wrap, "wrapT": wrap, "magFilter": 9729}

        def with_transform(g):
            g.use("KHR_texture_transform")
            return {"pbrMetallicRoughness": _pbr(baseColorTexture={
                "index": g.image(image, sampler), "extensions": {"KHR_texture_transform": transform}})}

        def plain(g):
            return {"pbrMetallicRoughness": _pbr(baseColorTexture={"index": g.image(image, sampler)})}
        got, _ = _trace(_quad(tmp_path / f"t{wrap}.glb", with_transform))
        want, _ = _trace(_quad(tmp_path / f"p{wrap}.glb", plain, uvs=moved))
        untransformed, _ = _trace(_quad(tmp_path / f"u{wrap}.glb", plain))
        assert _rel(got, want) < 1e-4, wrap
        assert _rel(untransformed, want) > 0.05


def test_texcoord_1_is_read_where_the_texture_names_it(tmp_path):
    image = np.empty((8, 8, 4), np.uint8)
    image[:, :4], image[:, 4:] = (230, 40, 40, 255), (40, 60, 220, 255)
    _, _, uvs, _ = grid_plane(2)
    flipped = np.c_[1.0 - uvs[:, 0], uvs[:, 1]]
    got, _ = _trace(_quad(tmp_path / "uv1.glb", lambda g: {"pbrMetallicRoughness": _pbr(
        baseColorTexture={"index": g.image(image), "texCoord": 1})}, uvs=uvs, uvs1=flipped))
    want, _ = _trace(_quad(tmp_path / "uv0.glb", lambda g: {"pbrMetallicRoughness": _pbr(
        baseColorTexture={"index": g.image(image)})}, uvs=flipped))
    assert _rel(got, want) < 1e-6


def test_emissive_texture_is_its_factor(tmp_path):
    texel = (250, 120, 10, 255)
    c = srgb_to_linear(np.array(texel[:3]) / 255.0)

    def textured(g):
        g.use("KHR_materials_emissive_strength")
        return {"pbrMetallicRoughness": _pbr(base=(0.2, 0.2, 0.2, 1.0)), "emissiveFactor": [1.0, 0.5, 1.0],
                "emissiveTexture": {"index": g.image(_solid(texel))},
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}

    def factors(g):
        return {"pbrMetallicRoughness": _pbr(base=(0.2, 0.2, 0.2, 1.0)), "emissiveFactor": [1.0, 1.0, 1.0],
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1.0}}}
    got, _ = _trace(_quad(tmp_path / "e.glb", textured))
    want_emission = 4.0 * c * np.array([1.0, 0.5, 1.0])
    ref, _ = _trace(_quad(tmp_path / "f.glb", factors))
    dark, _ = _trace(_quad(tmp_path / "d.glb", lambda g: {"pbrMetallicRoughness": _pbr(base=(0.2, 0.2, 0.2, 1.0))}))
    # the emission adds to the same reflected light: the image minus the unlit twin is the emission
    inside = (slice(3, SIZE - 3), slice(3, SIZE - 3))
    emitted = got[inside][..., :3] - dark[inside][..., :3]
    assert np.allclose(emitted, want_emission, rtol=1e-5)   # (float32 images)
    assert np.allclose(ref[inside][..., :3] - dark[inside][..., :3], 1.0, rtol=1e-5)   # the factor's twin


def test_metallic_roughness_texture_is_its_factors(tmp_path):
    # G = roughness, B = metallic (linear), times the factors.
    texel = (0, 153, 102, 255)

    def textured(g):
        return {"pbrMetallicRoughness": _pbr(base=(0.9, 0.6, 0.3, 1.0), metallic=1.0, roughness=0.8,
                                             metallicRoughnessTexture={"index": g.image(_solid(texel))})}
    got, _ = _trace(_quad(tmp_path / "mr.glb", textured), samples=32)
    want, _ = _trace(_quad(tmp_path / "f.glb", lambda g: {"pbrMetallicRoughness": _pbr(
        base=(0.9, 0.6, 0.3, 1.0), metallic=102 / 255, roughness=0.8 * 153 / 255)}), samples=32)
    assert _rel(got, want) < 1e-6
    plain, _ = _trace(_quad(tmp_path / "p.glb", lambda g: {"pbrMetallicRoughness": _pbr(
        base=(0.9, 0.6, 0.3, 1.0), metallic=1.0, roughness=0.8)}), samples=32)
    assert _rel(plain, want) > 0.05


def test_normal_map_tilts_the_shading_normal_as_tilted_vertex_normals(tmp_path):
    # A constant tangent-space normal (x, 0, z) on the flat quad against the quad's own normals
    # tilted the same way (tangent +X, bitangent +Y from the grid's uvs), under one light, direct only.
    theta = np.radians(30.0)
    texel = np.round((np.array([np.sin(theta), 0.0, np.cos(theta)]) + 1.0) / 2.0 * 255.0)
    m = texel / 255.0 * 2.0 - 1.0
    tilted = m / np.linalg.norm(m)
    light = [parse_light("directional:dir=-0.5,-0.3,-1:intensity=3")]
    def mapped(g):
        return {"pbrMetallicRoughness": _pbr(roughness=0.4), "normalTexture": {"index": g.image(_solid((*texel, 255)))}}
    got, warnings = _trace(_quad(tmp_path / "n.glb", mapped), radiance=None, lights=light, samples=4, jitter=False)
    want, _ = _trace(_quad(tmp_path / "t.glb", lambda g: {"pbrMetallicRoughness": _pbr(roughness=0.4)},
                           normals=np.tile(tilted, (9, 1))), radiance=None, lights=light, samples=4, jitter=False)
    flat, _ = _trace(_quad(tmp_path / "f.glb", lambda g: {"pbrMetallicRoughness": _pbr(roughness=0.4)}),
                     radiance=None, lights=light, samples=4, jitter=False)
    assert not warnings, warnings
    assert _rel(got, want) < 1e-5
    assert _rel(flat, want) > 0.05


def _holed(g, cutoff=0.5, base=0.8):
    image = np.full((8, 8, 4), 255, np.uint8)
    image[:, :4, 3] = 0   # the left half transparent
    return {"pbrMetallicRoughness": _pbr(base=(base, base, base, 1.0), baseColorTexture={"index": g.image(image)}),
            "alphaMode": "MASK", "alphaCutoff": cutoff}


def test_alpha_mask_lets_camera_rays_through(tmp_path):
    img, warnings = _trace(_quad(tmp_path / "m.glb", _holed))
    assert not warnings, warnings
    rows = slice(3, SIZE - 3)
    assert np.all(img[rows, 3:SIZE // 2 - 2, 3] == 0.0)           # the hole: nothing covered
    assert np.allclose(img[rows, 3:SIZE // 2 - 2, :3], 1.0)        # the environment behind it
    assert np.all(img[rows, SIZE // 2 + 2:SIZE - 3, 3] == 1.0)
    opaque, _ = _trace(_quad(tmp_path / "o.glb", lambda g: _holed(g, cutoff=0.0)))
    assert np.all(opaque[rows, 3:SIZE // 2 - 2, 3] == 1.0)        # cutoff 0 keeps every texel


def test_alpha_mask_lets_light_and_bounces_through(tmp_path):
    # The holed quad at z = 0 over a floor at z = -1 (4 x 4, facing +Z), a light straight down
    # the -Z axis, seen straight on: through the hole the floor is lit as beside the quad; under
    # the quad's opaque half it is darker under a uniform sky.
    floor = (np.array([[-2.0, -2.0, -1.0], [2.0, -2.0, -1.0], [2.0, 2.0, -1.0], [-2.0, 2.0, -1.0]]),
             np.tile([0.0, 0.0, 1.0], (4, 1)), [[0, 1, 2], [0, 2, 3]], {"pbrMetallicRoughness": _pbr(roughness=0.7)})
    light = [parse_light("directional:dir=0,0,-1:intensity=2")]
    wide = Camera(position=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), ortho_half_height=1.8)
    img, _ = _trace(_quad(tmp_path / "m.glb", _holed, extra=floor), radiance=None, lights=light, camera=wide,
                    samples=1, jitter=False)
    # columns 6-9 (x -0.875 .. -0.275 at half height 1.8) see the floor through the hole, columns
    # 1-2 (x < -1.4) the floor beside the quad
    hole, beside = img[8:16, 6:10, :3], img[8:16, 1:3, :3]
    assert beside.min() > 0.1
    assert np.allclose(hole, beside[0, 0], rtol=1e-6)
    # Under a uniform sky, seen from between a dark quad and the floor: the floor under the hole
    # (environment samples and bounces pass it) is brighter than under the quad without its hole,
    # and than under the opaque half (which sees the hole at a slant only).
    below = Camera(position=(0.0, 0.0, -0.5), target=(0.0, 0.0, -1.0), ortho_half_height=0.9)
    holed, _ = _trace(_quad(tmp_path / "d.glb", lambda g: _holed(g, base=0.02), extra=floor), camera=below, samples=64)
    whole, _ = _trace(_quad(tmp_path / "w.glb", lambda g: _holed(g, cutoff=0.0, base=0.02), extra=floor), camera=below,
                      samples=64)
    under_hole, under_quad = (slice(8, 16), slice(2, 8)), (slice(8, 16), slice(16, 22))
    assert holed[under_hole][..., :3].mean() > 1.3 * whole[under_hole][..., :3].mean()
    assert holed[under_hole][..., :3].mean() > 1.1 * holed[under_quad][..., :3].mean()


def test_warnings_name_only_the_maps_left_out(tmp_path):
    # The occlusion texture is baked visibility, which the paths find themselves: left out without
    # a word, and without darkening; a transmission texture is named (its factor applies).
    def occluded(g):
        return {"pbrMetallicRoughness": _pbr(), "occlusionTexture": {"index": g.image(_solid((0, 0, 0, 255)))}}
    got, warnings = _trace(_quad(tmp_path / "o.glb", occluded))
    plain, _ = _trace(_quad(tmp_path / "p.glb", lambda g: {"pbrMetallicRoughness": _pbr()}))
    assert not warnings, warnings
    assert np.array_equal(got, plain)

    def transmissive(g):
        g.use("KHR_materials_transmission")
        return {"pbrMetallicRoughness": _pbr(), "extensions": {"KHR_materials_transmission": {
            "transmissionFactor": 0.5, "transmissionTexture": {"index": g.image(_solid((255, 255, 255, 255)))}}}}
    _, warnings = _trace(_quad(tmp_path / "t.glb", transmissive))
    assert len(warnings) == 1 and warnings[0].endswith("the path tracer leaves out these texture maps (their factors "
                                                       "apply): transmission"), warnings
