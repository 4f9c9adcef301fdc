"""The glTF material's texture maps for the path tracer (app/accuracy/path_trace.py), on the CPU.

At a batch of hits (triangle, Embree's barycentrics u, v) the maps are read as the renderer's
mesh_material.glsl reads them: the uv set each textureInfo names (TEXCOORD_1 where the part has
it, else TEXCOORD_0), its KHR_texture_transform (alight.core.mesh.TextureTransform.gl_matrix, on
alight's OpenGL uvs), the sampler's wrap per axis (REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT folded
as the shader folds it), then

    base colour  = factor x texture (sRGB decoded per texel) x COLOR_0      (glTF 2.0 3.9.2)
    alpha        = factor's A x texture A x COLOR_0's A   (MASK: below alphaCutoff the hit is no surface)
    metallic     = factor x B,  roughness = factor x G of metallicRoughnessTexture (linear), clamped to [0, 1]
    emissive     = factor (x KHR_materials_emissive_strength) x texture (sRGB)
    normal       = normalTexture (2 x - 1, xy x scale) in the tangent frame about the shading normal
                   (the mesh's tangents, Gram-Schmidt, handedness w: mesh_material.glsl tangent_frame)
    clearcoat    = factor x clearcoatTexture R, its roughness factor x clearcoatRoughnessTexture G

Filtering: bilinear between the four nearest texels (nearest where the sampler's magFilter is
NEAREST), decoded to linear before the blend as an sRGB texture is on the GPU; no mipmaps. A
texture minified under a pixel is not prefiltered: the pixel's jittered samples land on different
texels, so the image converges to the box average over the pixel of the shading (what a pixel
sees), where the renderer's trilinear mip averages the texels first (the same for a colour,
which shades linearly; not for a roughness or a normal). Without jitter (TraceSettings.jitter
False) a minified texture aliases.

Not applied: the occlusion texture (baked ambient occlusion: the path tracer finds visibility
itself, so multiplying it in would darken twice), the layers' other maps (clearcoat normal,
transmission, specular, sheen, ... : ``untraced``), and alphaMode BLEND (drawn opaque).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alight.core.shading import srgb_to_linear

# The slots applied here, and the colour space of each (sRGB slots decode per texel).
TRACED_SLOTS = ("base_color", "metallic_roughness", "emissive", "normal", "clearcoat", "clearcoat_roughness")
SRGB_SLOTS = ("base_color", "emissive")
# Slots left out on purpose: baked occlusion would darken what the paths already occlude.
IGNORED_SLOTS = ("occlusion",)
# 8-bit texel -> linear value.
_SRGB_LUT = srgb_to_linear(np.arange(256) / 255.0)
_LINEAR_LUT = np.arange(256) / 255.0
# Re-casts past masked-out (and one-way) triangles before a ray stops where it is (foliage).
MASK_PASSES = 16


def _wrap_index(i, size: int, mode: str):
    if mode == "repeat":
        return np.mod(i, size)
    return np.clip(i, 0, size - 1)   # CLAMP_TO_EDGE, and MIRRORED_REPEAT after its fold


def sample_texture(image: np.ndarray, uv: np.ndarray, srgb: bool, wrap_s: str = "repeat", wrap_t: str = "repeat",
                   nearest: bool = False) -> np.ndarray:
    """An (H, W, 4) uint8 texture (row 0 the image's top) at OpenGL uvs (N, 2) (v = 0 the
    bottom row; texel centres at (i + 0.5) / W): (N, 4) float64 linear, RGB decoded from sRGB
    where ``srgb`` (A always linear), blended bilinearly after the decode (``nearest``: the
    nearest texel). Wrap modes: alight.core.mesh.WRAP_MODES, per axis."""
    h, w = image.shape[:2]
    uv = np.nan_to_num(np.asarray(uv, np.float64))
    u, v = uv[:, 0], uv[:, 1]
    # MIRRORED_REPEAT: the triangle wave of period 2 (mesh_material.glsl mirrored_repeat), then clamped
    if wrap_s == "mirrored_repeat":
        u = 1.0 - np.abs(np.mod(u, 2.0) - 1.0)
    if wrap_t == "mirrored_repeat":
        v = 1.0 - np.abs(np.mod(v, 2.0) - 1.0)
    x = u * w
    y = (1.0 - v) * h
    lut = _SRGB_LUT if srgb else _LINEAR_LUT

    def fetch(ix, iy):
        px = image[_wrap_index(iy, h, wrap_t), _wrap_index(ix, w, wrap_s)]
        out = np.empty(px.shape, np.float64)
        out[:, :3] = lut[px[:, :3]]
        out[:, 3] = _LINEAR_LUT[px[:, 3]]
        return out

    if nearest:
        return fetch(np.floor(x).astype(np.int64), np.floor(y).astype(np.int64))
    x -= 0.5
    y -= 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    ix, iy = x0.astype(np.int64), y0.astype(np.int64)
    top = fetch(ix, iy) * (1.0 - fx) + fetch(ix + 1, iy) * fx
    bottom = fetch(ix, iy + 1) * (1.0 - fx) + fetch(ix + 1, iy + 1) * fx
    return top * (1.0 - fy) + bottom * fy


@dataclass
class _Map:
    image: np.ndarray             # (H, W, 4) uint8
    srgb: bool
    tex_coord: int                # 0 or 1 (1 only where the part has TEXCOORD_1)
    matrix: np.ndarray | None     # (3, 3) KHR_texture_transform on OpenGL uvs
    wrap_s: str
    wrap_t: str
    nearest: bool

    def sample(self, uv0, uv1):
        uv = uv1 if self.tex_coord == 1 else uv0
        if self.matrix is not None:
            uv = uv @ self.matrix[:2, :2].T + self.matrix[:2, 2]
        return sample_texture(self.image, uv, self.srgb, self.wrap_s, self.wrap_t, self.nearest)


@dataclass
class _PartMaps:
    maps: dict                    # slot -> _Map (TRACED_SLOTS only)
    colors: bool                  # COLOR_0 multiplies base colour and alpha
    alpha: float                  # baseColorFactor's A
    cutoff: float | None          # alphaMode MASK's alphaCutoff, None: opaque
    metallic: float               # the factors, as the renderer clamps them after the maps
    roughness: float
    normal_scale: float


def part_maps(part, material, file_maps: bool, use_colors: bool) -> tuple[_PartMaps | None, set[str]]:
    """What of ``part``'s file material the path tracer draws (None: nothing per texel) and the
    names of the slots it has that are not traced (the occlusion texture is not among them: it is
    left out by design). ``material``: the alight.core.material.Material the part draws with and
    ``file_maps`` whether its file's maps apply (alight.render.variants.part_material: the
    scene's overrides are in its factors); ``use_colors``: COLOR_0 applies (file materials on)."""
    fm = part.material if file_maps else None
    colors = use_colors and part.colors is not None
    maps: dict = {}
    untraced: set[str] = set()
    has_uv1 = part.uvs1 is not None
    if fm is not None:
        for slot, info in fm.textures().items():
            if slot in IGNORED_SLOTS:
                continue
            if slot not in TRACED_SLOTS:
                untraced.add(slot)
                continue
            s = info.sampler
            maps[slot] = _Map(np.ascontiguousarray(info.image, np.uint8), slot in SRGB_SLOTS,
                              1 if info.tex_coord == 1 and has_uv1 else 0,
                              None if info.transform is None else np.asarray(info.transform.gl_matrix(), np.float64),
                              s.wrap_s, s.wrap_t, s.mag_filter == "nearest")
    cutoff = float(fm.alpha_cutoff) if fm is not None and fm.alpha_mode == "MASK" else None
    if not maps and not colors and cutoff is None:
        return None, untraced
    return _PartMaps(maps, colors, float(fm.alpha) if fm is not None else 1.0, cutoff, float(material.metallic),
                     float(material.roughness), float(fm.normal_scale) if fm is not None else 1.0), untraced


