"""The PNGs of ``alight chart`` (matplotlib, Agg, written atomically): error against time with
the Pareto frontier marked, the white furnace, and the map of error over (n.v, roughness)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

FACTOR_STYLE = {   # factor -> (colour, marker)
    "baseline": ("black", "*"),
    "irradiance": ("tab:blue", "o"),
    "specular cube": ("tab:orange", "s"),
    "prefilter samples": ("tab:green", "^"),
    "FIS": ("tab:red", "D"),
    "LUT size": ("tab:purple", "v"),
    "LUT samples": ("tab:brown", "P"),
    "IBL model": ("tab:pink", "X"),
    "multiple scattering": ("tab:gray", "h"),
}
# The visibility rows' panel: a marker per configuration, a colour per scene.
VISIBILITY_MARKER = {"off": "o", "occlusion": "s", "shadows": "^", "auto": "*"}
SCENE_COLOUR = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")


def _figure(width_in: float, height_in: float):
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    return Figure(figsize=(width_in, height_in), dpi=110, layout="constrained")


def _save(fig, path: Path) -> None:
    from alight.exchange.output import atomic_path

    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)


def _plain_log_ticks(axis, lo: float | None = None, hi: float | None = None) -> None:
    """Log-axis tick labels as plain numbers (2, 5, 10, 20) instead of 2x10^0; over a narrow
    range (hi / lo < 4) the minor ticks are labelled too."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    fmt = FuncFormatter(lambda v, _: f"{v:.3g}")
    axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(fmt)
    narrow = lo is not None and hi is not None and lo > 0 and hi / lo < 4.0
    axis.set_minor_locator(LogLocator(base=10.0, subs=tuple(range(1, 10))))
    axis.set_minor_formatter(fmt if narrow else FuncFormatter(lambda v, _: ""))


def _error_panel(ax, rows, time_key: str, front_key: str, xlabel: str) -> None:
    seen = set()
    pts = [r for r in rows if math.isfinite(r[time_key]) and math.isfinite(r["rel_mae_mean"])]
    for r in pts:
        colour, marker = FACTOR_STYLE.get(r["factor"], ("tab:olive", "o"))
        label = r["factor"] if r["factor"] not in seen else None
        seen.add(r["factor"])
        ax.scatter(r[time_key], r["rel_mae_mean"] * 100, c=colour, marker=marker, s=70 if marker == "*" else 36,
                   label=label, zorder=3, edgecolors="none")
    front = sorted((r for r in pts if r[front_key]), key=lambda r: r[time_key])
    if front:
        xs = [r[time_key] for r in front]
        ys = [r["rel_mae_mean"] * 100 for r in front]
        ax.step(xs, ys, where="post", color="black", lw=1.0, alpha=0.6, zorder=2, label="Pareto frontier")
        ax.scatter(xs, ys, s=130, facecolors="none", edgecolors="black", lw=1.0, zorder=4)
        offsets = ((5, 4), (5, -11), (-10, 12), (-10, -16))   # neighbours' labels apart
        for k, r in enumerate(front):
            ax.annotate(r["setting"], (r[time_key], r["rel_mae_mean"] * 100), xytext=offsets[k % len(offsets)],
                        textcoords="offset points", fontsize=7, ha="left" if k % 4 < 2 else "right")
    for r in pts:   # the models (and the baseline, which is the default model) and the layers are always named
        if r["factor"] in ("IBL model", "baseline", "layer") and not r[front_key]:
            colour = {"IBL model": "tab:pink", "layer": "tab:olive"}.get(r["factor"], "black")
            ax.annotate(r["setting"].replace("model ", "").replace("layer ", ""), (r[time_key], r["rel_mae_mean"] * 100),
                        xytext=(6, -3), textcoords="offset points", fontsize=7, color=colour)
    ax.set_xscale("log")
    ax.set_yscale("log")
    if pts:
        xs = [r[time_key] for r in pts]
        ys = [r["rel_mae_mean"] * 100 for r in pts]
        _plain_log_ticks(ax.xaxis, min(xs), max(xs))
        _plain_log_ticks(ax.yaxis, min(ys), max(ys))
    ax.set_xlabel(xlabel)
    ax.set_ylabel("probe error against the ground truth:\nmean relMAE over cases (%)")
    ax.grid(True, which="both", alpha=0.25)


