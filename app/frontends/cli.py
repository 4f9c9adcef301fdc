"""``alight``: render materials headless, bake environments, list presets.

A user's mistake (a bad file, a bad option) prints one line ``alight: error: ...`` and exits
with status 2; nothing is written. Heavy modules are imported after the arguments are parsed,
so ``--help`` and argument errors are instant.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
import time

from alight.core.ibl_models import DEFAULT_IBL_MODEL, IBL_MODELS
from alight.core.material_fields import FIELDS
from alight.errors import AlightError
from alight.frontends.options import build_look

QUALITIES = ("low", "medium", "high")
# alight.core.scene.TONEMAPS, written out so that --help needs no numpy (a test keeps them equal).
TONEMAP_CHOICES = ("none", "aces", "neutral", "aces-narkowicz", "aces-hill", "aces-hill-exposure-boost", "agx")


def _number(option: str, low: float | None = None, high: float | None = None):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"'{text}' is not finite")
        if (low is not None and value < low) or (high is not None and value > high):
            hi = "inf)" if high is None else f"{high:g}]"
            raise argparse.ArgumentTypeError(f"{value:g} is out of range [{low:g}, {hi}")
        return value

    parse.__name__ = option
    return parse


def _size(text: str) -> tuple[int, int]:
    try:
        parts = [int(x) for x in text.lower().split("x")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not W or WxH") from None
    one_side = len(parts) == 1
    if one_side:
        parts *= 2
    if len(parts) != 2 or not all(1 <= x <= 16384 for x in parts):
        raise argparse.ArgumentTypeError(f"'{text}' is not W or WxH with sides 1..16384")
    return _Size(parts[0], parts[1], one_side)


class _Size(tuple):
    """(width, height) as --size gave it; ``one_side``: only W was given (a square unless a
    camera's aspect ratio decides the height)."""

    def __new__(cls, width: int, height: int, one_side: bool = False):
        size = super().__new__(cls, (width, height))
        size.one_side = one_side
        return size


def _add_scene_options(p: argparse.ArgumentParser, views: bool = True) -> None:
    """``views``: offer --view (the editor draws the camera view only, and does not offer it)."""
    g = p.add_argument_group("scene")
    g.add_argument("--mesh", default="sphere",
                   help="a built-in (sphere, cube, plane, shader_ball, rounded_cube, drape) or a mesh file "
                        "(.obj .gltf .glb .ply .stl) (default: sphere)")
    g.add_argument("--env", default="studio",
                   help="'studio' (built in) or an equirectangular .hdr/.exr map, 2:1 (default: studio)")
    g.add_argument("--env-rotation", type=_number("--env-rotation"), default=0.0, metavar="DEG",
                   help="turn the environment about +Y by DEG degrees, right-handed (default: 0)")
    g.add_argument("--env-intensity", type=_number("--env-intensity", 0.0), default=1.0, metavar="X",
                   help="multiply the environment's radiance by X (default: 1)")
    g.add_argument("--no-ibl", action="store_true", help="no environment light (punctual lights and emission only)")
    g.add_argument("--light", action="append", default=[], metavar="SPEC",
                   help="add a light: point:pos=X,Y,Z, directional:dir=X,Y,Z or "
                        "spot:pos=X,Y,Z:dir=X,Y,Z[:inner=DEG][:outer=DEG], each [:color=R,G,B][:intensity=I] "
                        "(point and spot also [:range=R]); repeat for more (point and spot intensity is "
                        "W/sr-like, divided by distance squared; directional is irradiance). Without --light, "
                        "a glTF file's KHR_lights_punctual lights are used")
    g.add_argument("--no-file-lights", action="store_true", help="ignore the lights a glTF file brings")
    # Taken but not offered where only the camera view is drawn (the editor refuses probe in a line).
    g.add_argument("--view", choices=("camera", "probe"), default="camera",
                   help="camera: the mesh framed by a camera on +Z; probe: docs/conventions.md's analysis view "
                        "(a unit sphere, orthographic, exact per-pixel normals, no anti-aliasing)"
                   if views else argparse.SUPPRESS)
    _add_material_options(p)


def _add_camera_options(p: argparse.ArgumentParser) -> None:
    c = p.add_argument_group("camera (default: the mesh framed from +Z; a built-in preview mesh from its 3/4 view)")
    c.add_argument("--camera", default="auto", metavar="auto|gltf[:N]",
                   help="auto: frame the mesh (with the flags below); gltf[:N]: the glTF file's camera N "
                        "(default 0), placed by its node (default: auto)")
    # None: not given (a built-in preview mesh keeps its 3/4 view; given, either is from +Z).
    c.add_argument("--orbit", type=_number("--orbit"), default=None, metavar="DEG",
                   help="turn the camera about +Y from +Z by DEG degrees, right-handed (default: 0; a built-in "
                        "preview mesh without --orbit and --elevation: its 3/4 view)")
    c.add_argument("--elevation", type=_number("--elevation", -90.0, 90.0), default=None, metavar="DEG",
                   help="raise the camera by DEG degrees (default: 0, or as --orbit says)")
    c.add_argument("--distance", type=_number("--distance", 1e-6), default=None, metavar="X",
                   help="the camera's distance from the target (default: what frames the mesh)")
    c.add_argument("--fov", type=_number("--fov", 1.0, 179.0), default=None, metavar="DEG",
                   help="vertical field of view in degrees (default: 35, or the glTF camera's)")
    c.add_argument("--target", metavar="X,Y,Z", help="the point looked at (default: the mesh's bounding-box centre)")


def _camera(args, mesh, aspect: float):
    """The Camera --camera and the camera flags ask for (None: the renderer frames the mesh)."""
    from dataclasses import replace

    from alight.core.scene import orbit_camera

    spec = args.camera
    flags = {"--orbit": args.orbit is not None, "--elevation": args.elevation is not None,
             "--distance": args.distance is not None, "--target": args.target is not None}
    if spec == "auto":
        if not any(flags.values()) and args.fov is None:
            return None
        target = None
        if args.target is not None:
            try:
                target = tuple(float(x) for x in args.target.split(","))
            except ValueError:
                target = ()
            if len(target) != 3 or not all(math.isfinite(x) for x in target):
                raise AlightError(f"--target: '{args.target}' is not three comma-separated numbers")
        if mesh is None:
            raise AlightError("--orbit/--elevation/--distance/--fov/--target: only with --view camera")
        if target is not None:   # the file's coordinates, where the mesh was moved from (Mesh.origin)
            target = tuple(t - o for t, o in zip(target, getattr(mesh, "origin", (0.0, 0.0, 0.0))))
        centre, radius = mesh.bounding_sphere()
        orbit, elevation = args.orbit, args.elevation
        if orbit is None and elevation is None and getattr(mesh, "view", None) is not None:
            orbit, elevation = mesh.view   # --distance, --fov or --target alone keep a built-in's view
        return orbit_camera(centre, radius, aspect, orbit or 0.0, elevation or 0.0, args.distance,
                            35.0 if args.fov is None else args.fov, target, corners=mesh.corners())
    kind, _, index = spec.partition(":")
    if kind != "gltf":
        raise AlightError(f"--camera: '{spec}' is not auto, gltf or gltf:N")
    used = [name for name, on in flags.items() if on]
    if used:
        raise AlightError(f"{used[0]}: not with --camera {spec} (the file's camera is placed by its node)")
    try:
        n = int(index) if index else 0
    except ValueError:
        raise AlightError(f"--camera: '{spec}': N must be a whole number") from None
    cameras = getattr(mesh, "cameras", []) if mesh is not None else []
    if not cameras:
        raise AlightError(f"--camera: {args.mesh}: the file has no camera")
    if not 0 <= n < len(cameras):
        raise AlightError(f"--camera: {args.mesh}: camera {n} does not exist (the file has {len(cameras)})")
    camera = cameras[n]
    return camera if args.fov is None else replace(camera, fov_y_deg=args.fov)


def _add_material_options(p: argparse.ArgumentParser) -> None:
    m = p.add_argument_group("material (flags override the preset's fields)")
    m.add_argument("--preset", metavar="NAME|PATH",
                   help="a preset name (see 'alight presets') or a preset .json file; replaces the mesh file's own materials")
    m.add_argument("--texture-set", metavar="DIR",
                   help="a folder of texture maps assigned to slots by their names (Substance, ambientCG, Poly Haven, "
                        "Quixel/Unreal suffixes: _BaseColor, _Normal(GL|DX), _Roughness, _Gloss, _Metallic, _AO, _ORM, "
                        "...); the loaded slots' factors become 1 (glTF's convention); -v lists the assignment")
    m.add_argument("--map", action="append", default=[], metavar="SLOT=PATH",
                   help="one texture map (repeatable, after --texture-set): SLOT is base_color, metallic_roughness, "
                        "metallic, roughness, normal, emissive, occlusion, or normal_dx (a DirectX normal map, "
                        "green flipped), gloss (inverted into roughness), orm/arm (R occlusion, G rough, B metal)")
    y = p.add_argument_group("material layers (glTF extensions; each is off at its default, docs/layers.md)")
    for field in FIELDS:   # alight.core.material_fields: the same fields as batch specs and the API
        group = m if field.layer is None else y
        if field.kind == "color":   # parsed (R,G,B or one grey) and range-checked by options.build_look
            group.add_argument(field.flag, metavar=field.metavar, help=field.help)
        elif field.low_open or math.isinf(field.low):   # an open low end: build_look says "must be > 0"
            group.add_argument(field.flag, type=_number(field.flag), metavar=field.metavar, help=field.help)
        else:
            high = None if math.isinf(field.high) else field.high
            group.add_argument(field.flag, type=_number(field.flag, field.low, high), metavar=field.metavar,
                               help=field.help)


def _add_bake_options(p: argparse.ArgumentParser, auto: bool = False) -> None:
    g = p.add_argument_group("image-based lighting")
    if auto:
        g.add_argument("--quality", choices=QUALITIES + ("auto",), default="medium",
                       help="bake resolution and sample counts (app/ibl/bake.py's QUALITY table); auto: the "
                            "cheapest measured bake whose predicted error against the converged split sum "
                            "stays within --error-budget for this scene's materials and environment "
                            "(app/accuracy/auto_quality.py) (default: medium)")
        g.add_argument("--error-budget", type=_number("--error-budget", 0.01, 100.0), default=None, metavar="PCT",
                       help="with --quality auto: the probe's implementation error allowed, in percent (default: 2)")
    else:
        g.add_argument("--quality", choices=QUALITIES, default="medium",
                       help="bake resolution and sample counts (app/ibl/bake.py's QUALITY table) (default: medium)")
    g.add_argument("--irradiance", choices=("convolution", "sh9"),
                   help="diffuse irradiance by the lecture's hemisphere convolution or by 9 spherical "
                        "harmonics (default: the quality's choice)")
    g.add_argument("--ibl", choices=tuple(IBL_MODELS), default=DEFAULT_IBL_MODEL,
                   help="IBL shading model (app/core/ibl_models.py): 'lecture' is the seed lecture's split sum "
                        f"(default: {DEFAULT_IBL_MODEL})")
    g.add_argument("--multiple-scattering", action="store_true",
                   help="add the energy that single scattering loses on rough surfaces (Fdez-Aguera 2019): "
                        "a white furnace then gives 1, but the result leaves docs/conventions.md's single-scattering truth")


# A value that starts with '-' and is a number or comma-separated numbers (-0.18,0,0; -1e-3; -inf)
# is an option's value, not an option: argparse's own pattern takes only -1 and -.5 and so refused
# '--target -0.18,0,0' with 'expected one argument'. No option of alight's looks like a number.
_NUMBER = r"(?:\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|inf|infinity|nan)"
_NEGATIVE_VALUE = re.compile(rf"^-{_NUMBER}(?:,[-+]?{_NUMBER})*$", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """argparse, but a bad option is one line (no usage dump), like every other user error, and
    a negative number or vector is a value wherever an option takes one."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_VALUE

    def error(self, message: str):
        self.exit(2, f"alight: error: {' '.join(message.split())} (see '{self.prog} --help')\n")

# ---- alight edit (the interactive editor; everything else lives in app/frontends/editor/) ----

def _add_edit_parser(sub) -> None:
    e = sub.add_parser("edit", help="open the interactive material editor (needs a display)",
                       description="The material editor: a window with a live preview and a panel. "
                                   "Drop .hdr/.exr, mesh or preset .json files on it.")
    _add_scene_options(e, views=False)
    e.add_argument("--quality", choices=QUALITIES + ("auto",), default="medium",
                   help="bake quality; auto: the cheapest measured bake within 2%% for the environment and "
                        "the kind of material, shown in the panel (default: medium)")
    e.add_argument("--size", type=_size, default=(1280, 720), metavar="W|WxH", help="window size (default: 1280x720)")
    e.add_argument("--aa", choices=("none", "msaa"), default="none",
                   help="anti-aliasing of the preview (default: none; msaa costs ~2x on llvmpipe)")
    e.add_argument("--motion-scale", type=_number("--motion-scale", 0.25, 1.0), default=None, metavar="X",
                   help="the view's resolution while the camera moves, relative to the view area; a still "
                        "view is redrawn at full resolution (default: adaptive, the scale that holds 30 FPS)")
    e.add_argument("--screenshot", metavar="FILE.png",
                   help="render --frames frames, write the view (without the panel) at window size, exit")
    e.add_argument("--frames", type=int, default=0, metavar="N", help="frames before --screenshot (default 1), "
                                                                       "or measured by --benchmark (default 120)")
    e.add_argument("--benchmark", action="store_true",
                   help="1280x720, the material ball, IBL, 3 lights and the panel: print median and p95 frame times")
    e.add_argument("--script", action="append", default=[], metavar="FIELD=VALUE",
                   help="an edit applied after a frame (repeatable), e.g. roughness=0.9, preset=water, open=FILE. "
                        "FIELD: roughness, metallic, ior, base_color, emissive, specular_f0 (R,G,B linear), the "
                        "layers' fields (clearcoat, clearcoat_roughness, sheen_color, ..., as the material flags), "
                        "preset, open, mesh, env (a name or path), exposure, tonemap, env_rotation, env_intensity, "
                        "ibl (0/1), ibl_model, multiple_scattering (0/1), quality, debug_view, debug_mip, "
                        "map_SLOT (an image path, '' clears; SLOT: base_color, metallic_roughness, metallic, roughness, normal, emissive, occlusion), "
                        "uv_scale, uv_offset (U,V)")
    e.add_argument("--ui-test", metavar="FILE.py",
                   help="run FILE's test_*(ctx) functions with the Dear ImGui Test Engine against the real "
                        "window (ctx.set_ref('alight'); ctx.item_click('**/copper')); exit 0 when all pass, "
                        "1 with each failure; the session is saved as after a normal close")
    e.add_argument("--no-panel", action="store_true", help="draw the view only")
    e.add_argument("--new", action="store_true",
                   help="do not reopen the last session (it is reopened when no scene option is given)")


def _edit(args) -> int:
    import os

    if args.view != "camera":
        raise AlightError("--view: the editor shows the camera view")
    if args.frames < 0:
        raise AlightError(f"--frames: {args.frames} is negative")
    if args.screenshot:   # refuse a bad path before a window opens
        from alight.exchange.output import check_output_path

        check_output_path(args.screenshot, (".png",))
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        raise AlightError("editor: no display (DISPLAY is unset); run under xvfb-run -a, or use 'alight render'")
    from alight.frontends.editor.run import run

    return run(args)

# ---- end of alight edit ----


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="alight", description="A physically based material renderer "
                                     "(Cook-Torrance, split-sum image-based lighting) on ModernGL.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    r = sub.add_parser("render", help="render a material to a PNG or EXR, headless",
                       description="Render a material headless. With only --out: the default material ball "
                                   "in the built-in studio.")
    _add_scene_options(r)
    _add_camera_options(r)
    _add_bake_options(r, auto=True)
    r.add_argument("--occlusion", choices=("auto", "on", "off"), default="off",
                   help="occlusion of the environment light and one diffuse bounce from a per-vertex "
                        "ray-traced visibility bake (cached like the IBL bake): auto bakes it where the mesh "
                        "can occlude itself (not for the built-in sphere or a convex mesh); off by default while "
                        "it blots some models (docs/explanation/occlusion.md) (default: off)")
    d = r.add_argument_group("image")
    d.add_argument("--size", type=_size, default=_Size(1024, 1024, True), metavar="W|WxH",
                   help="image size; W alone is square, or with --camera gltf the camera's aspect ratio "
                        "(default: 1024)")
    d.add_argument("--tonemap", choices=TONEMAP_CHOICES, default=None,
                   help="PNG only (refused with .exr, which is linear): none (clamp); aces = aces-hill, Hill's "
                        "ACES fit; neutral, Khronos PBR Neutral; aces-narkowicz; aces-hill-exposure-boost (Hill "
                        "after /0.6: three.js's, model-viewer's and the glTF Sample Viewer's ACES); agx "
                        "(Blender's default view since 4.0) (default: aces)")
    d.add_argument("--exposure", type=_number("--exposure", -32.0, 32.0), default=0.0, metavar="EV",
                   help="PNG only (refused with .exr): multiply radiance by 2^EV before tone mapping (default: 0)")
    d.add_argument("--background", choices=("env", "blur", "color", "transparent"), default="env",
                   help="what lies behind the object (default: env); alpha is 0 there in every mode")
    d.add_argument("--background-color", metavar="R,G,B", help="linear colour for --background color")
    d.add_argument("--aa", choices=("none", "msaa", "ssaa"), default="msaa",
                   help="anti-aliasing: msaa (4 samples) or ssaa (2x2 supersampling) (default: msaa; "
                        "the probe view never blends pixels)")
    d.add_argument("--out", required=True, metavar="FILE.png|FILE.exr",
                   help=".png: 8-bit sRGB after exposure and tone mapping; .exr: linear float32 RGBA radiance, "
                        "alpha 1 on the surface (docs/conventions.md)")
    d.add_argument("--verbose", "-v", action="store_true", help="print the GL renderer and time per step")
    d.add_argument("--shadows", choices=("auto", "on", "off"), default="auto",
                   help="shadow maps for the lights and the environment's suns: auto draws them only where "
                        "something can be shadowed (not for a convex mesh such as the built-in sphere) (default: auto)")
    d.add_argument("--ground", action="store_true",
                   help="a ground under the model's bounding box that catches its shadow, composited over the "
                        "background (with --background transparent: the shadow in alpha)")

    b = sub.add_parser("bake", help="bake an environment's IBL maps and write them as images",
                       description="Write the baked maps as equirectangular images (linear .exr and "
                                   "ACES-tone-mapped .png): the source cube, the irradiance, each "
                                   "prefiltered roughness step, and the BRDF LUT.")
    b.add_argument("--env", default="studio", help="'studio' or an equirectangular .hdr/.exr map")
    _add_bake_options(b)
    b.add_argument("--width", type=int, default=512, help="width of the written equirect images (default: 512)")
    b.add_argument("--out", required=True, metavar="DIR", help="folder for the images (created if missing)")

    # --- alight export (glTF material round trip, app/exchange/gltf_material.py) -------------------
    e = sub.add_parser("export", help="write the material as a material-only .gltf, or a mesh with it as .glb",
                       description="Export a material (the default, a preset, or a glTF file's material, with "
                                   "the field flags on top) as glTF 2.0: a material-only .gltf, or --mesh with "
                                   "the material as .glb. A dielectric F0 other than 0.04 is written with "
                                   "KHR_materials_ior (and KHR_materials_specular when coloured).")
    e.add_argument("--mesh", help="a built-in (sphere, cube, plane, shader_ball, rounded_cube, drape) or a mesh "
                                  "file (default: none for .gltf, a material only; "
                                  "sphere for .glb); written with UVs, tangents and the maps")
    e.add_argument("--material-from", metavar="FILE.gltf|FILE.glb",
                   help="start from this glTF file's material instead of a preset")
    e.add_argument("--material-index", type=int, default=0, metavar="N",
                   help="which material of --material-from (default: 0)")
    _add_material_options(e)
    e.add_argument("--out", required=True, metavar="FILE.gltf|FILE.glb",
                   help="the file to write (.gltf: its images and .bin beside it)")
    e.add_argument("--verbose", "-v", action="store_true", help="list the texture set's assignment and conversions")
    # --- end alight export ---------------------------------------------------------------
    # --- alight batch (app/frontends/batch.py) ---------------------------------------------------------
    bt = sub.add_parser("batch", help="render meshes x environments x materials x angles from a spec",
                        description="Render every combination in a .toml/.json spec (see app/frontends/batch.py), a "
                                    "labelled contact sheet and optional turntables. Up-to-date outputs are "
                                    "skipped; failed items are reported and the rest go on (exit 1).")
    bt.add_argument("spec", metavar="SPEC.toml|SPEC.json")
    bt.add_argument("--executor", choices=("local", "ray", "inline"), default="local",
                    help="local: a process pool, one GL context per process; ray: Ray actors, each with its "
                         "own GL context and bake cache (RAY_ADDRESS or --ray-address picks the cluster; "
                         "none: a local one); inline: this process (default: local)")
    bt.add_argument("--ray-address", metavar="ADDR", help="Ray cluster address, e.g. auto or HEAD:6379")
    bt.add_argument("--workers", type=int, default=None, metavar="N", help="worker processes (default: CPU count)")
    bt.add_argument("--force", action="store_true", help="render every item even if its output is up to date")
    bt.add_argument("--out", metavar="DIR", help="output folder (default: the spec's 'out')")
    # --- end alight batch ---------------------------------------------------------------------
    # --- alight reference (app/accuracy/reference.py) --------------------------------------------------
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
    # --- end alight reference -----------------------------------------------------------------
    # --- alight compare / alight chart (app/accuracy/metrics.py, app/accuracy/chart.py) -----------------------
    cp = sub.add_parser("compare", help="error of a linear image against a reference: relMAE and FLIP",
                        description="Compare two linear .exr images (e.g. 'alight render --view probe --out t.exr' "
                                    "against 'alight reference --out r.exr'): the relative mean absolute error "
                                    "sum|test-ref|/sum|ref| over the covered pixels (alpha > 0) and RGB, and NVIDIA's "
                                    "FLIP on the ACES-tone-mapped sRGB images.")
    cp.add_argument("test", metavar="TEST.exr")
    cp.add_argument("ref", metavar="REF.exr")
    cp.add_argument("--heatmap", metavar="OUT.png", help="write the per-pixel relative error as a heat map")
    cp.add_argument("--flip-heatmap", metavar="OUT.png", help="write the per-pixel FLIP error as a heat map")
    cp.add_argument("--exposure", type=_number("--exposure", -32.0, 32.0), default=0.0, metavar="EV",
                    help="exposure before tone mapping, for FLIP (default: 0)")
    cp.add_argument("--bin", type=int, default=1, metavar="N",
                    help="also print relMAE after summing both images over NxN blocks (the blocks covered in both): "
                         "against a path-traced reference it divides the reference's noise by N (default: 1, off)")
    ch = sub.add_parser("chart", help="sweep the IBL settings: bake time, frame time, error against the ground truth",
                        description="Measure, one factor at a time around the medium quality, every IBL setting "
                                    "(irradiance method and size, specular cube size, sample counts, filtered "
                                    "importance sampling, LUT size and samples, every IBL model, multiple "
                                    "scattering judged by the white furnace) against the GPU ground truth on the "
                                    "presets x roughness x environments. Writes CSVs and PNG charts (app/accuracy/chart.py).")
    ch.add_argument("--quick", action="store_true",
                    help="a small sweep: royal_esplanade only, 3 presets, 3 roughness values, a few settings")
    ch.add_argument("--env", action="append", metavar="MAP",
                    help="an environment (repeatable; default: every 2:1 map in ../shared/data/env, else studio)")
    ch.add_argument("--presets", metavar="A,B,...", help="presets to measure (default: all; --quick: gold, "
                                                          "plastic_high, water)")
    ch.add_argument("--size", type=int, default=32, metavar="N", help="probe size for the errors (default: 32)")
    ch.add_argument("--out", default="alight-chart", metavar="DIR", help="output folder (default: alight-chart)")
    # --- end alight compare / alight chart ---------------------------------------------------
    sub.add_parser("presets", help="list the material presets (the lecture's F0 table)")
    # --- alight cache (app/ibl/bake_cache.py) ------------------------------------------------
    ca = sub.add_parser("cache", help="show or clear the bake cache (bakes reused across runs)",
                        description="The bakes kept between runs (app/ibl/bake_cache.py) and the BRDF LUTs, in "
                                    "ALIGHT_CACHE_DIR or the user's cache folder; the least recently used bakes "
                                    "go first past the size limit (ALIGHT_BAKE_CACHE_MB).")
    ca.add_argument("action", nargs="?", choices=("show", "clear"), default="show",
                    help="show: where it is, entries and size (default); clear: remove every bake and LUT")
    _add_edit_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """The ``alight`` command; returns the exit status. A reader that closes the pipe early
    (``alight presets | head``) ends the command quietly, as ``cat`` does: status 141 (128 +
    SIGPIPE), no traceback."""
    try:
        try:
            return _main(argv)
        finally:
            sys.stdout.flush()   # inside the try: a closed pipe shows here, not at interpreter exit
    except BrokenPipeError:
        _quiet_stdout()
        return 128 + 13


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so that Python's final flush of the closed pipe is silent."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        import os

        if not os.environ.get("DISPLAY"):
            parser.print_help()
            return 0
        args = parser.parse_args(["edit"])   # with a display, plain 'alight' opens the editor
    previous = _catch_termination()
    try:
        if args.command == "edit":
            return _edit(args)
        if args.command == "render":
            return _render(args)
        if args.command == "bake":
            return _bake(args)
        if args.command == "presets":
            return _presets()
        if args.command == "cache":  # alight cache
            return _cache(args)
        if args.command == "export":  # alight export
            return _export(args)
        if args.command == "reference":  # alight reference
            return _reference(args)
        if args.command == "compare":  # alight compare
            return _compare(args)
        if args.command == "chart":  # alight chart
            return _chart(args)
        if args.command == "batch":  # alight batch
            if args.workers is not None and args.workers < 1:
                raise AlightError(f"--workers: {args.workers} must be at least 1")
            import os

            from alight.frontends.batch import main as batch_main

            if args.ray_address:
                os.environ["ALIGHT_RAY_ADDRESS"] = args.ray_address

            return batch_main(args.spec, args.executor, args.workers, args.force, args.out)
    except AlightError as exc:
        print(f"alight: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except Terminated:
        print("alight: terminated", file=sys.stderr)
        return 128 + 15
    except KeyboardInterrupt:
        print("alight: interrupted", file=sys.stderr)
        return 130
    finally:
        _restore_termination(previous)
    return 0


class Terminated(KeyboardInterrupt):
    """SIGTERM (a job scheduler's or `kill`'s), raised where the process is, so that what is
    being written is removed as on Ctrl-C (alight.exchange.output.atomic_path) before it exits."""


def _on_terminate(signum, frame):
    raise Terminated()


def _catch_termination():
    """SIGTERM as ``Terminated`` in the main thread; returns the handler it replaces (None
    where signals cannot be set: another thread, an embedding host)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    try:
        return signal.signal(signal.SIGTERM, _on_terminate)
    except (ValueError, OSError):
        return None


def _restore_termination(previous) -> None:
    if previous is not None:
        import signal

        signal.signal(signal.SIGTERM, previous)


def _warn(lines) -> None:
    for line in lines:
        print(f"alight: warning: {line}", file=sys.stderr)


def _render(args) -> int:
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
    material, overrides, texture_maps = build_look(args)

    from alight.core.scene import Display, Scene, parse_light
    from alight.exchange.texture_sets import load_map_images
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment

    lights = [parse_light(spec) for spec in args.light]
    mesh = load_mesh(args.mesh) if args.view == "camera" else None
    if mesh is not None:
        _warn(mesh.warnings)
        if not args.light and not args.no_file_lights:
            lights = list(mesh.lights)
    width, height = _camera_size(args, mesh, width, height)
    camera = _camera(args, mesh, width / height)
    if camera is None and mesh is not None and getattr(mesh, "view", None) is None:   # a built-in has its own view
        normal = mesh.flat_normal()
        if normal is not None and abs(normal[2]) < 0.02:   # the default camera's view is -Z (docs/conventions.md)
            _warn([f"{args.mesh}: the mesh is flat and the default camera (on +Z) sees it edge-on, so it "
                   f"may not show; --elevation 30 (or --orbit) looks at it from another side"])
    env = None if args.no_ibl else load_environment(args.env)
    if env is not None:
        _warn(env.warnings)
    display = Display(tonemap=args.tonemap or "aces", exposure=args.exposure, background=args.background)
    if args.background_color:
        from alight.core.material import parse_color

        display.background_color = parse_color(args.background_color, "--background-color")
    scene = Scene(mesh=mesh, material=material, use_file_materials=args.preset is None and texture_maps is None,
                  texture_maps=texture_maps, texture_images=load_map_images(texture_maps) if texture_maps else {},
                  material_overrides=overrides, lights=lights, camera=camera, view=args.view,
                  env_rotation_deg=args.env_rotation, env_intensity=args.env_intensity,
                  ibl_enabled=env is not None, ibl_model=args.ibl,
                  multiple_scattering=args.multiple_scattering, display=display, shadows=args.shadows,
                  ground=args.ground, occlusion=args.occlusion)
    loaded = time.perf_counter()

    from alight.exchange.output import image_rows_writer
    from alight.ibl.bake import quality_named
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()
    if args.quality == "auto":
        quality = _auto_quality(args, scene, env)
        if quality is None:
            env = None
            scene.ibl_enabled = False
    else:
        quality = quality_named(args.quality, args.irradiance)
    maps = renderer.bake(env, quality) if env is not None else None
    baked = time.perf_counter()
    # Strip by strip (an image too big for one framebuffer is drawn in tiles): each band of rows
    # is written and dropped, so memory stays bounded at any --size.
    exr = out.suffix.lower() == ".exr"
    channels = 4 if exr or args.background == "transparent" else 3
    writing = 0.0
    with image_rows_writer(out, width, height, channels, linear=exr) as put:
        for strip in renderer.render_strips(scene, maps, width, height, aa=args.aa, read_linear=exr, read_srgb=not exr):
            t = time.perf_counter()
            put(strip.frame.linear if exr else strip.frame.srgb[:, :, :channels])
            writing += time.perf_counter() - t
    if args.verbose:
        from alight.core.gpu import describe

        done = time.perf_counter()
        print(f"{describe(renderer.ctx)}\nload {loaded - start:.3f}s  bake {baked - loaded:.3f}s "
              f"render {done - baked - writing:.3f}s  write {writing:.3f}s", file=sys.stderr)
        if maps is not None:
            print("bake passes: " + ", ".join(f"{k} {v * 1000:.0f}ms" for k, v in maps.pass_seconds.items()),
                  file=sys.stderr)
    print(out)
    return 0


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


def _camera_size(args, mesh, width: int, height: int) -> tuple[int, int]:
    """The image size for --camera gltf: a --size of one side takes the camera's aspect ratio
    (glTF's perspective.aspectRatio, or xmag/ymag), as viewers do; a size that does not match
    it is kept and warned (the vertical field of view is the camera's, so the sides are cut or
    widened)."""
    if args.camera == "auto" or mesh is None:
        return width, height
    from alight.exchange.camera_aspect import gltf_camera_aspects

    kind, _, index = args.camera.partition(":")
    try:
        aspect = gltf_camera_aspects(args.mesh)[int(index) if index else 0]
    except (IndexError, ValueError):
        return width, height        # _camera says what is wrong with the spec
    if aspect is None:
        return width, height
    if getattr(args.size, "one_side", False):
        return width, max(1, round(width / aspect))
    if abs(width / height - aspect) > 0.5 / height * aspect + 1e-9:
        side = "cut off" if width / height < aspect else "widened beyond the camera's frame"
        _warn([f"--camera {args.camera}: {args.mesh}'s camera has aspect ratio {aspect:.4g} but --size "
               f"{width}x{height} is {width / height:.4g}: the image's sides are {side}; give --size {width} "
               f"to take the camera's aspect"])
    return width, height


def _cache(args) -> int:
    from alight.ibl.bake import LutCache
    from alight.ibl.bake_cache import BakeCache

    bakes = BakeCache()
    luts = LutCache.files()
    if args.action == "clear":
        removed = bakes.clear()
        for path in luts:
            path.unlink(missing_ok=True)
        print(f"removed {removed} bake{'s' * (removed != 1)} and {len(luts)} BRDF LUT{'s' * (len(luts) != 1)} "
              f"from {bakes.directory.parent}")
        return 0
    count, size = bakes.stats()
    lut_bytes = sum(p.stat().st_size for p in luts)
    print(f"bake cache: {bakes.directory}")
    print(f"  {count} bake{'s' * (count != 1)}, {size / 2**20:.1f} MiB of {bakes.size_limit / 2**20:.0f} MiB "
          f"(past it, the least recently used go first; ALIGHT_BAKE_CACHE_MB sets it)")
    print(f"  BRDF LUTs: {len(luts)} file{'s' * (len(luts) != 1)}, {lut_bytes / 2**20:.1f} MiB")
    return 0


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


def _bake(args) -> int:
    import os
    from pathlib import Path

    import numpy as np

    from alight.ibl.environment import load_environment

    if args.width < 8 or args.width > 8192 or args.width % 2:
        raise AlightError(f"--width: {args.width} must be an even number from 8 to 8192")
    out_dir = Path(args.out)
    if out_dir.exists() and not out_dir.is_dir():
        raise AlightError(f"{out_dir}: exists and is not a folder")
    env = load_environment(args.env)
    _warn(env.warnings)

    from alight.core.shading import linear_to_srgb, tonemap_aces_fitted
    from alight.exchange.output import write_image
    from alight.ibl.bake import grid_roughness, quality_named, read_lut
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()
    q = quality_named(args.quality, args.irradiance)
    maps = renderer.bake(env, q)
    os.makedirs(out_dir, exist_ok=True)
    w = args.width

    def save(name: str, linear: np.ndarray) -> None:
        write_image(out_dir / f"{name}.exr", linear.astype(np.float32), linear=True)
        srgb = (linear_to_srgb(tonemap_aces_fitted(linear[:, :, :3])) * 255.0 + 0.5).astype(np.uint8)
        write_image(out_dir / f"{name}.png", srgb, linear=False)

    save("environment", _cube_as_equirect(renderer, maps.environment, 0.0, w))
    save("irradiance", _cube_as_equirect(renderer, maps.irradiance, 0.0, w))
    levels = q.prefiltered_levels
    for step in range(2 * levels - 1):
        cube = maps.prefiltered_radiance if step % 2 == 0 else maps.prefiltered_radiance_mid
        save(f"prefiltered_step{step:02d}_r{grid_roughness(step, levels):.3f}",
             _cube_as_equirect(renderer, cube, float(step // 2), w))
    lut = read_lut(maps.brdf_lut)[::-1]
    zero = np.zeros(lut.shape[:2] + (1,), np.float32)
    # The LUT is already in [0,1]: shown as is (n.v right, roughness up). brdf_lut: red = scale A,
    # green = bias B; brdf_lut_directions: red = t_A, green = t_B (brdf_lut.comp).
    for name, rg in (("brdf_lut", lut[..., :2]), ("brdf_lut_directions", lut[..., 2:])):
        rgb = np.concatenate([rg, zero], axis=2)
        write_image(out_dir / f"{name}.exr", rgb, linear=True)
        write_image(out_dir / f"{name}.png", (linear_to_srgb(rgb) * 255.0 + 0.5).astype(np.uint8), linear=False)
    if maps.suns:
        print(f"{len(maps.suns)} compact source(s) ({', '.join(f'{100 * s.fraction:.0f}%' for s in maps.suns)} of the "
              "power) are not in the irradiance and prefiltered maps: the forward pass adds them per pixel")
    for name, seconds in maps.pass_seconds.items():
        print(f"{name}: {seconds * 1000:.1f} ms")
    print(out_dir)
    return 0


def _cube_as_equirect(renderer, cube, lod: float, width: int):
    import moderngl
    import numpy as np

    ctx = renderer.ctx
    height = width // 2
    image = ctx.texture((width, height), 4, dtype="f4")
    prog = renderer.shaders.compute("ibl/cube_to_equirect.comp")
    cube.use(0)
    prog["u_cube"] = 0
    prog["u_lod"] = lod
    prog["u_size"] = (width, height)
    image.bind_to_image(0, read=False, write=True)
    prog.run((width + 7) // 8, (height + 7) // 8, 1)
    ctx.memory_barrier(moderngl.ALL_BARRIER_BITS)
    pixels = np.frombuffer(image.read(), np.float32).reshape(height, width, 4).copy()
    image.release()
    return pixels


def _presets() -> int:
    from alight.core.shading import linear_to_srgb
    from alight.exchange.presets import list_presets, load_preset

    print(f"{'preset':20s} {'metallic':>8s} {'roughness':>9s}  {'F0 linear':22s} F0 sRGB")
    for name in list_presets():
        m = load_preset(name)
        f0 = m.f0()
        srgb = linear_to_srgb(f0)
        print(f"{name:20s} {m.metallic:8.2f} {m.roughness:9.2f}  "
              f"({f0[0]:.2f}, {f0[1]:.2f}, {f0[2]:.2f})     ({srgb[0]:.2f}, {srgb[1]:.2f}, {srgb[2]:.2f})")
    return 0


# --- alight export ------------------------------------------------------------------------
def _export(args) -> int:
    from alight.exchange.output import check_output_path

    out = check_output_path(args.out, (".gltf", ".glb"))
    if args.material_from is not None and args.preset is not None:
        raise AlightError("--material-from: give either --preset or --material-from, not both")
    if args.material_from is not None:
        from alight.exchange.material_files import is_gltf

        if not is_gltf(args.material_from):
            raise AlightError(f"--material-from: {args.material_from} is not a .gltf or .glb file")
        args.preset = args.material_from   # build_look reads its material and its maps
    material, overrides, texture_maps = build_look(args, index=args.material_index)

    from alight.exchange.gltf_export import export_gltf

    mesh = None
    if args.mesh is not None or out.suffix.lower() == ".glb":
        from alight.exchange.meshes import load_mesh

        mesh = load_mesh(args.mesh or "sphere")
    _, notes = export_gltf(material, out, texture_maps, mesh)
    if args.verbose:
        for line in notes:
            print(f"alight: {line}", file=sys.stderr)
    print(out)
    return 0
# --- end alight export --------------------------------------------------------------------


# --- alight reference (app/accuracy/reference.py) --------------------------------------------------
def _reference(args) -> int:
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
# --- end alight reference -----------------------------------------------------------------


# --- alight compare / alight chart (app/accuracy/metrics.py, app/accuracy/chart.py) ---------------------------
def _compare(args) -> int:
    from alight.exchange.output import check_output_path

    if not 1 <= args.bin <= 64:
        raise AlightError(f"--bin: {args.bin} must be from 1 to 64")
    for opt, path in (("--heatmap", args.heatmap), ("--flip-heatmap", args.flip_heatmap)):
        if path:
            check_output_path(path, (".png",))
    from alight.accuracy.metrics import (
        compare_linear,
        read_linear,
        write_flip_heatmap,
        write_relative_heatmap,
    )

    test, ref = read_linear(args.test), read_linear(args.ref)
    if test.shape[:2] != ref.shape[:2]:
        raise AlightError(f"{args.test}: {test.shape[1]}x{test.shape[0]} does not match {args.ref}'s "
                          f"{ref.shape[1]}x{ref.shape[0]}")
    c = compare_linear(test, ref, args.exposure)
    if c.covered == 0:
        raise AlightError(f"{args.ref}: no covered pixel (alpha is 0 everywhere)")
    print(f"relMAE {c.relative_mae * 100:.4g}%  FLIP {c.flip:.4g}  over {c.covered} covered pixels")
    if args.bin > 1:
        from alight.accuracy.binned import binned_relative_mae, covered_blocks

        blocks = int(covered_blocks(test, ref, args.bin).sum())
        if blocks == 0:
            raise AlightError(f"--bin: no {args.bin}x{args.bin} block is covered in both images")
        value = binned_relative_mae(test, ref, args.bin)
        print(f"binned {args.bin}x{args.bin} relMAE {value * 100:.4g}%  over {blocks} blocks")
    if args.heatmap:
        print(write_relative_heatmap(args.heatmap, c.relative_map))
    if args.flip_heatmap:
        print(write_flip_heatmap(args.flip_heatmap, c.flip_map))
    return 0


def _chart(args) -> int:
    from pathlib import Path

    from alight.accuracy.chart import (
        QUICK_PRESETS,
        QUICK_ROUGHNESS,
        ChartConfig,
        default_env_dir,
        equirect_envs,
        run_chart,
        sweep,
    )
    from alight.exchange.presets import list_presets

    if args.size < 8 or args.size > 256:
        raise AlightError(f"--size: {args.size} must be from 8 to 256")
    if args.env:
        envs = list(args.env)
    else:
        env_dir = default_env_dir()
        if env_dir is None:
            envs = ["studio"]
        else:
            envs, skipped = equirect_envs(env_dir)
            for line in [] if args.quick else skipped:
                print(f"alight chart: skipped {line}", file=sys.stderr)
            if args.quick:
                pick = [e for e in envs if "royal_esplanade" in e]
                envs = pick or envs[:1] or ["studio"]
    presets = list(QUICK_PRESETS) if args.quick else list_presets()
    if args.presets:
        presets = [p.strip() for p in args.presets.split(",") if p.strip()]
    config = ChartConfig(envs=envs, presets=presets, size=args.size,
                         roughness=QUICK_ROUGHNESS if args.quick else ChartConfig.__dataclass_fields__["roughness"].default,
                         frame_size=(320, 180) if args.quick else (1280, 720),
                         frame_repeats=3 if args.quick else 7, settings=sweep(args.quick))
    start = time.perf_counter()
    results = run_chart(config, args.out)
    out = Path(args.out)
    print(f"{len(results)} settings x {len(envs)} environment(s) in {time.perf_counter() - start:.0f} s")
    print(f"{'setting':34s} {'bake ms':>8s} {'frame ms':>9s} {'relMAE %':>9s} {'max %':>7s} {'FLIP':>6s} "
          f"{'furnace r=1':>11s}")
    for res in results:
        fr = [f[1] for f in res.furnace if f[0] == 1.0]
        print(f"{res.setting.name:34s} {res.bake_median * 1000:8.0f} {res.frame_seconds * 1000:9.1f} "
              f"{res.rel_mean * 100:9.2f} {res.rel_max * 100:7.1f} {res.flip_mean:6.3f} "
              f"{fr[0] if fr else float('nan'):11.3f}")
    for name in ("chart.csv", "chart_cases.csv", "furnace.csv", "error_map.csv", "chart.png", "error_map.png"):
        if (out / name).exists():
            print(out / name)
    return 0
# --- end alight compare / alight chart ---------------------------------------------------
