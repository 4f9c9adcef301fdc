"""Fit the `stretched` IBL model's lobe table (app/core/stretched_lobe.json) in lobe space.

The real specular lobe seen from v (docs/conventions.md's BRDF, k = r^2/2: its F0-scaled part
(1 - Fc) D G / (4 n.v) and its bias part Fc D G / (4 n.v), over l) is not the round lobe the
prefiltered map holds (the prefilter assumes n = v = R): it is narrower across the plane of
incidence, reaches further toward n, and has heavier tails. For each (n.v, roughness) cell and
each part, this fits two round prefiltered lobes (the map's kernel: max(d.l, 0) D(h_dl),
normalised) placed in the plane of incidence at signed angles from the lobe's mean direction
(the dominant direction, brdf_lut.comp's t_A / t_B), with one shared narrower-or-wider alpha:

    q(l) = (1 - w) K(rot(c, a_lo), beta alpha; l) + w K(rot(c, a_hi), beta alpha; l)

Nothing here reads an environment map: the fit minimises the H^-1 (inverse Sobolev) norm of
p - q on an azimuthal-equidistant grid around c, i.e. the expected squared error of the lookup
under a random environment with the 1/k^2 power spectrum of natural images (the sum of
|FFT(p - q)|^2 / |k|^2). The map-independent objective is the point: the earlier attempts
fitted per map and traded wins on one map for losses on another (README, "IBL models").

Cells: n.v at the centres of 8 texels, roughness at the centres of 16 (rows below r = 0.2, where
the lobe is narrower than the grid resolves, keep the round lookup). The fit runs a Nelder-Mead
search per cell (scipy), warm-started from its neighbours so the table stays continuous, and
writes the canonical form (a_lo <= a_hi, w the weight at a_hi). About an hour on 2 cores.

The fit sees each cell at its centre only; the shader reads the table bilinearly, parameter by
parameter, so a fetch of ~1% weight far from the mean (free in one cell's objective) lands with
the neighbouring cell's larger weight between them. The checked-in table has two such cells set
by hand (part A, last n.v column, rows r 0.28 and 0.34: a_lo = the previous column's; the json's
"about", benchmarks/results/stretched_pair_from_r02.md): a rerun must do the same or bring back
a ghost on floors seen from 60 degrees at r 0.3.

    .venv/bin/pip install scipy            # the fit's only extra dependency (not alight's)
    .venv/bin/python tools/fit_stretched_lobe.py [--out app/core/stretched_lobe.json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
PI = np.pi
N_MU, N_R, MIN_FITTED_R = 8, 16, 0.2
GRID_N = 112


def unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def kernel_norm(alpha: float, n: int = 4000) -> float:
    """The prefilter kernel's integral over l for v = n = d: 2 pi int D(h) (d.l) 4 (d.h) sin dtheta_h."""
    th = (np.arange(n) + 0.5) * (PI / 4) / n
    a2 = alpha * alpha
    c = np.cos(th)
    D = a2 / (PI * (c * c * (a2 - 1) + 1) ** 2)
    return float(2 * PI * np.sum(D * np.cos(2 * th) * 4 * c * np.sin(th)) * (PI / 4) / n)


