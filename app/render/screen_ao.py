"""Screen-space ground-truth ambient occlusion (``--occlusion gtao``; alight.core.gtao, Jimenez et
al. 2016) for the scene pass: a prepass of the opaque parts' world positions
(render/gtao_depth.*), the horizon search (render/gtao.frag) and its 4x4 depth-aware denoise
(render/gtao_denoise.frag), at the pass's draw size; the forward pass and the visibility buffer's
shading pass read the result at gl_FragCoord (HAS_SCREEN_AO, common/occlusion.glsl).

Per frame and tile, so it follows a moving view with no bake; an occluder outside the tile or
behind the first surface is not seen (docs/explanation/occlusion.md, "Screen-space GTAO").
More rotations than the 4x4 pattern holds come from passes averaged (alight.core.gtao.rotation_offset):
a still image takes STILL_FRAMES in one draw; with ``keep`` (the editor's view) each frame of an
unchanged view adds one, up to TEMPORAL_FRAMES, after which the frame reuses the mean and searches
nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from alight.core import gtao
from alight.render.bindings import (UNIT_SCREEN_AO, UNIT_SCREEN_AO_HISTORY, UNIT_SCREEN_AO_NORMALS,
                                    UNIT_SCREEN_AO_OCCLUDERS, UNIT_SCREEN_AO_OCCLUDERS_HISTORY, UNIT_SCREEN_AO_WORK)


@dataclass
class ScreenAOTargets:
    """The pass's textures at one draw size: the prepass's world positions and face normals (and
    its depth buffer), the raw and the denoised visibility and occluders' normals."""

    size: tuple[int, int]
    depth: moderngl.Renderbuffer
    positions: moderngl.Texture
    normals: moderngl.Texture
    depth_fbo: moderngl.Framebuffer
    raw: moderngl.Texture
    raw_occluders: moderngl.Texture
    raw_fbo: moderngl.Framebuffer
    visibility: list          # two textures: the passes' mean so far and the next one (ping-pong)
    occluders: list           # ... and the occluders' normals beside each
    visibility_fbo: list

    def release(self) -> None:
        for x in (self.depth_fbo, self.raw_fbo, *self.visibility_fbo, self.depth, self.positions, self.normals,
                  self.raw, self.raw_occluders, *self.visibility, *self.occluders):
            x.release()


# What the occluded share of the light sees (common/occlusion.glsl): "occluders" (the default:
# the occluders' radiance, GTAO_OCCLUDERS), "multi_bounce" (the paper's albedo fit of V,
# GTAO_MULTI_BOUNCE) or "black" (V alone). benchmarks/results/gtao.md compares them.
OCCLUDED_LIGHT = ("occluders", "multi_bounce", "black")


def defines(occluded: str = "occluders") -> dict:
    """The forward pass's defines that read the visibility (common/occlusion.glsl)."""
    d = {"HAS_SCREEN_AO": None}
    if occluded == "occluders":
        d["GTAO_OCCLUDERS"] = None
        d["GTAO_FACING_RAMP_LOW"], d["GTAO_FACING_RAMP_HIGH"] = (repr(float(x)) for x in gtao.FACING_RAMP)
    elif occluded == "multi_bounce":
        d["GTAO_MULTI_BOUNCE"] = None
    return d


def part_size(gpu_part, part) -> float:
    """A part's bounding-box diagonal (world units), kept with its GPU buffers: as thick as GTAO
    takes an occluder of it to be (render/gtao.frag; app/core/gtao.py THICKNESS)."""
    size = getattr(gpu_part, "gtao_size", None)
    if size is None:
        p = np.asarray(part.positions, np.float64)
        size = float(np.linalg.norm(p.max(0) - p.min(0))) if len(p) else 0.0
        gpu_part.gtao_size = size
    return size


