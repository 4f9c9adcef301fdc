"""``alight render``: a material on a mesh in an environment, headless, to a PNG or EXR."""

from __future__ import annotations

import sys
import time

from alight.errors import AlightError, warn
from alight.frontends.cli.arguments import (
    TONEMAP_CHOICES,
    TONEMAP_HELP,
    Command,
    _add_bake_options,
    _add_camera_options,
    _add_occlusion_option,
    _add_scene_options,
    _add_shadow_options,
    _number,
    _size,
    _Size,
    _warn,
    _warn_line,
)
from alight.frontends.options import build_look


def add_parser(sub) -> None:
    r = sub.add_parser("render", help="render a material to a PNG or EXR, headless",
                       description="Render a material headless. With only --out: the default material ball "
                                   "in the built-in studio.")
    _add_scene_options(r)
    _add_camera_options(r)
    _add_bake_options(r, auto=True)
    _add_occlusion_option(r)
    d = r.add_argument_group("image")
    d.add_argument("--size", type=_size, default=_Size(1024, 1024, True), metavar="W|WxH",
                   help="image size; W alone is square, or with --camera gltf the camera's aspect ratio "
                        "(default: 1024)")
    d.add_argument("--tonemap", choices=TONEMAP_CHOICES, default=None,
                   help="PNG only (refused with .exr, which is linear): "
                        + "; ".join(f"{name} ({words})" for name, words in TONEMAP_HELP.items())
                        + " (default: aces)")
    d.add_argument("--exposure", type=_number("--exposure", -32.0, 32.0), default=0.0, metavar="EV",
                   help="PNG only (refused with .exr): multiply radiance by 2^EV before tone mapping (default: 0)")
    d.add_argument("--background", choices=("env", "blur", "color", "transparent"), default="env",
                   help="what lies behind the object (default: env). A .png is RGB with the background drawn "
                        "in, except with transparent: RGBA, alpha 0 (and RGB 0) there; a .exr is RGBA in every "
                        "mode, alpha 0 there (RGB the background's radiance, 0 with transparent)")
    d.add_argument("--background-color", metavar="R,G,B", help="linear colour for --background color")
    d.add_argument("--aa", choices=("none", "msaa", "ssaa"), default="msaa",
                   help="anti-aliasing: msaa (4 samples) or ssaa (2x2 supersampling) (default: msaa; "
                        "the probe view never blends pixels)")
    d.add_argument("--mesh-shading", choices=("auto", "forward", "vbuffer"), default="auto",
                   help="with --aa msaa, how a mesh file's opaque parts are shaded: forward (once per triangle "
                        "covering a pixel), vbuffer (once per pixel from a visibility buffer: faster on dense "
                        "meshes, slower on coarse ones), auto: vbuffer where the mesh has under 3 estimated covered "
                        "pixels per triangle (docs/performance.md) (default: auto)")
    d.add_argument("--out", required=True, metavar="FILE.png|FILE.exr",
                   help=".png: 8-bit sRGB after exposure and tone mapping; .exr: linear float32 RGBA radiance, "
                        "alpha 1 on the surface (docs/conventions.md)")
    d.add_argument("--verbose", "-v", action="store_true", help="print the GL renderer and time per step")
    _add_shadow_options(d)


def run(args) -> int:
    from alight.exchange.output import check_output_path

    start = time.perf_counter()
    out = check_output_path(args.out)
    width, height = args.size
    if args.view == "probe" and width != height:
        raise AlightError(f"--size: the probe view is square; got {width}x{height}")
    if args.quality == "auto" and args.irradiance:
        raise AlightError("--irradiance: --quality auto chooses the irradiance method itself")
    if args.quality != "auto" and args.error_budget is not None:
        raise AlightError("--error-budget: only with --quality auto")
    _check_output_options(args, out)
    setup = _scene(args, build_look(args))
    scene, env, width, height = setup.scene, setup.environment, setup.width, setup.height
    loaded = time.perf_counter()

    from alight.ibl.bake import quality_named
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()
    renderer.mesh_shading = args.mesh_shading
    renderer.mesh_shading_option = "--mesh-shading"     # (its warning names the flag)
    if args.quality == "auto":
        quality = _auto_quality(args, scene, env)
        if quality is None:
            env = None
            scene.ibl_enabled = False
    else:
        quality = quality_named(args.quality, args.irradiance)
    maps = renderer.bake(env, quality) if env is not None else None
    baked = time.perf_counter()
    writing = _write(args, out, renderer, scene, maps, width, height)
    if renderer.last_ground_idle:
        why = "--shadows off" if renderer.last_ground_idle == "shadows off" else \
            "no light, and no sun in the map that the IBL model shades exactly (add --light, or use a map with a sun)"
        warn(f"--ground: nothing casts a shadow on it, so it changes nothing: {why}")
    if args.verbose:
        from alight.core.gpu import describe

        done = time.perf_counter()
        print(f"{describe(renderer.ctx)}\nload {loaded - start:.3f}s  bake {baked - loaded:.3f}s "
              f"render {done - baked - writing:.3f}s  write {writing:.3f}s", file=sys.stderr)
        # Which shading the mesh took (--mesh-shading auto decides per scene, alight.render.vbuffer).
        print(f"mesh shading: {'vbuffer' if renderer.last_vbuffer else 'forward'} (--mesh-shading {args.mesh_shading}: "
              f"{renderer.last_mesh_shading_reason})", file=sys.stderr)
        if getattr(renderer, "last_occlusion_reason", ""):
            print(f"occlusion: {renderer.last_occlusion_reason}", file=sys.stderr)
        if maps is not None:
            print("bake passes: " + ", ".join(f"{k} {v * 1000:.0f}ms" for k, v in maps.pass_seconds.items()),
                  file=sys.stderr)
    print(out)
    return 0


