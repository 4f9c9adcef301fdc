"""``alight bake``: an environment's IBL maps written as images."""

from __future__ import annotations

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command, _add_bake_options, _warn


def add_parser(sub) -> None:
    b = sub.add_parser("bake", help="bake an environment's IBL maps and write them as images",
                       description="Write the baked maps as equirectangular images (linear .exr and "
                                   "ACES-tone-mapped .png): the source cube, the irradiance, each "
                                   "prefiltered roughness step, and the BRDF LUT.")
    b.add_argument("--env", default="studio", help="'studio' or an equirectangular .hdr/.exr map")
    _add_bake_options(b)
    b.add_argument("--width", type=int, default=512, help="width of the written equirect images (default: 512)")
    b.add_argument("--out", required=True, metavar="DIR", help="folder for the images (created if missing)")


def run(args) -> int:
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


COMMAND = Command("bake", add_parser, run)
