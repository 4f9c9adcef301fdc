"""The transmission LUT: the refracted lobe of KHR_materials_volume's BTDF as a 3D table over
(n.v, roughness, ior), baked once by ``shaders/ibl/transmission_lut.comp`` and kept in the user's
cache directory like the BRDF LUT (docs/layer_transmission.md, "Real-time").

Channels: E (the lobe's energy), bend (its mean direction: the sine of its angle from -n over
the view's sine), roughness (the prefiltered roughness with the same mean cosine). The numpy twin is
``alight.accuracy.converged.transmission_lut_converged``. Thin-walled transmission needs no table
of its own: its lobe is the reflection lobe mirrored through the surface (the BRDF LUT's A).
"""

from __future__ import annotations


import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary
from alight.ibl.table_files import load_table, save_table
from alight.paths import cache_dir

# Quality choices in one place: texels over n.v, roughness and the ior axis, and samples per
# texel. The lobe changes slowly along each axis (app/accuracy/converged.py's twin agrees with
# the table to TABLE_TOLERANCE, tests/test_transmission.py).
SIZE = (32, 32, 16)
SAMPLES = 4096
CHANNELS = 4
IOR_AXIS_MAX = 0.75   # common/transmission_lut.glsl: z = (1 - 1/ior) / IOR_AXIS_MAX


def lut_axis_of_ior(ior):
    """z in [0, 1] of an ior (>= 1) on the table's third axis."""
    return np.clip((1.0 - 1.0 / np.maximum(np.asarray(ior, dtype=np.float64), 1.0)) / IOR_AXIS_MAX, 0.0, 1.0)


def ior_of_lut_axis(z):
    return 1.0 / (1.0 - IOR_AXIS_MAX * np.asarray(z, dtype=np.float64))


def texel_centres() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (n.v, roughness, ior) of every texel, each of shape (depth, height, width)."""
    nx, ny, nz = SIZE
    z, y, x = np.meshgrid((np.arange(nz) + 0.5) / nz, (np.arange(ny) + 0.5) / ny, (np.arange(nx) + 0.5) / nx,
                          indexing="ij")
    return np.maximum(x, 1e-4), y, ior_of_lut_axis(z)


def read_table(tex: moderngl.Texture) -> np.ndarray:
    """The LUT as a (depth, height, width, CHANNELS) float32 array (z = ior axis, y = roughness)."""
    w, h, d = tex.size
    return np.frombuffer(tex.read(), dtype=np.float32).reshape(d, h, w, CHANNELS)


class TransmissionLut:
    """The table on one context: baked on first use, or read from the cache directory when a
    table from the same shader source is there (a bad or missing file only costs a bake)."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary):
        self.ctx = ctx
        self.shaders = shaders
        self._texture: moderngl.Texture | None = None
        self.last_source = ""   # 'memory', 'disk' or 'baked'

    def path(self):
        digest = self.shaders.digest("ibl/transmission_lut.comp")[:16]
        return cache_dir() / f"transmission_lut-{'x'.join(map(str, SIZE))}-{SAMPLES}-{digest}.npy"

    def texture(self) -> moderngl.Texture:
        if self._texture is not None:
            self.last_source = "memory"
            return self._texture
        path = self.path()
        shape = (SIZE[2], SIZE[1], SIZE[0], CHANNELS)
        table = load_table(path, shape)
        if table is not None:
            self.last_source = "disk"
            self._texture = self._upload(table)
        else:
            self.last_source = "baked"
            self._texture = self._bake()
            save_table(path, read_table(self._texture))
        return self._texture

    def _upload(self, table: np.ndarray) -> moderngl.Texture:
        tex = self.ctx.texture3d(SIZE, CHANNELS, np.ascontiguousarray(table, np.float32).tobytes(), dtype="f4")
        tex.repeat_x = tex.repeat_y = tex.repeat_z = False
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        return tex

    def _bake(self) -> moderngl.Texture:
        tex = self._upload(np.zeros((SIZE[2], SIZE[1], SIZE[0], CHANNELS), np.float32))
        prog = self.shaders.compute("ibl/transmission_lut.comp")
        prog["u_size"] = SIZE
        prog["u_samples"] = SAMPLES
        tex.bind_to_image(0, read=False, write=True)
        prog.run((SIZE[0] + 7) // 8, (SIZE[1] + 7) // 8, SIZE[2])
        self.ctx.memory_barrier()
        return tex

    def release(self) -> None:
        if self._texture is not None:
            self._texture.release()
            self._texture = None
