"""The camera flags of ``alight render`` and ``alight reference``, and the Camera they ask for."""

from __future__ import annotations

import argparse
import math

from alight.errors import AlightError
from alight.frontends.cli.arguments import _number, _warn


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