class SurfaceMaps:
    """The scene's per-part maps over the traced triangles: per-corner uvs, COLOR_0 and tangents
    (M, 3, k) in the path tracer's triangle order, and ``parts[material index]`` (a _PartMaps or
    None). Built by ``add`` per part in the order the triangles are concatenated, then ``finish``
    with the mask of degenerate triangles dropped."""

    def __init__(self):
        self.parts: list[_PartMaps | None] = []
        self._uv0, self._uv1, self._colors, self._tangents = [], [], [], []

    def add(self, part, tri: np.ndarray, pm: _PartMaps | None):
        """``tri`` (K, 3) the part's triangles' vertex indices; ``pm``: part_maps's."""
        self.parts.append(pm)
        k = len(tri)
        if pm is None:
            self._uv0.append(np.zeros((k, 3, 2), np.float32))
            self._uv1.append(np.zeros((k, 3, 2), np.float32))
            self._colors.append(np.ones((k, 3, 4), np.float32))
            self._tangents.append(np.zeros((k, 3, 4), np.float32))
            return
        self._uv0.append(np.asarray(part.uvs, np.float32)[tri])
        self._uv1.append(np.asarray(part.uvs1 if part.uvs1 is not None else part.uvs, np.float32)[tri])
        self._colors.append(np.asarray(part.colors, np.float32)[tri] if pm.colors else np.ones((k, 3, 4), np.float32))
        self._tangents.append(np.asarray(part.tangents, np.float32)[tri] if "normal" in pm.maps
                              else np.zeros((k, 3, 4), np.float32))

    def finish(self, keep: np.ndarray) -> "SurfaceMaps | None":
        """Concatenated, ``keep`` (M,) bool applied; None where no part has anything per texel."""
        if all(pm is None for pm in self.parts):
            return None
        self.uv0 = np.concatenate(self._uv0)[keep]
        self.uv1 = np.concatenate(self._uv1)[keep] if any(pm is not None and any(
            m.tex_coord == 1 for m in pm.maps.values()) for pm in self.parts) else None
        self.colors = np.concatenate(self._colors)[keep] if any(pm is not None and pm.colors for pm in self.parts) \
            else None
        self.tangents = np.concatenate(self._tangents)[keep] if any(
            pm is not None and "normal" in pm.maps for pm in self.parts) else None
        del self._uv0, self._uv1, self._colors, self._tangents
        return self

    def masked_triangles(self, material: np.ndarray) -> np.ndarray | None:
        """(M,) bool: the triangles of alphaMode MASK parts (None: there are none)."""
        masked = np.array([pm is not None and pm.cutoff is not None for pm in self.parts])
        return masked[material] if masked.any() else None

    @staticmethod
    def _lerp(corners, prim, bu, bv):
        c = corners[prim].astype(np.float64)
        return (1.0 - bu - bv)[:, None] * c[:, 0] + bu[:, None] * c[:, 1] + bv[:, None] * c[:, 2]

    def _uvs(self, prim, bu, bv):
        uv0 = self._lerp(self.uv0, prim, bu, bv)
        return uv0, (self._lerp(self.uv1, prim, bu, bv) if self.uv1 is not None else uv0)

    def cut_away(self, prim, bu, bv, material) -> np.ndarray:
        """(N,) bool: the hits on an alphaMode MASK part whose alpha is below its cutoff (no
        surface there: rays pass)."""
        out = np.zeros(len(prim), bool)
        for index in np.unique(material[prim]):
            pm = self.parts[index]
            if pm is None or pm.cutoff is None:
                continue
            rows = np.flatnonzero(material[prim] == index)
            alpha = np.full(len(rows), pm.alpha)
            if "base_color" in pm.maps:
                uv0, uv1 = self._uvs(prim[rows], bu[rows], bv[rows])
                alpha = alpha * pm.maps["base_color"].sample(uv0, uv1)[:, 3]
            if pm.colors:
                alpha = alpha * self._lerp(self.colors, prim[rows], bu[rows], bv[rows])[:, 3]
            out[rows] = alpha < pm.cutoff
        return out

    def shade(self, prim, bu, bv, m, n, base, metallic, roughness, emissive, coat, coat_rough, min_roughness: float):
        """The surface at hits (N,) on triangles ``prim`` of materials ``m``, n (N, 3) the shading
        normal facing the viewer, the other arrays the factors per hit (path_trace's table rows;
        coat arrays None where no part has a coat): the same arrays with the maps applied (new
        arrays; the inputs are not written)."""
        base, metallic, roughness, emissive, n = (x.copy() for x in (base, metallic, roughness, emissive, n))
        coat = None if coat is None else coat.copy()
        coat_rough = None if coat_rough is None else coat_rough.copy()
        for index in np.unique(m):
            pm = self.parts[index]
            if pm is None:
                continue
            rows = np.flatnonzero(m == index)
            p, u, v = prim[rows], bu[rows], bv[rows]
            if pm.maps:
                uv0, uv1 = self._uvs(p, u, v)
            maps = pm.maps
            if "base_color" in maps:
                base[rows] *= maps["base_color"].sample(uv0, uv1)[:, :3]
            if pm.colors:
                base[rows] *= self._lerp(self.colors, p, u, v)[:, :3]
            if "metallic_roughness" in maps:
                mr = maps["metallic_roughness"].sample(uv0, uv1)
                metallic[rows] = np.clip(pm.metallic * mr[:, 2], 0.0, 1.0)
                roughness[rows] = np.maximum(np.clip(pm.roughness * mr[:, 1], 0.0, 1.0), min_roughness)
            if "emissive" in maps:
                emissive[rows] *= maps["emissive"].sample(uv0, uv1)[:, :3]
            if coat is not None and "clearcoat" in maps:
                coat[rows] *= maps["clearcoat"].sample(uv0, uv1)[:, 0]
            if coat_rough is not None and "clearcoat_roughness" in maps:
                coat_rough[rows] = np.maximum(coat_rough[rows] * maps["clearcoat_roughness"].sample(uv0, uv1)[:, 1],
                                              min_roughness)
            if "normal" in maps:
                n[rows] = self._normal_mapped(maps["normal"].sample(uv0, uv1), pm.normal_scale, n[rows],
                                              self._lerp(self.tangents, p, u, v))
        return base, metallic, roughness, emissive, coat, coat_rough, n

    @staticmethod
    def _normal_mapped(texel, scale, n, tangent):
        """mesh_material.glsl normal_from_map: the texel's tangent-space normal about unit n."""
        t = tangent[:, :3] - n * np.einsum("ij,ij->i", n, tangent[:, :3])[:, None]
        tt = np.einsum("ij,ij->i", t, t)
        bad = tt < 1e-12
        if bad.any():   # a tangent along n (a broken file): any perpendicular
            axis = np.where((np.abs(n[bad, 1]) < 0.999)[:, None], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
            t[bad] = np.cross(axis, n[bad])
            tt = np.einsum("ij,ij->i", t, t)
        t = t / np.sqrt(np.maximum(tt, 1e-30))[:, None]
        b = np.cross(n, t) * np.where(tangent[:, 3] < 0.0, -1.0, 1.0)[:, None]
        m = texel[:, :3] * 2.0 - 1.0
        m[:, :2] *= scale
        mapped = m[:, 0:1] * t + m[:, 1:2] * b + m[:, 2:3] * n
        mm = np.einsum("ij,ij->i", mapped, mapped)
        return np.where((mm > 1e-12)[:, None], mapped / np.sqrt(np.maximum(mm, 1e-30))[:, None], n)
