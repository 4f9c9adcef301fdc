"""The split sum's energy term for KHR_materials_anisotropy (``shaders/ibl/anisotropy_lut.comp``).

Two 3D tables over (n.v, roughness, strength): the ratio of the stretched lobe's A and B (the
BRDF LUT's scale and bias on F0) to the round lobe's, at four azimuths of the view from the
stretch direction (0, 30, 60, 90 degrees; ``common/anisotropy.glsl`` interpolates between
them). The image-based light of an anisotropic material is the round lobe's LUT times these
ratios (docs/layer_anisotropy.md). Like the BRDF LUT it depends on nothing but its size, sample
count and shader, so it is baked once per machine, kept in the user's cache folder, and only
when a scene draws an anisotropic material.
"""

from __future__ import annotations


import moderngl
import numpy as np

from alight.core.gpu import ShaderLibrary
from alight.ibl.table_files import load_table, save_table
from alight.paths import cache_dir

# (n.v, roughness, strength) texels and Hammersley samples per lobe and azimuth. Strength
# texels sit at k / (n - 1), so strength 0 is a texel centre (ratio exactly 1 there).
LUT_SIZE = (32, 16, 16)
LUT_SAMPLES = 1024
SHADER = "ibl/anisotropy_lut.comp"


class AnisotropyLut:
    """The two ratio textures (RGBA32F 3D, linear filtering), baked or read from disk on first use."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary, size=LUT_SIZE, samples: int = LUT_SAMPLES):
        self.ctx = ctx
        self.shaders = shaders
        self.size = tuple(int(x) for x in size)
        self.samples = int(samples)
        self._textures: tuple[moderngl.Texture, moderngl.Texture] | None = None
        self.last_source = ""   # 'memory', 'disk' or 'baked'

    def path(self):
        digest = self.shaders.digest(SHADER)[:16]
        nx, ny, nz = self.size
        return cache_dir() / f"anisotropy_lut-{nx}x{ny}x{nz}-{self.samples}-{digest}.npy"

    def textures(self) -> tuple[moderngl.Texture, moderngl.Texture]:
        """(ratio of A, ratio of B); each texel holds the four azimuths in RGBA."""
        if self._textures is not None:
            self.last_source = "memory"
            return self._textures
        path = self.path()
        shape = (2, self.size[2], self.size[1], self.size[0], 4)
        table = load_table(path, shape)
        if table is None:
            self.last_source = "baked"
            table = self._bake()
            save_table(path, table)
        else:
            self.last_source = "disk"
        self._textures = (self._upload(table[0]), self._upload(table[1]))
        return self._textures

    def table(self) -> np.ndarray:
        """(2, strength, roughness, n.v, 4) float32: the ratios of A and B as baked."""
        a, b = self.textures()
        return np.stack([_read(a, self.size), _read(b, self.size)])

    def _upload(self, data: np.ndarray) -> moderngl.Texture:
        tex = self.ctx.texture3d(self.size, 4, np.ascontiguousarray(data, np.float32).tobytes(), dtype="f4")
        tex.repeat_x = tex.repeat_y = tex.repeat_z = False
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        return tex

    def _bake(self) -> np.ndarray:
        zeros = np.zeros((self.size[2], self.size[1], self.size[0], 4), np.float32)
        a, b = self._upload(zeros), self._upload(zeros)
        prog = self.shaders.compute(SHADER)
        prog["u_size"] = self.size
        prog["u_samples"] = self.samples
        a.bind_to_image(0, read=False, write=True)
        b.bind_to_image(1, read=False, write=True)
        prog.run(*((n + 3) // 4 for n in self.size))
        self.ctx.memory_barrier()
        self.ctx.finish()
        table = np.stack([_read(a, self.size), _read(b, self.size)])
        a.release()
        b.release()
        return table

    def release(self) -> None:
        if self._textures is not None:
            for tex in self._textures:
                tex.release()
            self._textures = None


def _read(tex: moderngl.Texture, size) -> np.ndarray:
    return np.frombuffer(tex.read(), dtype=np.float32).reshape(size[2], size[1], size[0], 4).copy()
