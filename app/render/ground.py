"""The ground under the model as a shadow catcher (``Scene.ground``; render/ground.frag): drawn
after the surfaces and the background, depth-tested against the model, it darkens what lies
behind it by the share of light the model takes from it (over a transparent background: a black
shadow in alpha). The geometry is alight.core.ground's."""

from __future__ import annotations

import moderngl
import numpy as np

from alight.core.ground import Ground, ground_under


class GroundPass:
    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], np.float32)
        self._vbo = ctx.buffer(corners.tobytes())
        self._vaos: dict[int, moderngl.VertexArray] = {}

    @staticmethod
    def ground_for(mesh) -> Ground:
        lo, hi = mesh.bounds()
        centre, radius = mesh.bounding_sphere()
        return ground_under(lo, hi, centre, radius)

    def draw(self, program: moderngl.Program, ground: Ground, view_projection: np.ndarray) -> None:
        """Draw the square with ``program`` (render/ground.vert + ground.frag, its lights, suns,
        environment and shadows bound by the caller) into the bound framebuffer."""
        ctx = self.ctx
        c = ground.centre
        program["u_ground"].value = (float(c[0]), float(c[1]), float(c[2]), float(ground.half_size))
        if "u_ground_fade" in program:
            program["u_ground_fade"].value = float(ground.fade)
        program["u_view_projection"].write(np.asarray(view_projection, np.float32).tobytes())
        vao = self._vaos.get(id(program))
        if vao is None:
            vao = self._vaos[id(program)] = ctx.vertex_array(program, [(self._vbo, "2f", "in_corner")])
        ctx.enable(moderngl.BLEND | moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        ctx.blend_func = (moderngl.ZERO, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)
        ctx.depth_mask = False
        try:
            vao.render(moderngl.TRIANGLES)
        finally:
            ctx.depth_mask = True
            ctx.disable(moderngl.BLEND)
            ctx.blend_func = moderngl.DEFAULT_BLENDING

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        self._vbo.release()
