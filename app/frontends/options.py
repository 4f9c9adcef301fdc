"""What the command-line front ends share: the material their flags describe.

``alight render``, ``export``, ``reference`` and ``edit`` take the same material flags; the
editor builds its first state from them too, so this sits below both ``cli`` and ``editor``.
"""

from __future__ import annotations

from alight.errors import AlightError


def build_material(args):
    """The preset (or the default material) with the field flags on top; also the overrides alone."""
    material, overrides, _ = build_look(args)
    return material, overrides


def build_look(args, report=None, index: int = 0):
    """(material, overrides, maps): the preset (a name, .json, or a .gltf/.glb with its maps) or
    the default material, the maps of ``--texture-set DIR`` then each ``--map SLOT=PATH`` on top
    (their factors set to 1, glTF's convention), then the field flags. ``report``: called with
    each line of the texture set's assignment and each warning (None: printed to stderr)."""
    from alight.core.material import Material, parse_color, with_overrides
    from alight.core.texture_maps import map_factors
    from alight.exchange.material_files import load_material_file
    from alight.exchange.texture_sets import apply_map, assign_folder, parse_map_option

    say = report or _stderr
    if args.preset is not None:
        base, maps, warnings = load_material_file(args.preset, index)
        for line in warnings:
            say(f"warning: {line}")
    else:
        base, maps = Material(), None
    loaded: set[str] = set()
    texture_set = getattr(args, "texture_set", None)
    if texture_set:
        found = assign_folder(texture_set, maps)
        maps = found.maps
        loaded.update(found.slots)
        for a in found.files:
            if not a.slots:
                say(f"warning: {texture_set}: {a.line()}")
            elif getattr(args, "verbose", False):
                say(f"texture set: {a.line()}")
    for text in getattr(args, "map", None) or []:
        from alight.core.texture_maps import TextureMaps

        name, path = parse_map_option(text)
        maps, slots = apply_map(maps or TextureMaps(), name, path, f"--map {text}")
        loaded.update(slots)
    base = with_overrides(base, **map_factors(loaded)) if loaded else base
    overrides = {
        "base_color": parse_color(args.base_color, "--base-color") if args.base_color else None,
        "metallic": args.metallic,
        "roughness": args.roughness,
        "specular_f0": parse_color(args.specular_f0, "--specular-f0") if args.specular_f0 else None,
        "emissive": parse_color(args.emissive, "--emissive") if args.emissive else None,
        "ior": args.ior,
        "clearcoat": args.clearcoat,
        "clearcoat_roughness": args.clearcoat_roughness,
        "sheen_color": parse_color(args.sheen_color, "--sheen-color") if args.sheen_color else None,
        "sheen_roughness": args.sheen_roughness,
        "anisotropy_strength": args.anisotropy_strength,
        "anisotropy_rotation": args.anisotropy_rotation,
        "transmission": args.transmission,
        "thickness": args.thickness,
        "attenuation_color": parse_color(args.attenuation_color, "--attenuation-color")
        if args.attenuation_color else None,
        "attenuation_distance": args.attenuation_distance,
    }
    overrides = {k: v for k, v in overrides.items() if v is not None}
    if "base_color" in overrides and max(overrides["base_color"]) > 1.0:
        raise AlightError(f"--base-color: {args.base_color} has a component above 1")
    for field in ("specular_f0", "sheen_color", "attenuation_color"):
        if field in overrides and max(overrides[field]) > 1.0:
            option = "--" + field.replace("_", "-")
            raise AlightError(f"{option}: {getattr(args, field)} has a component above 1")
    if "attenuation_distance" in overrides and overrides["attenuation_distance"] <= 0.0:
        raise AlightError(f"--attenuation-distance: {args.attenuation_distance:g} must be > 0")
    return with_overrides(base, **overrides), overrides, (maps if maps is not None and maps.paths() else None)


def _stderr(line: str) -> None:
    import sys

    print(f"alight: {line}", file=sys.stderr)
