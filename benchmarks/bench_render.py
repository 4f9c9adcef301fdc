"""alight's performance and accuracy figures. Prints them; not a test.

    python benchmarks/bench_render.py            # everything (several minutes on 2 cores)
    python benchmarks/bench_render.py --quick    # one environment, fewer roughness values (< ~2 min)

See benchmarks/README.md for what each figure means. The machine this runs on is usually shared
and noisy: every time is the median over repeats, and ratios are given where they help.
"""

from __future__ import annotations

import argparse
import csv
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

import numpy as np

ENV_DIR = REPO.parent / "shared" / "data" / "env"
BENCH_ENV = ENV_DIR / "royal_esplanade_1k.hdr"
RESULTS = Path(__file__).resolve().parent / "results"

GOLD = dict(base_color=(1.0, 0.71, 0.29), metallic=1.0)
GREY = dict(base_color=(0.8, 0.8, 0.8), metallic=0.0)
WHITE = dict(base_color=(1.0, 1.0, 1.0), metallic=0.0)


def median(xs):
    return statistics.median(xs)


def ms(x):
    return f"{x * 1000:8.1f} ms"


def section(title):
    print(f"\n== {title} " + "=" * max(0, 74 - len(title)), flush=True)


def _child_env():
    return dict(os.environ)   # the installed alight (make setup), as a user runs it


def run_child(args, cwd=None):
    """Run a subprocess; returns (wall seconds, stdout, maxrss in MiB) via os.wait4 (this child only)."""
    start = time.perf_counter()
    proc = subprocess.Popen(args, cwd=cwd or REPO, env=_child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out, err = proc.stdout.read(), proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    proc.stdout.close()
    proc.stderr.close()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, args))} failed ({proc.returncode}): {err.decode()[-2000:]}")
    return wall, out.decode(), usage.ru_maxrss / 1024.0  # Linux: KiB


# --------------------------------------------------------------------------------------------
# Bake
# --------------------------------------------------------------------------------------------

_COLD_BAKE = r"""
import json, sys, time
t0 = time.perf_counter()
from alight.render.renderer import ForwardRenderer
from alight.ibl.environment import load_environment
t1 = time.perf_counter()
r = ForwardRenderer()
t2 = time.perf_counter()
env = load_environment(sys.argv[1])
t3 = time.perf_counter()
maps = r.bake(env, sys.argv[2])
r.ctx.finish()
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "context": t2 - t1, "load": t3 - t2, "bake": t4 - t3,
                  "passes": maps.pass_seconds}))
"""


def bench_bake(qualities, repeats_cold, repeats_warm):
    from alight.ibl.bake import QUALITY, LutCache, bake_environment
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    section(f"Bake of {BENCH_ENV.name} (medians; cold = fresh process, LUT already on disk)")
    r = ForwardRenderer()
    env = load_environment(str(BENCH_ENV))
    for q in qualities:  # put every quality's LUT on disk so the cold runs measure the usual case
        r.bake(env, q)
    print(f"{'quality':8s} {'cold bake':>11s} {'warm bake':>11s} {'cold/warm':>9s}   per pass (warm median)")
    rows = {}
    for q in qualities:
        cold = [json.loads(run_child([sys.executable, "-c", _COLD_BAKE, str(BENCH_ENV), q])[1].strip().splitlines()[-1])
                for _ in range(repeats_cold)]
        warm_total, warm_passes = [], {}
        for _ in range(repeats_warm):
            t = time.perf_counter()
            maps = bake_environment(r.ctx, r.shaders, env, QUALITY[q], r.luts)
            r.ctx.finish()
            warm_total.append(time.perf_counter() - t)
            for k, v in maps.pass_seconds.items():
                warm_passes.setdefault(k, []).append(v)
            maps.release()
        c = median([x["bake"] for x in cold])
        w = median(warm_total)
        passes = ", ".join(f"{k} {median(v) * 1000:.0f}" for k, v in warm_passes.items())
        print(f"{q:8s} {ms(c):>11s} {ms(w):>11s} {c / w:9.2f}   {passes} (ms)")
        cold_passes = {}
        for x in cold:
            for k, v in x["passes"].items():
                cold_passes.setdefault(k, []).append(v)
        print(f"{'':8s} cold per pass: " + ", ".join(f"{k} {median(v) * 1000:.0f}" for k, v in cold_passes.items())
              + f" (ms); cold process before the bake: import {median([x['import'] for x in cold]) * 1000:.0f}, "
                f"GL context {median([x['context'] for x in cold]) * 1000:.0f}, "
                f"load .hdr {median([x['load'] for x in cold]) * 1000:.0f} (ms)")
        rows[q] = (c, w)

    print("\nBRDF LUT bake alone when not cached (fresh ALIGHT_CACHE_DIR each time; compiled shader; "
          "includes read-back and the .npy write):")
    for q in qualities:
        qq = QUALITY[q]
        times = []
        for _ in range(max(3, repeats_warm)):
            with tempfile.TemporaryDirectory() as tmp:
                old = os.environ.get("ALIGHT_CACHE_DIR")
                os.environ["ALIGHT_CACHE_DIR"] = tmp
                try:
                    luts = LutCache(r.ctx, r.shaders)
                    t = time.perf_counter()
                    luts.get(qq.lut_size, qq.lut_samples)
                    r.ctx.finish()
                    times.append(time.perf_counter() - t)
                    assert luts.last_source == "baked"
                    luts.release()
                finally:
                    os.environ["ALIGHT_CACHE_DIR"] = old
        lut = median(times)
        print(f"  {q:8s} {qq.lut_size}x{qq.lut_size}, {qq.lut_samples} samples: {ms(lut)} "
              f"({lut / rows[q][1] * 100:.0f}% of a warm bake)")
    r.release()


