"""Numpy twins of ``shaders/common/btdf.glsl``: the transmission BTDF of KHR_materials_transmission
(thin-walled) and KHR_materials_volume (refraction), and Beer-Lambert attenuation.

Each function has a GLSL function of the same name; ``tests/test_glsl_twins.py`` compares them.
Everything broadcasts over leading array dimensions, vectors in the last axis. ``v`` points from
the surface to the eye (outside, index of refraction 1), ``l`` toward where the light comes from:
for transmitted light it lies behind the surface, n.l < 0. The full definition, and how it is
measured, is ``docs/layer_transmission.md``.

- Thin-walled (``thickness`` 0, KHR_materials_transmission, "Transmission BTDF"): the reflection
  lobe mirrored through the surface plane, D(h) G / (4 |n.l| n.v) with h = normalize(v + l'),
  l' = l - 2 (n.l) n. Straight through (l = -v) gives h = n: no net bending.
- Volume (``thickness`` > 0, KHR_materials_volume, after Walter et al. 2007 "Microfacet Models
  for Refraction through Rough Surfaces", eq. 21, in the extension's form with v outside):
  |l.h| |v.h| / (|n.l| n.v) * ior^2 D(h) G / (v.h + ior l.h)^2 with h = -normalize(v + ior l).
  Integrated over l with |n.l| it gives 1 - F for a smooth surface: the ior^2 of entering and
  the 1/ior^2 of leaving the medium cancel, so it carries the environment's radiance as is.

G is docs/conventions.md's Schlick-GGX Smith term (the volume extension: "the same terms for G and D
as the microfacet BRDF"), with |n.l| for the light side, and the caller's k.
"""

from __future__ import annotations

import numpy as np

from alight.core.shading import MIN_N_DOT_V, D_GGX, G_Smith, _dot, _normalize

# Shared with btdf.glsl: |v + ior l| floor (l = -v at ior 1, where refraction bends nothing).
MIN_HALF_LENGTH = 1e-7


def mirror_through_surface(l, n):
    """l - 2 (n.l) n: a direction behind the surface brought to the front (thin-walled BTDF)."""
    l = np.asarray(l, dtype=np.float64)
    n = np.asarray(n, dtype=np.float64)
    return l - 2.0 * _dot(n, l)[..., None] * n


def half_vector_thin(n, v, l):
    """KHR_materials_transmission's transmission half vector normalize(v + l - 2 (n.l) n)."""
    return _normalize(np.asarray(v, dtype=np.float64) + mirror_through_surface(l, n))


def half_vector_refraction(v, l, ior):
    """Walter et al. 2007's h_t = -normalize(v + ior l) (v outside, index 1; l inside, index ior).
    It points outside (n.h > 0) for a real refraction when ior > 1."""
    s = np.asarray(v, dtype=np.float64) + np.asarray(ior, dtype=np.float64)[..., None] * np.asarray(l, dtype=np.float64)
    length = np.maximum(np.linalg.norm(s, axis=-1, keepdims=True), MIN_HALF_LENGTH)
    return -s / length


def btdf_thin(n_dot_v, n_dot_l, n_dot_h, roughness, k):
    """D(h) G / (4 |n.l| n.v), h = half_vector_thin (KHR_materials_transmission's specular_btdf
    without its Fresnel and tint). n.v must be > 0; n.l < 0 for transmitted light."""
    n_dot_v = np.asarray(n_dot_v, dtype=np.float64)
    nl = np.abs(np.asarray(n_dot_l, dtype=np.float64))
    return D_GGX(np.maximum(n_dot_h, 0.0), roughness) * G_Smith(n_dot_v, nl, k) / (4.0 * np.maximum(nl, 1e-8) * n_dot_v)


def btdf_refraction(n_dot_v, n_dot_l, n_dot_h, v_dot_h, l_dot_h, roughness, ior, k):
    """Walter et al. 2007's microfacet BTDF as KHR_materials_volume writes it, without its Fresnel
    and tint: |l.h| |v.h| / (|n.l| n.v) ior^2 D G / (v.h + ior l.h)^2, h = half_vector_refraction.
    Zero unless the microfacet faces both sides correctly (n.h > 0, v.h > 0, l.h < 0)."""
    n_dot_v = np.asarray(n_dot_v, dtype=np.float64)
    nl = np.abs(np.asarray(n_dot_l, dtype=np.float64))
    vh = np.asarray(v_dot_h, dtype=np.float64)
    lh = np.asarray(l_dot_h, dtype=np.float64)
    eta = np.asarray(ior, dtype=np.float64)
    ok = (np.asarray(n_dot_h) > 0.0) & (vh > 0.0) & (lh < 0.0)
    denominator = np.maximum((vh + eta * lh) ** 2, 1e-12)
    value = (np.abs(lh) * vh / (np.maximum(nl, 1e-8) * n_dot_v)) * eta * eta \
        * D_GGX(np.maximum(n_dot_h, 0.0), roughness) * G_Smith(n_dot_v, nl, k) / denominator
    return np.where(ok, value, 0.0)


def beer_lambert(attenuation_color, attenuation_distance, distance):
    """Transmittance over ``distance`` in a medium that leaves ``attenuation_color`` of white light
    after ``attenuation_distance`` (KHR_materials_volume): c^(distance / attenuation_distance),
    i.e. exp(-sigma distance) with sigma = -ln(c) / attenuation_distance. An infinite
    attenuation distance (the default) or zero distance gives 1; a zero colour channel gives 0."""
    c = np.asarray(attenuation_color, dtype=np.float64)
    ratio = np.asarray(distance, dtype=np.float64) / np.asarray(attenuation_distance, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return np.where(ratio > 0.0, np.power(c, ratio), 1.0)


def refract(i, n, eta):
    """GLSL refract(): the incident direction i bent at a surface with normal n for the ratio of
    indices eta = n_from / n_to; zero on total internal reflection."""
    i = np.asarray(i, dtype=np.float64)
    n = np.asarray(n, dtype=np.float64)
    eta = np.asarray(eta, dtype=np.float64)
    d = _dot(n, i)
    k = 1.0 - eta * eta * (1.0 - d * d)
    out = eta[..., None] * i - (eta * d + np.sqrt(np.maximum(k, 0.0)))[..., None] * n
    return np.where((k >= 0.0)[..., None], out, 0.0)


def transmission_btdf(n, v, l, roughness, k, ior, thin):
    """The BTDF (without Fresnel and tint) at unit n, v, l: the thin-walled one where ``thin``,
    else the refracting one at ``ior``; zero unless n.l < 0. Returns (btdf, v_dot_h), v.h at the
    BTDF's own half vector (clamped to [0, 1]), for the Fresnel term."""
    n, v, l = (np.asarray(x, dtype=np.float64) for x in (n, v, l))
    n_dot_v = np.maximum(_dot(n, v), MIN_N_DOT_V)
    n_dot_l = _dot(n, l)
    thin = np.asarray(thin, dtype=bool)
    h = np.where(thin[..., None], half_vector_thin(n, v, l), half_vector_refraction(v, l, ior))
    n_dot_h, v_dot_h, l_dot_h = _dot(n, h), _dot(v, h), _dot(l, h)
    value = np.where(thin, btdf_thin(n_dot_v, n_dot_l, n_dot_h, roughness, k),
                     btdf_refraction(n_dot_v, n_dot_l, n_dot_h, v_dot_h, l_dot_h, roughness, ior, k))
    return np.where(n_dot_l < 0.0, value, 0.0), np.clip(v_dot_h, 0.0, 1.0)
