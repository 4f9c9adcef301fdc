"""KHR_materials_anisotropy's image-based light against its exact answer, and its frame cost.
Prints the figures and writes results/anisotropy.md and results/anisotropy.csv; not a test.

    .venv/bin/python benchmarks/bench_anisotropy.py            # every shared 2:1 map (~30 min on 2 loaded cores)
    .venv/bin/python benchmarks/bench_anisotropy.py --quick    # royal_esplanade and venice_sunset

Error: the probe view (docs/conventions.md; the tangent is the probe's, docs/layers.md) rendered by
the GPU at the `medium` bake with the default IBL model, against the exact texel sum of
docs/layer_anisotropy.md (alight.accuracy.ground_truth.anisotropic_ground_truth_terms) over the
map reduced by 4, as sum |render - truth| / sum |truth| over the disk and RGB. Cases: roughness
0.3, 0.5, 0.7 x strength 0.5, 1 x rotation 0 (the stretch along the probe's longitude) and
pi/2 (along its meridians), for aluminium, gold and plastic_high's colours. Three lookups, the
same energy term (the anisotropy LUT) for all: `stretched` (the default), `round` (the
isotropic lookup at the material's roughness: what ignoring the stretch costs) and `bent`
(the Khronos sample viewer's bent normal), selected through anisotropy.glsl's
ANISOTROPY_LOOKUP in a copy of shaders/. spot1Lux is left out of the summary (its truth is
near zero over most of the ball), as in the README.

Frame cost: the material ball at 1280x720 with 3 point lights and the environment as background,
royal_esplanade at `medium`: aluminium without the layer, and brushed_aluminium's layer with
each lookup. Interleaved rounds (A B C D A B C D ...), render + finish, medians and ranges.
"""

from __future__ import annotations

import argparse
import csv
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks.bench_render import RESULTS, shared_environments  # noqa: E402

LOOKUPS = {"stretched": 0, "round": 1, "bent": 2}
CASES = [(r, s, rot) for r in (0.3, 0.5, 0.7) for s in (0.5, 1.0) for rot in (0.0, np.pi / 2)]
PRESETS = ("aluminium", "gold", "plastic_high")
PROBE = 32
EXEMPT = ("spot1Lux.hdr",)


def renderers():
    """One ForwardRenderer per lookup on one GL context, each with its own copy of shaders/."""
    from alight.core.gpu import ShaderLibrary
    from alight.paths import shader_dir
    from alight.render.renderer import ForwardRenderer

    main = ForwardRenderer()
    tmp = tempfile.TemporaryDirectory()
    out = {}
    for name, value in LOOKUPS.items():
        if value == 0:
            out[name] = main
            continue
        root = Path(tmp.name) / name / "shaders"
        shutil.copytree(shader_dir(), root)
        source = root / "common" / "anisotropy.glsl"
        source.write_text(source.read_text().replace("#define ANISOTROPY_LOOKUP 0", f"#define ANISOTROPY_LOOKUP {value}"))
        out[name] = ForwardRenderer(ctx=main.ctx, shaders=ShaderLibrary(main.ctx, root))
    return out, tmp


def errors(envs, rs):
    from alight.accuracy.converged import downsample_equirect
    from alight.accuracy.ground_truth import anisotropic_ground_truth_terms, probe_points
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.exchange.presets import load_preset

    pts, inside = probe_points(PROBE)
    rows = []
    presets = {p: load_preset(p) for p in PRESETS}
    for label, env in envs:
        t0 = time.perf_counter()
        terms = anisotropic_ground_truth_terms(downsample_equirect(env.radiance, 4), pts, (0.0, 0.0, 1.0), None, CASES)
        maps = rs["stretched"].bake(env, "medium")
        for (rough, strength, rot), term in zip(CASES, terms):
            for pname, p in presets.items():
                m = Material(base_color=p.base_color, metallic=p.metallic, specular_f0=p.specular_f0, roughness=rough,
                             anisotropy_strength=strength, anisotropy_rotation=rot)
                truth = term.combine(m.base_color, m.metallic, m.specular_f0)
                den = float(np.abs(truth).sum())
                for lookup, r in rs.items():
                    got = r.render(Scene(material=m, view="probe"), maps, PROBE, PROBE,
                                   read_srgb=False).linear[..., :3][inside]
                    rows.append(dict(environment=label, preset=pname, roughness=rough, strength=strength,
                                     rotation=round(rot, 4), lookup=lookup,
                                     relative_error=float(np.abs(got - truth).sum()) / den))
        print(f"  {label}: {time.perf_counter() - t0:.1f} s", flush=True)
    return rows