# --------------------------------------------------------------------------------------------
# Frames
# --------------------------------------------------------------------------------------------

def bench_frames(repeats):
    from alight.core.material import Material
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    section("Frame time: material ball (sphere, camera view, env background), "
            f"IBL ({BENCH_ENV.name}, medium) + 3 point lights")
    r = ForwardRenderer()
    maps = r.bake(load_environment(str(BENCH_ENV)), "medium")
    scene = Scene(mesh=sphere(), material=Material(),
                  lights=[Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
                          Light(vector=(0.0, -2.0, 3.0), intensity=4.0)])
    print(f"{'size':>10s} {'aa':>5s} {'render+finish':>14s} {'read linear f4':>15s} {'read sRGB u8':>13s} {'fps (render)':>12s}")
    base = {}
    for (w, h) in ((1024, 1024), (1920, 1080)):
        for aa in ("none", "msaa"):
            r.render(scene, maps, w, h, aa=aa, read_linear=False, read_srgb=False)  # targets + programs
            r.ctx.finish()
            draw, lin, srgb = [], [], []
            for _ in range(repeats):
                t = time.perf_counter()
                r.render(scene, maps, w, h, aa=aa, read_linear=False, read_srgb=False)
                r.ctx.finish()
                draw.append(time.perf_counter() - t)
                targets = r._targets  # the benchmark peeks at the renderer's targets to time read-back alone
                t = time.perf_counter()
                targets.radiance_fbo.read(components=4, dtype="f4")
                lin.append(time.perf_counter() - t)
                t = time.perf_counter()
                targets.display_fbo.read(components=4, dtype="f1")
                srgb.append(time.perf_counter() - t)
            d = median(draw)
            base[(w, h, aa)] = d
            print(f"{w:>5d}x{h:<4d} {aa:>5s} {ms(d):>14s} {ms(median(lin)):>15s} {ms(median(srgb)):>13s} {1 / d:12.1f}")
    for wh in ((1024, 1024), (1920, 1080)):
        print(f"msaa/none at {wh[0]}x{wh[1]}: {base[wh + ('msaa',)] / base[wh + ('none',)]:.2f}")
    print(f"1920x1080 / 1024x1024 (none): {base[(1920, 1080, 'none')] / base[(1024, 1024, 'none')]:.2f} "
          f"(pixel ratio {1920 * 1080 / 1024 ** 2:.2f})")
    r.release()


# --------------------------------------------------------------------------------------------
# The CLI, end to end
# --------------------------------------------------------------------------------------------

def bench_cli(repeats):
    section("Process start to PNG: python -m alight render --out x.png (1024x1024, studio, medium, msaa)")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "x.png"
        cmd = [sys.executable, "-m", "alight", "render", "--out", str(out)]
        first, _, first_rss = run_child(cmd)  # fills the LUT disk cache (not counted below)
        walls, rss = [], []
        for _ in range(repeats):
            w, _, m = run_child(cmd)
            walls.append(w)
            rss.append(m)
        assert out.exists()
    print(f"median of {repeats}: {median(walls):.3f} s  (min {min(walls):.3f}, max {max(walls):.3f}); "
          f"first run with no cached LUT: {first:.3f} s")
    print(f"peak memory (maxrss of the child): median {median(rss):.0f} MiB, max {max(rss):.0f} MiB "
          f"(first run {first_rss:.0f} MiB)")


# --------------------------------------------------------------------------------------------
# Accuracy
# --------------------------------------------------------------------------------------------

