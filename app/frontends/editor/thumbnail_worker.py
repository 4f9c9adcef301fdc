"""The thumbnails' render process: ``python -m alight.frontends.editor.thumbnail_worker``, a
worker_process.py child (the reference's and the warm-up's protocol, niced below the editor).

Each job is a ``ThumbnailJob``: a material and its maps (paths; the child decodes them), drawn on
the built-in sphere under the built-in studio ('low' bake, baked once for the process's life) at
its size (THUMB_SIZE), written to ``out`` atomically (a PNG). One process renders every thumbnail, so its
start, its bake and its shader variants are paid once, away from the editor's frames
(thumbnails.py sends one job at a time: a job sent while another runs would supersede it).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass
class ThumbnailJob:
    material: object       # alight.core.material.Material
    maps: object           # alight.core.texture_maps.TextureMaps (paths)
    out: str               # the PNG to write
    size: int              # pixels a side (thumbnails.THUMB_SIZE: carried, so no import cycle)


def main() -> int:
    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.exchange.output import write_image
    from alight.exchange.texture_sets import load_map_images
    from alight.frontends.editor.state import default_lights
    from alight.frontends.editor.worker_process import serve
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    renderer = ForwardRenderer()
    mesh = load_mesh("sphere")
    ibl = renderer.bake(load_environment("studio"), "low")

    def handle(job: ThumbnailJob, progress, superseded) -> bool:
        maps = job.maps
        scene = Scene(mesh=mesh, material=job.material, use_file_materials=False, lights=default_lights(),
                      texture_maps=maps, texture_images=load_map_images(maps) if maps.paths() else {})
        frame = renderer.render(scene, ibl, job.size, job.size, aa="none", read_linear=False, read_srgb=True)
        write_image(job.out, frame.srgb, linear=False)
        return True

    # serve's default niceness: the editor's frames first (a first start renders ~20 of these
    # while the artist already orbits).
    return serve(handle)


if __name__ == "__main__":
    sys.exit(main())
