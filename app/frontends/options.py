"""What the command-line front ends share: the material their flags describe.

``alight render``, ``export``, ``reference`` and ``edit`` take the same material flags; the
editor builds its first state from them too, so this sits below both ``cli`` and ``editor``.
"""

from __future__ import annotations

from alight.errors import AlightError


def build_material(args):
    """The preset (or the default material) with the field flags on top; also the overrides alone."""
    from alight.core.material import Material, parse_color, with_overrides
    from alight.exchange.presets import load_preset

    base = load_preset(args.preset) if args.preset is not None else Material()
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
    return with_overrides(base, **overrides), overrides
