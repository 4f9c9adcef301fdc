"""One batch item rendered in this process: the worker side of ``alight batch``.

A worker process (the local pool's or a Ray actor) keeps one renderer, its loaded meshes and
environments, and its bake cache for its whole life, so it bakes each environment once however
many items it renders. Both executors (``alight.frontends.batch`` and ``batch_ray``) call
``render_item``; it never raises, so one bad item cannot stop a batch.
"""

from __future__ import annotations

import contextlib
import time
from pathlib import Path
from typing import Any

from alight.core.material_fields import NAMES
from alight.errors import AlightError

# The material fields a spec may set on top of a preset: every field of alight.core.material_fields,
# the same as alight render's flags and Renderer.set_material's keywords.
MATERIAL_FIELDS = frozenset(NAMES)


_WORKER: dict[str, Any] = {}


def render_item(item) -> tuple[str, str | None, float, list[str]]:
    """Render one item in this process (its renderer and caches live as long as the process).
    Returns (name, error or None, seconds, warnings): the warning lines of the mesh and
    environment files this process read for the item (what the picture is drawn without; the
    batch prints each once). Never raises, so one bad item cannot stop a batch."""
    start = time.perf_counter()
    warnings: list[str] = []
    with _said(warnings):
        try:
            _render(item, warnings)
            return item.name, None, time.perf_counter() - start, warnings
        except AlightError as e:
            return item.name, " ".join(str(e).split()), time.perf_counter() - start, warnings
        except Exception as e:  # a bug or a driver failure: still one line, and the batch goes on
            return item.name, f"{type(e).__name__}: {' '.join(str(e).split())}", time.perf_counter() - start, warnings


@contextlib.contextmanager
def _said(lines: list[str]):
    """The AlightWarnings issued within (a worker is not under the CLI's alight.errors.on_stderr:
    the render's own warnings, an occlusion or shadow it drew without), added to ``lines`` for
    the batch to print once each rather than as Python warnings on the worker's stderr."""
    import warnings

    from alight.errors import AlightWarning

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", AlightWarning)
            yield
    finally:   # (outside the catch: what is shown again is not caught again)
        for w in caught:
            if issubclass(w.category, AlightWarning):
                lines.append(str(w.message))
            else:   # not ours: as Python would have shown it
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _render(item, warnings: list[str]) -> None:
    from alight.core.mesh import select_variant
    from alight.exchange.meshes import load_mesh
    from alight.frontends.api import Renderer
    from alight.ibl.environment import load_environment

    r = _WORKER.get("renderer")
    if r is None:
        r = _WORKER["renderer"] = Renderer(quality=item.quality)
        _WORKER["meshes"], _WORKER["envs"] = {}, {}
    meshes, envs = _WORKER["meshes"], _WORKER["envs"]
    if item.mesh not in meshes:
        meshes[item.mesh] = load_mesh(item.mesh)
    variant = getattr(item, "variant", None)
    if (item.mesh, variant) not in meshes:   # one Mesh per variant, so its upload is kept too
        meshes[(item.mesh, variant)] = select_variant(meshes[item.mesh], variant)
    if item.environment not in envs:
        envs[item.environment] = load_environment(item.environment)
    warnings.extend([*meshes[item.mesh].warnings, *envs[item.environment].warnings])
    r.quality, r.aa, r.mesh_shading = item.quality, item.aa, item.mesh_shading
    r.width, r.height = item.size
    r.set_mesh(meshes[(item.mesh, variant)]).set_environment(envs[item.environment], rotation_deg=item.environment_deg)
    material, maps = _material(item.material)
    r.set_material(material, **maps).set_display(tonemap=item.tonemap, background=item.background)
    r.set_shadows(item.shadows, ground=item.ground)
    r.set_camera(orbit_deg=item.camera_deg)
    Path(item.out).parent.mkdir(parents=True, exist_ok=True)
    r.save(item.out)


def _material(m: Any) -> tuple[Any, dict]:
    """The item's material for ``Renderer.set_material``: (a preset name or file, a .gltf/.glb
    with its maps, or a Material) and the keywords on top: texture_set and maps (the slots they
    load get factor 1), then the spec's fields, which win."""
    if m == "own":   # alight.frontends.batch.OWN: each mesh file's own materials
        from alight.core.material import Material

        return Material(), {"use_file_materials": True}
    if isinstance(m, str):
        return m, {}
    if "from" in m or "preset" in m:
        base = str(m["from"] if "from" in m else m["preset"])
    else:
        from alight.core.material import Material

        base = Material()
    keywords = {k: (tuple(v) if isinstance(v, list) else v) for k, v in m.items() if k in MATERIAL_FIELDS}
    if "name" in m:
        keywords["name"] = str(m["name"])
    for key in ("texture_set", "maps"):
        if key in m:
            keywords[key] = m[key]
    return base, keywords
