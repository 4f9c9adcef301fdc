"""What the subcommands share: the argument types, the parser class, the option groups that
several subcommands take (scene, camera, material, bake), the ``Command`` each subcommand module
declares, and the warning line. The flags are read into a scene by app/frontends/scene_setup.py
(scene, camera) and app/frontends/options.py (material)."""

from __future__ import annotations

import argparse
import math
import re
import sys
from dataclasses import dataclass
from typing import Callable

from alight.core.ibl_models import DEFAULT_IBL_MODEL, IBL_MODELS
from alight.core.material_fields import FIELDS

QUALITIES = ("low", "medium", "high")
# alight.core.scene.TONEMAPS with a few words each for --help, written out so that --help needs no
# numpy; tests/test_tonemaps.py keeps the names and their order equal to TONEMAPS, so a new curve
# cannot reach the command without its line in --help.
TONEMAP_HELP = {
    "none": "clamp",
    "aces": "Hill's ACES fit",
    "neutral": "Khronos PBR Neutral",
    "aces-narkowicz": "Narkowicz's ACES fit",
    "aces-hill": "= aces",
    "aces-hill-exposure-boost": "Hill after /0.6: three.js's, model-viewer's and the glTF Sample Viewer's ACES",
    "agx": "Blender's default view since 4.0",
}
TONEMAP_CHOICES = tuple(TONEMAP_HELP)


@dataclass(frozen=True)
class Command:
    """One subcommand: ``add_parser(subparsers)`` declares its parser and arguments,
    ``run(args)`` runs it and returns the exit status (an AlightError is the user's mistake)."""

    name: str
    add_parser: Callable[[argparse._SubParsersAction], None]
    run: Callable[[argparse.Namespace], int]


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
    g.add_argument("--variant", metavar="NAME",
                   help="a glTF file's material variant (KHR_materials_variants) to draw, by name "
                        "(default: each part's own material)")
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


def _add_shadow_options(p, editor: bool = False) -> None:
    """--shadows and --ground, 'alight render''s and 'alight edit''s (the panel's 'shadows' combo and
    'ground' checkbox)."""
    p.add_argument("--shadows", choices=("auto", "on", "off"), default="auto",
                   help="shadow maps for the lights and the environment's suns: auto draws them only where "
                        "something can be shadowed (not for a convex mesh such as the built-in sphere) (default: auto)")
    p.add_argument("--ground", action="store_true",
                   help="a ground under the model's bounding box that catches its shadow, composited over the "
                        + ("background (the panel's 'ground' checkbox)" if editor else
                           "background (with --background transparent: the shadow in alpha)"))


def _add_occlusion_option(p: argparse.ArgumentParser, editor: bool = False) -> None:
    """--occlusion, 'alight render''s and 'alight edit''s (the panel's 'occlusion' combo)."""
    p.add_argument("--occlusion", choices=("auto", "on", "off", "gtao"), default="auto",
                   help="occlusion of the environment light and one diffuse bounce from a per-vertex "
                        "ray-traced visibility bake (cached like the IBL bake): auto bakes it where the mesh "
                        "occludes more than 3%% of its own surface (never the built-in sphere or a convex mesh), "
                        "and draws a mesh too big to bake (over 250k vertices) with gtao; gtao: screen-space "
                        "ambient occlusion per frame from the depth buffer, no bake (docs/explanation/occlusion.md"
                        + ("; the editor bakes it in a background process and draws the view without it "
                           "meanwhile" if editor else "") + ") (default: auto)")


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
                   help="IBL shading model (app/core/ibl_models.py): 'lecture' is the lecture's split sum "
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


def _warn(lines) -> None:
    for line in lines:
        print(f"alight: warning: {line}", file=sys.stderr)


def _warn_line(line: str) -> None:
    """One warning line (scene_setup's ``report``)."""
    _warn([line])
