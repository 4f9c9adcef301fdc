"""pytest plugin (entry point ``pytest11: alight``): headless renders in other projects' tests.

Fixtures:
  ``alight_renderer``        one ``alight.frontends.api.Renderer`` for the session (256x256, low
                             quality bakes; ini options ``alight_size`` and ``alight_quality``, or
                             ``--alight-size`` and ``--alight-quality``), reset (``Renderer.reset``)
                             before each test: a test starts from the constructor's scene whatever
                             the one before set, and the GL context, programs and bakes are kept.
  ``assert_image_matches``   ``assert_image_matches`` with relative golden paths taken
                             from the test file's folder and ``--alight-update-goldens`` applied.

``pytest --alight-update-goldens`` writes the current render as the golden instead of
comparing, and ends with ``alight: wrote N goldens``. On a mismatch ``<golden>.actual.png``,
``<golden>.expected.png`` and ``<golden>.diff.png`` are written beside the golden image (a size
mismatch writes no diff); a golden that passes or is updated has its old ones removed. The ``rel`` diff image is
|actual - expected| on a fixed scale: black 0, white 0.25 x the golden's mean.

Metrics: ``rel`` (relative mean absolute error: mean |a - e| / mean |e| over RGB) and ``flip``
(mean NVIDIA FLIP error, from the ``flip-evaluator`` package: a dependency of alight; an
environment without it fails a ``flip`` comparison with a line that says so). Either way a
comparison also fails when the worst 16x16 block's rel error exceeds the local tolerance (default 0.25,
ini option ``alight_local_tolerance``): a frame's mean hides a small object's change.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

METRICS = ("rel", "flip")
DEFAULT_TOLERANCE = {"rel": 0.02, "flip": 0.05}
# The local criterion: the rel error of the worst BLOCK x BLOCK block (its mean |a - e| over the
# golden's whole-frame mean |e|). A frame mean hides a small object's change (Duck.glb at
# distance 12, textured -> red, 256x256: rel 0.017 < 0.02 but worst block 0.63); 16x16 blocks
# average away edge differences that another GPU's rasterisation makes (msaa vs none or vs a
# camera moved 1e-4: <= 0.13 over sphere 48/128 px and Duck 256 px, sRGB and linear), where 8x8
# blocks let those reach 0.29. docs/guides/pytest-plugin.md gives the measurements.
BLOCK = 16
DEFAULT_LOCAL_TOLERANCE = 0.25
# The rel diff image's white, as a share of the golden's mean: DEFAULT_LOCAL_TOLERANCE, so a
# block that is white throughout fails the local check.
DIFF_SCALE = 0.25
# alight.frontends.api.Quality's values (a test keeps them equal): the plugin checks the
# option before the session imports the renderer.
QUALITIES = ("low", "medium", "high", "auto")
_UPDATE = False  # set from --alight-update-goldens by pytest_configure
_WRITTEN = 0  # goldens written this session, for the terminal summary
_RENDERER_SETTINGS = pytest.StashKey[tuple]()  # ((w, h), quality) for alight_renderer
_LOCAL_TOLERANCE = DEFAULT_LOCAL_TOLERANCE  # set from the alight_local_tolerance ini option


def pytest_addoption(parser) -> None:
    group = parser.getgroup("alight")
    group.addoption("--alight-update-goldens", action="store_true", default=False,
                    help="write renders compared by assert_image_matches as the new golden images")
    group.addoption("--alight-size", default=None, metavar="W[xH]",
                    help="alight_renderer's default render size (ini alight_size; default 256)")
    group.addoption("--alight-quality", default=None, choices=QUALITIES,
                    help="alight_renderer's bake quality (ini alight_quality; default low)")
    parser.addini("alight_size", default="256", help="alight_renderer's default render size, W or WxH")
    parser.addini("alight_quality", default="low", help=f"alight_renderer's bake quality: {', '.join(QUALITIES)}")
    parser.addini("alight_local_tolerance", default=str(DEFAULT_LOCAL_TOLERANCE),
                  help="assert_image_matches' default local tolerance: the largest rel error of a "
                       f"{BLOCK}x{BLOCK} block (inf turns the local check off)")


def pytest_configure(config) -> None:
    global _UPDATE, _LOCAL_TOLERANCE
    _UPDATE = bool(config.getoption("alight_update_goldens", default=False))
    _LOCAL_TOLERANCE = _ini_float(config, "alight_local_tolerance")
    quality = config.getoption("alight_quality", default=None) or config.getini("alight_quality")
    if quality not in QUALITIES:   # --alight-quality's choices are checked by its parser
        raise pytest.UsageError(f"ini option alight_quality: {quality!r} is not one of {', '.join(QUALITIES)}")
    config.stash[_RENDERER_SETTINGS] = (_renderer_size(config), quality)


def _renderer_size(config) -> tuple[int, int]:
    option = config.getoption("alight_size", default=None)
    text, where = (option, "--alight-size") if option else (config.getini("alight_size"), "ini option alight_size")
    w, _, h = str(text).strip().lower().partition("x")
    try:
        size = (int(w), int(h or w))
    except ValueError:
        size = (0, 0)
    if min(size) < 1:
        raise pytest.UsageError(f"{where}: {text!r} is not a size (W or WxH, in pixels)")
    return size


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:
    if config.getoption("alight_update_goldens", default=False):
        terminalreporter.write_line(f"alight: wrote {_WRITTEN} golden{'' if _WRITTEN == 1 else 's'}")


def _ini_float(config, name: str) -> float:
    text = config.getini(name)
    try:
        return float(text)
    except ValueError:
        raise pytest.UsageError(f"ini option {name}: {text!r} is not a number") from None


@pytest.fixture(scope="session")
def _alight_session_renderer(pytestconfig):
    """The one renderer (its context, programs and bakes) of the session, its size and quality from
    the alight_size and alight_quality ini options or --alight-size/--alight-quality; released at
    its end."""
    from alight.frontends.api import Renderer

    (w, h), quality = pytestconfig.stash[_RENDERER_SETTINGS]
    with Renderer(w, h, quality=quality) as r:
        yield r


@pytest.fixture
def alight_renderer(_alight_session_renderer):
    """The session's renderer, reset to the constructor's scene for this test: a mesh, material
    or camera one test set never reaches the next (a gold duck with its head cut off)."""
    return _alight_session_renderer.reset().open()   # open(): a test that closed it leaves it usable


@pytest.fixture(name="assert_image_matches")
def _assert_image_matches_fixture(request):
    """``assert_image_matches(actual, golden, metric="rel", tolerance=None, local_tolerance=None)``;
    a relative golden path is taken from the folder of the test file."""
    here = Path(str(request.node.fspath)).parent
    update = request.config.getoption("alight_update_goldens")

    def check(actual, golden_path, metric: str = "rel", tolerance: float | None = None,
              local_tolerance: float | None = None) -> float:
        __tracebackhide__ = True  # a failure shows the test's line, not the plugin's source
        golden = Path(golden_path)
        return _assert_image_matches(actual, golden if golden.is_absolute() else here / golden, metric,
                                     tolerance, update, local_tolerance)

    return check


def assert_image_matches(actual: np.ndarray, golden_path: str | os.PathLike, metric: str = "rel",
                         tolerance: float | None = None, local_tolerance: float | None = None) -> float:
    """Compare an image with a golden file; returns the error (of ``metric``).

    ``actual`` is (H, W, 3|4): uint8 sRGB (goldens are .png) or float linear radiance
    (goldens are .exr). Alpha is ignored. It fails when the ``metric`` error exceeds
    ``tolerance``, or when the rel error of any 16x16 block exceeds ``local_tolerance``
    (default 0.25, or the ``alight_local_tolerance`` ini option; ``math.inf`` turns it off).
    On failure the actual, expected and difference images are written beside the golden and
    an AssertionError says where.
    """
    __tracebackhide__ = True
    return _assert_image_matches(actual, Path(golden_path), metric, tolerance, _UPDATE, local_tolerance)


def _assert_image_matches(actual, golden: Path, metric: str, tolerance: float | None, update: bool,
                          local_tolerance: float | None = None) -> float:
    __tracebackhide__ = True
    global _WRITTEN
    from alight.exchange.output import write_image

    if metric not in METRICS:
        raise ValueError(f"metric {metric!r} is not one of {METRICS}")
    tol = DEFAULT_TOLERANCE[metric] if tolerance is None else float(tolerance)
    local_tol = _LOCAL_TOLERANCE if local_tolerance is None else float(local_tolerance)
    actual = np.asarray(actual)
    if actual.ndim != 3 or actual.shape[2] not in (3, 4):
        raise ValueError(f"actual: expected an (H, W, 3|4) image, got shape {actual.shape}")
    hdr = actual.dtype.kind == "f"
    _check_format(actual, golden, hdr)
    if update or not golden.exists():
        if not update:
            pytest.fail(f"{golden}: no golden image (run pytest --alight-update-goldens to write it)")
        golden.parent.mkdir(parents=True, exist_ok=True)
        write_image(golden, actual.astype(np.float32) if hdr else actual.astype(np.uint8), linear=hdr)
        _remove_failure(golden)
        _WRITTEN += 1
        return 0.0
    expected = _read(golden)
    a, e = _as_float(actual), _as_float(expected)
    if a.shape != e.shape:
        wrote = _write_failure(golden, a, e, None, hdr, metric)
        raise AssertionError(f"{golden}: size {a.shape[1]}x{a.shape[0]} differs from the golden's "
                             f"{e.shape[1]}x{e.shape[0]}; {wrote}")
    if metric == "rel":
        diff = np.abs(a - e)
        error = float(diff.mean() / max(float(np.abs(e).mean()), 1e-12))
        # A fixed scale, so that a faint difference looks faint: white is DIFF_SCALE x the
        # golden's mean, an error that fails the local check when a whole block has it.
        diff_image = diff / (DIFF_SCALE * max(float(np.abs(e).mean()), 1e-12))
    else:
        error, diff_image = _flip(a, e, hdr, golden)
    if not error <= tol:
        wrote = _write_failure(golden, a, e, diff_image, hdr, metric)
        raise AssertionError(f"{golden}: {metric} error {error:.4g} > tolerance {tol:g}; {wrote}")
    local, (x, y) = _local_error(a, e)
    if not local <= local_tol:
        wrote = _write_failure(golden, a, e, diff_image, hdr, metric)
        raise AssertionError(f"{golden}: local error {local:.4g} (rel error of the {BLOCK}x{BLOCK} block at "
                             f"x={x}, y={y}) > local tolerance {local_tol:g}; {wrote}")
    _remove_failure(golden)
    return error


def _local_error(a: np.ndarray, e: np.ndarray) -> tuple[float, tuple[int, int]]:
    """The worst block's mean |a - e| over the whole golden's mean |e|, and the block's corner.

    Blocks tile the image from the top left; the last row and column of blocks end at the
    image's edge (overlapping their neighbours) so that no sliver of a block weighs a few
    pixels as much as a whole block.
    """
    d = np.abs(a - e).mean(axis=2, dtype=np.float64)
    h, w = d.shape
    bh, bw = min(BLOCK, h), min(BLOCK, w)
    # Block sums from the summed-area table.
    sat = np.zeros((h + 1, w + 1))
    sat[1:, 1:] = d.cumsum(0).cumsum(1)
    ys = np.unique(np.minimum(np.arange(0, h, bh), h - bh))
    xs = np.unique(np.minimum(np.arange(0, w, bw), w - bw))
    sums = (sat[ys[:, None] + bh, xs[None, :] + bw] - sat[ys[:, None], xs[None, :] + bw]
            - sat[ys[:, None] + bh, xs[None, :]] + sat[ys[:, None], xs[None, :]])
    i, j = np.unravel_index(int(np.argmax(sums)), sums.shape)
    return float(sums[i, j] / (bh * bw) / max(float(np.abs(e).mean()), 1e-12)), (int(xs[j]), int(ys[i]))


def _check_format(actual: np.ndarray, golden: Path, hdr: bool) -> None:
    """Refuse a golden format that cannot hold the image as it is, at update and compare alike:
    a float render written to .png is clipped and sRGB-encoded, so it never matches again, and
    a lossy .jpg golden differs from the render it was written from."""
    __tracebackhide__ = True
    suffix = golden.suffix.lower()
    if not hdr and actual.dtype != np.uint8:
        pytest.fail(f"{golden}: actual is {actual.dtype}; give a uint8 sRGB image (.png golden) or a "
                    f"float linear one (.exr golden)", pytrace=False)
    want = ".exr" if hdr else ".png"
    if suffix != want:
        kind = "a float (linear) image needs" if hdr else "a uint8 (sRGB) image needs"
        lossy = " (lossy formats change the pixels they store)" if suffix in (".jpg", ".jpeg", ".webp") else ""
        pytest.fail(f"{golden}: {kind} a {want} golden, not {suffix or 'no extension'}{lossy}", pytrace=False)


def _read(path: Path) -> np.ndarray:
    __tracebackhide__ = True
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise AssertionError(f"{path}: cannot read the golden image ({oiio.geterror()})")
    try:
        fmt = oiio.FLOAT if path.suffix.lower() == ".exr" else oiio.UINT8
        return np.asarray(image.read_image(format=fmt))
    finally:
        image.close()


def _as_float(image: np.ndarray) -> np.ndarray:
    """RGB as float in [0,1] for uint8, or as is for float; alpha dropped."""
    rgb = np.asarray(image)[:, :, :3]
    return rgb.astype(np.float32) / 255.0 if rgb.dtype.kind in "ui" else rgb.astype(np.float32)


def _flip(a: np.ndarray, e: np.ndarray, hdr: bool, golden: Path) -> tuple[float, np.ndarray]:
    __tracebackhide__ = True
    try:
        import flip_evaluator
    except ImportError:
        # A dependency of alight, but an install made with --no-deps (or a package removed since)
        # lacks it; rel comparisons need nothing from it.
        pytest.fail(f"{golden}: metric 'flip' needs the flip-evaluator package, a dependency of alight "
                    f"missing from this environment (pip install flip-evaluator)", pytrace=False)
    error_map, mean, _ = flip_evaluator.evaluate(np.ascontiguousarray(e), np.ascontiguousarray(a),
                                                 "HDR" if hdr else "LDR", applyMagma=True)
    return float(mean), np.asarray(error_map, np.float32)


def _failure_paths(golden: Path) -> list[Path]:
    stem = golden.with_suffix("")
    return [Path(f"{stem}.{kind}.png") for kind in ("actual", "expected", "diff")]


def _remove_failure(golden: Path) -> None:
    """A passing or updated golden's failure images from an earlier run would only mislead."""
    for path in _failure_paths(golden):
        path.unlink(missing_ok=True)


def _write_failure(golden: Path, a, e, diff, hdr: bool, metric: str) -> str:
    """actual / expected / diff as 8-bit PNGs people can open (HDR images clipped to [0,1]);
    returns the words that say where they are and the diff image's scale."""
    from alight.core.shading import linear_to_srgb
    from alight.exchange.output import write_image

    def png(x):
        x = np.clip(np.nan_to_num(x), 0.0, 1.0)
        if hdr:
            x = linear_to_srgb(x)
        return (np.asarray(x) * 255.0 + 0.5).astype(np.uint8)

    _remove_failure(golden)   # a size mismatch writes no diff: an older one would not match
    out = _failure_paths(golden)
    write_image(out[0], png(a), linear=False)
    write_image(out[1], png(e), linear=False)
    scale = ""
    if diff is not None:
        write_image(out[2], (np.clip(diff, 0, 1) * 255.0 + 0.5).astype(np.uint8), linear=False)
        scale = (f" (diff: |actual - expected|, black 0 to white {DIFF_SCALE:g} x the golden's mean)"
                 if metric == "rel" else " (diff: the FLIP error map, magma, 0 to 1)")
    else:
        out = out[:2]
    return f"wrote {', '.join(p.name for p in out)} in {golden.parent}{scale}"
