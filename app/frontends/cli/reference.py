"""``alight reference``: docs/conventions.md's ground truth (app/accuracy/reference.py), or a path-traced one."""

from __future__ import annotations

import sys
import time

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command, _add_scene_options, _size, _warn
from alight.frontends.cli.camera import _add_camera_options, _camera
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
    rd.add_argument("--size", type=_size, default=(256, 256), metavar="W|WxH", help="image size (default: 256)")
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
    level = None
    if args.env_level != "auto":
        try:
            level = int(args.env_level)
        except ValueError:
            raise AlightError(f"--env-level: '{args.env_level}' is not a whole number or 'auto'") from None
        if not 0 <= level <= 8:
            raise AlightError(f"--env-level: {level} is out of range [0, 8]")
    material, overrides, texture_maps = build_look(args)
    from alight.core.mesh import CONVEX_BUILTINS

    integrator = args.integrator
    if integrator == "auto":   # a concave built-in (the shader ball's groove) shadows itself: paths
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

    from alight.accuracy.reference import check_layer_roughness, check_roughness
    from alight.core.scene import Scene, parse_light
    from alight.exchange.texture_sets import load_map_images
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment

    if not args.no_ibl and integrator == "exact":
        check_roughness(material.roughness)   # before any file is read
        check_layer_roughness(material)
    lights = [parse_light(spec) for spec in args.light]
    mesh = load_mesh(args.mesh) if args.view == "camera" else None
    if mesh is not None:
        _warn(mesh.warnings)
        if not args.light and not args.no_file_lights:
            lights = list(mesh.lights)
    camera = _camera(args, mesh, width / height)
    env = None if args.no_ibl else load_environment(args.env)
    if env is not None:
        _warn(env.warnings)
    scene = Scene(mesh=mesh, material=material, use_file_materials=args.preset is None and texture_maps is None,
                  texture_maps=texture_maps, texture_images=load_map_images(texture_maps) if texture_maps else {},
                  material_overrides=overrides, lights=lights, camera=camera, view=args.view,
                  env_rotation_deg=args.env_rotation, env_intensity=args.env_intensity,
                  ibl_enabled=env is not None)
    if integrator == "path":
        from alight.accuracy.path_trace import TraceSettings, trace
        from alight.exchange.output import write_image

        result = trace(scene, env.radiance if env is not None else None, width, height,
                       TraceSettings(samples=args.samples, max_bounces=args.max_bounces, seed=args.seed))
        _warn(result.warnings)
        write_image(out, result.linear, linear=True)
        if args.verbose:
            print(f"path traced, {args.samples} samples a pixel, seed {args.seed}; total "
                  f"{time.perf_counter() - start:.3f}s; "
                  + ", ".join(f"{k} {v:.3f}s" for k, v in result.seconds.items()),
                  file=sys.stderr)
        print(out)
        return 0

    from alight.accuracy.reference import ReferenceRenderer
    from alight.exchange.output import write_image

    ref = ReferenceRenderer()
    result = ref.render(scene, env.radiance if env is not None else None, width, height, env_level=level)
    write_image(out, result.linear, linear=True)
    if args.verbose:
        from alight.core.gpu import describe

        where = "no environment" if result.env_size is None else \
            f"env level {result.env_level} ({result.env_size[0]}x{result.env_size[1]})"
        print(f"{describe(ref.ctx)}\n{where}, {result.dispatches} dispatches; total "
              f"{time.perf_counter() - start:.3f}s; " + ", ".join(f"{k} {v:.3f}s" for k, v in result.seconds.items()),
              file=sys.stderr)
    print(out)
    return 0


COMMAND = Command("reference", add_parser, run)