class Grid:
    """An N x N azimuthal-equidistant grid of directions around c, extent U radians, with each
    cell's solid angle and the 1/|k|^2 weights of a zero-padded FFT."""

    def __init__(self, c, n: int, extent: float):
        c = unit(np.asarray(c, float))
        a = np.array([0.0, 1.0, 0.0]) if abs(c[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e2 = unit(np.cross(c, a))
        e1 = np.cross(e2, c)
        x = (np.arange(n) + 0.5) / n * 2 * extent - extent
        u, w = np.meshgrid(x, x, indexing="ij")
        psi = np.hypot(u, w)
        valid = psi < PI - 1e-3
        s = np.where(psi > 1e-9, np.sin(psi) / np.maximum(psi, 1e-12), 1.0)
        self.l = np.cos(psi)[..., None] * c + (s * u)[..., None] * e1 + (s * w)[..., None] * e2
        self.cell = (2 * extent / n) ** 2
        self.d_omega = np.where(valid, s, 0.0) * self.cell
        k = np.fft.fftfreq(2 * n, d=2 * extent / n) * 2 * PI
        kx, ky = np.meshgrid(k, k, indexing="ij")
        k2 = kx ** 2 + ky ** 2
        self.inv_k2 = np.where(k2 > 0, 1.0 / np.maximum(k2, 1e-30), 0.0)
        self.n, self.extent = n, extent

    def h_minus_1(self, p, q) -> float:
        density = np.zeros((2 * self.n, 2 * self.n))
        density[:self.n, :self.n] = (p - q) * self.d_omega / self.cell
        f = np.fft.fft2(density) * self.cell
        return float(np.sqrt(np.sum(np.abs(f) ** 2 * self.inv_k2)) / (2 * self.n * 2 * self.extent / self.n))


def true_lobe(l, n_dot_v: float, alpha: float, part: str):
    """docs/conventions.md's specular lobe times n.l over l (n = +z, v in the xz plane), without F0:
    D G1(n.l) G1(n.v) / (4 n.v) times (1 - Fc) (part A) or Fc (part B); k = alpha / 2."""
    v = np.array([np.sqrt(max(1 - n_dot_v ** 2, 0.0)), 0.0, n_dot_v])
    nl = l[..., 2]
    h = unit(l + v)
    nh, vh = h[..., 2], np.clip(np.sum(h * v, -1), 0, 1)
    a2 = alpha * alpha
    D = a2 / (PI * (nh * nh * (a2 - 1) + 1) ** 2)
    k = alpha / 2
    g1l = np.where(nl > 0, nl / (nl * (1 - k) + k), 0.0)
    g = D * g1l * (n_dot_v / (n_dot_v * (1 - k) + k)) / (4 * n_dot_v)
    fc = (1 - vh) ** 5
    return np.where(nl > 0, g * ((1 - fc) if part == "A" else fc), 0.0)


def kernel(l, d, alpha: float, norms: dict):
    """The prefiltered map's kernel around d, normalised over the sphere."""
    key = round(alpha, 7)
    if key not in norms:
        norms[key] = kernel_norm(alpha)
    nh = np.sum(unit(l + d) * d, -1)
    a2 = alpha * alpha
    D = a2 / (PI * (nh * nh * (a2 - 1) + 1) ** 2)
    return np.where(l @ d > 0, (l @ d) * D, 0.0) / norms[key]


def unpack(x, alpha):
    main = x[0]
    tail = np.log1p(np.exp(x[1]))
    w_tail = 1.0 / (1.0 + np.exp(-np.clip(x[2], -50, 50)))
    beta = 0.05 + 1.25 / (1.0 + np.exp(-x[3]))
    return main, tail, w_tail, beta * alpha


def fit_cell(n_dot_v: float, r: float, part: str, starts, norms: dict):
    from scipy.optimize import minimize

    from alight.accuracy.converged import lobe_directions_converged

    alpha = r * r
    ta, tb = lobe_directions_converged(n_dot_v, r, 256, 64)
    t = float(ta if part == "A" else tb)
    n = np.array([0.0, 0.0, 1.0])
    v = np.array([np.sqrt(max(1 - n_dot_v ** 2, 0.0)), 0.0, n_dot_v])
    c = unit(n + t * (2 * n_dot_v * n - v - n))
    e = c * (n @ c) - n
    e = unit(e) if np.linalg.norm(e) > 1e-6 else np.array([-1.0, 0.0, 0.0])
    grid = Grid(c, GRID_N, float(np.clip(10 * alpha + 0.8, 1.2, 2.2)))
    p = true_lobe(grid.l, n_dot_v, alpha, part)
    p = p / np.sum(p * grid.d_omega)

    def lookup(x):
        main, tail, w, ap = unpack(x, alpha)
        d_main = np.cos(main) * c + np.sin(main) * e
        d_tail = np.cos(tail) * c - np.sin(tail) * e
        return (1 - w) * kernel(grid.l, d_main, ap, norms) + w * kernel(grid.l, d_tail, ap, norms)

    best = None
    for x0 in starts:
        o = minimize(lambda x: grid.h_minus_1(p, lookup(x)), x0, method="Nelder-Mead",
                     options=dict(maxiter=300, xatol=1e-4, fatol=1e-9))
        if best is None or o.fun < best.fun:
            best = o
    round_error = grid.h_minus_1(p, kernel(grid.l, c, alpha, norms))
    return best.x, float(best.fun), round_error


def canonical(x, alpha):
    """(a_lo, a_hi, w_hi, beta): the two fetches' signed angles (toward the horizon positive)
    in increasing order, the weight of the second, and alpha' / alpha."""
    main, tail, w, ap = unpack(x, alpha)
    tail = -float(np.arctan2(np.sin(tail), np.cos(tail)))
    (a_lo, w_lo), (a_hi, w_hi) = sorted([(float(main), 1.0 - float(w)), (tail, float(w))])
    return [a_lo, a_hi, w_hi, float(ap / alpha)]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(REPO / "app" / "core" / "stretched_lobe.json"))
    args = parser.parse_args(argv)
    mus = [(j + 0.5) / N_MU for j in range(N_MU)]
    rs = [(i + 0.5) / N_R for i in range(N_R)]
    fitted = [r for r in rs if r > MIN_FITTED_R]
    norms: dict = {}
    default = [np.array([0.05, np.log(np.expm1(0.3)), -1.5, 0.5]), np.array([0.15, np.log(np.expm1(0.6)), -1.0, 0.0])]
    table = {"A": [[[0.0, 0.0, 0.0, 1.0]] * N_MU for _ in rs], "B": [[[0.0, 0.0, 0.0, 1.0]] * N_MU for _ in rs]}
    raw: dict = {}
    report = []
    # A before B (B starts from A's cell too); rows from the roughest down, n.v from 1 down,
    # each cell starting from its fitted neighbours.
    for part in ("A", "B"):
        for r in sorted(fitted, reverse=True):
            i = rs.index(r)
            for mu in sorted(mus, reverse=True):
                j = mus.index(mu)
                t0 = time.perf_counter()
                starts = [raw[key] for key in ((part, i + 1, j), (part, i, j + 1), ("A", i, j))
                          if key in raw and key != (part, i, j)]
                if len(starts) < 2:
                    starts += default
                x, err, round_err = fit_cell(mu, r, part, starts, norms)
                if err >= round_err:   # never worse than the round lookup it replaces
                    x = np.array([0.0, -30.0, -50.0, np.log((1.0 - 0.05) / (1.30 - 1.0))])
                    err = round_err
                raw[(part, i, j)] = x
                table[part][i][j] = canonical(x, r * r)
                report.append((part, r, mu, round_err, err))
                print(f"{part} r {r:.3f} n.v {mu:.3f}: {table[part][i][j]}  H^-1 {1e3 * round_err:.1f} -> "
                      f"{1e3 * err:.1f}  {time.perf_counter() - t0:.0f}s", flush=True)
    doc = {
        "about": "tools/fit_stretched_lobe.py: per (n.v, roughness) texel centre and lobe part (A: the F0-scaled "
                 "part, B: the bias), two round prefiltered fetches at signed angles (radians, toward the horizon "
                 "positive) from the lobe's mean direction in the plane of incidence: [a_lo, a_hi, w_hi, beta], "
                 "weights 1 - w_hi and w_hi, roughness r sqrt(beta); rows roughness, columns n.v",
        "n_dot_v": mus, "roughness": rs, "A": table["A"], "B": table["B"],
        "h_minus_1": [[p, r, mu, round_err, err] for p, r, mu, round_err, err in report],
    }
    Path(args.out).write_text(json.dumps(doc, indent=1) + "\n")
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