def _visibility_panel(ax, rows, label: tuple[str, str]) -> None:
    """The visibility rows: each scene's configurations, error against frame time, joined in the
    order off, occlusion, shadows, auto; the reference's own noise as a dashed line."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    for k, scene in enumerate(scenes):
        colour = SCENE_COLOUR[k % len(SCENE_COLOUR)]
        group = [r for r in rows if r["scene"] == scene and math.isfinite(r["frame_ms"])
                 and math.isfinite(r["rel_mae_mean"])]
        for r in group:
            config = r["setting"].split(": ", 1)[-1]
            ax.scatter(r["frame_ms"], r["rel_mae_mean"] * 100, c=colour, marker=VISIBILITY_MARKER.get(config, "o"),
                       s=90 if config == "auto" else 40, zorder=3, edgecolors="black" if r["pareto_frame"] else "none",
                       label=f"{scene}: {config}")
        noise = [r["ref_noise_mean"] for r in group if math.isfinite(r.get("ref_noise_mean", math.nan))]
        if noise:
            ax.axhline(noise[0] * 100, color=colour, ls="--", lw=0.8, alpha=0.7,
                       label=f"{scene}: reference noise (seed 0 vs 1)")
    ax.set_yscale("log")
    ys = [r["rel_mae_mean"] * 100 for r in rows if math.isfinite(r["rel_mae_mean"])]
    ys += [r["ref_noise_mean"] * 100 for r in rows if math.isfinite(r.get("ref_noise_mean", math.nan))]
    if ys:
        _plain_log_ticks(ax.yaxis, min(ys), max(ys))
    frame, error = label
    ax.set_xlabel(f"frame time: {frame or 'scene camera'}, median (ms)")
    ax.set_ylabel(f"scene error against the path tracer{' (' + error + ')' if error else ''}:\n"
                  "4x4-binned relMAE, mean over environments (%)")
    ax.set_title("visibility: error against frame time\n(black edge: per-scene Pareto frontier)", fontsize=10)
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), framealpha=0.85)   # beside: off the points
    ax.grid(True, which="both", alpha=0.25)


def plot_chart(rows: list[dict], furnace: list[dict], path: Path, title: str, frame_label: str,
               visibility_label: tuple[str, str] = ("", "")) -> Path:
    """chart.png from chart.csv's rows and furnace.csv's rows (dicts, numbers as float); the
    visibility rows (factor 'visibility') in a panel of their own: their error is a scene's
    against the path tracer, not the probe's against the ground truth."""
    vis_rows = [r for r in rows if r["factor"] == "visibility"]
    rows = [r for r in rows if r["factor"] != "visibility"]
    panels = 4 if vis_rows else 3
    fig = _figure(18.0 + (6.0 if vis_rows else 0.0), 6.2)
    axes = fig.subplots(1, panels, gridspec_kw={"width_ratios": [1.15, 1.15, 0.9, 1.15][:panels]})
    if vis_rows:
        _visibility_panel(axes[3], vis_rows, visibility_label)
    _error_panel(axes[0], rows, "bake_ms", "pareto_bake",
                 "bake time per environment, warm, LUT cached (ms, log)")
    axes[0].set_title("error against bake time")
    _error_panel(axes[1], rows, "frame_ms", "pareto_frame", f"frame time: {frame_label} (ms, log)")
    axes[1].set_title("error against frame time")
    axes[0].legend(fontsize=7, loc="best", framealpha=0.85)

    ax = axes[2]
    cmap = __import__("matplotlib").colormaps["tab10"]
    factor = {r["setting"]: r["factor"] for r in rows}
    # Models whose furnace curves agree (they share the LUT: a white furnace cannot tell the
    # split sum's models apart) are one line naming them all: twelve lines drawn over each other
    # left two visible and a legend of twelve.
    curves: dict[tuple, list[str]] = {}
    for name in dict.fromkeys(f["setting"] for f in furnace):
        fs = [f for f in furnace if f["setting"] == name]
        if name == "ground truth":
            ax.plot([f["roughness"] for f in fs], [f["mean"] for f in fs], "k:", lw=1.6,
                    label="ground truth (single scattering)")
            continue
        if factor.get(name) not in ("baseline", "IBL model", "multiple scattering"):
            continue
        key = (bool(fs[0]["multiple_scattering"]),
               tuple((round(f["roughness"], 4), round(f["mean"], 4), round(f["min"], 4), round(f["max"], 4)) for f in fs))
        curves.setdefault(key, [])
        if fs[0]["ibl_model"] not in curves[key]:
            curves[key].append(fs[0]["ibl_model"])
    every = {m for names in curves.values() for m in names}
    for k, ((ms, points), names) in enumerate(curves.items()):
        colour = cmap(k % 10)
        rs = [p[0] for p in points]
        who = f"every IBL model ({len(names)})" if len(every) > 1 and set(names) == every else ", ".join(names)
        ax.plot(rs, [p[1] for p in points], "--s" if ms else "-o", color=colour, ms=4,
                label=f"{who}, MS {'on' if ms else 'off'}")
        ax.fill_between(rs, [p[2] for p in points], [p[3] for p in points], color=colour, alpha=0.12)
    ax.axhline(1.0, color="black", lw=0.8, ls="-", alpha=0.4)
    ax.set_xlabel("roughness")
    ax.set_ylabel("probe radiance, mean over the ball (band: min..max)")
    ax.set_ylim(top=1.06)
    ax.set_title("white furnace: metal F0 = 1, radiance 1\n(MS on should give 1)", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, alpha=0.25)
    what = "; visibility (occlusion, shadows) on test scenes" if vis_rows else ""
    fig.suptitle(f"alight chart: split-sum IBL settings around 'medium', one factor at a time{what}\n{title}",
                 fontsize=10)
    _save(fig, path)
    return path


