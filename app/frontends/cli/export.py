"""``alight export``: the material as glTF 2.0 (app/exchange/gltf_material.py), material-only or on a mesh; a mesh file alone with its own materials (app/exchange/gltf_file_materials.py)."""

from __future__ import annotations

import sys

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command, _add_material_options
from alight.frontends.options import build_look


def add_parser(sub) -> None:
    e = sub.add_parser("export", help="write the material as a material-only .gltf, or a mesh with it as .glb",
                       description="Export a material (the default, a preset, or a glTF file's material, with "
                                   "the field flags on top) as glTF 2.0: a material-only .gltf, or --mesh with "
                                   "the material as .glb. A dielectric F0 other than 0.04 is written with "
                                   "KHR_materials_ior (and KHR_materials_specular when coloured). A --mesh file given "
                                   "alone is written with its own materials and textures, as 'alight render' "
                                   "draws it.")
    e.add_argument("--mesh", help="a built-in (sphere, cube, plane, shader_ball, rounded_cube, drape) or a mesh "
                                  "file (default: none for .gltf, a material only; "
                                  "sphere for .glb); written with UVs, tangents and the maps. A mesh file "
                                  "given without --preset, --material-from, maps or field flags keeps its own "
                                  "materials and textures, as 'alight render --mesh' draws them")
    e.add_argument("--material-from", metavar="FILE.gltf|FILE.glb",
                   help="start from this glTF file's material instead of a preset")
    e.add_argument("--material-index", type=int, default=0, metavar="N",
                   help="which material of --material-from (default: 0)")
    _add_material_options(e)
    e.add_argument("--out", required=True, metavar="FILE.gltf|FILE.glb",
                   help="the file to write (.gltf: its images and .bin beside it)")
    e.add_argument("--verbose", "-v", action="store_true", help="list the texture set's assignment and conversions")


def run(args) -> int:
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
    # As `alight render` decides (scene_setup): no preset and no maps draw the file's own
    # materials; field flags, which render lays over each of them, select the flag-built one here.
    own = args.preset is None and texture_maps is None and not overrides
    _, notes = export_gltf(material, out, texture_maps, mesh, file_materials=own)
    for line in notes:
        if args.verbose or "left out" in line:   # what the file lost is always said
            print(f"alight: {line}", file=sys.stderr)
    print(out)
    return 0


COMMAND = Command("export", add_parser, run)
