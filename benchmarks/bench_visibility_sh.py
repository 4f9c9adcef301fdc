"""Directional visibility as spherical harmonics against the visible sky weight, per vertex, in numpy.

docs/explanation/occlusion.md named "directional visibility per vertex" (a few SH coefficients of
visibility from the bake's rays, the environment's SH irradiance integrated against them:
E_vis = integral L(w) V(w) max(n.w, 0) dw, an SH double product as in precomputed radiance
transfer) as the next step for the bowl under newport_loft. The visible sky weight
(alight.core.sky_weight) already estimates that same integral, by the rays themselves:
W E(n) = pi mean_rays free(l) L(l) over cosine-weighted rays. This script measures both against a
dense estimate of E_vis (REFERENCE_RAYS cosine-weighted rays a vertex, same environment texels),
on the refined vertices of a scene's bake:

- "sky weight": pi mean(free L) over the bake's 192 rays (W E(n), unsmoothed: the shader's term
  before the neighbour smoothing), and W as drawn (filled and smoothed, ``sky_weight``) times E(n);
- "SH order k": the transfer T(w) = free(w) max(n.w, 0) projected onto real SH bands 0..k-1
  from the same 192 rays (t_lm = pi mean(free Y_lm)), dotted with the environment's SH
  coefficients (from the 16x16-texel cube, solid-angle weighted): k = 2 (4 coefficients), 3 (9),
  4 (16); and the same with the transfer from the dense rays (the truncation alone, no ray noise);
- "V E(n)": the ambient-occlusion form, the share of directions times the whole irradiance.

Prints, per region (by the vertex normal), sum |est - ref| / sum ref and sum est / sum ref in
luminance. Asserts nothing.

    .venv/bin/python benchmarks/bench_visibility_sh.py [--scene bowl] [--maps newport_loft.hdr,...]
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ENV_DIR = HERE.parent.parent / "shared" / "data" / "env"
REFERENCE_RAYS = 4096
LUMA = np.array([0.2126, 0.7152, 0.0722])


def real_sh(d: np.ndarray, bands: int) -> np.ndarray:
    """(..., bands^2) real orthonormal spherical harmonics of unit directions ``d`` (..., 3), l < 4."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    out = [np.full_like(x, 0.282095)]
    if bands > 1:
        out += [0.488603 * y, 0.488603 * z, 0.488603 * x]
    if bands > 2:
        out += [1.092548 * x * y, 1.092548 * y * z, 0.315392 * (3 * z * z - 1), 1.092548 * x * z,
                0.546274 * (x * x - y * y)]
    if bands > 3:
        out += [0.590044 * y * (3 * x * x - y * y), 2.890611 * x * y * z, 0.457046 * y * (5 * z * z - 1),
                0.373176 * z * (5 * z * z - 3), 0.457046 * x * (5 * z * z - 1), 1.445306 * z * (x * x - y * y),
                0.590044 * x * (x * x - 3 * y * y)]
    return np.stack(out, axis=-1)


def environment_sh(texels: np.ndarray, bands: int) -> np.ndarray:
    """(bands^2, 3): the SH coefficients of the cube ``texels`` (6, S, S, 3), each texel weighted
    by its solid angle."""
    from alight.core.sky_weight import cube_texel_directions

    size = texels.shape[1]
    d = cube_texel_directions(size)
    c = 2.0 * (np.arange(size) + 0.5) / size - 1.0
    t, s = np.meshgrid(c, c, indexing="ij")
    area = (2.0 / size) ** 2 / (1.0 + s * s + t * t) ** 1.5
    w = np.broadcast_to(area, (6, size, size))
    y = real_sh(d, bands)
    return np.einsum("fijk,fij,fijc->kc", y, w, texels.astype(np.float64))


