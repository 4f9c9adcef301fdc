"""Shadow maps for the forward pass: one depth atlas holding a view per shadowed source.

Sources: the scene's punctual lights (directional: one orthographic view; spot: one perspective
view; point: six, a cube's faces) and the compact sources the bake took out of the environment
(alight.ibl.sun: the suns, each an orthographic view, soft by its angular radius). Placement is
app/core/shadow_fit.py's (the scene's bounding sphere, not the camera's frustum), filtering
shaders/common/shadows.glsl's (PCF, PCSS where the source has a size).

A map depends on the geometry and the sources only, never on the camera: it is drawn when one
of them changes and reused otherwise (the editor orbiting a still scene draws none).

``--shadows``: ``off`` never; ``on`` wherever a source shines on a mesh; ``auto`` (the default)
only where something can be shadowed: the mesh can shadow itself (shadow_fit.can_shadow_itself:
not a closed convex solid, not flat) or a receiver is added under it (the ground). The built-in
sphere, the cube and a plane compile no shadow code and draw no depth pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np

from alight.core.gpu import release_objects
from alight.errors import warn
from alight.core.ibl_models import SUNS_AS_BAKED
from alight.core.shading import rotate_world_to_map
from alight.core.shadow_fit import (
    ShadowView,
    can_shadow_itself,
    directional_view,
    point_views,
    spot_view,
)

SHADOW_MODES = ("auto", "on", "off")
# A depth map stops light or lets it all through: a part that lets at least this share through
# (alight.render.visibility_parts.light_through: transmission, a blended part's 1 - alpha) casts
# nothing, one below casts as opaque; either way the error is the smaller of t and 1 - t.
CASTER_MAX_THROUGH = 0.5
MAX_SHADOW_VIEWS = 16      # shaders/common/shadows.glsl's MAX_SHADOW_VIEWS
MAX_SHADOW_LIGHTS = 16     # punctual.glsl's MAX_LIGHTS
MAX_SHADOW_SUNS = 4        # suns.glsl's MAX_SUNS
# Texels along a view's side. Orthographic views cover the casters; a point light's faces
# cover a quarter of its sphere each. A sun's shadow is soft (PCSS), but a low sun stretches a
# texel along the ground by 1 / sin(elevation) (5.7 at quarry_01's 10 degrees): at 1024 the
# helmet's ground shadow showed texel-wide streaks along the light (benchmarks/bench_ground_shadow.py).
RESOLUTION = {"directional": 2048, "sun": 2048, "spot": 1024, "point": 512}
# The source's RMS angular spread (alight.ibl.sun.Sun.spread) as a disk's radius: a uniform
# disk of radius R has RMS angle R / sqrt(2).
SPREAD_TO_RADIUS = math.sqrt(2.0)


@dataclass(frozen=True)
class ShadowPlan:
    """The views of one frame's sources: ``views`` in atlas order, ``light_first``/``sun_view``
    the first view of each light and sun (-1: not shadowed), ``rects`` each view's tile in atlas
    texels (x, y, size), ``atlas`` the atlas's (width, height)."""

    views: tuple[ShadowView, ...]
    light_first: tuple[int, ...]
    sun_view: tuple[int, ...]
    rects: tuple[tuple[int, int, int], ...]
    atlas: tuple[int, int]


def pack(sizes: list[int], max_width: int = 4096) -> tuple[list[tuple[int, int, int]], tuple[int, int]]:
    """Square tiles of ``sizes`` texels placed in rows (largest first), left to right:
    their (x, y, size) in the given order and the atlas's (width, height)."""
    order = sorted(range(len(sizes)), key=lambda i: -sizes[i])
    rects: list = [None] * len(sizes)
    x = y = row = width = 0
    for i in order:
        s = sizes[i]
        if x + s > max_width and x > 0:
            x, y, row = 0, y + row, 0
        rects[i] = (x, y, s)
        x += s
        row = max(row, s)
        width = max(width, x)
    return rects, (max(width, 1), max(y + row, 1))


