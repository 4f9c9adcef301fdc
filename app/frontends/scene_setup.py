"""The scene the front ends describe, set up one way for all of them.

``alight render`` and ``alight reference`` build their Scene from the same flags with
``scene_from_flags`` (so the same flags give the same scene, the same image size and the same
warnings); the Python API (``alight.Renderer``, and through it ``alight batch``) loads its mesh
with ``load_scene_mesh`` and says ``framing_warnings`` before it renders. What the picture is
drawn without (a mesh file's repairs, an environment's clamps, a flat mesh seen edge-on, a glTF
camera whose aspect ratio is not the image's) goes to ``report`` one line at a time, as it is
found: the CLI prints ``alight: warning: ...`` lines, the API issues an ``AlightWarning`` each.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from alight.errors import AlightError

Report = Callable[[str], None]


@dataclass
class SceneSetup:
    """A scene ready to render: the Scene, the environment it is lit by (None: --no-ibl) and
    the image size in pixels (a glTF camera's aspect ratio may have set the height)."""

    scene: object          # alight.core.scene.Scene (imported lazily: --help needs no numpy)
    environment: object    # alight.ibl.environment.Environment | None
    width: int
    height: int


def scene_from_flags(args, size: tuple[int, int], look, report: Report, **fields) -> SceneSetup:
    """The scene of the scene, camera and material flags (the groups of
    app/frontends/cli/arguments.py). ``look``: options.build_look's
    (material, overrides, maps); ``size``: --size's (W, H), W alone (``one_side``) letting a
    glTF camera set H; ``fields``: the Scene fields only one command has (render's display,
    IBL model, shadows, ...). Errors: AlightError of one line (a bad light, camera or file)."""
    from alight.core.scene import Scene, parse_light
    from alight.exchange.texture_sets import load_map_images

    material, overrides, texture_maps = look
    check_probe_flags(args)
    lights = [parse_light(spec) for spec in args.light]
    variant = getattr(args, "variant", None)
    mesh = load_scene_mesh(args.mesh, report, variant) if args.view == "camera" else None
    if variant is not None and (args.preset is not None or texture_maps is not None):
        report(f"--variant {variant}: changes nothing here: the material flags' material replaces the file's "
               f"materials (leave out --preset, --texture-set and --map to see the variant)")
    if mesh is not None and not args.light and not args.no_file_lights:
        lights = list(mesh.lights)
    width, height = camera_size(args, mesh, *size, report)
    camera = flag_camera(args, mesh, width / height)
    for line in framing_warnings(mesh, args.mesh, camera):
        report(line)
    env = None if args.no_ibl else load_scene_environment(args.env, report)
    scene = Scene(mesh=mesh, material=material, use_file_materials=args.preset is None and texture_maps is None,
                  texture_maps=texture_maps, texture_images=load_map_images(texture_maps) if texture_maps else {},
                  material_overrides=overrides, lights=lights, camera=camera, view=args.view,
                  env_rotation_deg=args.env_rotation, env_intensity=args.env_intensity,
                  ibl_enabled=env is not None, **fields)
    return SceneSetup(scene, env, width, height)


PROBE_CAMERA = "the probe view has its own orthographic camera on the unit sphere"


def check_probe_flags(args) -> None:
    """--view probe draws the material on a unit sphere through its own orthographic camera
    (docs/conventions.md): a flag that asks for a mesh, a camera or what a mesh brings (a ground,
    shadows, occlusion, a mesh-shading path) would be silently ignored, so it is refused in one
    line, as the camera flags always were. Only flags given (not at their defaults) are refused."""
    if getattr(args, "view", "camera") != "probe":
        return
    asked = [("--camera " + str(args.camera), getattr(args, "camera", "auto") != "auto", PROBE_CAMERA)]
    for flag in ("orbit", "elevation", "distance", "fov", "target"):
        asked.append((f"--{flag}", getattr(args, flag, None) is not None, PROBE_CAMERA))
    asked += [
        (f"--mesh {getattr(args, 'mesh', 'sphere')}", getattr(args, "mesh", "sphere") != "sphere",
         "the probe view draws no mesh, only the material on its unit sphere"),
        ("--ground", bool(getattr(args, "ground", False)), "the probe view draws no ground"),
        (f"--shadows {getattr(args, 'shadows', 'auto')}", getattr(args, "shadows", "auto") == "on",
         "the probe view draws no shadows (there is no mesh to cast them)"),
        (f"--occlusion {getattr(args, 'occlusion', 'auto')}", getattr(args, "occlusion", "auto") in ("on", "gtao"),
         "the probe view has no mesh to occlude"),
        (f"--mesh-shading {getattr(args, 'mesh_shading', 'auto')}",
         getattr(args, "mesh_shading", "auto") != "auto", "the probe view draws no mesh"),
        (f"--variant {getattr(args, 'variant', None)}", getattr(args, "variant", None) is not None,
         "the probe view draws no mesh, so none of a file's material variants"),
    ]
    for flag, given, why in asked:
        if given:
            raise AlightError(f"{flag}: not with --view probe ({why}); use --view camera")


def load_scene_mesh(spec: str, report: Report, variant: str | None = None):
    """A built-in or a mesh file (alight.exchange.meshes.load_mesh), its warnings reported;
    ``variant``: the file's material variant of that name made active (alight.core.mesh.select_variant;
    an error of one line, naming --variant, where the file has none or no such name)."""
    from alight.core.mesh import select_variant
    from alight.exchange.meshes import load_mesh

    mesh = load_mesh(spec)
    if variant is not None:
        try:
            mesh = select_variant(mesh, variant)
        except AlightError as e:
            raise AlightError(f"--variant {variant}: {e}") from None
    for line in mesh.warnings:
        report(line)
    return mesh


def load_scene_environment(spec: str, report: Report):
    """'studio' or an equirectangular map (alight.ibl.environment.load_environment), its warnings
    reported; a missing file with the nearest name ('stuido: no such file; did you mean studio?')."""
    from alight.ibl.environment import load_environment

    try:
        env = load_environment(spec)
    except AlightError as e:
        hint = closest_environment(spec) if not Path(spec).exists() else ""
        if not hint:
            raise
        raise AlightError(f"{e}{hint}") from None
    for line in env.warnings:
        report(line)
    return env


def closest_environment(path: str) -> str:
    """'; did you mean studio?' (or the closest .hdr/.exr in the folder the entry names) for a
    misspelt environment, else '': batch's plan, alight render's --env and
    Renderer.set_environment say the same."""
    wanted = Path(path)
    folder = wanted.parent
    try:
        files = [p.name for p in folder.iterdir() if p.suffix.lower() in (".hdr", ".exr")] if folder.is_dir() else []
    except OSError:
        files = []
    close = difflib.get_close_matches(wanted.name, files, n=1) or \
        difflib.get_close_matches(wanted.stem, [Path(f).stem for f in files], n=1)
    if close:
        match = next((f for f in files if f == close[0] or Path(f).stem == close[0]), close[0])
        return f"; did you mean {folder / match}?"
    if difflib.get_close_matches(wanted.name.lower(), ["studio"], n=1):
        return "; did you mean studio?"
    return ""


def framing_warnings(mesh, name: str, camera, way_out: str = "--elevation 30 (or --orbit)") -> list[str]:
    """The default camera (camera None, on +Z looking down -Z: docs/conventions.md) sees a flat
    mesh edge-on, so it may not show; a built-in has its own 3/4 view (Mesh.view). ``way_out``:
    how this front end turns the camera."""
    if camera is not None or mesh is None or getattr(mesh, "view", None) is not None:
        return []
    normal = mesh.flat_normal()
    if normal is None or abs(normal[2]) >= 0.02:
        return []
    return [f"{name}: the mesh is flat and the default camera (on +Z) sees it edge-on, so it "
            f"may not show; {way_out} looks at it from another side"]


def flag_camera(args, mesh, aspect: float):
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
        if mesh is None:   # (check_probe_flags refuses these first, naming the flag)
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
        from alight.exchange.meshes import is_builtin

        if is_builtin(args.mesh):
            raise AlightError(f"--camera {spec}: the built-in mesh '{args.mesh}' has no glTF camera; "
                              f"give a .gltf/.glb file with --mesh, or use --camera auto")
        raise AlightError(f"--camera {spec}: {args.mesh}: the file has no camera")
    if not 0 <= n < len(cameras):
        raise AlightError(f"--camera: {args.mesh}: camera {n} does not exist (the file has {len(cameras)})")
    camera = cameras[n]
    return camera if args.fov is None else replace(camera, fov_y_deg=args.fov)


def camera_size(args, mesh, width: int, height: int, report: Report) -> tuple[int, int]:
    """The image size for --camera gltf: a --size of one side (or none) takes the camera's
    aspect ratio (glTF's perspective.aspectRatio, or xmag/ymag), as viewers do; a WxH that does
    not match it is kept (the camera's vertical field of view, or ymag, is kept, so the sides are
    cut or widened). Either way the picture is not the WxH or the square --size's help promises
    by default, so each says so in one line (``camera_size_line``)."""
    if args.camera == "auto" or mesh is None:
        return width, height
    from alight.exchange.camera_aspect import gltf_camera_frames

    kind, _, index = args.camera.partition(":")
    try:
        n = int(index) if index else 0
        frame = gltf_camera_frames(args.mesh)[n]
    except (IndexError, ValueError):
        return width, height        # flag_camera says what is wrong with the spec
    if frame.aspect is None:
        return width, height
    one_side = getattr(args.size, "one_side", False)
    if one_side:
        height = max(1, round(width / frame.aspect))
    line = camera_size_line(args.camera, args.mesh, n, frame, (width, height), one_side)
    if line:
        report(line)
    return width, height


def camera_size_line(spec: str, path: str, n: int, frame, size: tuple[int, int], one_side: bool) -> str | None:
    """The one warning line for --camera ``spec``'s image size, or None where the image is what
    --size asked for and fits the camera (a one-side --size on a square camera, a matching WxH)."""
    camera = f"{path}'s camera " + (f"'{frame.name}'" if frame.name else str(n))
    aspect = frame.aspect
    width, height = size
    if one_side:
        if width == height:
            return None
        return (f"--camera {spec}: {camera} has aspect ratio {aspect:.4g}, so the image is {width}x{height} "
                f"(give --size WxH to choose both)")
    if abs(width / height - aspect) <= 0.5 / height * aspect + 1e-9:
        return None
    kept = "vertical extent (ymag)" if frame.orthographic else "vertical field of view"
    side = "cut off" if width / height < aspect else "widened beyond the camera's frame"
    return (f"--camera {spec}: {camera} has aspect ratio {aspect:.4g} but --size {width}x{height} is "
            f"{width / height:.4g}: the image keeps the camera's {kept}, so its sides are {side} "
            f"(give --size {width} to take the camera's aspect ratio)")