def shared_environments():
    """Every 2:1 map in ../shared/data/env, loaded; prints the ones skipped and why."""
    from alight.errors import AlightError
    from alight.ibl.environment import load_environment

    envs = []
    for path in sorted(glob.glob(str(ENV_DIR / "*.hdr")) + glob.glob(str(ENV_DIR / "*.exr"))):
        try:
            env = load_environment(path)
        except AlightError as e:
            print(f"  skipped: {e}")
            continue
        note = f" ({env.width}x{env.height})" if env.width != 1024 else ""
        envs.append((Path(path).name + note, env))
    return sorted(envs, key=lambda e: e[0])


def bench_split_sum_error(envs, roughnesses, size=48):
    from alight.accuracy.converged import (
        brdf_lut_converged,
        irradiance_converged,
        prefiltered_converged,
    )
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.core.shading import F_SchlickRoughness, f0_of, probe_normals, reflect
    from alight.render.renderer import ForwardRenderer

    section(f"Probe error vs the converged split sum, quality 'medium', probe {size}x{size}: "
            "sum|render - ideal| / sum|ideal| in %")
    normals, inside = probe_normals(size)
    pts = normals[inside]
    v = np.array([0.0, 0.0, 1.0])
    nv = np.maximum(pts[:, 2], 0.0)
    R = reflect(-v, pts)
    t = time.perf_counter()
    luts = {rr: brdf_lut_converged(nv, rr) for rr in roughnesses}  # environment-independent
    print(f"(converged BRDF LUT for {len(pts)} pixels x {len(roughnesses)} roughness values: "
          f"{time.perf_counter() - t:.1f} s, reused for every environment and material)")
    mats = (("grey dielectric", GREY), ("gold", GOLD))
    print(f"{'environment':34s} {'material':16s} " + " ".join(f"r={rr:<5g}" for rr in roughnesses))
    r = ForwardRenderer()
    worst = {}
    for name, env in envs:
        maps = r.bake(env, "medium")
        E = irradiance_converged(env.radiance, pts)
        pref = {rr: prefiltered_converged(env.radiance, R, rr) for rr in roughnesses}
        for mname, m in mats:
            errs = []
            for rr in roughnesses:
                base = np.asarray(m["base_color"], float)
                f0 = f0_of(base, m["metallic"], np.full(3, 0.04))
                F = F_SchlickRoughness(nv, f0, rr)
                A, B = luts[rr]
                ideal = np.zeros(inside.shape + (3,))
                ideal[inside] = (1.0 - F) * (1.0 - m["metallic"]) * base * E + pref[rr] * (F * A[:, None] + B[:, None])
                mat = Material(base_color=m["base_color"], metallic=m["metallic"], roughness=rr)
                frame = r.render(Scene(material=mat, view="probe"), maps, size, size, read_srgb=False)
                err = _rel(frame.linear, ideal, inside)
                errs.append(err)
                worst[(mname, rr)] = max(worst.get((mname, rr), 0.0), err)
            print(f"{name:34s} {mname:16s} " + " ".join(f"{e * 100:7.2f}" for e in errs), flush=True)
        maps.release()
        r._bakes.clear()
    print(f"{'worst over environments':34s}")
    for mname, _ in mats:
        print(f"{'':34s} {mname:16s} " + " ".join(f"{worst[(mname, rr)] * 100:7.2f}" for rr in roughnesses))
    r.release()


def _rel(render, ref, mask):
    from alight.accuracy.ground_truth import relative_error

    return relative_error(render, ref, mask)