def plan_views(lights, suns, centre, radius: float, env_rotation_deg: float = 0.0, casters=None) -> ShadowPlan:
    """The views for ``lights`` (alight.core.scene.Light) and ``suns`` (alight.ibl.sun.Sun, in the
    map's frame: turned into the world by ``env_rotation_deg`` as the renderer turns them),
    covering the sphere (``centre``, ``radius``), at most MAX_SHADOW_VIEWS of them (sources past
    that are left unshadowed). ``casters``: (centre, radius) of the casters where that sphere
    also holds receivers that cast nothing (the ground): the orthographic views are only as wide
    as the casters (shadow_fit.directional_view), so the ground costs them no resolution."""
    receivers = None
    if casters is not None:
        receivers = (centre, radius)
        ortho_centre, ortho_radius = casters
    else:
        ortho_centre, ortho_radius = centre, radius
    views: list[ShadowView] = []
    light_first: list[int] = []
    for light in lights[:MAX_SHADOW_LIGHTS]:
        if light.kind == "directional":
            made = [directional_view(light.vector, ortho_centre, ortho_radius, RESOLUTION["directional"],
                                     receivers=receivers)]
        elif light.kind == "spot":
            made = [spot_view(light.vector, light.direction, light.outer_cone_deg, centre, radius, RESOLUTION["spot"])]
        else:
            made = point_views(light.vector, centre, radius, RESOLUTION["point"])
        if len(views) + len(made) > MAX_SHADOW_VIEWS:
            light_first.append(-1)
            continue
        light_first.append(len(views))
        views.extend(made)
    sun_view: list[int] = []
    for sun in suns[:MAX_SHADOW_SUNS]:
        if len(views) >= MAX_SHADOW_VIEWS:
            sun_view.append(-1)
            continue
        toward = rotate_world_to_map(np.asarray(sun.direction, np.float64), -env_rotation_deg)
        sun_view.append(len(views))
        views.append(directional_view(-np.asarray(toward, np.float64), ortho_centre, ortho_radius, RESOLUTION["sun"],
                                      angular_radius=float(sun.spread) * SPREAD_TO_RADIUS, receivers=receivers))
    rects, atlas = pack([v.resolution for v in views])
    return ShadowPlan(tuple(views), tuple(light_first), tuple(sun_view), tuple(rects), atlas)


