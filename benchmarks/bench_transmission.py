"""The transmission layer (KHR_materials_transmission, _volume, _ior) against its exact answer, per
shared map: the real-time error the README and docs/layer_transmission.md report. Prints the
figures and writes results/transmission.csv and results/transmission.md; not a test.

    python benchmarks/bench_transmission.py            # every shared 2:1 map (~30 min on 2 loaded cores)
    python benchmarks/bench_transmission.py --quick    # two maps, two roughness values

Materials: the four transmissive presets (water, plastic_glass_low, glass_high_ruby, diamond:
volumes) and a thin-walled white glass (ior 1.5, transmission 1, no volume), at roughness 0.3,
0.5, 0.7 and 1 (the presets are polished at 0.05, below what a texel sum can judge). A volume's
roughness is left out where its refracted lobe is too narrow for the texel sum
(alight.accuracy.ground_truth.check_transmission_lobe: water and plastic_glass_low at 0.3).

Error: the probe view rendered by the GPU at the `medium` bake with the default IBL model,
against the exact texel sum (app/accuracy/ground_truth.py: ground_truth_terms and
transmission_terms, the map reduced by 2), as sum |render - truth| / sum |truth| over the disk
and RGB. Beside it, the Khronos Sample Viewer's approach with converged maps (numpy): the
transmitted weight 1 - (F0 A + B), one fetch along refract(-v, n, 1/ior) (straight through for a
thin wall) at roughness r clamp(2 ior - 2, 0, 1), alight's prefiltered radiance standing in for
its framebuffer's mips; the reflected part is alight's (ibl_converged), so the column differs
only in the transmitted part.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.bench_render import RESULTS, section, shared_environments  # noqa: E402

ROUGHNESS = (0.3, 0.5, 0.7, 1.0)
PROBE = 32
PRESETS = ("water", "plastic_glass_low", "glass_high_ruby", "diamond")
EXEMPT = ("spot1Lux.hdr",)


def materials():
    from alight.core.material import Material
    from alight.exchange.presets import load_preset

    out = {name: load_preset(name) for name in PRESETS}
    out["thin glass"] = Material(base_color=(1.0, 1.0, 1.0), roughness=0.3, transmission=1.0, ior=1.5, name="thin glass")
    return out


def sample_viewer_transmitted(radiance, pts, m):
    """The Sample Viewer's transmitted part with converged maps (module docstring)."""
    from alight.accuracy.converged import brdf_lut_converged, prefiltered_converged
    from alight.core.btdf import beer_lambert, refract

    v = np.array([0.0, 0.0, 1.0])
    nv = np.clip(pts[:, 2], 0.0, 1.0)
    a, b = brdf_lut_converged(nv, m.roughness)
    f0 = np.asarray(m.f0())
    weight = (1.0 - (f0 * a[:, None] + b[:, None])) * (1.0 - m.metallic) * m.transmission * np.asarray(m.base_color)
    volume = "volume" in m.layers()
    if volume:
        weight = weight * beer_lambert(m.attenuation_color, m.attenuation_distance, m.thickness)
        direction = refract(np.broadcast_to(-v, pts.shape), pts, np.full(len(pts), 1.0 / m.ior))
    else:
        direction = np.broadcast_to(-v, pts.shape)
    rough = m.roughness * min(max(2.0 * m.ior - 2.0, 0.0), 1.0)
    return weight * prefiltered_converged(radiance, direction, max(rough, 0.05))