def plot_error_map(maps: dict[str, tuple[list[float], np.ndarray]], path: Path, title: str) -> Path:
    """error_map.png: per IBL model, (roughness values, relMAE (R, n.v bins) as a fraction)."""
    from matplotlib.colors import LogNorm

    models = list(maps)
    cols = min(3, len(models))
    rows = (len(models) + cols - 1) // cols
    fig = _figure(6.0 * cols + 1.2, 4.6 * rows + 0.6)
    grid = fig.subplots(rows, cols, squeeze=False)
    axes = grid.ravel()[:len(models)]
    for ax in grid.ravel()[len(models):]:
        ax.set_visible(False)
    rs = np.asarray(maps[models[0]][0])
    edges_r = np.arange(len(rs) + 1) - 0.5     # one equal row per roughness value
    nb = maps[models[0]][1].shape[1]
    edges_nv = np.linspace(0.0, 1.0, int(nb) + 1)
    rels = {m: np.asarray(maps[m][1], np.float64) * 100 for m in models}
    finite = np.concatenate([v[np.isfinite(v) & (v > 0)] for v in rels.values()])
    lo, hi = (max(float(finite.min()), 0.1), float(finite.max())) if finite.size else (0.1, 100.0)
    norm = LogNorm(vmin=lo, vmax=max(hi, lo * 10))
    mesh = None
    for ax, m in zip(axes, models):
        v = rels[m]
        mesh = ax.pcolormesh(edges_nv, edges_r, np.ma.masked_invalid(v), cmap="magma", norm=norm)
        for i, r in enumerate(rs):
            for b in range(v.shape[1]):
                if np.isfinite(v[i, b]):
                    dark = norm(v[i, b]) < 0.6
                    ax.text((edges_nv[b] + edges_nv[b + 1]) / 2, i, f"{v[i, b]:.3g}", ha="center", va="center",
                            fontsize=6, color="white" if dark else "black")
        ax.set_xlabel("n.v (probe pixel: n.z; 0 = grazing at the rim)")
        ax.set_ylabel("roughness")
        ax.set_yticks(range(len(rs)), [f"{r:g}" for r in rs])
        ax.set_title(f"IBL model '{m}': relMAE per bin (%)", fontsize=9)
    if mesh is not None:
        bar = fig.colorbar(mesh, ax=list(grid.ravel()), label="sum|render - truth| / sum|truth| in the bin (%, log)")
        _plain_log_ticks(bar.ax.yaxis, norm.vmin, norm.vmax)
    fig.suptitle(f"Where the split sum fails: quality medium, all presets and environments pooled\n{title}",
                 fontsize=9)
    _save(fig, path)
    return path
