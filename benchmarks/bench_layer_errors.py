"""The clearcoat's and the sheen's real-time error against their exact answers (docs/layer_clearcoat.md,
docs/layer_sheen.md), on every shared 2:1 map; prints the figures and writes
results/layer_errors.csv and results/layer_errors.md. Not a test.

    python benchmarks/bench_layer_errors.py            # every shared map (~30 min on 2 loaded cores)
    python benchmarks/bench_layer_errors.py --quick    # royal_esplanade and quarry_01 only

Error: the probe view (docs/conventions.md) rendered by the GPU at the `medium` bake with the default
IBL model (alight), against `alight reference` (the GPU texel sum of the layered BRDF; the map at
level 0, or 1 where reference.py's choose_env_level allows), as sum |render - truth| /
sum |truth| over the disk and RGB. Each layered case is printed beside the same material
without its layer, so what the layer adds to the base model's own error shows.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402

from benchmarks.bench_render import RESULTS, section, shared_environments  # noqa: E402

PROBE = 48
EXEMPT = ("spot1Lux.hdr",)   # its truth is near 0 over most of the ball (README)


def cases():
    """(layer, label, layered material, the same without the layer)."""
    from alight.core.material import Material
    from alight.exchange.presets import load_preset

    car = load_preset("car_paint")
    velvet = load_preset("velvet")
    out = []
    for rc in (0.1, 0.3, 0.6):
        m = dataclasses.replace(car, clearcoat_roughness=rc)
        out.append(("clearcoat", f"car_paint r_c={rc}", m, dataclasses.replace(m, clearcoat=0.0)))
    coated_gold = Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.5, clearcoat=1.0,
                           clearcoat_roughness=0.25, name="coated_gold")
    out.append(("clearcoat", "gold r=0.5 r_c=0.25", coated_gold, dataclasses.replace(coated_gold, clearcoat=0.0)))
    for rs in (0.3, 0.6, 1.0):
        m = dataclasses.replace(velvet, sheen_roughness=rs)
        out.append(("sheen", f"velvet r_s={rs}", m, dataclasses.replace(m, sheen_color=(0.0, 0.0, 0.0))))
    sheen_white = Material(base_color=(0.05, 0.05, 0.05), roughness=0.9, sheen_color=(1.0, 1.0, 1.0),
                           sheen_roughness=0.5, name="white_sheen")
    out.append(("sheen", "white sheen r_s=0.5 on black", sheen_white,
                dataclasses.replace(sheen_white, sheen_color=(0.0, 0.0, 0.0))))
    return out


def relative(a, b, inside):
    return float(np.abs(a[..., :3][inside] - b[..., :3][inside]).sum() / np.abs(b[..., :3][inside]).sum())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    from alight.accuracy.reference import ReferenceRenderer
    from alight.core.scene import Scene
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    ref = ReferenceRenderer(r)
    envs = [(label, env) for label, env in shared_environments() if label.split()[0] not in EXEMPT]
    if args.quick:
        envs = [(label, env) for label, env in envs if label in ("royal_esplanade_1k.hdr", "quarry_01_1k.hdr")]
    rows = []
    section(f"probe {PROBE}x{PROBE}, medium bake, alight model, against alight reference")
    for name, env in envs:
        t0 = time.perf_counter()
        maps = r.bake(env, "medium")
        for layer, label, layered, bare in cases():
            errs = []
            for m in (layered, bare):
                scene = Scene(material=m, view="probe")
                got = r.render(scene, maps, PROBE, PROBE, read_srgb=False).linear
                truth = ref.render(scene, env.radiance, PROBE, PROBE).linear
                errs.append(relative(got, truth, truth[..., 3] > 0))
            rows.append(dict(environment=name, layer=layer, case=label, error=errs[0], without_layer=errs[1]))
            print(f"  {name:28s} {label:30s} {100 * errs[0]:6.2f}%  (without the layer {100 * errs[1]:6.2f}%)", flush=True)
        maps.release()
        print(f"  {name}: {time.perf_counter() - t0:.0f} s", flush=True)
    suffix = "_quick" if args.quick else ""
    RESULTS.mkdir(exist_ok=True)
    with open(RESULTS / f"layer_errors{suffix}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    labels = list(dict.fromkeys(row["case"] for row in rows))
    lines = ["| map | " + " | ".join(labels) + " |", "| --- |" + " --- |" * len(labels)]
    for name in dict.fromkeys(row["environment"] for row in rows):
        cells = {row["case"]: row for row in rows if row["environment"] == name}
        lines.append(f"| {name} | " + " | ".join(
            f"{100 * cells[c]['error']:.1f} ({100 * cells[c]['without_layer']:.1f})" for c in labels) + " |")
    text = ("Relative error (%) of the probe at `medium` against `alight reference`, with the layer "
            "(and, in brackets, the same material without it):\n\n" + "\n".join(lines) + "\n")
    (RESULTS / f"layer_errors{suffix}.md").write_text(text)
    print("\n" + text)
    r.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
