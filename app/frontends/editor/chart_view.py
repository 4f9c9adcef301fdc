"""The editor panel's view of the latest ``alight chart``: error against bake time, the Pareto
frontier marked (implot). It reads the chart's CSV (app/accuracy/chart.py) and nothing else; the data
part (``ChartData``) needs no imgui, so it is tested on its own."""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class ChartData:
    """chart.csv as plot series: per factor (bake ms, mean relMAE %, names), and the frontier."""

    path: Path
    factors: dict[str, tuple[np.ndarray, np.ndarray, list[str]]] = field(default_factory=dict)
    frontier: tuple[np.ndarray, np.ndarray, list[str]] = (np.zeros(0), np.zeros(0), [])
    settings: int = 0


def load_chart(path: str | os.PathLike) -> ChartData:
    """The series of a chart.csv; settings without a ground-truth error (multiple scattering)
    are left out. Raises OSError/ValueError/KeyError on an unreadable file."""
    from alight.accuracy.chart import read_summary

    rows = read_summary(path)
    data = ChartData(Path(path), settings=len(rows))
    pts = [r for r in rows if math.isfinite(r["bake_ms"]) and math.isfinite(r["rel_mae_mean"])]
    for r in pts:
        xs, ys, names = data.factors.setdefault(r["factor"], ([], [], []))
        xs.append(r["bake_ms"])
        ys.append(r["rel_mae_mean"] * 100.0)
        names.append(r["setting"])
    data.factors = {k: (np.asarray(x, np.float64), np.asarray(y, np.float64), n) for k, (x, y, n) in data.factors.items()}
    front = sorted((r for r in pts if r.get("pareto_bake") == 1.0), key=lambda r: r["bake_ms"])
    data.frontier = (np.asarray([r["bake_ms"] for r in front], np.float64),
                     np.asarray([r["rel_mae_mean"] * 100.0 for r in front], np.float64),
                     [r["setting"] for r in front])
    return data


def find_chart_csv(explicit: str | os.PathLike | None = None) -> Path | None:
    """The chart to show: an explicit path, else the one the last ``alight chart`` noted, else
    ./alight-chart/chart.csv (the command's default output)."""
    from alight.accuracy.chart import latest_chart_csv

    for candidate in (explicit, latest_chart_csv(), Path("alight-chart") / "chart.csv"):
        if candidate and Path(candidate).is_file():
            return Path(candidate)
    return None


class ChartView:
    """Draws the chart in the current imgui window; re-reads the CSV when it changes (checked
    at most once a second)."""

    def __init__(self, path: str | os.PathLike | None = None):
        self.explicit = path
        self.data: ChartData | None = None
        self.error = ""
        self._stamp = None
        self._checked = 0.0

    def refresh(self) -> None:
        now = time.monotonic()
        if now - self._checked < 1.0:
            return
        self._checked = now
        path = find_chart_csv(self.explicit)
        if path is None:
            self.data, self.error, self._stamp = None, "", None
            return
        try:
            stamp = (str(path), path.stat().st_mtime_ns)
            if stamp != self._stamp:
                self.data, self.error, self._stamp = load_chart(path), "", stamp
        except (OSError, ValueError, KeyError) as exc:
            self.data, self.error = None, f"{path}: {' '.join(str(exc).split())}"

    def draw(self) -> None:
        from imgui_bundle import imgui, implot

        self.refresh()
        if self.error:
            imgui.text_wrapped(f"chart: {self.error}")
            return
        if self.data is None:
            imgui.text_disabled("no chart yet: run 'alight chart' (or --quick)")
            return
        d = self.data
        imgui.text_disabled(f"{d.path} ({d.settings} settings)")
        if implot.begin_plot("error vs bake time", imgui.ImVec2(-1, 220)):
            implot.setup_axes("bake ms (log)", "relMAE % (log)")
            implot.setup_axis_scale(implot.ImAxis_.x1, implot.Scale_.log10)
            implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
            for factor, (xs, ys, _) in d.factors.items():
                implot.plot_scatter(factor, xs, ys)
            if len(d.frontier[0]):
                implot.plot_stairs("Pareto frontier", d.frontier[0], d.frontier[1])
            implot.end_plot()
        for x, y, name in zip(*d.frontier):
            imgui.text(f"frontier: {name}: {x:.0f} ms, {y:.2f}%")
