"""The exact image-based-lighting answer of docs/conventions.md ("Ground truth for image-based lighting").

    L_o(n, v) = emissive + sum over the environment's texels t of f(l_t, v) L(l_t) max(n.l_t, 0) dOmega_t

with f exactly docs/conventions.md's Cook-Torrance BRDF: a = r^2, D = GGX, G = Schlick-GGX with
k = r^2/2 (the IBL k), F = Fresnel-Schlick at v.h *per light direction*, kd = (1 - F)(1 - metallic),
f = kd base/pi + D F G / (4 n.l n.v), F0 = mix(specular_f0, base, metallic). Texel directions and
solid angles are docs/conventions.md's (``alight.core.shading.texel_directions``): nothing is sampled, so the
answer is deterministic and is what every IBL approximation (the split sum, the GPU bake) is
measured against.

How it is computed. Since F = F0 + (1 - F0) Fc with Fc = (1 - v.h)^5, the outgoing radiance is
linear in four per-point sums over the texels (W_t = L_t dOmega_t, RGB):

    S1 = sum max(n.l, 0) W            S2 = sum max(n.l, 0) Fc W
    S3 = sum [n.l > 0] D G/(4 n.v) W   S4 = sum [n.l > 0] D G/(4 n.v) Fc W

    L_o = emissive + (1 - m) base/pi (1 - F0)(S1 - S2) + F0 S3 + (1 - F0) S4

S1 and S2 do not depend on the material at all, and S3, S4 only on the roughness, so one pass
over the texels (``ground_truth_terms``) serves any number of materials and several
roughness values. The texel sums are chunked over points: each chunk is a few (p, T) float32
arrays (T = texels), bounded by ``_CHUNK_ELEMS``, so memory stays well under 1.5 GB whatever the
number of points. n.l and l.v come from matmuls; v.h = sqrt((1 + l.v)/2) and
n.h = (n.l + n.v)/|l + v| need no per-texel vectors.

Guards:
- n.v is clamped to >= 1e-4 (the shaders' MIN_N_DOT_V): the view-dependent factor is then
  G1(n.v)/n.v = 1/(n.v (1 - k) + k) <= 1/k, finite for every roughness this module accepts.
- roughness must be >= ``MIN_ROUGHNESS`` (0.1). The GGX lobe's angular width is about
  alpha = r^2 radians in h, so about 2 r^2 in l: 0.02 rad at r = 0.1, while a texel of a
  1024x512 map spans 2 pi/1024 = 0.006 rad (0.012 rad at 512x256). Below r = 0.1 the lobe covers
  at most a few texels, the sum samples D at a handful of texel centres and stops being an
  integral (at r = 0 it is a delta: the mirror answer F L(reflect(-v, n)) is then the exact
  value, which is a lookup, not this sum). Smaller roughness is refused with ValueError rather
  than silently returning a wrong number. Even at r = 0.1 on a 512-wide map expect percent-level
  discretisation error near bright small sources; trust it fully from about r = 0.2 up.
- |l + v| is floored at 1e-7 (l = -v only happens for n.v < 0, where n.l > 0 can still hold).

Rotation and intensity: radiance arriving from world direction d is intensity times the map's
radiance in R_y(-deg) d (docs/conventions.md), so the map texel with map-space direction m lights
the world direction R_y(+deg) m = ``rotate_world_to_map(m, -deg)``; the texel sum runs over the
rotated texel directions with unchanged solid angles.

Cost (2 cores): about 0.1 us per point-texel pair for one roughness, e.g. a 32x32 probe
(~800 points) at 512x256 in ~3-4 s; each extra roughness in one call adds ~60% of that.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alight.core.shading import (
    PI,
    f0_of,
    probe_normals,
    rotate_world_to_map,
    texel_directions,
)

MIN_N_DOT_V = 1e-4  # shaders/common/brdf.glsl
MIN_ROUGHNESS = 0.1

# Points x texels per chunk: each (p, T) float32 temporary is at most 2**24 * 4 B = 64 MiB and a
# chunk holds about 8 of them at once (~0.5 GB peak).
_CHUNK_ELEMS = 1 << 24


def _texels(radiance, rotation_deg: float, intensity: float):
    """World-space texel directions (T, 3) float32 and W = L dOmega (T, 3) float32."""
    rad = np.asarray(radiance)
    if rad.ndim != 3 or rad.shape[2] != 3 or rad.shape[1] != 2 * rad.shape[0]:
        raise ValueError(f"expected an (H, 2H, 3) equirect radiance array, got {rad.shape}")
    h, w = rad.shape[:2]
    dirs, omega = texel_directions(h, w)
    dirs = dirs.reshape(-1, 3)
    if float(rotation_deg) != 0.0:
        dirs = rotate_world_to_map(dirs, -float(rotation_deg))  # map direction m -> world R_y(+deg) m
    wt = rad.reshape(-1, 3).astype(np.float64) * np.asarray(omega).reshape(-1, 1) * float(intensity)
    return np.ascontiguousarray(dirs, dtype=np.float32), np.ascontiguousarray(wt, dtype=np.float32)


def _unit_rows(d, n: int | None = None):
    d = np.asarray(d, dtype=np.float64)
    if d.ndim == 1:
        d = d[None, :]
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    if n is not None and d.shape[0] != n:
        d = np.ascontiguousarray(np.broadcast_to(d, (n, 3)))
    return d


def _check_roughness(r) -> float:
    r = float(r)
    if not np.isfinite(r) or r > 1.0 or r < 0.0:
        raise ValueError(f"roughness must be in [0, 1], got {r!r}")
    if r < MIN_ROUGHNESS - 1e-9:
        raise ValueError(f"roughness {r:g} < {MIN_ROUGHNESS}: the GGX lobe is narrower than a few texels and the "
                         "texel sum is no longer an integral (see alight.accuracy.ground_truth's docstring)")
    return r


@dataclass
class GroundTruthTerms:
    """The material-independent sums of the module docstring for P points.

    ``s1``, ``s2``: (P, 3); ``s3``, ``s4``: (R, P, 3), one per entry of ``roughness``.
    """

    roughness: tuple[float, ...]
    s1: np.ndarray
    s2: np.ndarray
    s3: np.ndarray
    s4: np.ndarray

    def diffuse_irradiance(self) -> np.ndarray:
        """E(n)/pi = S1/pi: the pure cosine-weighted irradiance (no Fresnel), (P, 3)."""
        return self.s1 / PI

    def combine(self, base_color, metallic, specular_f0, emissive=(0.0, 0.0, 0.0),
                roughness: float | None = None, parts: bool = False):
        """L_o (P, 3) for one material at one of the roughness values (default: the only one).

        With ``parts`` returns (diffuse, specular) without the emissive term instead.
        """
        if roughness is None:
            if len(self.roughness) != 1:
                raise ValueError("several roughness values were summed: say which one")
            i = 0
        else:
            matches = [j for j, r in enumerate(self.roughness) if abs(r - float(roughness)) < 1e-9]
            if not matches:
                raise ValueError(f"roughness {roughness} was not summed (have {self.roughness})")
            i = matches[0]
        base = np.asarray(base_color, dtype=np.float64)
        m = float(metallic)
        f0 = f0_of(base, m, np.asarray(specular_f0, dtype=np.float64))
        diffuse = (1.0 - m) * base / PI * (1.0 - f0) * (self.s1 - self.s2)
        specular = f0 * self.s3[i] + (1.0 - f0) * self.s4[i]
        if parts:
            return diffuse, specular
        return np.asarray(emissive, dtype=np.float64) + diffuse + specular


def ground_truth_terms(radiance, normals, views, roughness, rotation_deg: float = 0.0,
                       intensity: float = 1.0) -> GroundTruthTerms:
    """The sums S1..S4 (module docstring) for each point, at one or several roughness values.

    ``normals`` (P, 3); ``views`` one direction (3,) or (P, 3); ``roughness`` a scalar or a
    sequence (each in [MIN_ROUGHNESS, 1]). Computed in float32 per chunk, accumulated in float64
    across chunks (the matmuls accumulate in float32 blocks: relative error ~1e-6).
    """
    rs = tuple(_check_roughness(r) for r in np.atleast_1d(np.asarray(roughness, dtype=np.float64)))
    dirs, wt = _texels(radiance, rotation_deg, intensity)
    n = _unit_rows(normals)
    p = n.shape[0]
    v = _unit_rows(views, p)
    nv_all = np.maximum(np.sum(n * v, axis=-1), MIN_N_DOT_V)
    t = dirs.shape[0]
    s1 = np.zeros((p, 3))
    s2 = np.zeros((p, 3))
    s3 = np.zeros((len(rs), p, 3))
    s4 = np.zeros((len(rs), p, 3))
    step = max(1, _CHUNK_ELEMS // max(t, 1))
    n32, v32 = n.astype(np.float32), v.astype(np.float32)
    for a in range(0, p, step):
        sl = slice(a, min(p, a + step))
        nl = n32[sl] @ dirs.T                       # (p, T)
        lv = v32[sl] @ dirs.T                       # (p, T)
        nv = nv_all[sl].astype(np.float32)[:, None]  # (p, 1)
        lit = nl > 0.0
        nl_c = np.where(lit, nl, np.float32(0.0))
        # |l + v| = sqrt(2 + 2 l.v); v.h = (1 + l.v)/|l + v| = sqrt((1 + l.v)/2)
        one_lv = np.maximum(lv + np.float32(1.0), np.float32(0.0))
        del lv
        len_lv = np.sqrt(np.float32(2.0) * one_lv)
        vh = np.sqrt(np.float32(0.5) * one_lv)
        del one_lv
        fc = np.clip(np.float32(1.0) - vh, 0.0, 1.0) ** 5
        del vh
        s1[sl] += nl_c @ wt
        s2[sl] += (nl_c * fc) @ wt
        # n.h = (n.l + n.v_raw)/|l + v|, using the unclamped n.v (h is geometric)
        nv_raw = np.sum(n[sl] * v[sl], axis=-1).astype(np.float32)[:, None]
        nh = (nl + nv_raw) / np.maximum(len_lv, np.float32(1e-7))
        del len_lv
        nh2 = nh * nh
        del nh
        for i, r in enumerate(rs):
            a2 = np.float32(r ** 4)
            k = np.float32(r * r / 2.0)
            den = nh2 * (a2 - np.float32(1.0)) + np.float32(1.0)
            np.square(den, out=den)
            # D G / (4 n.l n.v) n.l = D G1(n.l) G1(n.v) / (4 n.v); G1(n.v)/n.v = 1/(n.v(1-k)+k)
            # G1(n.l) = n.l / (n.l (1 - k) + k), zero where n.l <= 0 (nl_c = 0 there).
            g1l = nl_c / (nl_c * (np.float32(1.0) - k) + k)
            spec = g1l / den
            del g1l, den
            spec *= (a2 / np.float32(4.0 * PI)) / (nv * (np.float32(1.0) - k) + k)
            s3[i, sl] += spec @ wt
            spec *= fc
            s4[i, sl] += spec @ wt
            del spec
        del nl, nl_c, lit, fc, nh2
    return GroundTruthTerms(rs, s1, s2, s3, s4)


def transmission_terms(radiance, normals, views, roughness, ior: float = 1.5, thin: bool = True,
                       rotation_deg: float = 0.0, intensity: float = 1.0) -> np.ndarray:
    """The transmitted light's texel sum S_T (docs/layer_transmission.md) for each point: (R, P, 3).

        S_T = sum over texels with n.l < 0 of btdf(l, v) (1 - Fc(v.h)) |n.l| W

    with the thin-walled BTDF (``thin``) or the refracting one at index ``ior`` (v outside, index
    1), k = r^2/2, Fc = (1 - v.h)^5 at the BTDF's own half vector (``alight.core.btdf``). Since
    1 - F = (1 - F0)(1 - Fc), the transmitted radiance is (1 - m) t c T (1 - F0) S_T: see
    ``transmission_combine``. Same chunking, guards and roughness limits as
    ``ground_truth_terms``; the refracting lobe is narrower than the reflected one by about
    (ior - 1) / (2 ior), so ``check_transmission_lobe`` refuses lobes under a texel's scale.
    """
    rs = tuple(_check_roughness(r) for r in np.atleast_1d(np.asarray(roughness, dtype=np.float64)))
    eta = float(ior)
    if not thin:
        for r in rs:
            check_transmission_lobe(r, eta)
    dirs, wt = _texels(radiance, rotation_deg, intensity)
    n = _unit_rows(normals)
    p = n.shape[0]
    v = _unit_rows(views, p)
    nv_raw_all = np.sum(n * v, axis=-1)
    nv_all = np.maximum(nv_raw_all, MIN_N_DOT_V)
    t = dirs.shape[0]
    out = np.zeros((len(rs), p, 3))
    step = max(1, _CHUNK_ELEMS // max(t, 1))
    n32, v32 = n.astype(np.float32), v.astype(np.float32)
    one = np.float32(1.0)
    for a in range(0, p, step):
        sl = slice(a, min(p, a + step))
        nl = n32[sl] @ dirs.T                       # (p, T)
        lv = v32[sl] @ dirs.T
        nv = nv_all[sl].astype(np.float32)[:, None]
        nv_raw = nv_raw_all[sl].astype(np.float32)[:, None]
        behind = nl < 0.0
        anl = np.where(behind, -nl, np.float32(0.0))   # |n.l| behind the surface, else 0
        if thin:
            # l' = l - 2 (n.l) n: n.l' = -n.l, v.l' = v.l - 2 (n.l)(n.v); h = normalize(v + l')
            vlm = lv - np.float32(2.0) * nl * nv_raw
            length = np.sqrt(np.maximum(np.float32(2.0) * (one + vlm), np.float32(0.0)))
            vh = np.sqrt(np.maximum(np.float32(0.5) * (one + vlm), np.float32(0.0)))
            nh = (-nl + nv_raw) / np.maximum(length, np.float32(1e-7))
            del vlm, length
            lh = None
        else:
            # h = -(v + eta l)/|v + eta l|: n.h, v.h, l.h from n.l and v.l
            e = np.float32(eta)
            length = np.sqrt(np.maximum(one + e * e + np.float32(2.0) * e * lv, np.float32(0.0)))
            inv = one / np.maximum(length, np.float32(1e-7))
            nh = -(nv_raw + e * nl) * inv
            vh = -(one + e * lv) * inv
            lh = -(lv + e) * inv
            del length, inv
        ok = behind & (nh > 0.0) & (vh > 0.0)
        if lh is not None:
            ok &= lh < 0.0
        fresnel = one - np.clip(one - vh, 0.0, 1.0) ** 5   # 1 - Fc
        nh2 = nh * nh
        for i, r in enumerate(rs):
            a2 = np.float32(r ** 4)
            k = np.float32(r * r / 2.0)
            den = nh2 * (a2 - one) + one
            np.square(den, out=den)
            # G1(|n.l|) |n.l| ... over (n.v): G1(n.v)/n.v = 1/(n.v (1 - k) + k)
            g1l = anl / (anl * (one - k) + k)
            view = (a2 / np.float32(PI)) / (nv * (one - k) + k)
            if thin:
                # D G / (4 |n.l| n.v) |n.l| = D G1(|n.l|) G1(n.v) / (4 n.v)
                value = g1l / den * (view / np.float32(4.0))
            else:
                # |l.h| |v.h| / (|n.l| n.v) eta^2 D G / (v.h + eta l.h)^2 |n.l|, where
                # (v.h + eta l.h)^2 = |v + eta l|^2 = 1 + eta^2 + 2 eta v.l
                len2 = one + np.float32(eta * eta) + np.float32(2.0 * eta) * lv
                value = (np.abs(lh) * vh) * np.float32(eta * eta) * g1l / den * view / np.maximum(len2, np.float32(1e-12))
            value = np.where(ok, value * fresnel, np.float32(0.0))
            out[i, sl] += value @ wt
            del value, den, g1l
        del nl, lv, behind, anl, nh, vh, lh, ok, fresnel, nh2
    return out


def dispersion_transmission_terms(radiance, normals, views, roughness, ior: float, dispersion: float,
                                  rotation_deg: float = 0.0, intensity: float = 1.0) -> np.ndarray:
    """KHR_materials_dispersion's S_T (R, P, 3) (docs/layer_dispersion.md): channel c of
    ``transmission_terms`` for the refracting BTDF at that channel's index
    (``alight.core.layers.dispersion.dispersion_iors``). Combine with
    ``transmission_combine`` as the undispersed S_T."""
    from alight.core.layers.dispersion import dispersion_iors

    iors = dispersion_iors(ior, dispersion)
    sums = [transmission_terms(radiance, normals, views, roughness, float(iors[c]), False, rotation_deg,
                               intensity)[..., c] for c in range(3)]
    return np.stack(sums, -1)


def check_transmission_lobe(roughness: float, ior: float) -> None:
    """The refracting lobe spans about alpha (ior - 1) / (2 ior) of the reflected lobe's alpha (at
    normal incidence, a facet tilted by theta bends the refracted ray by theta (1 - 1/ior), the
    reflected one by 2 theta): refuse lobes narrower than the reflected lobe at MIN_ROUGHNESS,
    where the texel sum stops being an integral (ValueError)."""
    r = float(roughness)
    eta = float(ior)
    if not np.isfinite(eta) or eta < 1.0:
        raise ValueError(f"ior must be >= 1 for a refracting volume, got {ior!r}")
    effective = r * r * (eta - 1.0) / (2.0 * eta)
    if effective < MIN_ROUGHNESS ** 2 * (1.0 - 1e-9):
        raise ValueError(f"roughness {r:g} at ior {eta:g}: the refracted lobe (alpha {effective:.2g}) is narrower than "
                         f"the reflected lobe at roughness {MIN_ROUGHNESS} and the texel sum is no longer an integral")


def transmission_combine(reflection: np.ndarray | tuple, s_t: np.ndarray, base_color, metallic, specular_f0,
                         transmission: float, attenuation=(1.0, 1.0, 1.0)) -> np.ndarray:
    """L_o with transmission (docs/layer_transmission.md): the reflected part with its diffuse scaled by
    (1 - transmission), plus (1 - m) t c T (1 - F0) S_T. ``reflection`` is ``GroundTruthTerms.combine
    (..., parts=True)``'s (diffuse, specular); ``s_t`` one roughness's (P, 3) of
    ``transmission_terms``; ``attenuation`` the Beer-Lambert transmittance T (RGB)."""
    diffuse, specular = reflection
    base = np.asarray(base_color, dtype=np.float64)
    m = float(metallic)
    t = float(transmission)
    f0 = f0_of(base, m, np.asarray(specular_f0, dtype=np.float64))
    transmitted = (1.0 - m) * t * base * np.asarray(attenuation, dtype=np.float64) * (1.0 - f0) * s_t
    return (1.0 - t) * diffuse + specular + transmitted


def reflectance_ground_truth(radiance, normals, views, base_color, metallic, roughness, specular_f0,
                             emissive=(0.0, 0.0, 0.0), rotation_deg: float = 0.0,
                             intensity: float = 1.0) -> np.ndarray:
    """docs/conventions.md's exact IBL answer L_o(n, v) for each point: (P, 3) float64.

    ``radiance``: (H, 2H, 3) equirect map (docs/conventions.md mapping); ``normals`` (P, 3);
    ``views`` (3,) or (P, 3), pointing from the surface to the eye; one material (roughness
    >= MIN_ROUGHNESS, else ValueError). ``rotation_deg`` and ``intensity`` as the renderer's
    env_rotation_deg and env_intensity.
    """
    terms = ground_truth_terms(radiance, normals, views, roughness, rotation_deg, intensity)
    return terms.combine(base_color, metallic, specular_f0, emissive)


# Pairs per chunk of the layered sum: each (p, T, 3) float64 temporary is at most 2**21 * 3 * 8 B
# = 48 MiB, and a layer holds a few at once.
_LAYERED_CHUNK_PAIRS = 1 << 21


def layered_ground_truth(radiance, normals, views, material, tangents=None, rotation_deg: float = 0.0,
                         intensity: float = 1.0) -> np.ndarray:
    """The exact answer L_o(n, v) (P, 3) float64 for a material with layers (docs/layers.md):
    emission through the coat plus the sum over the texels of the whole layered BRDF
    (``alight.core.layers.stack.layered_brdf_cos``) times W = L dOmega.

    Without the S1..S4 factorisation (layers are not linear in one F0), so every pair is
    evaluated: about 10x the cost of ``reflectance_ground_truth`` per point. ``tangents``
    (P, 3): the anisotropy's frame (default: the probe's, ``probe_tangents``). The base
    roughness and the layers' roughness must be >= MIN_ROUGHNESS where their lobes are narrow
    (each layer module says which).
    """
    from alight.core.layers.stack import Pairs, layered_brdf_cos, layered_emission, probe_tangents

    _check_roughness(material.roughness)
    if "clearcoat" in material.layers():
        try:
            _check_roughness(material.clearcoat_roughness)
        except ValueError as e:
            raise ValueError(f"clearcoat_roughness: {e}") from None
    dirs, wt = _texels(radiance, rotation_deg, intensity)
    dirs64, wt64 = dirs.astype(np.float64), wt.astype(np.float64)
    n = _unit_rows(normals)
    v = _unit_rows(views, n.shape[0])
    t = probe_tangents(n) if tangents is None else _unit_rows(tangents, n.shape[0])
    b = np.cross(n, t)
    out = np.zeros((n.shape[0], 3))
    step = max(1, _LAYERED_CHUNK_PAIRS // max(dirs.shape[0], 1))
    for a in range(0, n.shape[0], step):
        sl = slice(a, min(n.shape[0], a + step))
        pairs = Pairs(n=n[sl], v=v[sl], l=dirs64, t=t[sl], b=b[sl])
        f = layered_brdf_cos(material, pairs)                       # (p, T, 3)
        out[sl] = layered_emission(material, pairs) + np.einsum("ptc,tc->pc", f, wt64)
    return out


def anisotropic_ground_truth_terms(radiance, normals, views, tangents, cases, rotation_deg: float = 0.0,
                                   intensity: float = 1.0) -> list[GroundTruthTerms]:
    """The sums S1..S4 of the module docstring with the specular lobe of KHR_materials_anisotropy
    (docs/layer_anisotropy.md), one ``GroundTruthTerms`` per case.

    ``cases``: (roughness, anisotropy_strength, anisotropy_rotation) triples; ``tangents`` (P, 3)
    the tangent frame's t at each point (default: the probe's, ``stack.probe_tangents``), b =
    cross(n, t). The lobe is still linear in F0 (F = F0 (1 - Fc) + Fc), so ``combine`` gives any
    base colour, metallic and F0 from these sums: the numpy twin of what
    ``layered_ground_truth`` sums pair by pair, at a fraction of its cost (float32 matmuls per
    chunk, as ``ground_truth_terms``).
    """
    from alight.core.layers.anisotropy import anisotropic_alpha

    cases = [(_check_roughness(r), float(s), float(rot)) for r, s, rot in cases]
    dirs, wt = _texels(radiance, rotation_deg, intensity)
    n = _unit_rows(normals)
    p = n.shape[0]
    v = _unit_rows(views, p)
    if tangents is None:
        from alight.core.layers.stack import probe_tangents

        tangents = probe_tangents(n)
    t0 = _unit_rows(tangents, p)
    t0 = _unit_rows(t0 - n * np.sum(n * t0, -1, keepdims=True))
    b0 = np.cross(n, t0)
    nv_raw_all = np.sum(n * v, axis=-1)
    nv_all = np.maximum(nv_raw_all, MIN_N_DOT_V)
    t = dirs.shape[0]
    s1 = np.zeros((p, 3))
    s2 = np.zeros((p, 3))
    s3 = np.zeros((len(cases), p, 3))
    s4 = np.zeros((len(cases), p, 3))
    step = max(1, _CHUNK_ELEMS // max(t, 1) // 2)
    one = np.float32(1.0)
    for a in range(0, p, step):
        sl = slice(a, min(p, a + step))
        nl = n[sl].astype(np.float32) @ dirs.T
        lv = v[sl].astype(np.float32) @ dirs.T
        lit = nl > 0.0
        nl_c = np.where(lit, nl, np.float32(0.0))
        one_lv = np.maximum(lv + one, np.float32(0.0))
        del lv
        inv_len = one / np.maximum(np.sqrt(np.float32(2.0) * one_lv), np.float32(1e-7))
        fc = np.clip(one - np.sqrt(np.float32(0.5) * one_lv), 0.0, 1.0) ** 5
        del one_lv
        s1[sl] += nl_c @ wt
        s2[sl] += (nl_c * fc) @ wt
        nh = (nl + nv_raw_all[sl].astype(np.float32)[:, None]) * inv_len
        nv = nv_all[sl][:, None]
        for i, (r, strength, rot) in enumerate(cases):
            at, ab = (np.float32(x) for x in anisotropic_alpha(r, strength))
            c, s_ = np.cos(rot), np.sin(rot)
            td = c * t0[sl] + s_ * b0[sl]
            bd = np.cross(n[sl], td)
            tl = td.astype(np.float32) @ dirs.T
            bl = bd.astype(np.float32) @ dirs.T
            th = (tl + np.sum(td * v[sl], -1).astype(np.float32)[:, None]) * inv_len
            bh = (bl + np.sum(bd * v[sl], -1).astype(np.float32)[:, None]) * inv_len
            q = (th / at) ** 2 + (bh / ab) ** 2 + nh * nh
            del th, bh
            spec = np.float32(1.0 / (PI * float(at) * float(ab))) / (q * q)
            del q
            # G1(n.l) at l's projected alpha (k = alpha/2), zero where n.l <= 0.
            sin2 = np.maximum(tl * tl + bl * bl, np.float32(1e-12))
            k = np.float32(0.5) * np.sqrt((tl * tl * (at * at) + bl * bl * (ab * ab)) / sin2)
            del tl, bl, sin2
            spec *= nl_c / (nl_c * (one - k) + k)
            del k
            # G1(n.v) / (4 n.v) = 1 / (4 (n.v (1 - k_v) + k_v)), k_v at v's projected alpha.
            tv, bv = np.sum(td * v[sl], -1), np.sum(bd * v[sl], -1)
            sin2v = tv * tv + bv * bv
            alpha_v = np.where(sin2v >= 1e-12, np.sqrt((tv * tv * float(at) ** 2 + bv * bv * float(ab) ** 2)
                                                         / np.maximum(sin2v, 1e-12)), float(ab))
            kv = alpha_v[:, None] / 2.0
            spec *= (1.0 / (4.0 * (nv * (1.0 - kv) + kv))).astype(np.float32)
            s3[i, sl] += spec @ wt
            spec *= fc
            s4[i, sl] += spec @ wt
            del spec
        del nl, nl_c, lit, fc, nh, inv_len
    return [GroundTruthTerms((r,), s1, s2, s3[i:i + 1], s4[i:i + 1]) for i, (r, _, _) in enumerate(cases)]


def probe_points(width: int):
    """Normals (N, 3) of the probe pixels inside the disk and the (W, W) inside mask."""
    normals, inside = probe_normals(int(width))
    return normals[inside], inside


def probe_ground_truth(radiance, width: int, material, rotation_deg: float = 0.0, intensity: float = 1.0,
                       roughness=None) -> np.ndarray:
    """docs/conventions.md's probe view rendered exactly: (W, W, 3) float64, row 0 at the top.

    v = (0, 0, 1), n from ``alight.core.shading.probe_normals``, zeros outside the disk. ``material`` is
    an ``alight.core.material.Material`` (or anything with its fields); ``roughness`` overrides its
    roughness when given.
    """
    pts, inside = probe_points(width)
    r = material.roughness if roughness is None else roughness
    out = np.zeros(inside.shape + (3,))
    if getattr(material, "layers", None) and material.layers():
        import dataclasses

        m = material if roughness is None else dataclasses.replace(material, roughness=float(roughness))
        out[inside] = layered_ground_truth(radiance, pts, (0.0, 0.0, 1.0), m, None, rotation_deg, intensity)
        return out
    out[inside] = reflectance_ground_truth(radiance, pts, (0.0, 0.0, 1.0), material.base_color, material.metallic,
                                           r, material.specular_f0, material.emissive, rotation_deg, intensity)
    return out


def relative_error(render, reference, mask) -> float:
    """sum |render - reference| / sum |reference| over the masked pixels and the RGB channels.

    ``render`` may carry alpha ((H, W, 4)); only the first three channels count.
    """
    mask = np.asarray(mask, dtype=bool)
    a = np.asarray(render, dtype=np.float64)[..., :3][mask]
    b = np.asarray(reference, dtype=np.float64)[..., :3][mask]
    den = float(np.sum(np.abs(b)))
    if den == 0.0:
        raise ValueError("the reference is zero over the mask")
    return float(np.sum(np.abs(a - b)) / den)