def bench_ground_truth_curve(envs, roughnesses, size=32, factor=2, suffix=""):
    from alight.accuracy.converged import downsample_equirect
    from alight.accuracy.ground_truth import ground_truth_terms, probe_points
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.render.renderer import ForwardRenderer

    section(f"Probe error vs the ground truth of docs/conventions.md (app/accuracy/ground_truth.py), quality 'medium', "
            f"probe {size}x{size}, in %")
    print(f"The ground truth sums over the environment DOWNSAMPLED BY {factor} (alight.accuracy.converged.downsample_equirect, "
          f"e.g. 1024x512 -> {1024 // factor}x{512 // factor}) to keep it fast; the GPU bakes the full map. "
          "At r = 0.1 the lobe spans only a few texels of the reduced map (see app/accuracy/ground_truth.py).")
    pts, inside = probe_points(size)
    mats = (("gold", GOLD), ("white dielectric", WHITE))
    print(f"{'environment':34s} {'material':16s} " + " ".join(f"r={rr:<5g}" for rr in roughnesses))
    r = ForwardRenderer()
    rows = []
    for name, env in envs:
        maps = r.bake(env, "medium")
        t = time.perf_counter()
        terms = ground_truth_terms(downsample_equirect(env.radiance, factor), pts, (0.0, 0.0, 1.0), roughnesses)
        gt_seconds = time.perf_counter() - t
        for mname, m in mats:
            errs = []
            for rr in roughnesses:
                ideal = np.zeros(inside.shape + (3,))
                ideal[inside] = terms.combine(m["base_color"], m["metallic"], (0.04, 0.04, 0.04), roughness=rr)
                mat = Material(base_color=m["base_color"], metallic=m["metallic"], roughness=rr)
                frame = r.render(Scene(material=mat, view="probe"), maps, size, size, read_srgb=False)
                err = _rel(frame.linear, ideal, inside)
                errs.append(err)
                rows.append((name.split(" ")[0], mname, rr, err))
            print(f"{name:34s} {mname:16s} " + " ".join(f"{e * 100:7.2f}" for e in errs), flush=True)
        print(f"{'':34s} (ground truth sums: {gt_seconds:.1f} s)")
        maps.release()
        r._bakes.clear()
    r.release()

    RESULTS.mkdir(parents=True, exist_ok=True)
    csv_path = RESULTS / f"ground_truth_curve{suffix}.csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["environment", "material", "roughness", "relative_error", "probe_size", "gt_downsample"])
        for env_name, mname, rr, err in rows:
            w.writerow([env_name, mname, f"{rr:g}", f"{err:.6g}", size, factor])
    print(f"wrote {csv_path.relative_to(REPO)}")
    _plot(rows, RESULTS / f"ground_truth_curve{suffix}.png", size, factor)


def _plot(rows, path, size, factor):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no chart (pip install matplotlib into the venv to get "
              f"{path.relative_to(REPO)}; it is not a dependency of alight)")
        return
    mats = sorted({m for _, m, _, _ in rows})
    envs = sorted({e for e, _, _, _ in rows})
    fig, axes = plt.subplots(1, len(mats), figsize=(6.5 * len(mats), 5), sharey=True)
    axes = np.atleast_1d(axes)
    cmap = plt.get_cmap("tab10")
    for ax, mname in zip(axes, mats):
        for i, e in enumerate(envs):
            pts = sorted((rr, err) for en, m, rr, err in rows if en == e and m == mname)
            ax.plot([p[0] for p in pts], [p[1] * 100 for p in pts], "o-", color=cmap(i % 10), label=e, ms=4)
        ax.set_yscale("log")
        ax.set_xlabel("roughness r")
        ax.set_title(f"{mname}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("sum|render - ground truth| / sum|ground truth|  (%)")
    axes[-1].legend(fontsize=8, loc="upper right")
    fig.suptitle(f"alight probe ({size}x{size}, quality medium) vs docs/conventions.md ground truth "
                 f"(env downsampled x{factor} for the reference)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path.relative_to(REPO)}")


# --------------------------------------------------------------------------------------------

def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="one environment, fewer roughness values and repeats")
    args = p.parse_args(argv)
    quick = args.quick

    # Keep the benchmark's LUT cache away from the user's.
    cache = tempfile.TemporaryDirectory(prefix="alight-bench-cache-")
    os.environ["ALIGHT_CACHE_DIR"] = cache.name
    from alight.core.gpu import describe
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    print(f"alight benchmark ({'quick' if quick else 'full'}); {describe(r.ctx)}; "
          f"{os.cpu_count()} CPUs; python {sys.version.split()[0]}; numpy {np.__version__}")
    r.release()
    start = time.perf_counter()

    bench_bake(("low", "medium") if quick else ("low", "medium", "high"),
               repeats_cold=1 if quick else 3, repeats_warm=3 if quick else 5)
    bench_frames(repeats=5 if quick else 15)
    bench_cli(repeats=3 if quick else 5)

    section("Environments for the accuracy figures")
    if quick:
        from alight.ibl.environment import load_environment

        envs = [(BENCH_ENV.name, load_environment(str(BENCH_ENV)))]
        print(f"  --quick: {BENCH_ENV.name} only")
    else:
        envs = shared_environments()
        print("  (memorial.exr is 512x768, not a 2:1 equirect map, so the loader refuses it)")
        print("  using: " + ", ".join(n for n, _ in envs))
    bench_split_sum_error(envs, (0.25, 1.0) if quick else (0.25, 0.5, 0.75, 1.0))
    bench_ground_truth_curve(envs, (0.1, 0.4, 1.0) if quick else (0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0),
                             suffix="_quick" if quick else "")
    print(f"\ntotal {time.perf_counter() - start:.0f} s")
    cache.cleanup()


if __name__ == "__main__":
    main()
