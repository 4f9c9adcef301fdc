"""KHR_materials_iridescence's numpy twins (shaders/common/iridescence_terms.glsl and
iridescence.glsl, same names; exact definition: docs/layer_iridescence.md).

A thin film of index ``iridescence_ior`` and thickness d (nm) over the base. Its Fresnel
F_film(n.v) is Belcour and Barla 2017's ("A Practical Extension to Microfacet Theory for the
Modeling of Varying Iridescence") Airy sum to the second order, with the CIE XYZ sensitivity
as their Gaussian fits in Fourier space, converted to linear Rec. 709; as the Khronos glTF
Sample Viewer evaluates it, at the view's n.v (one value per shading point) with the base's
F0 as the substrate. It replaces the base's Fresnel, mixed by the factor:

    F_specular = mix(F_Schlick(v.h), F_film(n.v), iridescence)
    F_diffuse  = mix(F_Schlick(v.h), max_rgb F_film(n.v), iridescence)   kd = (1 - F_diffuse)(1 - metallic)
    d          = mix(thickness_minimum, thickness_maximum, thicknessTexture.g)   (maximum without a map)

d = 0 is no film (the factor is then 0, as the Sample Viewer does). The diffuse lobe takes
the largest channel so that it never turns the film's colour into its complement.

One guard beyond the Sample Viewer: F_film is clamped to [0, 1], not only below. The Airy sum
converted to Rec. 709 leaves the gamut above 1 too (over 200 000 random cases of index,
thickness, angle and substrate: 3% of them, up to 2.19; over a 0.95 metal 7%, up to 1.22; over
F0 0.04 0.02%, up to 1.12), where a white furnace would reflect more than it receives.
"""

from __future__ import annotations

import numpy as np

from alight.core.shading import MIN_N_DOT_V, PI

# CIE XYZ to linear Rec. 709 (sRGB primaries, D65), as the Sample Viewer's XYZ_TO_REC709.
XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                          [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])
# Belcour and Barla's Gaussian fits of the XYZ sensitivities in Fourier space (their
# supplemental code): amplitude, position and variance per channel, and X's second lobe.
_SENSITIVITY_VAL = np.array([5.4856e-13, 4.4201e-13, 5.2481e-13])
_SENSITIVITY_POS = np.array([1.6810e+06, 1.7953e+06, 2.2084e+06])
_SENSITIVITY_VAR = np.array([4.3278e+09, 9.3046e+09, 6.6121e+09])
_SENSITIVITY_X2 = (9.7470e-14, 2.2399e+06, 4.5282e+09)
_SENSITIVITY_NORM = 1.0685e-7
# A film thinner than this (nm) fades to no film (the Sample Viewer's smoothstep).
FILM_FADE_NM = 0.03
MAX_SUBSTRATE_F0 = 0.9999   # F0 = 1 has no ior


def _f(x):
    return np.asarray(x, np.float64)


def ior_to_f0(transmitted_ior, incident_ior):
    """Normal-incidence reflectance of an interface: ((n_t - n_i) / (n_t + n_i))^2."""
    t, i = _f(transmitted_ior), _f(incident_ior)
    return ((t - i) / (t + i)) ** 2


def f0_to_ior(f0):
    """The inverse against air: (1 + sqrt(F0)) / (1 - sqrt(F0))."""
    s = np.sqrt(_f(f0))
    return (1.0 + s) / (1.0 - s)


def fresnel_schlick_scalar(f0, cos_theta):
    """Schlick 1994 with F90 = 1, for the film's two interfaces: f0 + (1 - f0)(1 - cos)^5."""
    x = np.clip(1.0 - _f(cos_theta), 0.0, 1.0)
    return _f(f0) + (1.0 - _f(f0)) * x ** 5


def iridescence_sensitivity(opd, shift):
    """The XYZ sensitivity at optical path difference ``opd`` (nm, shape S) with phase ``shift``
    (S + (3,)), in linear Rec. 709 (S + (3,)) (Belcour and Barla 2017, their Gaussian fits)."""
    phase = 2.0 * PI * _f(opd)[..., None] * 1.0e-9
    shift = _f(shift)
    xyz = _SENSITIVITY_VAL * np.sqrt(2.0 * PI * _SENSITIVITY_VAR) * np.cos(_SENSITIVITY_POS * phase + shift) \
        * np.exp(-phase ** 2 * _SENSITIVITY_VAR)
    a, pos, var = _SENSITIVITY_X2
    x2 = a * np.sqrt(2.0 * PI * var) * np.cos(pos * phase[..., 0] + shift[..., 0]) * np.exp(-var * phase[..., 0] ** 2)
    xyz = xyz + np.stack([x2, np.zeros_like(x2), np.zeros_like(x2)], axis=-1)
    return (xyz / _SENSITIVITY_NORM) @ XYZ_TO_REC709.T