class ScreenAO:
    """The GTAO pass's targets (kept while the draw size stays) and its draw."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.targets: ScreenAOTargets | None = None
        self.occluded = "occluders"  # OCCLUDED_LIGHT (the benchmarks compare them)
        self.radius_fraction = gtao.RADIUS_FRACTION
        self.passes = 0          # passes in the mean that visibility[latest] holds
        self.latest = 0
        self._keys = (None, None)   # the last two kept views' keys (the latest first)
        self.refining = False    # the last draw kept its view and another frame would add a pass

    def _targets(self, size: tuple[int, int]) -> ScreenAOTargets:
        t = self.targets
        if t is None or t.size != size:
            if t is not None:
                t.release()
            depth = self.ctx.depth_renderbuffer(size)
            # World positions in float32 (render/gtao_depth.frag: a 24-bit depth unprojected
            # made an open floor occlude itself).
            positions = self.ctx.texture(size, 4, dtype="f4")
            # (unit face normals: half floats are enough; render/gtao_depth.frag)
            normals = self.ctx.texture(size, 4, dtype="f2")
            # (the occluded directions' sum in xyz, V in w; the occluders' normals' weighted sum in
            # xyz, the weights' sum in w: render/gtao.frag)
            raw = self.ctx.texture(size, 4, dtype="f4")
            raw_occluders = self.ctx.texture(size, 4, dtype="f2")
            visibility = [self.ctx.texture(size, 4, dtype="f4") for _ in range(2)]
            occluders = [self.ctx.texture(size, 4, dtype="f2") for _ in range(2)]
            for tex in (normals, raw, raw_occluders, *visibility, *occluders):
                tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            positions.filter = (moderngl.LINEAR, moderngl.LINEAR)    # (the samples: gtao.frag)
            positions.repeat_x = positions.repeat_y = False
            self.targets = t = ScreenAOTargets(
                size, depth, positions, normals,
                self.ctx.framebuffer(color_attachments=[positions, normals], depth_attachment=depth), raw,
                raw_occluders, self.ctx.framebuffer(color_attachments=[raw, raw_occluders]), visibility, occluders,
                [self.ctx.framebuffer(color_attachments=[v, o]) for v, o in zip(visibility, occluders)])
            self.passes = 0
        return t

    def draw(self, r, gpu_parts, parts, size: tuple[int, int], view_projection: np.ndarray,
             inverse_vp: np.ndarray, camera, pixel_scale: float, radius: float, keep: bool = False) -> moderngl.Texture:
        """The denoised visibility of the opaque ``gpu_parts`` (with their MeshParts ``parts``)
        seen through ``view_projection`` at ``size`` (the draw size); returns its texture. Leaves
        the framebuffer binding and viewport to the caller.

        ``keep`` false: the mean of gtao.STILL_FRAMES passes, nothing kept for the next call (the
        same picture every time). True: one more pass into the mean kept from the last call where
        the view (size, matrices, camera, radius and parts) is the same, up to
        gtao.TEMPORAL_FRAMES, then none; else a new mean of one pass. ``refining`` then says
        whether another call would add one (false also where the views alternate, A B A: the
        editor's split view, which would otherwise never settle)."""
        ctx = self.ctx
        t = self._targets(size)
        key = None
        if keep:
            key = (size, np.asarray(view_projection, np.float32).tobytes(), np.asarray(inverse_vp, np.float32).tobytes(),
                   tuple(float(x) for x in camera.position), float(radius), float(pixel_scale),
                   tuple(id(g) for g in gpu_parts))
            alternating = key == self._keys[1] and key != self._keys[0]
            continued = key == self._keys[0] and self.passes > 0
            self._keys = (key, self._keys[0])
            if not continued:
                self.passes = 0
            passes, total = (0 if self.passes >= gtao.TEMPORAL_FRAMES else 1), gtao.TEMPORAL_FRAMES
            self.refining = self.passes + passes < total and not alternating
        else:
            self._keys = (None, None)
            self.passes, continued = 0, False
            passes = total = gtao.STILL_FRAMES
            self.refining = False
        if passes == 0:
            self._bind_result(t)
            return t.visibility[self.latest]
        ctx.viewport = (0, 0, size[0], size[1])
        if not continued:
            self._positions(r, t, gpu_parts, parts, view_projection)
        for _ in range(passes):
            self._pass(r, t, view_projection, inverse_vp, camera, pixel_scale, radius, total)
        self._bind_result(t)
        return t.visibility[self.latest]

    def _bind_result(self, t: ScreenAOTargets) -> None:
        """What the forward pass reads: u_screen_ao, u_screen_ao_occluders (common/occlusion.glsl)."""
        t.visibility[self.latest].use(UNIT_SCREEN_AO)
        t.occluders[self.latest].use(UNIT_SCREEN_AO_OCCLUDERS)

    @property
    def visibility(self) -> moderngl.Texture | None:
        """The last draw's visibility (the passes' mean): occluded directions' sum in xyz, V in w."""
        return None if self.targets is None else self.targets.visibility[self.latest]

    @property
    def occluders(self) -> moderngl.Texture | None:
        """The last draw's occluders' normals (the passes' mean): their sum weighted by the
        occluded share each hides in xyz, the weights' sum in w (render/gtao.frag)."""
        return None if self.targets is None else self.targets.occluders[self.latest]

    def _positions(self, r, t: ScreenAOTargets, gpu_parts, parts, view_projection) -> None:
        """The prepass: the opaque parts' world positions at each pixel."""
        ctx = self.ctx
        t.depth_fbo.use()
        t.depth_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        prog = r.program("render/gtao_depth.vert", "render/gtao_depth.frag")
        prog["u_view_projection"].write(np.ascontiguousarray(view_projection, np.float32).tobytes())
        from alight.render.part_bindings import set_culling

        for gpu_part, part in zip(gpu_parts, parts):
            set_culling(ctx, gpu_part, part)     # the forward pass's culling: the same front surface
            prog["u_part_size"] = part_size(gpu_part, part)
            gpu_part.vao_for(prog).render(moderngl.TRIANGLES)
        ctx.disable(moderngl.CULL_FACE)
        ctx.disable(moderngl.DEPTH_TEST)

    def _pass(self, r, t: ScreenAOTargets, view_projection, inverse_vp, camera, pixel_scale: float,
              radius: float, total: int) -> None:
        """One turn of the pattern (pass ``self.passes`` of ``total``) searched, denoised and
        averaged into the mean so far."""
        k = self.passes
        vp = np.ascontiguousarray(view_projection, np.float32).tobytes()
        ivp = np.ascontiguousarray(inverse_vp, np.float32).tobytes()
        search = r.program("render/fullscreen.vert", "render/gtao.frag",
                           {"GTAO_SLICES": gtao.SLICES, "GTAO_STEPS": gtao.STEPS,
                            "GTAO_THICKNESS": repr(float(gtao.THICKNESS)),
                            "GTAO_THIN_OCCLUDER": repr(float(gtao.THIN_OCCLUDER)),
                            "GTAO_FACING_THICKNESS": repr(float(gtao.FACING_THICKNESS))})
        t.positions.use(UNIT_SCREEN_AO_WORK)
        search["u_positions"] = UNIT_SCREEN_AO_WORK
        t.normals.use(UNIT_SCREEN_AO_NORMALS)
        search["u_normals"] = UNIT_SCREEN_AO_NORMALS
        t.visibility[self.latest].use(UNIT_SCREEN_AO_HISTORY)    # (the occluders' own V: gtao.frag)
        search["u_history"] = UNIT_SCREEN_AO_HISTORY
        search["u_has_history"] = k > 0
        search["u_inverse_vp"].write(ivp)
        search["u_view_projection"].write(vp)
        search["u_camera_position"] = tuple(float(x) for x in camera.position)
        search["u_radius"] = float(radius)
        search["u_pixel_scale"] = float(pixel_scale)
        search["u_max_radius_px"] = max(float(gtao.MAX_RADIUS_PX), gtao.MAX_RADIUS_HEIGHT * t.size[1])
        search["u_rotation_offset"] = gtao.rotation_offset(k, total)
        t.raw_fbo.use()
        r.fullscreen(search)
        denoise = r.program("render/fullscreen.vert", "render/gtao_denoise.frag")
        t.raw.use(UNIT_SCREEN_AO)
        denoise["u_raw"] = UNIT_SCREEN_AO
        t.raw_occluders.use(UNIT_SCREEN_AO_OCCLUDERS)
        denoise["u_raw_occluders"] = UNIT_SCREEN_AO_OCCLUDERS
        denoise["u_positions"] = UNIT_SCREEN_AO_WORK
        denoise["u_camera_position"] = tuple(float(x) for x in camera.position)
        history = self.latest
        t.visibility[history].use(UNIT_SCREEN_AO_HISTORY)
        denoise["u_history"] = UNIT_SCREEN_AO_HISTORY
        t.occluders[history].use(UNIT_SCREEN_AO_OCCLUDERS_HISTORY)
        denoise["u_history_occluders"] = UNIT_SCREEN_AO_OCCLUDERS_HISTORY
        denoise["u_history_weight"] = k / (k + 1.0)
        self.latest = 1 - history
        t.visibility_fbo[self.latest].use()
        r.fullscreen(denoise)
        self.passes = k + 1

    def release(self) -> None:
        if self.targets is not None:
            self.targets.release()
            self.targets = None
