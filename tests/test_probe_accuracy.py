"""Probe renders of royal_esplanade_1k.hdr against a numpy twin of the *converged* split sum of
the same formulas (app/accuracy/converged.py): irradiance as E/pi summed over the map's texels, the
prefiltered radiance as the exact ratio of integrals the lecture's loop converges to (N = V = R,
weight n.l), the LUT by fine quadrature. What remains is the implementation's own error: sample
counts, cube resolution, the roughness grid's blending, the LUT's table.

Bounds (sum |render - ideal| / sum |ideal| over the disk) at the default quality: 2% on
royal_esplanade (no dominant sun) and 5% on quarry_01 (a sun holding half the map's power),
the project's targets. Measured here: royal dielectric 0.5%, metal 0.6-1.5%; quarry dielectric
0.1-0.3%, metal 0.4-0.9% (bright compact sources are added in closed form, app/ibl/sun.py). Run
with -s to see them. The metal is the hard case: its whole signal is the
prefiltered map, whose first rough step (r = 0.25) is the least sampled per solid angle. The
in-between roughness values (0.3, 0.75) are not grid steps: they measure the blending too.
"""

import numpy as np
import pytest

from alight.accuracy.converged import (
    brdf_lut_converged,
    downsample_equirect,
    ibl_converged,
    irradiance_converged,
    prefiltered_converged,
)
from alight.core import shading
from alight.core.material import Material
from alight.core.scene import Scene
from alight.ibl.environment import load_environment
from tests.gpu import renderer

WIDTH = 48
ROUGHNESS = [0.25, 0.3, 0.5, 0.75, 1.0]
MATERIALS = {
    "dielectric": Material(base_color=(0.8, 0.8, 0.8), metallic=0.0),
    "metal": Material(base_color=(1.0, 0.71, 0.29), metallic=1.0),
}


ENVIRONMENTS = {"royal_esplanade_1k.hdr": 0.02, "quarry_01_1k.hdr": 0.05}
_cache: dict = {}


def ideal_parts(shared_data, env_name, roughness):
    """The converged irradiance (per map) and prefiltered radiance (per map and roughness)."""
    if env_name not in _cache:
        env = load_environment(str(shared_data / "env" / env_name))
        n, inside = shading.probe_normals(WIDTH)
        normals = n[inside]
        _cache[env_name] = (env, inside, normals, irradiance_converged(env.radiance, normals), {})
    env, inside, normals, irradiance, prefiltered = _cache[env_name]
    if roughness not in prefiltered:
        reflected = shading.reflect(-np.array([0.0, 0.0, 1.0]), normals)
        prefiltered[roughness] = prefiltered_converged(env.radiance, reflected, roughness)
    return env, inside, normals, irradiance, prefiltered[roughness]


@pytest.mark.parametrize("env_name,roughness", [(e, r) for e in ENVIRONMENTS for r in ROUGHNESS
                                                if e == "royal_esplanade_1k.hdr" or r in (0.25, 0.5, 1.0)])
@pytest.mark.parametrize("name", list(MATERIALS))
def test_probe_within_bound_of_converged_split_sum(shared_data, env_name, name, roughness):
    env, inside, normals, irradiance, prefiltered = ideal_parts(shared_data, env_name, roughness)
    m = Material(base_color=MATERIALS[name].base_color, metallic=MATERIALS[name].metallic, roughness=roughness)
    r = renderer()
    maps = r.bake(env, "medium")
    got = r.render(Scene(material=m, view="probe", ibl_model="lecture"), maps, WIDTH, WIDTH).linear[..., :3][inside]

    n_dot_v = np.maximum(normals[:, 2], 0.0)
    f0 = shading.f0_of(m.base_color, m.metallic, m.specular_f0)
    F = shading.F_SchlickRoughness(n_dot_v, f0, roughness)
    kd = (1 - F) * (1 - m.metallic)
    a, b = brdf_lut_converged(n_dot_v, np.full_like(n_dot_v, roughness))
    ideal = kd * np.array(m.base_color) * irradiance + prefiltered * (F * a[:, None] + b[:, None])

    error = np.abs(got - ideal).sum() / np.abs(ideal).sum()
    bound = ENVIRONMENTS[env_name]
    print(f"{env_name} {name} r={roughness}: {error * 100:.2f}%")
    assert np.isfinite(got).all()
    assert error <= bound, f"{env_name} {name} r={roughness}: {error * 100:.2f}% > {bound * 100:.0f}%"


MODEL_CASES = [(e, r) for e in ENVIRONMENTS for r in (0.3, 0.5, 1.0)]


@pytest.mark.parametrize("env_name,roughness", MODEL_CASES)
@pytest.mark.parametrize("name", list(MATERIALS))
@pytest.mark.parametrize("model", ["alight", "stretched"])
def test_default_model_within_bound_of_its_converged_twin(shared_data, env_name, name, roughness, model):
    """The default model (alight), and `stretched` (its two fitted fetches, app/core/stretched_lobe.py),
    against alight.accuracy.converged.ibl_converged, its numpy twin with
    converged maps: the same bounds as the lecture's. This checks the shader's lobe directions,
    diffuse weight and exact compact sources, not only the bake. The twin sums over the map
    reduced by 2 (alight.accuracy.converged.downsample_equirect: <= 0.06% at r >= 0.25) to keep it fast.
    Measured: royal 0.5% (dielectric), 0.7-1.4% (metal); quarry 0.2-0.5%, 0.6-1.5%."""
    env = load_environment(str(shared_data / "env" / env_name))
    n, inside = shading.probe_normals(WIDTH)
    m = Material(base_color=MATERIALS[name].base_color, metallic=MATERIALS[name].metallic, roughness=roughness)
    ideal = ibl_converged(model, downsample_equirect(env.radiance, 2), n[inside], (0.0, 0.0, 1.0),
                          m.base_color, m.metallic, roughness, m.specular_f0)
    r = renderer()
    maps = r.bake(env, "medium")
    got = r.render(Scene(material=m, view="probe", ibl_model=model), maps, WIDTH, WIDTH).linear[..., :3][inside]
    error = np.abs(got - ideal).sum() / np.abs(ideal).sum()
    bound = ENVIRONMENTS[env_name]
    print(f"{model} {env_name} {name} r={roughness}: {error * 100:.2f}%")
    assert np.isfinite(got).all()
    assert error <= bound, f"{model} {env_name} {name} r={roughness}: {error * 100:.2f}% > {bound * 100:.0f}%"
