"""The BRDF integration map (the lecture's integrate_brdf, k = r^2/2) against an independent
deterministic quadrature of the same formula (app.converged.brdf_lut_converged)."""

import numpy as np
import pytest

from app.bake import QUALITY, LutCache
from app.converged import brdf_lut_converged
from tests.gpu import renderer

# (n.v, roughness) points spread over the table, including grazing and the smooth end.
POINTS = [(0.02, 0.1), (0.05, 0.5), (0.1, 0.9), (0.25, 0.25), (0.5, 0.5), (0.5, 0.05),
          (0.75, 0.75), (0.9, 0.3), (1.0, 1.0), (0.99, 0.01), (0.3, 1.0), (0.6, 0.15)]


def read_lut(tex, size):
    return np.frombuffer(tex.read(), np.float32).reshape(size, size, 2)


@pytest.mark.parametrize("quality", ["low", "medium"])
def test_lut_matches_quadrature_at_texel_centres(quality):
    q = QUALITY[quality]
    r = renderer()
    lut = read_lut(r.luts.get(q.lut_size, q.lut_samples), q.lut_size)
    s = q.lut_size
    cols = [min(s - 1, int(nv * s)) for nv, _ in POINTS]
    rows = [min(s - 1, int(rr * s)) for _, rr in POINTS]
    n_dot_v = (np.array(cols) + 0.5) / s       # texel centres: where the table was integrated
    rough = (np.array(rows) + 0.5) / s
    a, b = brdf_lut_converged(n_dot_v, rough)
    got = lut[rows, cols]
    # Tolerance: Hammersley quasi-Monte Carlo with N samples errs by O(log N / N); measured worst
    # over the whole table vs this quadrature: 3.3e-3 at N = 1024 (grazing n.v), more at N = 256.
    tol = 4e-3 if q.lut_samples >= 1024 else 1e-2
    np.testing.assert_allclose(got[:, 0], a, atol=tol)
    np.testing.assert_allclose(got[:, 1], b, atol=tol)
    assert np.isfinite(lut).all() and (lut >= 0).all()
    assert (lut.sum(axis=2) <= 1.0 + 1e-3).all()    # single scattering never gains energy


def test_lut_is_cached_on_disk_and_a_corrupt_cache_is_rebaked(tmp_path, monkeypatch):
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(tmp_path))
    r = renderer()
    cache = LutCache(r.ctx, r.shaders)
    first = read_lut(cache.get(32, 64), 32)
    assert cache.last_source == "baked"
    path = cache.path_for(32, 64)
    assert path.is_file() and path.parent == tmp_path
    again = LutCache(r.ctx, r.shaders)
    np.testing.assert_array_equal(read_lut(again.get(32, 64), 32), first)
    assert again.last_source == "disk"
    path.write_bytes(b"not a numpy file")
    third = LutCache(r.ctx, r.shaders)
    np.testing.assert_array_equal(read_lut(third.get(32, 64), 32), first)
    assert third.last_source == "baked"
    # The key includes the shader's hash: another size or sample count is another file.
    assert cache.path_for(32, 128) != path and cache.path_for(64, 64) != path
    for c in (cache, again, third):
        c.release()
