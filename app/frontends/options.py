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
    from alight.core.material_fields import FIELDS
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
    overrides = {}
    for field in FIELDS:   # alight.core.material_fields: every flag of cli.arguments._add_material_options
        text = getattr(args, field.name, None)
        if text is None or text == "":   # an empty colour flag is not given (as before the registry)
            continue
        if field.kind == "color":
            value = parse_color(text, field.flag)
            if max(value) > field.high:
                raise AlightError(f"{field.flag}: {text} has a component above {field.high:g}")
        else:
            value = text
            if field.low_open and value <= field.low:
                raise AlightError(f"{field.flag}: {value:g} must be > {field.low:g}")
        overrides[field.name] = value
    return with_overrides(base, **overrides), overrides, (maps if maps is not None and maps.paths() else None)


def _stderr(line: str) -> None:
    import sys

    print(f"alight: {line}", file=sys.stderr)
