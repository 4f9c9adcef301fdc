"""The thumbnails' render process: ``python -m alight.frontends.editor.thumbnail_worker``.

Reads one job a line on stdin, ``MATERIAL_FILE<TAB>OUT.png`` (a .json preset, or a .glb with
maps), renders the material on the built-in sphere under the built-in studio ('low' bake, baked
once for the process's life) at THUMB_SIZE, writes OUT.png atomically and answers one line,
``ok`` or ``error: MESSAGE``. One process renders every thumbnail, so its start, its bake and
its shader variants are paid once, away from the editor's frames (thumbnails.py drives it).
"""

from __future__ import annotations

import sys


def main() -> int:
    from alight.core.scene import Scene
    from alight.exchange.material_files import load_material_file
    from alight.exchange.meshes import load_mesh
    from alight.exchange.output import write_image
    from alight.exchange.texture_sets import load_map_images
    from alight.frontends.editor.state import default_lights
    from alight.frontends.editor.thumbnails import THUMB_SIZE
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()
    mesh = load_mesh("sphere")
    ibl = renderer.bake(load_environment("studio"), "low")
    for line in sys.stdin:
        source, _, out = line.rstrip("\n").partition("\t")
        try:
            material, maps, _ = load_material_file(source)
            scene = Scene(mesh=mesh, material=material, use_file_materials=False, lights=default_lights(),
                          texture_maps=maps, texture_images=load_map_images(maps) if maps.paths() else {})
            frame = renderer.render(scene, ibl, THUMB_SIZE, THUMB_SIZE, aa="none", read_linear=False, read_srgb=True)
            write_image(out, frame.srgb, linear=False)
            answer = "ok"
        except Exception as exc:   # one line back, and the next job goes on
            answer = f"error: {' '.join(f'{type(exc).__name__}: {exc}'.split())}"
        print(answer, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