class ShadowMaps:
    """The depth atlas and its views, drawn for a scene when its geometry or sources change.
    ``passes_run`` counts depth passes drawn (tests: none for a convex mesh); ``last_active``
    says whether the last prepared frame is shadowed."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.passes_run = 0
        self.last_active = False
        self._atlas: moderngl.Texture | None = None
        self._sampler: moderngl.Sampler | None = None
        self._fbo: moderngl.Framebuffer | None = None
        self._key = None
        self._mesh = None      # the mesh the atlas was drawn for (its id alone could be reused)
        self._plan: ShadowPlan | None = None
        self._self_shadowing: dict[int, tuple[object, bool]] = {}   # by id(mesh): (mesh, result)

    def mesh_can_shadow_itself(self, mesh) -> bool:
        """shadow_fit.can_shadow_itself for ``mesh``'s parts, computed once per mesh."""
        entry = self._self_shadowing.get(id(mesh))
        if entry is None or entry[0] is not mesh:
            # Closedness is left to the test: it welds and sorts only when its sample of faces
            # against vertices finds no plane that splits the mesh (mesh.closed_edges).
            parts = [(p.positions, p.indices) for p in mesh.parts]
            entry = self._self_shadowing[id(mesh)] = (mesh, can_shadow_itself(parts))
        return entry[1]

    def know_self_shadowing(self, mesh, value: bool) -> None:
        """``mesh_can_shadow_itself``'s answer computed elsewhere (alight.render.mesh_upload, on
        the editor's worker thread): the frame that first draws ``mesh`` does not compute it."""
        self._self_shadowing[id(mesh)] = (mesh, bool(value))

    def wanted(self, scene, maps, receivers: bool = False) -> bool:
        """Whether ``scene`` is drawn with shadows (``scene.shadows``, the module docstring).
        ``receivers``: a surface that is not the mesh takes shadows (the ground)."""
        mode = getattr(scene, "shadows", "auto")
        if mode == "off" or scene.view == "probe" or scene.mesh is None or not scene.mesh.parts:
            return False
        suns = shadowed_suns(scene, maps)
        if not scene.lights and not suns:
            return False
        return mode == "on" or receivers or self.mesh_can_shadow_itself(scene.mesh)

    def prepare(self, scene, maps, gpu_parts, draw_parts, bounds=None) -> bool:
        """Draw the maps for ``scene`` if they are out of date; returns whether the frame is
        shadowed. ``gpu_parts``: the mesh's uploaded parts (casters); ``draw_parts(program,
        parts)`` draws them with a program; ``bounds``: (centre, radius) the views must cover
        (default: the mesh's bounding sphere)."""
        receivers = bounds is not None
        self.last_active = self.wanted(scene, maps, receivers)
        if not self.last_active:
            return False
        suns = shadowed_suns(scene, maps)
        centre, radius = bounds if bounds is not None else scene.mesh.bounding_sphere()
        key = (id(scene.mesh), bool(scene.use_file_materials), tuple(id(g) for g in gpu_parts), tuple(_light_key(x) for x in scene.lights),
               tuple((tuple(np.round(s.direction, 9)), round(float(s.spread), 9)) for s in suns),
               float(scene.env_rotation_deg) if suns else 0.0, tuple(np.round(centre, 9)), round(float(radius), 9))
        if key == self._key and self._atlas is not None and self._mesh is scene.mesh:
            return True
        casters = scene.mesh.bounding_sphere() if receivers else None
        plan = plan_views(scene.lights, suns, centre, radius, scene.env_rotation_deg, casters)
        if not plan.views:
            self.last_active = False
            return False
        self._draw(plan, draw_parts, gpu_parts)
        self._plan, self._key, self._mesh = plan, key, scene.mesh
        return True

    def _draw(self, plan: ShadowPlan, draw_parts, gpu_parts) -> None:
        ctx = self.ctx
        if self._atlas is None or self._atlas.size != plan.atlas:
            self._release_atlas()
            self._atlas = ctx.depth_texture(plan.atlas)
            self._atlas.filter = (moderngl.LINEAR, moderngl.LINEAR)   # bilinear comparisons (PCF)
            self._atlas.repeat_x = self._atlas.repeat_y = False
            self._atlas.compare_func = "<="
            # The same texels read as depths (the blocker search): a sampler without comparison.
            self._sampler = ctx.sampler(texture=self._atlas, filter=(moderngl.NEAREST, moderngl.NEAREST),
                                        repeat_x=False, repeat_y=False, compare_func="")
            self._fbo = ctx.framebuffer(depth_attachment=self._atlas)
        self._fbo.use()
        self._fbo.clear(depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        # Both sides cast, but for single-sided parts (draw_parts culls their faces turned away
        # from the light: alight.core.mesh.single_sided). A closed part's nearest depth is its
        # lit front either way, so culling changes no closed caster's shadow, nor its acne.
        ctx.disable(moderngl.CULL_FACE)
        try:
            for view, (x, y, size) in zip(plan.views, plan.rects):
                ctx.viewport = (x, y, size, size)
                ctx.scissor = (x, y, size, size)
                draw_parts(np.ascontiguousarray(view.matrix.T, np.float32).tobytes(), gpu_parts)
        finally:
            ctx.scissor = None
            ctx.disable(moderngl.DEPTH_TEST)
            ctx.disable(moderngl.CULL_FACE)
        self.passes_run += 1

    def bind(self, program: moderngl.Program, unit_compare: int, unit_depth: int) -> None:
        """shaders/common/shadows.glsl's uniforms for the plan last drawn."""
        plan = self._plan
        self._atlas.use(unit_compare)
        self._sampler.use(unit_depth)
        matrices = np.zeros((MAX_SHADOW_VIEWS, 4, 4), np.float32)
        rects = np.zeros((MAX_SHADOW_VIEWS, 4), np.float32)
        params = np.zeros((MAX_SHADOW_VIEWS, 4), np.float32)
        ranges = np.zeros((MAX_SHADOW_VIEWS, 2), np.float32)
        w, h = plan.atlas
        for i, (view, (x, y, size)) in enumerate(zip(plan.views, plan.rects)):
            matrices[i] = view.matrix.T          # GLSL reads columns
            rects[i] = (x / w, y / h, (x + size) / w, (y + size) / h)
            params[i] = (view.kind, view.texel, view.source, 0.0)
            ranges[i] = (view.near, view.far)
        lights = np.full(MAX_SHADOW_LIGHTS, -1, np.int32)
        lights[:len(plan.light_first)] = plan.light_first
        suns = np.full(MAX_SHADOW_SUNS, -1, np.int32)
        suns[:len(plan.sun_view)] = plan.sun_view
        for name, value in (("u_shadow_matrix", matrices), ("u_shadow_rect", rects), ("u_shadow_params", params),
                            ("u_shadow_range", ranges), ("u_light_shadow", lights), ("u_sun_shadow", suns)):
            member = program.get(name, None)
            if member is not None:
                member.write(np.ascontiguousarray(value[:max(member.array_length, 1)]).tobytes())
        member = program.get("u_shadow_atlas_size", None)
        if member is not None:
            member.value = (float(w), float(h))

    def _release_atlas(self) -> None:
        release_objects(self.ctx, self._fbo, self._sampler, self._atlas)
        self._fbo = self._sampler = self._atlas = None
        self._key = self._mesh = None

    def release(self) -> None:
        self._release_atlas()
        self._self_shadowing.clear()


def casters(scene) -> list[bool]:
    """Per part of ``scene.mesh``, whether it casts into the shadow maps (CASTER_MAX_THROUGH);
    says once in a warning line which parts cast nothing because they let light through."""
    from alight.render.visibility_parts import light_through

    through = light_through(scene) or (0.0,) * len(scene.mesh.parts)
    cast = [t < CASTER_MAX_THROUGH for t in through]
    skipped = [p.name or str(i) for i, (p, c) in enumerate(zip(scene.mesh.parts, cast)) if not c]
    if skipped:
        # (under shadows 'auto' a map's sun turns shadows on unasked: the line says why they are
        # drawn, in words that fit --shadows and set_shadows alike)
        why = " (shadows are on: shadows 'auto' draws them for a light or the map's sun)" if scene.shadows == "auto" else ""
        warn(f"{scene.mesh.source}: part(s) {', '.join(skipped)} cast no shadow: they let at least "
             f"{CASTER_MAX_THROUGH:g} of the light through (transmission or alpha blending), which a shadow map "
             f"cannot weigh{why}")
    return cast


def shadowed_suns(scene, maps) -> list:
    """The compact sources the frame shades exactly, hence can shadow: none for the models that
    keep them baked into the maps (alight.core.ibl_models.SUNS_AS_BAKED)."""
    if maps is None or not scene.ibl_enabled or scene.ibl_model in SUNS_AS_BAKED:
        return []
    return list(maps.suns)


def _light_key(light) -> tuple:
    return (light.kind, tuple(map(float, light.vector)), tuple(map(float, light.direction)),
            float(light.outer_cone_deg))