def frame_times(rs, repeats):
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment

    env = load_environment(str(REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"))
    maps = rs["stretched"].bake(env, "medium")
    lights = [Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
              Light(vector=(0.0, -2.0, 3.0), intensity=4.0)]
    mesh = sphere()
    variants = {"aluminium, no layer": (rs["stretched"], load_preset("aluminium"))}
    variants.update({f"brushed_aluminium, {k}": (r, load_preset("brushed_aluminium")) for k, r in rs.items()})
    scenes = {k: (r, Scene(mesh=mesh, material=m, lights=lights)) for k, (r, m) in variants.items()}

    def draw(r, scene):
        r.render(scene, maps, 1280, 720, aa="none", read_linear=False, read_srgb=False)
        r.ctx.finish()

    for r, scene in scenes.values():
        draw(r, scene)
    times = {k: [] for k in scenes}
    for _ in range(repeats):
        for k, (r, scene) in scenes.items():
            t = time.perf_counter()
            draw(r, scene)
            times[k].append(time.perf_counter() - t)
    return times


def report(rows, times, path_md: Path):
    envs = sorted({x["environment"] for x in rows})
    lookups = list(LOOKUPS)
    lines = ["# KHR_materials_anisotropy against its exact answer (probe, medium bake)", "",
             f"Relative error in percent, worst (and mean) over the {len(CASES)} cases (roughness 0.3/0.5/0.7 x "
             "strength 0.5/1 x rotation 0/pi/2) per map and preset, per lookup.", "",
             "| map | preset | " + " | ".join(f"{k} worst (mean)" for k in lookups) + " |",
             "|" + " --- |" * (len(lookups) + 2)]
    err = {(x["environment"], x["preset"], x["roughness"], x["strength"], x["rotation"], x["lookup"]): x["relative_error"]
           for x in rows}
    overall = {k: [] for k in lookups}
    for e in envs:
        for p in PRESETS:
            cells = []
            for k in lookups:
                vals = [v for key, v in err.items() if key[0] == e and key[1] == p and key[5] == k]
                cells.append(f"{100 * max(vals):.1f} ({100 * statistics.mean(vals):.1f})")
                if not any(e.startswith(x) for x in EXEMPT):
                    overall[k] += vals
            lines.append(f"| {e} | {p} | " + " | ".join(cells) + " |")
    lines += ["", "Over every map but spot1Lux: " + ", ".join(
        f"{k} worst {100 * max(v):.1f}%, mean {100 * statistics.mean(v):.1f}%" for k, v in overall.items() if v), ""]
    if times:
        ref = statistics.median(next(iter(times.values())))
        lines += ["## Frame time, 1280x720 ball + 3 point lights, royal_esplanade medium, no AA", "",
                  "| variant | median | range | / no layer |", "| --- | --- | --- | --- |"]
        for k, ts in times.items():
            med = statistics.median(ts)
            lines.append(f"| {k} | {1000 * med:.1f} ms | {1000 * min(ts):.1f}-{1000 * max(ts):.1f} ms | {med / ref:.2f} |")
        lines += ["", f"{len(next(iter(times.values())))} interleaved rounds on a shared 2-core machine; "
                  "the ratio is the figure to read."]
    text = "\n".join(lines) + "\n"
    path_md.write_text(text)
    print(text)


def masking_comparison() -> str:
    """A white metal's directional albedo with alight's masking (Schlick-GGX at the projected
    alpha) over the extension's (height-correlated Smith V), by a midpoint rule over the
    hemisphere: how far alight's BRDF departs from the extension's text (docs/layer_anisotropy.md)."""
    from alight.core.layers import anisotropy as an

    nt, nph = 300, 600
    th = (np.arange(nt) + 0.5) * (np.pi / 2 / nt)
    ph = (np.arange(nph) + 0.5) * (2 * np.pi / nph)
    T, P = np.meshgrid(th, ph, indexing="ij")
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    dw = (np.sin(T) * (np.pi / 2 / nt) * (2 * np.pi / nph)).reshape(-1)
    lines = ["| r | strength | n.v | azimuth | alight | extension | ratio |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in (0.3, 0.6):
        for s in (0.0, 0.5, 1.0):
            for mu in (0.9, 0.5, 0.2):
                for azimuth in (0.0, 90.0):
                    sn = np.sqrt(1 - mu * mu)
                    v = np.array([sn * np.cos(np.radians(azimuth)), sn * np.sin(np.radians(azimuth)), mu])
                    at, ab = an.anisotropic_alpha(r, s)
                    h = l + v
                    h /= np.linalg.norm(h, axis=-1, keepdims=True)
                    D = an.D_GGX_anisotropic(h[:, 0], h[:, 1], h[:, 2], at, ab)
                    nl = l[:, 2]
                    g = an.G1_anisotropic(mu, an.projected_alpha(v[0], v[1], at, ab), False) * \
                        an.G1_anisotropic(nl, an.projected_alpha(l[:, 0], l[:, 1], at, ab), False)
                    ours = float(np.sum(D * g / (4 * mu) * dw))
                    vis = 0.5 / (nl * np.sqrt((at * v[0]) ** 2 + (ab * v[1]) ** 2 + mu ** 2)
                                 + mu * np.sqrt((at * l[:, 0]) ** 2 + (ab * l[:, 1]) ** 2 + nl ** 2))
                    theirs = float(np.sum(D * vis * nl * dw))
                    lines.append(f"| {r} | {s} | {mu} | {azimuth:.0f} | {ours:.3f} | {theirs:.3f} | {ours / theirs:.3f} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="royal_esplanade and venice_sunset only")
    parser.add_argument("--repeats", type=int, default=11, help="interleaved frame-time rounds (0: none)")
    parser.add_argument("--masking", action="store_true", help="only print the masking comparison and exit")
    args = parser.parse_args(argv)
    if args.masking:
        print(masking_comparison())
        return 0
    rs, tmp = renderers()
    envs = shared_environments()
    if args.quick:
        envs = [(label, env) for label, env in envs if label.startswith(("royal_esplanade", "venice_sunset"))]
    rows = errors(envs, rs)
    RESULTS.mkdir(parents=True, exist_ok=True)
    suffix = "_quick" if args.quick else ""
    with open(RESULTS / f"anisotropy{suffix}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    times = frame_times(rs, args.repeats) if args.repeats > 0 else {}
    report(rows, times, RESULTS / f"anisotropy{suffix}.md")
    tmp.cleanup()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