def _scene(args, look):
    """The scene of the flags (app/frontends/scene_setup.py, as 'alight reference' reads them) with
    render's own fields: the display, the IBL model, shadows, ground and occlusion."""
    from alight.core.scene import Display
    from alight.frontends.scene_setup import scene_from_flags

    setup = scene_from_flags(args, args.size, look, _warn_line, ibl_model=args.ibl,
                             multiple_scattering=args.multiple_scattering, shadows=args.shadows,
                             ground=args.ground, occlusion=args.occlusion)
    display = Display(tonemap=args.tonemap or "aces", exposure=args.exposure, background=args.background)
    if args.background_color:
        from alight.core.material import parse_color

        display.background_color = parse_color(args.background_color, "--background-color")
    setup.scene.display = display
    return setup


def _write(args, out, renderer, scene, maps, width: int, height: int) -> float:
    """Render and write ``out`` strip by strip (an image too big for one framebuffer is drawn in
    tiles): each band of rows is written and dropped, so memory stays bounded at any --size.
    Returns the seconds spent writing."""
    from alight.exchange.output import image_rows_writer

    exr = out.suffix.lower() == ".exr"
    channels = 4 if exr or args.background == "transparent" else 3
    writing = 0.0
    with image_rows_writer(out, width, height, channels, linear=exr) as put:
        for strip in renderer.render_strips(scene, maps, width, height, aa=args.aa, read_linear=exr, read_srgb=not exr):
            t = time.perf_counter()
            put(strip.frame.linear if exr else strip.frame.srgb[:, :, :channels])
            writing += time.perf_counter() - t
    return writing


def _check_output_options(args, out) -> None:
    """Refuse the render options that would do nothing for this output, and warn about those
    that do nothing for this scene, before anything is loaded: an option silently ignored reads
    as a bug in the picture."""
    if out.suffix.lower() == ".exr":
        if args.tonemap not in (None, "none"):
            raise AlightError(f"--tonemap {args.tonemap}: {out} is linear radiance, never tone mapped; "
                              f"write a .png to tone map, or drop --tonemap")
        if args.exposure != 0.0:
            raise AlightError(f"--exposure: {out} is linear radiance, written without exposure; write a .png "
                              f"or scale the EXR afterwards")
    if args.background_color and args.background != "color":
        raise AlightError(f"--background-color: only with --background color (got --background {args.background})")
    if args.no_ibl:
        unused = [flag for flag, on in (("--env-rotation", args.env_rotation != 0.0),
                                        ("--env-intensity", args.env_intensity != 1.0)) if on]
        if unused:
            _warn([f"{' and '.join(unused)}: no effect with --no-ibl (there is no environment light)"])
    if args.light and args.no_file_lights:
        _warn(["--no-file-lights: no effect with --light (the file's lights are used only without --light)"])


def _auto_quality(args, scene, env):
    """--quality auto: the chosen BakeQuality (None: nothing to bake), said in one line."""
    from alight.accuracy.auto_quality import (
        DEFAULT_ERROR_BUDGET,
        choose_quality,
        environment_features,
        scene_needs,
    )

    budget = DEFAULT_ERROR_BUDGET if args.error_budget is None else args.error_budget / 100.0
    off = env is None or scene.env_intensity == 0.0
    choice = choose_quality(scene_needs(scene), None if off else environment_features(env.radiance), budget,
                            off_reason="--no-ibl" if env is None else "--env-intensity 0")
    print(f"alight: {choice.line(budget)}", file=sys.stderr)
    return choice.quality


COMMAND = Command("render", add_parser, run)