def errors(envs, roughnesses):
    import dataclasses

    from alight.accuracy.converged import downsample_equirect, ibl_converged
    from alight.accuracy.ground_truth import (
        check_transmission_lobe,
        ground_truth_terms,
        probe_points,
        transmission_combine,
        transmission_terms,
    )
    from alight.core.btdf import beer_lambert
    from alight.core.scene import Scene
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    pts, inside = probe_points(PROBE)
    v = (0.0, 0.0, 1.0)
    rows = []
    for label, env in envs:
        t0 = time.perf_counter()
        radiance = downsample_equirect(env.radiance, 2)
        terms = ground_truth_terms(radiance, pts, v, roughnesses)
        maps = r.bake(env, "medium")
        for name, base in materials().items():
            volume = "volume" in base.layers()
            rs = []
            for rough in roughnesses:
                try:
                    if volume:
                        check_transmission_lobe(rough, base.ior)
                    rs.append(rough)
                except ValueError:
                    pass
            if not rs:
                continue
            s_t = transmission_terms(radiance, pts, v, rs, base.ior, not volume)
            attenuation = beer_lambert(base.attenuation_color, base.attenuation_distance, base.thickness) if volume else 1.0
            for i, rough in enumerate(rs):
                m = dataclasses.replace(base, roughness=rough)
                reflected = terms.combine(m.base_color, m.metallic, m.specular_f0, roughness=rough, parts=True)
                truth = transmission_combine(reflected, s_t[i], m.base_color, m.metallic, m.specular_f0, m.transmission,
                                             attenuation)
                den = float(np.abs(truth).sum())
                got = r.render(Scene(material=m, view="probe"), maps, PROBE, PROBE, read_srgb=False).linear[..., :3][inside]
                sv = ibl_converged("alight", radiance, pts, v, m.base_color, m.metallic, rough, m.specular_f0,
                                   diffuse_scale=1.0 - m.transmission) + sample_viewer_transmitted(radiance, pts, m)
                rows.append(dict(environment=label, material=name, roughness=rough,
                                 alight=float(np.abs(got - truth).sum()) / den,
                                 sample_viewer=float(np.abs(sv - truth).sum()) / den))
                # as it goes: a long run on a loaded machine still leaves its finished cases
                print(f"  {label:28s} {name:18s} r={rough:<4g} alight {100 * rows[-1]['alight']:6.2f}%  "
                      f"sample viewer's {100 * rows[-1]['sample_viewer']:6.2f}%", flush=True)
        maps.release()
        print(f"  {label}: {time.perf_counter() - t0:.1f} s", flush=True)
    r.release()
    return rows


def report(rows, path: Path) -> None:
    envs = list(dict.fromkeys(x["environment"] for x in rows))
    names = list(dict.fromkeys(x["material"] for x in rows))
    lines = ["Worst relative error over roughness (0.3, 0.5, 0.7, 1 where the texel sum can judge the lobe), "
             "alight / the Sample Viewer's approach, in percent:", "",
             "| map | " + " | ".join(names) + " |", "| --- |" + " --- |" * len(names)]
    for e in envs:
        cells = []
        for n in names:
            sel = [x for x in rows if x["environment"] == e and x["material"] == n]
            if not sel:
                cells.append("")
                continue
            cells.append(f"{100 * max(x['alight'] for x in sel):.1f} / {100 * max(x['sample_viewer'] for x in sel):.0f}")
        lines.append(f"| {e} | " + " | ".join(cells) + " |")
    judged = [x for x in rows if not any(e in x["environment"] for e in EXEMPT)]
    if judged:
        lines += ["", f"Mean over every case ({', '.join(EXEMPT)} aside): alight "
                      f"{100 * np.mean([x['alight'] for x in judged]):.1f}%, the Sample Viewer's approach "
                      f"{100 * np.mean([x['sample_viewer'] for x in judged]):.1f}%."]
    path.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    envs = shared_environments()
    roughnesses = ROUGHNESS
    if args.quick:
        envs = [e for e in envs if e[0].startswith(("royal", "venice"))]
        roughnesses = (0.5, 1.0)
    section("Transmission vs its exact answer (probe 32x32, medium bake, truth over the map reduced by 2)")
    rows = errors(envs, roughnesses)
    suffix = "_quick" if args.quick else ""
    RESULTS.mkdir(exist_ok=True)
    with open(RESULTS / f"transmission{suffix}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    report(rows, RESULTS / f"transmission{suffix}.md")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
