"""``alight presets``: the material presets (the lecture's F0 table)."""

from __future__ import annotations

from alight.frontends.cli.arguments import Command


def add_parser(sub) -> None:
    sub.add_parser("presets", help="list the material presets (the lecture's F0 table)")


def run(args) -> int:
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


COMMAND = Command("presets", add_parser, run)