def measure(scene: str, maps: list[str]) -> None:
    from alight.accuracy.scenes import write_scene
    from alight.core import sky_weight as sw
    from alight.core.visibility import DEFAULT_RAYS, bake_visibility
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer
    from alight.render.visibility_parts import environment_texels

    folder = Path(tempfile.mkdtemp(prefix="alight-sh-"))
    write_scene(scene, folder)
    mesh = load_mesh(str(folder / f"{scene}.obj"))
    baked = bake_visibility(mesh)
    parts = baked.parts
    normals = np.concatenate([p.normals for p in parts])
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    v_bake = np.concatenate([p.visibility for p in parts])
    few = sw.sky_rays(parts, DEFAULT_RAYS)
    many = sw.sky_rays(parts, REFERENCE_RAYS)
    free_few = np.concatenate([f for f, _ in few]).astype(np.float64) / 255.0
    ang_few = np.concatenate([a for _, a in few]).astype(np.float64)
    free_many = np.concatenate([f for f, _ in many]).astype(np.float64) / 255.0
    ang_many = np.concatenate([a for _, a in many]).astype(np.float64)
    d_few = sw.ray_directions(normals, ang_few, free_few.shape[1])
    renderer = ForwardRenderer(bake_cache=None)
    regions = {"facing up (n.y > 0.7)": normals[:, 1] > 0.7, "sideways": np.abs(normals[:, 1]) <= 0.7,
               "all": np.ones(len(normals), bool)}
    print(f"{scene}: {len(normals)} refined vertices; rays {free_few.shape[1]} a vertex, reference {REFERENCE_RAYS}")
    for env_name in maps:
        env = load_environment(str(ENV_DIR / env_name))
        maps_ = renderer.bake(env, "medium")
        texels, _ = environment_texels(renderer.shaders, maps_)
        # The dense reference: pi mean(free L) over REFERENCE_RAYS cosine rays; E(n) likewise with free = 1.
        ref = np.zeros((len(normals), 3))
        e_n = np.zeros((len(normals), 3))
        sh_dense = {k: np.zeros((len(normals), 3)) for k in (2, 3, 4)}
        env_sh = {k: environment_sh(texels, k) for k in (2, 3, 4)}
        for s0 in range(0, len(normals), 256):
            s1 = min(s0 + 256, len(normals))
            d = sw.ray_directions(normals[s0:s1], ang_many[s0:s1], REFERENCE_RAYS)
            L = sw.cube_lookup(texels, d).astype(np.float64)
            f = free_many[s0:s1]
            ref[s0:s1] = math.pi * np.einsum("nr,nrc->nc", f, L) / REFERENCE_RAYS
            e_n[s0:s1] = math.pi * L.mean(axis=1)
            y = real_sh(d, 4)
            for k in (2, 3, 4):
                t = math.pi * np.einsum("nr,nrk->nk", f, y[..., :k * k]) / REFERENCE_RAYS
                sh_dense[k][s0:s1] = t @ env_sh[k]
        L_few = sw.cube_lookup(texels, d_few).astype(np.float64)
        rows = {"sky weight (192 rays)": math.pi * np.einsum("nr,nrc->nc", free_few, L_few) / free_few.shape[1]}
        smoothed = np.concatenate([sw.sky_weight(f, a, p.normals, p.indices.reshape(-1, 3), texels, positions=p.positions)
                                   for (f, a), p in zip(few, parts)])
        rows["sky weight, smoothed (as drawn)"] = smoothed[:, :3] * e_n
        y_few = real_sh(d_few, 4)
        for k in (2, 3, 4):
            t = math.pi * np.einsum("nr,nrk->nk", free_few, y_few[..., :k * k]) / free_few.shape[1]
            rows[f"SH order {k} ({k * k} coeff., 192 rays)"] = t @ env_sh[k]
        for k in (2, 3, 4):
            rows[f"SH order {k} ({k * k} coeff., {REFERENCE_RAYS} rays)"] = sh_dense[k]
        rows["V E(n) (AO)"] = v_bake[:, None] * e_n
        print(f"\n{env_name}")
        print("| estimate | " + " | ".join(f"{r}: err %, sum ratio" for r in regions) + " |")
        print("|---|" + "---|" * len(regions))
        ref_y = ref @ LUMA
        for name, est in rows.items():
            est_y = est @ LUMA
            cells = []
            for mask in regions.values():
                err = np.abs(est_y[mask] - ref_y[mask]).sum() / ref_y[mask].sum()
                cells.append(f"{100 * err:.1f}, {est_y[mask].sum() / ref_y[mask].sum():.3f}")
            print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="bowl")
    p.add_argument("--maps", default="newport_loft.hdr,royal_esplanade_1k.hdr")
    args = p.parse_args()
    measure(args.scene, [m for m in args.maps.split(",") if m])


if __name__ == "__main__":
    sys.exit(main())
