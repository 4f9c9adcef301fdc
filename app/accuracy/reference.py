"""``alight reference``: docs/conventions.md's ground truth computed on the GPU, per pixel.

    L_o(n, v) = emissive + sum over the environment's texels of f(l, v) L(l) max(n.l, 0) dOmega
                + the punctual lights (punctual.glsl's punctual_light, k = (r+1)^2/8)

f is exactly docs/conventions.md's BRDF with k = r^2/2 and F per direction at v.h
(``shaders/accuracy/ground_truth.glsl``: ``brdf_ground_truth``, ``ground_truth_rows``). There
is no occlusion and nothing is sampled: it is the numpy ground truth of ``app/accuracy/ground_truth.py``,
evaluated in float32 on the GPU (each environment row is summed on its own, then added to the
total).

    probe view: a G-buffer filled in numpy (docs/conventions.md's exact per-pixel normals, v = +Z)
    mesh view:  render/pbr.vert + render/gbuffer.frag -> float G-buffer (position, n, v,
                base colour, metallic, roughness, specular F0, emissive; the mesh's texture maps
                apply, as in the forward pass)
    then accuracy/reference.comp, one dispatch per chunk of environment rows (each dispatch
    does at most ``CHUNK_PAIRS`` pixel-texel pairs, so no single dispatch runs long enough for
    a GPU watchdog), accumulating into an rgba32f image.

Environment level: level L sums over the map box-reduced by 2^L in both axes (area-weighted,
``alight.core.equirect.box_reduce``, on the CPU, uploaded as its own texture): 4^L times fewer
texels. The change level 1 makes against level 0, measured with this module on 32x32 probes
(relative error over the disk / worst pixel):
    royal_esplanade_1k (a 6% sun): r = 0.25: dielectric 1.7e-5 / 2.3e-4, gold 1.5e-4 / 1.0e-3;
        r >= 0.5: <= 2e-5 / 1.4e-4; r = 0.1: 2.4e-3 / 0.10 (dielectric), 5.5e-3 / 0.48 (gold)
    quarry_01_1k (a sun with 48% of the power in a few texels): r = 0.25: 4e-3 / 3e-2 (dielectric),
        9e-3 / 4e-2 (gold); r = 1: 9e-4 / 1.8e-2, 1.1e-3 / 2.3e-2
A compact source moves and spreads when its texels are averaged, so ``choose_env_level`` takes
level 1 only when every roughness is >= 0.25, the map is at least 1024 wide and no compact source
(``alight.ibl.sun.extract_suns``) holds 10% or more of the map's power; otherwise level 0 (exact).

Roughness below ``MIN_ROUGHNESS`` (0.1) is refused when an environment lights the scene: the
GGX lobe then covers only a few texels and the sum is no longer an integral (see
app/accuracy/ground_truth.py). Roughness from a mesh's texture maps cannot be checked up front; pixels
whose textured roughness falls below 0.1 are summed anyway and are not to be trusted.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import moderngl
import numpy as np

from alight.accuracy.ground_truth import MIN_ROUGHNESS
from alight.core.gpu import release_objects
from alight.core.layers import layer_defines
from alight.core.layers.stack import probe_tangents
from alight.core.material import LAYER_FIELDS
from alight.core.shading import probe_normals
from alight.errors import AlightError
from alight.render.bindings import rotation_cos_sin as _rotation_cos_sin
from alight.render.bindings import set_material as _set_material
from alight.render.bindings import set_uniform as _set
from alight.render.renderer import ForwardRenderer
from alight.render.variants import part_material

# Pixel-texel pairs per dispatch at most (a 256^2 probe on a 1024x512 map: ~26 dispatches).
CHUNK_PAIRS = 1 << 28
# Roughness from which a factor-2 environment level is taken by default.
LEVEL1_MIN_ROUGHNESS = 0.25
# ... and while no compact source holds this much of the map's power (quarry_01's sun: 48%).
LEVEL1_MAX_SUN_FRACTION = 0.10
# Texels per invocation per dispatch at most. Mesa's llvmpipe (gallivm) stops any shader loop
# after 65535 iterations (LP_MAX_TGSI_LOOP_ITERATIONS), counting the inner loop's iterations
# across the outer loop: a 512x256 map in one dispatch summed only its upper half. Measured:
# constant radiance 1 gave 0.496 instead of 0.99998 at 512x256, 0.012 at 1024x512.
MAX_TEXELS_PER_DISPATCH = 1 << 15
GBUFFER = ("position", "normal", "view", "base_color", "specular_f0", "emissive", "tangent")
_UNIT_ENV = 7   # texture units 0-6: the G-buffer
_UNIT_SHEEN_LUT = 8


@dataclass
class ReferenceResult:
    """Linear radiance (H, W, 4) float32, row 0 at the top, alpha 1 on the surface."""

    linear: np.ndarray
    env_level: int | None
    env_size: tuple[int, int] | None   # (W, H) of the level summed over
    dispatches: int
    seconds: dict[str, float] = field(default_factory=dict)


def cli_option(field: str) -> str:
    """How the command line names a material field in a message: its flag (--clearcoat-roughness)."""
    return "--" + field.replace("_", "-")


def check_roughness(roughness: float, what: str = "roughness", name=cli_option) -> None:
    """Errors: AlightError when ``roughness`` is below MIN_ROUGHNESS, led by ``name(what)``: the
    CLI's flag, or the editor's control (the editor passes its own names)."""
    if roughness < MIN_ROUGHNESS - 1e-9:
        raise AlightError(f"{name(what)}: {what} {roughness:g} < {MIN_ROUGHNESS}: the GGX lobe is narrower than a "
                          f"few texels and the texel sum is no longer an integral (no reference below {MIN_ROUGHNESS})")


def check_layer_lobes(material, roughnesses, name=cli_option) -> None:
    """A refracting volume's lobe is narrower than the reflected one (about (ior - 1) / (2 ior) of
    its alpha): refused, one line, where it is narrower than the reflected lobe at MIN_ROUGHNESS
    (alight.accuracy.ground_truth.check_transmission_lobe; docs/layer_transmission.md)."""
    from alight.accuracy.ground_truth import check_transmission_lobe

    if not {"transmission", "volume"} <= material.layers():   # a diffuse transmission's volume refracts nothing
        return
    for r in roughnesses:
        try:
            check_transmission_lobe(r, material.ior)
        except ValueError as exc:
            raise AlightError(f"{name('roughness')}: {exc} (no reference there)") from None


def check_layer_roughness(material, name=cli_option) -> None:
    """The layers' own GGX lobes need the same: the coat's roughness (a coat below 0.1 is a
    mirror; its sum would sample a delta). The sheen's Charlie lobe is wide at every roughness."""
    if "clearcoat" in material.layers():
        check_roughness(material.clearcoat_roughness, "clearcoat_roughness", name)


