"""Vertex attributes as the GPU keeps them (alight.render.gpu_mesh): int16 snorm normals and
tangents, half-float uvs only where they hold, tangents made and uploaded only when a program
reads them, and no mesh-sized array kept on the CPU by the uploaded part.

The packed path must draw what the float32 path draws: on the models below the measured
difference was relMAE 1.5e-5 to 7.4e-5 and at most 0.3% of the pixels off by more than 1e-3
(docs/performance-assets.md), so the bounds here are a few times that."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import Mesh, MeshPart, compute_tangents, sphere
from alight.core.scene import Scene
from alight.core.texture_maps import TextureMaps
from alight.exchange.images import load_map_image
from alight.exchange.meshes import load_mesh
from alight.ibl.environment import load_environment
from alight.render import gpu_mesh
from alight.render.renderer import ForwardRenderer

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
MIRROR = DATA / "models" / "khronos" / "NormalTangentMirrorTest" / "glTF-Binary" / "NormalTangentMirrorTest.glb"
DUCK = DATA / "models" / "Duck.glb"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"

REL_MAE = 3e-4          # relative mean absolute error of the linear image
OFF_PIXELS = 0.01       # the fraction of pixels whose largest channel differs by more than 1e-3


@pytest.fixture(scope="module")
def renderer():
    with ForwardRenderer(bake_cache=None) as r:
        yield r, r.bake(load_environment(str(ENV)), "low")


def _render(r, maps, scene, packed: bool, size: int = 160) -> np.ndarray:
    saved = gpu_mesh.PACK_VERTICES
    gpu_mesh.PACK_VERTICES = packed
    try:
        r.meshes.release_meshes()
        return r.render(scene, maps, size, size).linear[..., :3].astype(np.float64)
    finally:
        gpu_mesh.PACK_VERTICES = saved
        r.meshes.release_meshes()


def _difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    d = np.abs(a - b)
    return float(d.sum() / a.sum()), float((d.max(axis=2) > 1e-3).mean())


@pytest.mark.parametrize("name, scene", [
    ("helmet", lambda: Scene(mesh=load_mesh(str(HELMET)))),
    ("normal-map mirror test", lambda: Scene(mesh=load_mesh(str(MIRROR)))),
    ("smooth gold shader ball", lambda: Scene(mesh=load_mesh("shader_ball"), use_file_materials=False,
                                            material=Material(base_color=(1.0, 0.78, 0.34), metallic=1.0,
                                                              roughness=0.1))),
    ("duck", lambda: Scene(mesh=load_mesh(str(DUCK)))),
])
def test_packed_attributes_render_as_the_float32_ones(renderer, name, scene):
    r, maps = renderer
    s = scene()
    float32, packed = _render(r, maps, s, False), _render(r, maps, s, True)
    assert float32.sum() > 0.0
    rel, off = _difference(float32, packed)
    assert rel <= REL_MAE and off <= OFF_PIXELS, (name, rel, off)


def test_snorm16_round_trip():
    rng = np.random.default_rng(3)
    v = rng.uniform(-1.0, 1.0, (10000, 4))
    v[:4] = [[-1.0, 0.0, 1.0, -1.0], [1.0, -1.0, 0.0, 1.0], [0.5, -0.5, 1e-9, -1e-9], [2.0, -2.0, 0.0, 0.0]]
    back = gpu_mesh.unpack_snorm16(gpu_mesh.pack_snorm16(v))
    assert np.abs(back - np.clip(v, -1.0, 1.0)).max() <= 0.5 / 32767.0 + 1e-7
    assert np.array_equal(back[0], np.float32([-1.0, 0.0, 1.0, -1.0]))   # the ends and 0 exactly (w = +-1)


def test_half_uvs_only_where_they_hold():
    ok = np.array([[0.0, 0.0], [0.25, 0.5], [1.0, 1.0]], np.float32)
    fine = np.linspace(0.0, 1.0, 1001, dtype=np.float32)[:, None].repeat(2, axis=1)
    assert gpu_mesh.uvs_hold_as_half(ok, 4096)            # exact in half floats
    assert not gpu_mesh.uvs_hold_as_half(ok, 0)           # no texture: float32 kept
    assert not gpu_mesh.uvs_hold_as_half(fine, 1024)      # up to 2^-12 off: a quarter of a texel
    assert gpu_mesh.uvs_hold_as_half(fine, 256)           # 1/16 of a texel
    assert not gpu_mesh.uvs_hold_as_half(np.float32([[1e5, 0.0]]), 16)   # outside half's range


def test_the_uploaded_part_keeps_no_mesh_sized_array_and_no_tangents_it_does_not_draw(renderer):
    """A part without a normal map: 28 bytes a vertex on the GPU (24 with half-float uvs), its
    tangents never made; the
    GpuPart's own arrays are a few numbers (the MeshPart it points to is the caller's)."""
    r, maps = renderer
    mesh = load_mesh(str(DUCK))
    part = mesh.parts[0]
    assert part.material.normal_texture is None and not part.has_tangents
    r.render(Scene(mesh=mesh), maps, 64, 64)
    gpu = r.meshes.parts(mesh)[0]
    assert gpu.packed and not part.has_tangents and gpu.tangent_buffer is None
    assert gpu.vertex_bytes == (24 if gpu.half_uvs else 28)
    assert gpu.vbo.size == gpu.vertex_bytes * len(part.positions)
    assert gpu.ibo.size == 12 * len(part.indices)
    for name, value in vars(gpu).items():
        if name != "_part" and isinstance(value, np.ndarray):
            assert value.size <= 16, name
    r.meshes.release_meshes()


def test_a_normal_map_makes_and_uploads_the_tangents_once_and_renders_as_given_ones(renderer, tmp_path):
    """A user's normal map on a mesh loaded without tangents: drawn with the tangents made on
    first use, the same pixels as the same part given compute_tangents' tangents up front."""
    from PIL import Image

    r, maps = renderer
    rng = np.random.default_rng(5)
    bumps = np.clip(128 + rng.normal(0, 40, (64, 64, 3)), 0, 255).astype(np.uint8)
    bumps[..., 2] = 255
    path = tmp_path / "bumps_normal.png"
    Image.fromarray(bumps).save(path)
    base = load_mesh("sphere").parts[0]
    lazy = MeshPart("lazy", base.positions, base.normals, base.uvs, None, base.indices, None)
    given = MeshPart("given", base.positions, base.normals, base.uvs,
                     compute_tangents(base.positions, base.normals, base.uvs, base.indices), base.indices, None)
    images = []
    texture_maps = TextureMaps().with_slot("normal", str(path))
    texture_images = {str(path): load_map_image(str(path))}
    for part in (lazy, given):
        mesh = Mesh([part], "test")
        scene = Scene(mesh=mesh, use_file_materials=False, texture_maps=texture_maps, texture_images=texture_images)
        images.append(r.render(scene, maps, 96, 96).linear)
        gpu = r.meshes.parts(mesh)[0]
        assert gpu.tangent_buffer is not None and gpu.tangent_buffer.size == 8 * len(part.positions)
    assert lazy.has_tangents
    assert np.array_equal(images[0], images[1])
    r.meshes.release_meshes()


def test_self_occludes_samples_a_big_mesh_without_per_face_arrays():
    """The occlusion test's sample of 2000 faces is drawn before any per-face array: a 1M-face
    mesh's peak stays far below its (T, 3, 3) float64 corners (72 MiB)."""
    from alight.core.visibility import self_occludes

    mesh = sphere(1400, 700)
    assert len(mesh.parts[0].indices) > 1_000_000
    tracemalloc.start()
    try:
        verdict = self_occludes(mesh.parts)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert verdict is False                 # convex
    assert peak < 40 * 2**20, peak / 2**20
