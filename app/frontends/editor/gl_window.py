"""The editor window's OpenGL configuration, in one place for the window and for the variant
warm-up process's hidden window (variant_warmup.py).

llvmpipe generates a shader's fragment code per draw state, the framebuffer's formats included,
and keeps it in Mesa's shader disk cache under that state: code made for an offscreen texture is
not the code the window's own framebuffer needs. The warm-up process draws the view's moving
frames (drawn straight into the window, renderer.draw_display's ``into``) into a hidden window
made with these hints, so its cache entries are the ones the editor's window reads.
"""

from __future__ import annotations

import os


def set_window_hints(glfw, visible: bool = True) -> None:
    """glfw's hints for the editor's window: OpenGL 4.5 core, a depth buffer (moving views are
    drawn straight into the window: EditorWindow.render_view) and an sRGB-capable framebuffer
    (which encodes those frames itself: EditorWindow._screen_encodes_srgb)."""
    glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 4)
    glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 5)
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
    glfw.window_hint(glfw.DEPTH_BITS, 24)
    glfw.window_hint(glfw.SRGB_CAPABLE, True)
    glfw.window_hint(glfw.VISIBLE, visible)


def hidden_window_context(size: tuple[int, int] = (64, 64)):
    """(a hidden glfw window, a moderngl context on it, current) configured as the editor's
    window, or None where no window can be opened (no display, no glfw): the caller then draws
    offscreen only."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return None
    try:
        import glfw
        import moderngl

        if not glfw.init():
            return None
        set_window_hints(glfw, visible=False)
        window = glfw.create_window(size[0], size[1], "alight warm-up", None, None)
        if not window:
            glfw.terminate()
            return None
        glfw.make_context_current(window)
        return window, moderngl.create_context(require=450)
    except Exception:   # any failure leaves the offscreen drawing, which needs no window
        return None