def iridescence_fresnel(outside_ior, film_ior, cos_theta1, thickness, base_f0):
    """F_film (S + (3,)): the thin film's reflectance at cos theta1 (shape S) for a film of
    ``film_ior`` and ``thickness`` nm (S) over a substrate of F0 ``base_f0`` (S + (3,)), seen
    from a medium of ``outside_ior`` (Belcour and Barla 2017; the Sample Viewer's evalIridescence).
    Total internal reflection in the film gives 1; out-of-gamut values clamp to [0, 1] (the Sample
    Viewer clamps only below: its sum reaches 2.2 over metals at grazing, docs/layer_iridescence.md)."""
    cos1 = _f(cos_theta1)
    d = _f(thickness)
    x = np.clip(d / FILM_FADE_NM, 0.0, 1.0)
    film = outside_ior + (_f(film_ior) - outside_ior) * (x * x * (3.0 - 2.0 * x))   # smoothstep
    sin2_sq = (outside_ior / film) ** 2 * (1.0 - cos1 ** 2)
    cos2_sq = 1.0 - sin2_sq
    tir = cos2_sq < 0.0
    cos2 = np.sqrt(np.maximum(cos2_sq, 0.0))
    # The first interface (outside -> film): a phase flip of pi where the film is the lower index.
    r12 = fresnel_schlick_scalar(ior_to_f0(film, outside_ior), cos1)[..., None]
    t121 = 1.0 - r12
    phi12 = np.where(film < outside_ior, PI, 0.0)[..., None]
    phi21 = PI - phi12
    # The second interface (film -> substrate).
    base_ior = f0_to_ior(np.clip(_f(base_f0), 0.0, MAX_SUBSTRATE_F0))
    r23 = fresnel_schlick_scalar(ior_to_f0(base_ior, film[..., None]), cos2[..., None])
    phi23 = np.where(base_ior < film[..., None], PI, 0.0)
    opd = 2.0 * film * d * cos2
    phi = phi21 + phi23
    r123 = np.clip(r12 * r23, 1e-5, 0.9999)
    rs = t121 ** 2 * r23 / (1.0 - r123)
    out = r12 + rs                       # m = 0: the incoherent sum
    cm = rs - t121
    for m in (1, 2):                     # m > 0: the interference terms
        cm = cm * np.sqrt(r123)
        out = out + cm * 2.0 * iridescence_sensitivity(m * opd, m * phi)
    out = np.clip(out, 0.0, 1.0)
    return np.where(tir[..., None], 1.0, out)


def iridescence_thickness(m, thickness_map=None):
    """The film's thickness in nm: the maximum, or mix(minimum, maximum, the map's G)."""
    if thickness_map is None:
        return float(m.iridescence_thickness_maximum)
    g = _f(thickness_map)
    return m.iridescence_thickness_minimum + (m.iridescence_thickness_maximum - m.iridescence_thickness_minimum) * g


def iridescence_fresnel_at_view(m, n_dot_v, thickness=None):
    """F_film at the view (shape of n_dot_v + (3,)); n.v clamped to [MIN_N_DOT_V, 1]."""
    nv = np.clip(_f(n_dot_v), MIN_N_DOT_V, 1.0)
    d = iridescence_thickness(m) if thickness is None else thickness
    f0 = np.broadcast_to(np.asarray(m.f0(), np.float64), nv.shape + (3,))
    return iridescence_fresnel(1.0, m.iridescence_ior, nv, np.broadcast_to(_f(d), nv.shape), f0)


def iridescence_weight(m, thickness=None) -> float:
    """The factor the film mixes in with: iridescence, 0 where the film has no thickness."""
    d = iridescence_thickness(m) if thickness is None else thickness
    return float(m.iridescence) if np.all(_f(d) > 0.0) else 0.0


def iridescence_specular_fresnel(F, film_fresnel, weight):
    """The specular lobe's Fresnel: mix(F, F_film, weight)."""
    return _f(F) + (_f(film_fresnel) - _f(F)) * weight


def iridescence_diffuse_fresnel(F, film_fresnel, weight):
    """The diffuse lobe's Fresnel: mix(F, max_rgb F_film, weight)."""
    peak = np.max(_f(film_fresnel), axis=-1, keepdims=True)
    return _f(F) + (peak - _f(F)) * weight


def iridescence_fresnels(m, p, F):
    """(F_specular, F_diffuse) for ``alight.core.layers.stack.Pairs`` ``p`` and the base's
    Fresnel F (P, T, 3): the film at each point's n.v, (P, 1, 3) against T directions."""
    film = iridescence_fresnel_at_view(m, p.n_dot_v)          # (P, 1, 3)
    w = iridescence_weight(m)
    return iridescence_specular_fresnel(F, film, w), iridescence_diffuse_fresnel(F, film, w)


def iridescence_uniforms(m) -> dict[str, float]:
    """The uniforms of common/material_iridescence.glsl for material ``m`` (name -> value)."""
    return {"u_iridescence": float(m.iridescence), "u_iridescence_ior": float(m.iridescence_ior),
            "u_iridescence_thickness_minimum": float(m.iridescence_thickness_minimum),
            "u_iridescence_thickness_maximum": float(m.iridescence_thickness_maximum)}


def iridescence_ibl_weights(film_fresnel, weight, a, b, diffuse_weight, spec_albedo):
    """The split sum's (diffuse_weight, spec_albedo) with the film mixed in: F_film is constant
    over the lobe, so its specular albedo is F_film (A + B) and its diffuse weight
    1 - max_rgb F_film (common/iridescence.glsl). ``a``, ``b``: the BRDF LUT's scale and bias."""
    film = _f(film_fresnel)
    ab = (_f(a) + _f(b))[..., None]
    peak = np.max(film, axis=-1, keepdims=True)
    return (_f(diffuse_weight) + (1.0 - peak - _f(diffuse_weight)) * weight,
            _f(spec_albedo) + (film * ab - _f(spec_albedo)) * weight)
