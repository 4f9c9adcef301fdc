"""The side bar's pixels kept between frames.

While the artist orbits, the panel's draw data is the same frame after frame (the controls do not
move; the performance readout lies below the fold), yet drawing it costs llvmpipe about 2 ms of
triangle setup on the main thread and as much again to rasterise: a tenth of an orbiting frame.
So once imgui's draw data is the same two frames running, it is drawn into an offscreen image,
and each frame while it stays the same copies that image's side-bar rectangle into the window
(one full-screen triangle, no blending).

The copy is exact: the panel is drawn over the same cleared (0, 0, 0, 0) pixels as in the
window, and nothing else is drawn there. Where any of imgui's triangles reaches into the view (a
tooltip, an open combo box over the scene) or a texture update is pending, the draw data
is drawn straight into the window, as without the cache (tests/editor_window_checks.py compares
the two).
"""

from __future__ import annotations

import ctypes
import math

import moderngl
import numpy as np

from alight.core.gpu import release_objects

_COPY_VERTEX = """#version 450 core
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
"""
# texelFetch at the window's own pixel: the viewport is the side bar's rectangle, the image the
# window's size, so no coordinate is scaled or filtered.
_COPY_FRAGMENT = """#version 450 core
uniform sampler2D u_panel;
layout(location = 0) out vec4 out_color;
void main() {
    out_color = texelFetch(u_panel, ivec2(gl_FragCoord.xy), 0);
}
"""


def draw_data_key(imgui, draw_data, framebuffer_size: tuple[int, int]) -> tuple | None:
    """Everything imgui's renderer reads from ``draw_data`` (vertices, indices, commands, display
    size and scale) and the framebuffer size, as one comparable value; None where a texture is
    to be created or updated (the renderer must run to apply it; one left to destroy can wait),
    or where imgui's vertex is not the (pos, uv, col) layout drawn_left_edge reads."""
    if imgui.VERTEX_SIZE != 20:
        return None
    pending = (imgui.ImTextureStatus.want_create, imgui.ImTextureStatus.want_updates)
    for texture in draw_data.textures or ():
        if texture.status in pending:
            return None
    lists = []
    for cmd_list in draw_data.cmd_lists:
        vtx, idx = cmd_list.vtx_buffer, cmd_list.idx_buffer
        commands = tuple((tuple(c.clip_rect), c.get_tex_id(), c.idx_offset, c.vtx_offset, c.elem_count)
                         for c in cmd_list.cmd_buffer)
        lists.append((ctypes.string_at(vtx.data_address(), vtx.size() * imgui.VERTEX_SIZE),
                      ctypes.string_at(idx.data_address(), idx.size() * imgui.INDEX_SIZE), commands))
    return (tuple(draw_data.display_pos), tuple(draw_data.display_size), tuple(draw_data.framebuffer_scale),
            framebuffer_size, tuple(lists))


def drawn_left_edge(draw_data, key: tuple) -> float:
    """The leftmost framebuffer x any of the draw data's triangles can reach: the least vertex x
    (a triangle lies within its vertices), or the least clip rectangle's left edge if that is
    further right. ``key``: draw_data_key's (it holds the vertex bytes)."""
    sx = draw_data.framebuffer_scale[0]
    px = draw_data.display_pos[0]
    left = math.inf
    for vertices, _, commands in key[4]:
        drawn = [c for c in commands if c[4]]
        if not drawn or not vertices:
            continue
        x = np.frombuffer(vertices, np.float32).reshape(-1, 5)[:, 0]     # ImDrawVert: pos, uv, col
        left = min(left, max(float(x.min()), min(c[0][0] for c in drawn)))
    return (left - px) * sx


class PanelImage:
    """imgui's drawing kept as pixels of the side bar (module docstring). ``render`` draws draw
    data into the bound framebuffer (the editor's imgui renderer)."""

    def __init__(self, ctx: moderngl.Context, render):
        self.ctx = ctx
        self._render = render
        self._key = None          # the draw data the kept pixels show
        self._last_key = None     # the last frame's draw data
        self._texture: moderngl.Texture | None = None
        self._fbo: moderngl.Framebuffer | None = None
        self._program = ctx.program(vertex_shader=_COPY_VERTEX, fragment_shader=_COPY_FRAGMENT)
        self._vao = ctx.vertex_array(self._program, [])
        self.reused = 0      # frames that copied the kept pixels (tests, the benchmark)

    def draw(self, imgui, draw_data, framebuffer_size: tuple[int, int], panel_x0: int) -> None:
        """Draw ``draw_data`` into the window (bound): from the kept pixels where it is the last
        frame's and stays right of ``panel_x0`` (framebuffer pixels), else as the renderer does
        (and keep its pixels for the next frame where it stays there)."""
        w, h = framebuffer_size
        key = draw_data_key(imgui, draw_data, framebuffer_size)
        last, self._last_key = self._last_key, key
        # The kept image shows this key: it was checked against panel_x0 (which the framebuffer
        # size in the key fixes) when it was kept.
        keep_new = key != self._key
        if key is None or key != last or panel_x0 >= w or \
                (keep_new and drawn_left_edge(draw_data, key) < panel_x0):
            # Over the view, a texture to update, or new this frame (a panel that changes every
            # frame, its frame-time plot in view, would pay for the image and the copy): straight in.
            self._key = None
            self._render(draw_data)
            return
        window = self.ctx.screen
        if keep_new:
            if self._texture is None or self._texture.size != (w, h):
                self.release_image()
                self._texture = self.ctx.texture((w, h), 4)
                self._fbo = self.ctx.framebuffer([self._texture])
            self._fbo.use()
            self._fbo.clear(0.0, 0.0, 0.0, 0.0)    # as the window is cleared under the panel
            self._render(draw_data)
            self._key = key
        else:
            self.reused += 1
        window.use()
        self.ctx.disable(moderngl.BLEND)
        self.ctx.viewport = (panel_x0, 0, w - panel_x0, h)
        self._texture.use(0)
        self._program["u_panel"] = 0
        self._vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.viewport = (0, 0, w, h)

    def release_image(self) -> None:
        release_objects(self.ctx, self._fbo, self._texture)
        self._fbo = self._texture = None
        self._key = None

    def release(self) -> None:
        self.release_image()
        self._vao.release()
        self._program.release()