def choose_env_level(radiance: np.ndarray, roughnesses) -> int:
    """Level 1 (factor 2) when every roughness is >= 0.25, the map is >= 1024 wide and no
    compact bright source holds >= ``LEVEL1_MAX_SUN_FRACTION`` of its power; else 0."""
    rs = list(roughnesses)
    if not rs or min(rs) < LEVEL1_MIN_ROUGHNESS or radiance.shape[1] < 1024:
        return 0
    from alight.ibl.sun import extract_suns

    _, suns = extract_suns(np.asarray(radiance, np.float32))
    return 0 if any(sun.fraction >= LEVEL1_MAX_SUN_FRACTION for sun in suns) else 1


def env_level_radiance(radiance: np.ndarray, level: int) -> np.ndarray:
    """The map box-reduced by 2^level (area-weighted, alight.core.equirect.box_reduce)."""
    from alight.core.equirect import box_reduce

    factor = 1 << int(level)
    h, w = radiance.shape[:2]
    if level < 0 or h % factor or w % factor:
        raise AlightError(f"--env-level: {level} does not divide the {w}x{h} map by 2^{level}")
    return box_reduce(radiance, factor)


def probe_gbuffer(size: int, material) -> dict[str, np.ndarray]:
    """docs/conventions.md's probe view as G-buffer arrays (size, size, 4), row 0 at the top."""
    normals, inside = probe_normals(int(size))
    g = {name: np.zeros((size, size, 4), np.float32) for name in GBUFFER}
    g["position"][..., :3] = normals
    g["position"][..., 3] = inside
    g["normal"][..., :3] = normals
    g["normal"][..., 3] = material.roughness
    g["view"][..., 2] = 1.0
    g["view"][..., 3] = material.metallic
    g["base_color"][..., :3] = material.base_color
    g["specular_f0"][..., :3] = material.specular_f0
    g["specular_f0"][..., 3] = 1.0   # F90 (a probe's material has no KHR_materials_specular)
    g["emissive"][..., :3] = material.emissive
    g["tangent"][..., :3] = probe_tangents(normals)
    g["tangent"][..., 3] = 1.0
    for name in GBUFFER[1:]:
        g[name][~inside] = 0.0
    return g


