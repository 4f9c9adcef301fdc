"""The BRDF integration map (the lecture's integrate_brdf, k = r^2/2, plus the specular lobe's
mean directions t_A, t_B) against an independent deterministic quadrature of the same formulas
(alight.accuracy.converged.brdf_lut_converged and lobe_directions_converged)."""

import numpy as np
import pytest

from alight.accuracy.converged import (
    brdf_lut_converged,
    diffuse_fresnel,
    diffuse_fresnel_converged,
    lobe_directions_converged,
)
from alight.ibl.bake import QUALITY, LutCache, read_lut
from tests.gpu import renderer

# (n.v, roughness) points spread over the table, including grazing and the smooth end.
POINTS = [(0.02, 0.1), (0.05, 0.5), (0.1, 0.9), (0.25, 0.25), (0.5, 0.5), (0.5, 0.05),
          (0.75, 0.75), (0.9, 0.3), (1.0, 1.0), (0.99, 0.01), (0.3, 1.0), (0.6, 0.15)]


def lut_at_points(q):
    """The quality's LUT, its texels nearest POINTS, and those texels' centres (n.v, roughness):
    where the table was integrated."""
    lut = read_lut(renderer().luts.get(q.lut_size, q.lut_samples))
    s = q.lut_size
    cols = [min(s - 1, int(nv * s)) for nv, _ in POINTS]
    rows = [min(s - 1, int(rr * s)) for _, rr in POINTS]
    return lut, lut[rows, cols], (np.array(cols) + 0.5) / s, (np.array(rows) + 0.5) / s


@pytest.mark.parametrize("quality", ["low", "medium"])
def test_lut_matches_quadrature_at_texel_centres(quality):
    q = QUALITY[quality]
    lut, got, n_dot_v, rough = lut_at_points(q)
    a, b = brdf_lut_converged(n_dot_v, rough)
    # Tolerance: Hammersley quasi-Monte Carlo with N samples errs by O(log N / N); measured worst
    # over the whole table vs this quadrature: 3.3e-3 at N = 1024 (grazing n.v), more at N = 256.
    tol = 4e-3 if q.lut_samples >= 1024 else 1e-2
    np.testing.assert_allclose(got[:, 0], a, atol=tol)
    np.testing.assert_allclose(got[:, 1], b, atol=tol)
    assert np.isfinite(lut).all() and (lut >= 0).all()
    assert (lut[..., :2].sum(axis=2) <= 1.0 + 1e-3).all()    # single scattering never gains energy
    assert (lut[..., 2:] <= 1.0).all()                       # lerp factors between n and R


@pytest.mark.parametrize("quality", ["low", "medium"])
def test_lobe_directions_match_quadrature(quality):
    """t_A, t_B (where the lobe points, between n and R) against the quadrature's mean directions.
    A mean direction from N quasi-random samples is noisier than A and B where the lobe is wide
    and grazing, hence the looser tolerance; the shading tests bound what that costs."""
    q = QUALITY[quality]
    _, got, n_dot_v, rough = lut_at_points(q)
    t_a, t_b = lobe_directions_converged(n_dot_v, rough)
    tol = 0.02 if q.lut_samples >= 1024 else 0.04
    np.testing.assert_allclose(got[:, 2], t_a, atol=tol)
    np.testing.assert_allclose(got[:, 3], t_b, atol=tol)
    # The physics: a smooth lobe sits on R; a rough one leans toward n, the more so at grazing.
    assert lobe_directions_converged(0.5, 0.05)[0] > 0.99
    t_rough = lobe_directions_converged([0.2, 0.5, 0.8], 0.7)[0]
    assert (t_rough < 0.7).all() and t_rough[0] < t_rough[1] < t_rough[2]


def test_diffuse_fresnel_fit_matches_its_integral():
    """ibl.glsl's quartic for the Fresnel part of the Lambert lobe against the integral it fits."""
    nv = np.linspace(0.0, 1.0, 21)
    exact = diffuse_fresnel_converged(nv)
    np.testing.assert_allclose(diffuse_fresnel(nv), exact, atol=2e-5)
    assert 0.027 < exact[0] < 0.029 and exact[-1] < 1e-4   # grazing peak, vanishing head-on


def test_lut_is_cached_on_disk_and_a_corrupt_cache_is_rebaked(tmp_path, monkeypatch):
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(tmp_path))
    r = renderer()
    cache = LutCache(r.ctx, r.shaders)
    first = read_lut(cache.get(32, 64))
    assert cache.last_source == "baked"
    path = cache.path_for(32, 64)
    assert path.is_file() and path.parent == tmp_path
    again = LutCache(r.ctx, r.shaders)
    np.testing.assert_array_equal(read_lut(again.get(32, 64)), first)
    assert again.last_source == "disk"
    path.write_bytes(b"not a numpy file")
    third = LutCache(r.ctx, r.shaders)
    np.testing.assert_array_equal(read_lut(third.get(32, 64)), first)
    assert third.last_source == "baked"
    # The key includes the shader's hash: another size or sample count is another file.
    assert cache.path_for(32, 128) != path and cache.path_for(64, 64) != path
    for c in (cache, again, third):
        c.release()
