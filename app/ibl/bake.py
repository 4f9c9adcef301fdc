"""The image-based-lighting bake: GLSL compute passes that turn an environment into the
split sum's maps (Karis 2013, as the lecture teaches it).

    equirect --equirect_to_cube--> source cube (+ box mip chain, for filtered importance sampling)
             --irradiance | sh9--> irradiance cube (E/pi)
             --prefilter-------->  prefiltered radiance cube, one roughness per mip
    (independent of the environment)  --brdf_lut--> (A, B) over (n.v, roughness), cached on disk

Every quality choice is in ``QUALITY`` below.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary, float_cube
from alight.core.shading import D_GGX, hammersley, importance_sample_ggx_tangent
from alight.ibl.sun import Sun, extract_suns
from alight.ibl.table_files import load_table, save_table
from alight.paths import cache_dir

if TYPE_CHECKING:
    from alight.ibl.environment import Environment

IRRADIANCE_METHODS = ("convolution", "sh9")
# Samples per texel of a grid step above a quality's max_roughness: never read by the scene's
# materials, so it is only kept finite and roughly right (the background's blur may read it).
SKIPPED_STEP_SAMPLES = 16


@dataclass(frozen=True)
class BakeQuality:
    """One row of the quality table: the resolutions and sample counts of every bake pass."""

    name: str
    cube_size: int                 # source cube, level 0 face size
    equirect_subsamples: int       # per axis, per source-cube texel
    prefiltered_size: int          # grid A's mip 0 face size (roughness 2^(-(levels-1)/2))
    prefiltered_min_size: int      # grid A's last mip (roughness 1)
    prefilter_samples: int         # GGX samples per texel of grid A's mip 0
    prefilter_sample_growth: int   # times more samples per coarser mip: a mip has 4x fewer texels,
    prefilter_max_samples: int     # so rough mips get many samples for about the same cost
    filtered_importance_sampling: bool
    lod_bias: float                # added to the filtered-importance-sampling mip
    irradiance: str                # 'convolution' (the lecture's) or 'sh9'
    irradiance_size: int
    irradiance_phi_steps: int
    irradiance_theta_steps: int
    sh9_source_width: int          # width of the equirect mip that the SH projection reads
    lut_size: int
    lut_samples: int
    # Steps rougher than this get only a few samples (finite and roughly right, not accurate):
    # a scene whose roughest material is r needs the grid only up to the first step >= r.
    max_roughness: float = 1.0

    @property
    def prefiltered_levels(self) -> int:
        return int(math.log2(self.prefiltered_size // self.prefiltered_min_size)) + 1

    @property
    def irradiance_source_size(self) -> int:
        """Face size of the source mip that the convolution reads: its texel spans about one
        sample spacing (2 pi / phi_steps), so the box mips' averages stand in for the radiance
        between samples. A finer source lets a small bright source (a sun, the moon) fall between
        samples: 9% irradiance error on moonless_golf at 32^2 faces, 2.3% at 16^2 (64 steps)."""
        return max(1, self.irradiance_phi_steps // 4)

    def prefilter_samples_at(self, step: int) -> int:
        """Samples per texel at a grid step (step 2m: grid A's mip m; 2j+1: grid B's mip j).
        Steps beyond the first one at or above ``max_roughness`` times FETCH_REACH (the roughest
        any IBL model fetches for a material that rough) get SKIPPED_STEP_SAMPLES."""
        if self.max_roughness < 1.0 and step > 0 and \
                grid_roughness(step - 1, self.prefiltered_levels) >= self.max_roughness * FETCH_REACH:
            return SKIPPED_STEP_SAMPLES
        return min(self.prefilter_max_samples, int(self.prefilter_samples * self.prefilter_sample_growth ** (step / 2)))


# The `stretched` model (the default) fetches at up to sqrt(beta) times the material's roughness,
# beta <= 1.3 in its table (alight.core.stretched_lobe; tests/test_ibl_models.py holds the bound).
FETCH_REACH = 1.15


# The one place where bake quality is chosen. 'medium' is the default: it keeps the probe within
# 1.6% of the converged split sum at roughness >= 0.25 on every shared map (docs/explanation/accuracy.md, "Implementation
# error"; tests/test_probe_accuracy.py) and bakes a 1k map in 0.3-0.4 s (warm, LUT cached)
# on 2-core llvmpipe, the prefilter being two thirds of it (benchmarks/bench_render.py).
QUALITY: dict[str, BakeQuality] = {
    "low": BakeQuality(
        name="low", cube_size=128, equirect_subsamples=2,
        prefiltered_size=64, prefiltered_min_size=8, prefilter_samples=32, prefilter_sample_growth=4, prefilter_max_samples=1024,
        filtered_importance_sampling=True, lod_bias=0.0,
        irradiance="sh9", irradiance_size=16,
        irradiance_phi_steps=32, irradiance_theta_steps=8, sh9_source_width=128,
        lut_size=64, lut_samples=256,
    ),
    "medium": BakeQuality(
        name="medium", cube_size=256, equirect_subsamples=2,
        prefiltered_size=128, prefiltered_min_size=8, prefilter_samples=160, prefilter_sample_growth=2, prefilter_max_samples=4096,
        filtered_importance_sampling=True, lod_bias=0.0,
        irradiance="convolution", irradiance_size=32,
        irradiance_phi_steps=64, irradiance_theta_steps=16, sh9_source_width=256,
        lut_size=128, lut_samples=1024,
    ),
    "high": BakeQuality(
        name="high", cube_size=512, equirect_subsamples=2,
        prefiltered_size=256, prefiltered_min_size=8, prefilter_samples=256, prefilter_sample_growth=4, prefilter_max_samples=16384,
        filtered_importance_sampling=True, lod_bias=0.0,
        irradiance="convolution", irradiance_size=32,
        irradiance_phi_steps=128, irradiance_theta_steps=32, sh9_source_width=512,
        lut_size=256, lut_samples=4096,
    ),
}
DEFAULT_QUALITY = "medium"


def quality_named(name: str, irradiance: str | None = None) -> BakeQuality:
    q = QUALITY[name]
    return replace(q, irradiance=irradiance) if irradiance else q


def grid_roughness(step: int, levels: int) -> float:
    """Roughness prefiltered at a step of the grid; ibl.glsl's roughness_to_grid_step() inverts it.

    The grid steps alpha = r^2 by sqrt(2): even steps 2m are grid A's mips m, whose resolution
    halves as alpha doubles (A's last mip is r = 1); odd steps 2j+1 are grid B's mips j, halfway
    (in log alpha) between A's mips j and j+1 at the resolution of A's mip j+1. Below A's mip 0 the
    source cube's box mips stand in (the mirror at r = 0). With the lecture's linear steps
    (r = m / max_mip) trilinear blending alone costs 9% at r = 0.25 on a metal; this grid keeps
    blends near 1% (tests/test_probe_accuracy.py).
    """
    return 2.0 ** (step / 4.0 - (levels - 1) / 2.0)


def roughness_to_grid_step(roughness, levels: int):
    """Numpy twin of ibl.glsl's roughness_to_grid_step."""
    r = np.maximum(np.asarray(roughness, dtype=np.float64), 1e-4)
    return 2.0 * (2.0 * np.log2(r) + (levels - 1))


def prefilter_sample_set(roughness: float, count: int, source_size: int, lod_bias: float,
                         filtered: bool) -> np.ndarray:
    """The prefilter's samples for one roughness: (K, 4) float32 rows of (l.xyz, source mip) in
    the tangent frame of n = v, with the K <= count samples below the horizon dropped."""
    h = importance_sample_ggx_tangent(hammersley(np.arange(count), count), roughness)
    l = 2.0 * h[:, 2:3] * h - np.array([0.0, 0.0, 1.0])   # reflect v = n about h
    keep = l[:, 2] > 0.0
    lod = np.zeros(count)
    if filtered:
        # pdf over l is D(h) n.h / (4 v.h) = D(h) / 4 when v = n.
        pdf = D_GGX(h[:, 2], roughness) / 4.0
        sample_solid_angle = 1.0 / (count * pdf + 1e-6)
        texel_solid_angle = 4.0 * np.pi / (6.0 * source_size * source_size)
        lod = np.maximum(0.5 * np.log2(sample_solid_angle / texel_solid_angle) + lod_bias, 0.0)
    return np.ascontiguousarray(np.column_stack([l[keep], lod[keep]]), dtype=np.float32)


@dataclass
class IBLMaps:
    """The baked maps of one environment at one quality, ready to bind."""

    environment: moderngl.TextureCube        # source radiance cube with a box mip chain
    irradiance: moderngl.TextureCube         # E/pi
    prefiltered_radiance: moderngl.TextureCube       # grid A (see grid_roughness)
    prefiltered_radiance_mid: moderngl.TextureCube   # grid B
    brdf_lut: moderngl.Texture               # RGBA: (A, B, t_A, t_B), see brdf_lut.comp
    quality: BakeQuality
    pass_seconds: dict[str, float] = field(default_factory=dict)
    # Compact bright sources (app/ibl/sun.py): not in the irradiance and prefiltered maps; the forward
    # pass adds them exactly. sun_prefilter_scale[step]: what a delta source of power P adds to
    # that roughness step of the prefiltered map per unit P (n.l) D(h) (prefilter.glsl).
    suns: list[Sun] = field(default_factory=list)
    sun_prefilter_scale: list[float] = field(default_factory=list)
    # The source cube without the compact sources (None when there are none): below the
    # prefiltered grid the models that shade the sources exactly read it instead of environment.
    lighting_environment: moderngl.TextureCube | None = None

    @property
    def prefiltered_max_mip(self) -> float:
        return float(self.quality.prefiltered_levels - 1)

    def release(self) -> None:
        # The LUT is shared between bakes (see LutCache) and released with the cache.
        for tex in (self.environment, self.irradiance, self.prefiltered_radiance, self.prefiltered_radiance_mid,
                    self.lighting_environment):
            if tex is not None:
                tex.release()


def _groups(size: int, local: int = 8) -> int:
    return (size + local - 1) // local


def _timed(ctx: moderngl.Context, seconds: dict[str, float], name: str, run):
    """run()'s result; its seconds added to seconds[name]. finish() bounds each pass so its time
    is its own; it costs a sync, not GPU work."""
    start = time.perf_counter()
    result = run()
    ctx.finish()
    seconds[name] = seconds.get(name, 0.0) + time.perf_counter() - start
    return result


def _dispatch_faces(ctx: moderngl.Context, prog: moderngl.ComputeShader, target: moderngl.TextureCube,
                    size: int, level: int = 0) -> None:
    """Run a cube pass: one invocation per texel of the six faces of one level of target."""
    target.bind_to_image(0, read=False, write=True, level=level)
    prog.run(_groups(size), _groups(size), 6)
    ctx.memory_barrier()


def upload_equirect(ctx: moderngl.Context, radiance: np.ndarray, mipmaps: bool = False) -> moderngl.Texture:
    """The equirect as a float texture; u wraps (the seam), v clamps (the poles). Mips only when
    a pass reads them (the SH projection): building them costs more than the upload."""
    h, w, _ = radiance.shape
    tex = ctx.texture((w, h), 3, np.ascontiguousarray(radiance, dtype=np.float32).tobytes(), dtype="f4")
    tex.repeat_x = True
    tex.repeat_y = False
    if mipmaps:
        tex.build_mipmaps()
        tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    else:
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return tex


def _cube(ctx: moderngl.Context, size: int, levels: int) -> moderngl.TextureCube:
    # Levels allocated, not filtered: every pass writes each level it owns.
    return float_cube(ctx, size, levels)


LUT_CHANNELS = 4   # brdf_lut.comp: A, B, t_A, t_B


def read_lut(tex: moderngl.Texture) -> np.ndarray:
    """The BRDF LUT texture as a (size, size, LUT_CHANNELS) float32 array, row 0 = roughness 0."""
    size = tex.size[0]
    return np.frombuffer(tex.read(), dtype=np.float32).reshape(size, size, LUT_CHANNELS)


class LutCache:
    """The BRDF integration map depends only on its size, sample count and shader: bake it once
    per machine and keep it in the user's cache directory (``alight.paths.cache_dir``)."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary):
        self.ctx = ctx
        self.shaders = shaders
        self._textures: dict[tuple, moderngl.Texture] = {}
        self.last_source = ""   # 'memory', 'disk' or 'baked'

    def path_for(self, size: int, samples: int):
        digest = self.shaders.digest("ibl/brdf_lut.comp")[:16]
        return cache_dir() / f"brdf_lut-{size}-{samples}-{digest}.npy"

    @staticmethod
    def files() -> list:
        """The LUT files in the cache folder (``alight cache`` shows and clears them)."""
        folder = cache_dir()
        return sorted(folder.glob("brdf_lut-*.npy")) if folder.is_dir() else []

    def get(self, size: int, samples: int) -> moderngl.Texture:
        return self._get(("brdf", size, samples), self.path_for(size, samples), size,
                         lambda: self._bake(size, samples))

    def sheen(self, size: int | None = None, steps: int | None = None) -> moderngl.Texture:
        """The sheen LUT (ibl/sheen_lut.comp: E, the lobe's mean direction and width over n.v and
        sheen roughness; numpy twin alight.core.layers.sheen.sheen_lut_table), cached like the
        BRDF LUT. Baked only when a material with sheen is drawn."""
        from alight.core.layers.sheen import _QUADRATURE, SHEEN_LUT_SIZE

        size = size or SHEEN_LUT_SIZE
        steps = steps or _QUADRATURE
        digest = self.shaders.digest("ibl/sheen_lut.comp")[:16]
        path = cache_dir() / f"sheen_lut-{size}-{steps}-{digest}.npy"
        return self._get(("sheen", size, steps), path, size, lambda: self._bake_sheen(size, steps))

    def _get(self, key: tuple, path, size: int, bake) -> moderngl.Texture:
        if key in self._textures:
            self.last_source = "memory"
            return self._textures[key]
        table = load_table(path, (size, size, LUT_CHANNELS))
        if table is not None:
            self.last_source = "disk"
            tex = self._upload(table)
        else:
            self.last_source = "baked"
            tex = bake()
            save_table(path, read_lut(tex))
        self._textures[key] = tex
        return tex

    def _upload(self, table: np.ndarray) -> moderngl.Texture:
        size = table.shape[0]
        tex = self.ctx.texture((size, size), LUT_CHANNELS, table.tobytes(), dtype="f4")
        tex.repeat_x = tex.repeat_y = False
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        return tex

    def _bake_sheen(self, size: int, steps: int) -> moderngl.Texture:
        return self._run("ibl/sheen_lut.comp", size, u_steps=steps)

    def _bake(self, size: int, samples: int) -> moderngl.Texture:
        return self._run("ibl/brdf_lut.comp", size, u_samples=samples)

    def _run(self, shader: str, size: int, **uniforms) -> moderngl.Texture:
        """A size x size LUT written by one compute pass (``shader``, ``u_size`` and ``uniforms``)."""
        tex = self._upload(np.zeros((size, size, LUT_CHANNELS), np.float32))
        prog = self.shaders.compute(shader)
        prog["u_size"] = size
        for name, value in uniforms.items():
            prog[name] = value
        tex.bind_to_image(0, read=False, write=True)
        prog.run(_groups(size), _groups(size), 1)
        self.ctx.memory_barrier()
        return tex

    def release(self) -> None:
        for tex in self._textures.values():
            tex.release()
        self._textures.clear()


def bake_environment(ctx: moderngl.Context, shaders: ShaderLibrary, env: Environment,
                     quality: BakeQuality, luts: LutCache) -> IBLMaps:
    """Run every bake pass for one environment; returns the maps and each pass's seconds."""
    return run_to_completion(bake_steps(ctx, shaders, env, quality, luts))


# Prefilter levels at least this size are dispatched two faces at a time in bake_steps, and
# one at a time from twice the size (the medium bake's first level, all six faces, took about
# 0.3 s on a loaded 2-core llvmpipe: a visible stall in the editor).
PREFILTER_SPLIT_SIZE = 64


def _set_uniform(prog, name: str, value) -> None:
    member = prog.get(name, None)
    if member is not None:
        member.value = value


def run_to_completion(steps):
    """Drive a step generator (``bake_steps``) to its end; its return value."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


def bake_steps(ctx: moderngl.Context, shaders: ShaderLibrary, env: Environment,
               quality: BakeQuality, luts: LutCache):
    """``bake_environment`` in small GPU passes: yields ``(fraction done, label of the pass just
    done)`` after each pass (so a caller can spread a bake over frames) and returns the IBLMaps.
    Each pass ends with a finish() (its time, see _timed), so nothing is left in flight between
    steps. Closing the generator early releases what it made."""
    q = quality
    seconds: dict[str, float] = {}
    levels = q.prefiltered_levels
    prefilter_steps = 2 * levels - 1
    owned: list = []    # released if the caller stops early
    # Step weights: a prefilter step or the irradiance counts two, an upload or a cube one.
    total = 1.0 + 2.0 + 2.0 + 2.0 * prefilter_steps
    done = 0.0

    def progress(weight: float, label: str):
        nonlocal done
        done += weight
        return min(done / total, 0.999), label

    try:
        lighting_radiance, suns = _timed(ctx, seconds, "suns", lambda: extract_suns(env.radiance))
        total += 2.0 if suns else 0.0
        yield progress(1, "suns")

        # The environment as seen (background, mirror) keeps its sun; the lighting passes read a
        # copy without it, and the forward pass adds the sun back exactly (shaders/common/ibl.glsl).
        source = yield from _source_cube_steps(ctx, shaders, env.radiance, q, seconds, "environment", owned,
                                               progress)
        lighting = source
        if suns:
            lighting = yield from _source_cube_steps(ctx, shaders, lighting_radiance, q, seconds, "lighting",
                                                     owned, progress)

        irradiance = _cube(ctx, q.irradiance_size, 1)
        owned.append(irradiance)
        if q.irradiance == "convolution":
            def convolve():
                prog = shaders.compute("ibl/irradiance.comp")
                lighting.use(0)
                prog["u_environment"] = 0
                prog["u_size"] = q.irradiance_size
                prog["u_phi_steps"] = q.irradiance_phi_steps
                prog["u_theta_steps"] = q.irradiance_theta_steps
                prog["u_source_mip"] = max(0.0, math.log2(q.cube_size / q.irradiance_source_size))
                _dispatch_faces(ctx, prog, irradiance, q.irradiance_size)
            _timed(ctx, seconds, "irradiance_convolution", convolve)
        elif q.irradiance == "sh9":
            _timed(ctx, seconds, "irradiance_sh9",
                   lambda: _irradiance_sh9(ctx, shaders, lighting_radiance, irradiance, q))
        else:
            raise ValueError(f"unknown irradiance method {q.irradiance!r}")
        yield progress(2, "irradiance")

        prefiltered = _cube(ctx, q.prefiltered_size, levels)
        owned.append(prefiltered)
        prefiltered_mid = _cube(ctx, q.prefiltered_size // 2, levels - 1)
        owned.append(prefiltered_mid)

        sun_scale: list[float] = []
        for step in range(prefilter_steps):
            target, mip = (prefiltered, step // 2) if step % 2 == 0 else (prefiltered_mid, step // 2)
            size = target.size[0] >> mip
            # The big levels go a few faces at a time, so that no step holds a frame long.
            faces = 6 if size < PREFILTER_SPLIT_SIZE else 2 if size < 2 * PREFILTER_SPLIT_SIZE else 1
            for first in range(0, 6, faces):
                def prefilter(step=step, target=target, mip=mip, size=size, first=first):
                    prog = shaders.compute("ibl/prefilter.comp")
                    lighting.use(0)
                    prog["u_environment"] = 0
                    roughness = grid_roughness(step, levels)
                    total = q.prefilter_samples_at(step)
                    sample_set = prefilter_sample_set(roughness, total, q.cube_size, q.lod_bias,
                                                      q.filtered_importance_sampling)
                    buffer = ctx.buffer(sample_set.tobytes())
                    buffer.bind_to_storage_buffer(1)
                    prog["u_size"] = size
                    prog["u_sample_count"] = len(sample_set)
                    if first == 0:
                        # What a delta source of power P adds to this step's sum per unit P (n.l) D(h):
                        # the forward pass adds compact sources with it (prefilter.glsl says why).
                        sun_scale.append(0.25 * total / max(float(sample_set[:, 2].sum()), 1e-8))
                    _set_uniform(prog, "u_face_offset", first)
                    target.bind_to_image(0, read=False, write=True, level=mip)
                    prog.run(_groups(size), _groups(size), faces)
                    ctx.memory_barrier()
                    buffer.release()

                _timed(ctx, seconds, "prefilter", prefilter)
                yield progress(2.0 * faces / 6, f"prefilter {step + 1}/{prefilter_steps}"
                               + (f" (faces {first + 1}-{first + faces})" if faces > 1 and faces < 6 else
                                  f" (face {first + 1})" if faces == 1 else ""))
        lut = _timed(ctx, seconds,
                     f"brdf_lut ({'cached' if luts.path_for(q.lut_size, q.lut_samples).exists() else 'baked'})",
                     lambda: luts.get(q.lut_size, q.lut_samples))
    except BaseException:   # GeneratorExit (closed early) or a failed pass: free the partial bake
        for tex in owned:
            tex.release()
        raise
    return IBLMaps(source, irradiance, prefiltered, prefiltered_mid, lut, q, seconds, suns, sun_scale,
                   lighting if lighting is not source else None)



def _source_cube_steps(ctx, shaders: ShaderLibrary, radiance: np.ndarray, q: BakeQuality,
                       seconds: dict[str, float], name: str, owned: list, progress):
    """_source_cube as two steps, the upload then the cube with its mips, each followed by
    ``yield progress(weight, label)``. The cube goes into ``owned``."""
    levels = int(math.log2(q.cube_size)) + 1
    cube = _cube(ctx, q.cube_size, levels)
    owned.append(cube)
    equirect = _timed(ctx, seconds, f"upload ({name})", lambda: upload_equirect(ctx, radiance))
    try:
        yield progress(1, f"upload ({name})")

        def to_cube():
            prog = shaders.compute("ibl/equirect_to_cube.comp")
            equirect.use(0)
            prog["u_equirect"] = 0
            prog["u_size"] = q.cube_size
            prog["u_subsamples"] = q.equirect_subsamples
            _dispatch_faces(ctx, prog, cube, q.cube_size)
            downsample = shaders.compute("ibl/cube_downsample.comp")
            for level in range(1, levels):
                size = q.cube_size >> level
                cube.bind_to_image(0, read=True, write=False, level=level - 1)
                cube.bind_to_image(1, read=False, write=True, level=level)
                downsample["u_size"] = size
                downsample.run(_groups(size), _groups(size), 6)
                ctx.memory_barrier()

        _timed(ctx, seconds, f"equirect_to_cube ({name})", to_cube)
    finally:
        equirect.release()
    yield progress(1, f"equirect_to_cube ({name})")
    return cube


def _irradiance_sh9(ctx, shaders, radiance: np.ndarray, irradiance, q: BakeQuality) -> None:
    h, w, _ = radiance.shape
    equirect_tex = upload_equirect(ctx, radiance, mipmaps=True)
    level = max(0, int(round(math.log2(max(1, w // q.sh9_source_width)))))
    lw, lh = max(1, w >> level), max(1, h >> level)
    gx, gy = _groups(lw), _groups(lh)
    partials = ctx.buffer(reserve=gx * gy * 9 * 16)
    prog = shaders.compute("ibl/sh9_project.comp")
    equirect_tex.use(0)
    prog["u_equirect"] = 0
    prog["u_level"] = level
    prog["u_level_size"] = (lw, lh)
    partials.bind_to_storage_buffer(0)
    prog.run(gx, gy, 1)
    ctx.memory_barrier()
    coeffs = np.frombuffer(partials.read(), dtype=np.float32).reshape(gx * gy, 9, 4)[:, :, :3].sum(axis=0)
    partials.release()
    equirect_tex.release()
    fill = shaders.compute("ibl/sh9_to_cube.comp")
    fill["u_size"] = q.irradiance_size
    fill["u_coeffs"].write(np.ascontiguousarray(coeffs, dtype=np.float32).tobytes())
    _dispatch_faces(ctx, fill, irradiance, q.irradiance_size)


def sh9_basis(d) -> np.ndarray:
    """Numpy twin of sh9.glsl's sh9_basis: the 9 real SH of order <= 2 at unit direction d."""
    x, y, z = (float(c) for c in d)
    return np.array([0.282095, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y,
                     1.092548 * y * z, 0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z,
                     0.546274 * (x * x - y * y)])


def read_cube(shaders: ShaderLibrary, tex: moderngl.TextureCube, level: int = 0) -> np.ndarray:
    """Faces of one level as (6, size, size, 4) float32 in OpenGL's face order (+X -X +Y -Y +Z -Z),
    row 0 = the first row in memory."""
    ctx = shaders.ctx
    size = max(1, tex.size[0] >> level)
    out = ctx.buffer(reserve=6 * size * size * 16)
    prog = shaders.compute("ibl/read_cube_level.comp")
    prog["u_size"] = size
    tex.bind_to_image(0, read=True, write=False, level=level)
    out.bind_to_storage_buffer(0)
    prog.run(_groups(size), _groups(size), 6)
    ctx.memory_barrier()
    faces = np.frombuffer(out.read(), dtype=np.float32).reshape(6, size, size, 4).copy()
    out.release()
    return faces