class ReferenceRenderer:
    """The GPU ground truth, on a ``ForwardRenderer``'s context and shader library."""

    def __init__(self, renderer: ForwardRenderer | None = None):
        self.renderer = renderer or ForwardRenderer()
        self.ctx = self.renderer.ctx

    # --- G-buffers -----------------------------------------------------------------------

    def _textures_from_arrays(self, g: dict[str, np.ndarray]) -> list[moderngl.Texture]:
        texs = []
        for name in GBUFFER:
            a = np.ascontiguousarray(g[name], dtype=np.float32)
            tex = self.ctx.texture((a.shape[1], a.shape[0]), 4, a.tobytes(), dtype="f4")
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            texs.append(tex)
        return texs

    def mesh_gbuffer(self, scene, width: int, height: int) -> tuple[list[moderngl.Texture], list]:
        """Rasterise the mesh into float G-buffer textures (GL rows: bottom first)."""
        ctx = self.ctx
        r = self.renderer
        texs = [ctx.texture((width, height), 4, dtype="f4") for _ in GBUFFER]
        for tex in texs:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        depth = ctx.depth_renderbuffer((width, height))
        fbo = ctx.framebuffer(texs, depth)
        fbo.use()
        ctx.viewport = (0, 0, width, height)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        camera = r.camera_for(scene, width / height)
        def prog(defines: dict):   # each part's variant (uv sets, vertex colours, texture transforms)
            return r.program("render/pbr.vert", "render/gbuffer.frag", defines)

        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        r.draw_mesh_parts(scene, prog, camera, camera.view_projection(width / height))
        ctx.disable(moderngl.DEPTH_TEST)
        ctx.finish()
        release_objects(ctx, fbo, depth)
        return texs

    def layered_material(self, scene):
        """The material whose layer factors the reference applies at every pixel (the G-buffer
        carries the base model only): the scene's, or the one all the mesh's parts share. Parts
        with different layer factors are refused (one line) rather than summed wrongly."""
        if scene.view == "probe" or scene.mesh is None:
            return scene.material
        materials = [part_material(scene, part)[0] for part in scene.mesh.parts]
        distinct = {tuple(getattr(m, f) for f in ("ior", *LAYER_FIELDS)) for m in materials if m.layers()}
        if len(distinct) > 1:
            raise AlightError(f"{scene.mesh.source}: parts with different layer factors (clearcoat, sheen, ...): "
                              "the reference takes one set per scene")
        layered = [m for m in materials if m.layers()]
        return layered[0] if layered else scene.material

    def scene_roughnesses(self, scene) -> list[float]:
        """The roughness factors the scene's surfaces use (textures not included)."""
        if scene.view == "probe" or scene.mesh is None:
            return [float(scene.material.roughness)]
        out = []
        for part in scene.mesh.parts:
            fm = part.material
            if fm is None or not scene.use_file_materials:
                out.append(float(scene.material.roughness))
            else:
                out.append(float(scene.material_overrides.get("roughness", fm.roughness)))
        return out

    # --- the sum -------------------------------------------------------------------------

    def render(self, scene, radiance: np.ndarray | None, width: int, height: int,
               env_level: int | None = None, chunk_pairs: int = CHUNK_PAIRS) -> ReferenceResult:
        """The reference of ``scene`` lit by ``radiance`` ((H, 2H, 3) equirect, or None: no
        environment) at ``env_level`` (None: ``choose_env_level``)."""
        seconds: dict[str, float] = {}
        t0 = time.perf_counter()
        if scene.view == "probe" and width != height:
            raise AlightError(f"--size: the probe view is square; got {width}x{height}")
        use_env = radiance is not None and scene.ibl_enabled
        if use_env:
            for r in self.scene_roughnesses(scene):
                check_roughness(r)
            check_layer_roughness(self.layered_material(scene))
            check_layer_lobes(self.layered_material(scene), self.scene_roughnesses(scene))
        ctx = self.ctx
        if scene.view == "probe":
            gtex = self._textures_from_arrays(probe_gbuffer(width, scene.material))
            flip = False
        elif scene.mesh is not None:
            gtex = self.mesh_gbuffer(scene, width, height)
            flip = True
        else:
            gtex = self._textures_from_arrays({n: np.zeros((height, width, 4), np.float32) for n in GBUFFER})
            flip = False
        seconds["gbuffer"] = time.perf_counter() - t0
        return self._sum(gtex, flip, scene, radiance if use_env else None, width, height, env_level, chunk_pairs,
                         seconds, self.scene_roughnesses(scene), self.layered_material(scene))

    def render_gbuffer(self, g: dict[str, np.ndarray], scene, radiance: np.ndarray | None,
                       env_level: int | None = None, chunk_pairs: int = CHUNK_PAIRS) -> ReferenceResult:
        """The reference at the pixels of a G-buffer given as arrays (``GBUFFER`` names, each
        (H, W, 4), row 0 at the top; see ``probe_gbuffer``). ``scene`` gives the lights, the
        environment's rotation and intensity, and ``ibl_enabled``."""
        height, width = g["position"].shape[:2]
        covered = g["position"][..., 3] > 0.5
        roughnesses = [float(np.min(g["normal"][..., 3][covered]))] if covered.any() else []
        use_env = radiance is not None and scene.ibl_enabled
        if use_env:
            for r in roughnesses:
                check_roughness(r)
            check_layer_roughness(scene.material)
            check_layer_lobes(scene.material, roughnesses)
        return self._sum(self._textures_from_arrays(g), False, scene, radiance if use_env else None, width, height,
                         env_level, chunk_pairs, {}, roughnesses, scene.material)

    def _sum(self, gtex, flip: bool, scene, radiance, width: int, height: int, env_level, chunk_pairs: int,
             seconds: dict[str, float], roughnesses, material) -> ReferenceResult:
        ctx = self.ctx
        use_env = radiance is not None
        t1 = time.perf_counter()
        level = None
        env_tex = columns = None
        rows, env_w = 0, 0
        if use_env:
            level = choose_env_level(radiance, roughnesses) if env_level is None \
                else int(env_level)
            reduced = env_level_radiance(np.asarray(radiance, np.float32), level)
            rows, env_w = reduced.shape[0], reduced.shape[1]
            env_tex = ctx.texture((env_w, rows), 3, np.ascontiguousarray(reduced, np.float32).tobytes(), dtype="f4")
            env_tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            phi = (np.arange(env_w) + 0.5) * (2.0 * math.pi / env_w) - math.pi
            columns = ctx.buffer(np.column_stack([np.sin(phi), np.cos(phi)]).astype(np.float32).tobytes())
        else:
            columns = ctx.buffer(np.zeros(2, np.float32).tobytes())
        t2 = time.perf_counter()
        seconds["environment"] = t2 - t1

        accum = ctx.texture((width, height), 4, dtype="f4")
        defines = layer_defines([material])
        prog = self.renderer.shaders.compute("accuracy/reference.comp", defines)
        _set_material(prog, material)   # the layers' factors (the G-buffer holds the base's)
        if "HAS_SHEEN" in defines:
            self.renderer.luts.sheen().use(_UNIT_SHEEN_LUT)
            _set(prog, "u_sheen_lut", _UNIT_SHEEN_LUT)
        for unit, (name, tex) in enumerate(zip(GBUFFER, gtex)):
            tex.use(unit)
            _set(prog, f"u_g_{name}", unit)
        if env_tex is not None:
            env_tex.use(_UNIT_ENV)
        _set(prog, "u_env", _UNIT_ENV)
        columns.bind_to_storage_buffer(2)
        self.renderer.lights.write(scene)
        accum.bind_to_image(0, read=True, write=True)
        _set(prog, "u_size", (width, height))
        _set(prog, "u_env_enabled", bool(use_env))
        _set(prog, "u_env_rotation", _rotation_cos_sin(scene.env_rotation_deg))
        _set(prog, "u_env_intensity", float(scene.env_intensity))
        rows_per = max(1, min(chunk_pairs // max(1, width * height * max(env_w, 1)),
                              MAX_TEXELS_PER_DISPATCH // max(env_w, 1))) if use_env else 1
        chunks = [(a, min(rows, a + rows_per)) for a in range(0, rows, rows_per)] if use_env else [(0, 0)]
        groups = ((width + 7) // 8, (height + 7) // 8, 1)
        for i, (a, b) in enumerate(chunks):
            _set(prog, "u_first", i == 0)
            _set(prog, "u_row_begin", a)
            _set(prog, "u_row_end", b)
            prog.run(*groups)
            ctx.memory_barrier(moderngl.SHADER_IMAGE_ACCESS_BARRIER_BIT)
        ctx.finish()
        t3 = time.perf_counter()
        seconds["sum"] = t3 - t2
        pixels = np.frombuffer(accum.read(), np.float32).reshape(height, width, 4).copy()
        if flip:
            pixels = pixels[::-1].copy()
        for obj in [accum, columns, *gtex] + ([env_tex] if env_tex is not None else []):
            obj.release()
        return ReferenceResult(pixels, level, (env_w, rows) if use_env else None, len(chunks), seconds)

    def release(self) -> None:
        """Meshes live in the ForwardRenderer's cache; they go with ``self.renderer.release()``."""
