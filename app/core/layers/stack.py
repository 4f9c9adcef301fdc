"""The exact layered BRDF, pair by pair: the numpy twin of ``accuracy/ground_truth.glsl``'s
``brdf_ground_truth`` and ``common/layers.glsl``'s ``layered_light`` (docs/layers.md).

    base   = docs/conventions.md's Cook-Torrance, k = r^2/2, F per direction at v.h; its diffuse lobe
             scaled by 1 - transmission, plus the transmitted part (transmission.py), and by
             1 - diffuse_transmission, plus the back lobe (diffuse_transmission.py); its
             specular lobe anisotropic where the material says so (anisotropy.py), its
             Fresnel the thin film's where it has one (iridescence.py)
    sheen  = sheen BRDF + base * sheen albedo scaling                         (sheen.py)
    coated = clearcoat BRDF + sheen * (1 - clearcoat F_c(n_c.v))              (clearcoat.py)

Everything is per pair of a point (rows, P) and a light direction (columns, T): arrays (P, T)
and colours (P, T, 3), float64. ``Pairs`` holds the geometry and computes each dot product once.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from alight.core.layers import anisotropy, clearcoat, diffuse_transmission, iridescence, sheen, transmission
from alight.core.material import Material
from alight.core.shading import MIN_PUNCTUAL_ROUGHNESS, PI, D_GGX, F_Schlick, G1_SchlickGGX, k_ibl

MIN_N_DOT_V = 1e-4   # brdf.glsl


@dataclass
class Pairs:
    """P points x T directions. ``n``, ``v`` (P, 3) unit; ``l`` (T, 3) unit; the tangent
    frame ``t``, ``b`` (P, 3) (anisotropy; the probe's is ``probe_tangents``) and the
    coat's normal ``n_c`` (P, 3) where a layer needs them (n_c defaults to n)."""

    n: np.ndarray
    v: np.ndarray
    l: np.ndarray
    t: np.ndarray | None = None
    b: np.ndarray | None = None
    n_c: np.ndarray | None = None
    # A compact source's RMS angular radius (ibl.glsl: sun_layered): widens the GGX lobes to
    # alpha' = sqrt(alpha^2 + spread^2), floored at MIN_PUNCTUAL_ROUGHNESS; 0 for the exact sum.
    spread: float = 0.0
    _cache: dict = field(default_factory=dict, repr=False)

    def _get(self, key, make):
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def n_dot_l(self) -> np.ndarray:
        """(P, T), signed."""
        return self._get("nl", lambda: self.n @ self.l.T)

    @property
    def n_dot_v_raw(self) -> np.ndarray:
        """(P, 1), signed (the geometric half vector uses it)."""
        return self._get("nv_raw", lambda: np.sum(self.n * self.v, axis=-1)[:, None])

    @property
    def n_dot_v(self) -> np.ndarray:
        """(P, 1), clamped to MIN_N_DOT_V as the shaders clamp it."""
        return self._get("nv", lambda: np.maximum(self.n_dot_v_raw, MIN_N_DOT_V))

    @property
    def l_dot_v(self) -> np.ndarray:
        return self._get("lv", lambda: self.v @ self.l.T)

    @property
    def half_length(self) -> np.ndarray:
        """|l + v| (P, T), floored at 1e-7 as ground_truth.glsl floors it."""
        return self._get("hl", lambda: np.maximum(np.sqrt(np.maximum(2.0 + 2.0 * self.l_dot_v, 0.0)), 1e-7))

    @property
    def n_dot_h(self) -> np.ndarray:
        """n.h with h = (l + v)/|l + v| (P, T)."""
        return self._get("nh", lambda: (self.n_dot_l + self.n_dot_v_raw) / self.half_length)

    @property
    def v_dot_h(self) -> np.ndarray:
        """v.h = (1 + l.v)/|l + v|, clamped to [0, 1] (P, T)."""
        return self._get("vh", lambda: np.clip((1.0 + self.l_dot_v) / self.half_length, 0.0, 1.0))

    def dot_l(self, a: np.ndarray, key: str) -> np.ndarray:
        """a.l (P, T) for a per-point vector ``a`` (P, 3), cached under ``key``."""
        return self._get(key + ".l", lambda: a @ self.l.T)

    def dot_h(self, a: np.ndarray, key: str) -> np.ndarray:
        """a.h (P, T) for a per-point vector ``a`` (P, 3), cached under ``key``."""
        return self._get(key + ".h", lambda: (self.dot_l(a, key) + np.sum(a * self.v, -1)[:, None]) / self.half_length)

    @property
    def coat_normal(self) -> np.ndarray:
        return self.n if self.n_c is None else self.n_c


def base_brdf_cos(m: Material, p: Pairs) -> np.ndarray:
    """The base's f(l, v) max(n.l, 0) (P, T, 3), docs/conventions.md's BRDF with the IBL k; with
    transmission, the diffuse lobe scaled by 1 - transmission and the transmitted part added."""
    nl = p.n_dot_l
    lit = nl > 0.0
    nl_c = np.where(lit, nl, 0.0)
    f0 = np.asarray(m.f0(), np.float64)
    F = F_Schlick(p.v_dot_h, f0)                         # (P, T, 3)
    F_diffuse = F
    if "iridescence" in m.layers():
        F, F_diffuse = iridescence.iridescence_fresnels(m, p, F)
    kd = (1.0 - F_diffuse) * (1.0 - m.metallic)
    if "transmission" in m.layers():
        kd = kd * (1.0 - m.transmission)
    if "diffuse_transmission" in m.layers():
        kd = kd * diffuse_transmission.front_weight(m)
    if "anisotropy" in m.layers():
        specular_cos = anisotropy.anisotropic_specular(m, p, F, spread=p.spread) * nl_c[..., None]
    else:
        r = m.roughness
        lobe = r
        if p.spread > 0.0:   # a compact source (ibl.glsl: sun_light)
            r = max(r, MIN_PUNCTUAL_ROUGHNESS)
            lobe = max(float(np.sqrt(np.sqrt(m.roughness ** 4 + p.spread ** 2))), MIN_PUNCTUAL_ROUGHNESS)
        k = k_ibl(r)
        # D G / (4 n.l n.v) n.l = D G1(n.l) G1(n.v) / (4 n.v)
        dg = D_GGX(np.maximum(p.n_dot_h, 0.0) if p.spread > 0.0 else p.n_dot_h, lobe) \
            * G1_SchlickGGX(nl_c, k) * G1_SchlickGGX(p.n_dot_v, k)
        specular_cos = (dg / (4.0 * p.n_dot_v))[..., None] * F
    f = kd * (np.asarray(m.base_color) / PI) * nl_c[..., None] + specular_cos
    f = np.where(lit[..., None], f, 0.0)
    if "transmission" in m.layers():
        f = f + transmission.transmission_light(m, p)
    if "diffuse_transmission" in m.layers():
        f = f + diffuse_transmission.diffuse_transmission_light(m, p)
    return f


def layered_brdf_cos(m: Material, p: Pairs) -> np.ndarray:
    """The whole material's f(l, v) |n.l| (P, T, 3): the base with its layers over it
    (common/layers.glsl: layered_light, with docs/conventions.md's exact choices)."""
    f = base_brdf_cos(m, p)
    used = m.layers()
    if "sheen" in used:
        f = f * sheen.sheen_base_weight(m, p)[..., None] + sheen.sheen_light(m, p)
    if "clearcoat" in used:
        f = f * clearcoat.clearcoat_base_weight(m, p)[..., None] + clearcoat.clearcoat_light(m, p)
    return f


def layered_emission(m: Material, p: Pairs) -> np.ndarray:
    """Emission seen through the coat (P, 3) (common/layers.glsl: layered_emission)."""
    e = np.broadcast_to(np.asarray(m.emissive, np.float64), p.n.shape)
    if "clearcoat" in m.layers():
        e = e * clearcoat.clearcoat_base_weight(m, p)[..., :1]
    return e


def probe_tangents(normals) -> np.ndarray:
    """The probe view's tangents (..., 3) for its normals: the direction of increasing longitude
    about +Y, as the built-in sphere's u, +X at the poles (common/material_layers.glsl:
    probe_tangent_frame). The bitangent is cross(n, t)."""
    n = np.asarray(normals, np.float64)
    along = np.stack([n[..., 2], np.zeros(n.shape[:-1]), -n[..., 0]], axis=-1)
    length = np.linalg.norm(along, axis=-1, keepdims=True)
    return np.where(length > 1e-6, along / np.maximum(length, 1e-300), np.array([1.0, 0.0, 0.0]))
