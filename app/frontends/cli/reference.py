"""``alight reference``: docs/conventions.md's ground truth (app/accuracy/reference.py), or a path-traced one."""

from __future__ import annotations

import sys
import time

from alight.errors import AlightError
from alight.frontends.cli.arguments import (
    Command,
    _add_camera_options,
    _add_scene_options,
    _size,
    _Size,
    _warn,
    _warn_line,
)
from alight.frontends.options import build_look


def add_parser(sub) -> None:
    rf = sub.add_parser("reference", help="the exact IBL ground truth (docs/conventions.md) on the GPU, as linear EXR",
                        description="Compute docs/conventions.md's ground truth per pixel on the GPU: the sum over "
                                    "every texel of the environment of f(l, v) L(l) max(n.l, 0) dOmega (k = r^2/2, "
                                    "F per direction at v.h), plus emission and the punctual lights (k = (r+1)^2/8), "
                                    "no occlusion. Roughness below 0.1 is refused when an environment is used. "
                                    "--integrator path (the default for a mesh file) path-traces the scene instead, "
                                    "with the same BRDF, shadows and inter-reflection (docs/explanation/path-traced-reference.md).")
    _add_scene_options(rf)
    _add_camera_options(rf)
    rd = rf.add_argument_group("reference")
    rd.add_argument("--integrator", choices=("auto", "exact", "path"), default="auto",
                    help="exact: the texel sum above, no occlusion (exact on a convex mesh, noise-free); path: "
                         "path-trace the scene with the same BRDF, with shadows and inter-reflection "
                         "(app/accuracy/path_trace.py, needs embreex: pip install 'alight[reference]'); auto: path "
                         "for a mesh file in the camera view, exact for the built-in meshes and the probe "
                         "(default: auto)")
    rd.add_argument("--samples", type=int, default=256, metavar="N",
                    help="--integrator path: samples per pixel (default: 256); noise falls as 1/sqrt(N)")
    rd.add_argument("--seed", type=int, default=0, metavar="N",
                    help="--integrator path: the random generator's seed; the same seed gives the same image "
                         "(default: 0)")
    rd.add_argument("--max-bounces", type=int, default=8, metavar="N",
                    help="--integrator path: surface vertices per path at most, 1 = direct light only (default: 8)")
    rd.add_argument("--size", type=_size, default=_Size(256, 256, True), metavar="W|WxH",
                    help="image size; W alone is square, or with --camera gltf the camera's aspect ratio, as in "
                         "'alight render' (default: 256)")
    rd.add_argument("--env-level", default="auto", metavar="N|auto",
                    help="sum over the map box-reduced by 2^N (area-weighted): 4^N times faster. Level 1 "
                         "changed royal_esplanade by <= 0.015%% (worst pixel 0.1%%) at r >= 0.25, but by 0.5%% "
                         "at r = 0.1 and ~1%% on quarry_01's compact sun. auto: 1 when every roughness is >= 0.25, "
                         "the map is >= 1024 wide and no compact source holds >= 10%% of its power, else 0 "
                         "(default: auto)")
    rd.add_argument("--out", required=True, metavar="FILE.exr",
                    help="linear float32 RGBA radiance, alpha 1 on the surface (docs/conventions.md); .exr only")
    rd.add_argument("--verbose", "-v", action="store_true", help="print the GL renderer, the level and the times")


def run(args) -> int:
    from alight.exchange.output import check_output_path

    start = time.perf_counter()
    out = check_output_path(args.out, (".exr",))
    width, height = args.size
    if args.view == "probe" and width != height:
        raise AlightError(f"--size: the probe view is square; got {width}x{height}")
    level = _env_level(args)
    look = build_look(args)
    integrator = _integrator(args, level)

    from alight.accuracy.reference import check_layer_roughness, check_roughness

    material = look[0]
    if not args.no_ibl and integrator == "exact":
        check_roughness(material.roughness)   # before any file is read
        check_layer_roughness(material)
    setup = _scene(args, look)
    if integrator == "path":
        _path_trace(args, setup, out, start)
    else:
        _exact(args, setup, out, level, start)
    print(out)
    return 0


def _scene(args, look):
    """The scene of the flags, read as 'alight render' reads them (app/frontends/scene_setup.py);
    the reference has no display, IBL model or shadow options of its own."""
    from alight.frontends.scene_setup import scene_from_flags

    return scene_from_flags(args, args.size, look, _warn_line)


def _env_level(args) -> int | None:
    """--env-level as a whole number 0..8 (None: auto)."""
    if args.env_level == "auto":
        return None
    try:
        level = int(args.env_level)
    except ValueError:
        raise AlightError(f"--env-level: '{args.env_level}' is not a whole number or 'auto'") from None
    if not 0 <= level <= 8:
        raise AlightError(f"--env-level: {level} is out of range [0, 8]")
    return level


def _integrator(args, level: int | None) -> str:
    """'exact' or 'path' (--integrator auto: a concave built-in, the shader ball's groove, or a mesh
    file shadows itself: paths), its flags checked and embreex found before any file is read."""
    from alight.core.mesh import CONVEX_BUILTINS

    integrator = args.integrator
    if integrator == "auto":
        integrator = "path" if args.view == "camera" and args.mesh not in CONVEX_BUILTINS else "exact"
    if integrator == "path":
        for option, value, low in (("--samples", args.samples, 1), ("--max-bounces", args.max_bounces, 1)):
            if value < low:
                raise AlightError(f"{option}: {value} must be at least {low}")
        if args.view != "camera":
            raise AlightError("--integrator path: only with --view camera (the probe has nothing to occlude)")
        if level is not None:
            raise AlightError("--env-level: only with --integrator exact (the path tracer samples the full map)")
        from alight.accuracy.path_trace import _import_embree

        _import_embree()   # a missing install is said before any file is read
    return integrator


def _path_trace(args, setup, out, start: float) -> None:
    from alight.accuracy.path_trace import TraceSettings, trace
    from alight.exchange.output import write_image

    env = setup.environment
    result = trace(setup.scene, env.radiance if env is not None else None, setup.width, setup.height,
                   TraceSettings(samples=args.samples, max_bounces=args.max_bounces, seed=args.seed))
    _warn(result.warnings)
    write_image(out, result.linear, linear=True)
    if args.verbose:
        print(f"path traced, {args.samples} samples a pixel, seed {args.seed}; total "
              f"{time.perf_counter() - start:.3f}s; "
              + ", ".join(f"{k} {v:.3f}s" for k, v in result.seconds.items()),
              file=sys.stderr)


def _exact(args, setup, out, level: int | None, start: float) -> None:
    from alight.accuracy.reference import ReferenceRenderer
    from alight.exchange.output import write_image

    env = setup.environment
    ref = ReferenceRenderer()
    result = ref.render(setup.scene, env.radiance if env is not None else None, setup.width, setup.height,
                        env_level=level)
    write_image(out, result.linear, linear=True)
    if args.verbose:
        from alight.core.gpu import describe

        where = "no environment" if result.env_size is None else \
            f"env level {result.env_level} ({result.env_size[0]}x{result.env_size[1]})"
        print(f"{describe(ref.ctx)}\n{where}, {result.dispatches} dispatches; total "
              f"{time.perf_counter() - start:.3f}s; " + ", ".join(f"{k} {v:.3f}s" for k, v in result.seconds.items()),
              file=sys.stderr)


COMMAND = Command("reference", add_parser, run)
