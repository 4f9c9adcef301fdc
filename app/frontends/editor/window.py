"""The editor's window: glfw, a ModernGL context made from it, the main loop.

Each frame: build the imgui panel (it edits EditorState; a side bar on the right), render the
scene with the ForwardRenderer, tone mapped as it is drawn (ForwardRenderer.draw_display), into its offscreen
view image the size of the area left of the panel, and only when something it depends on
changed; copy that into the default framebuffer, draw imgui on top, swap. The ForwardRenderer never sees imgui; the panel never sees GL.

imgui backends: input from imgui-bundle's pure-python GLFW backend (python_backends.glfw_backend,
on the pyGLFW window we own); drawing by Dear ImGui's own OpenGL 3 renderer, the C++ one that
imgui-bundle ships (imgui.backends.opengl3_*), on the same context ModernGL uses. Both save and
restore the GL state they touch. The C++ renderer draws the same bytes as the Python one (checked
side by side) and spends none of the Python one's ~2 ms a frame in PyOpenGL calls; where it
cannot start (its GL loader finds no libGL) the Python renderer draws. Either handles imgui
1.92's dynamic font atlas (ImTextureData requests): we do not write a third copy of that code.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import os
import sys
import time

from alight.core.gpu import ShaderCompileError
from alight.frontends.editor.gl_window import set_window_hints
from alight.frontends.editor.variant_warmup import draw_view
from alight.errors import AlightError
from alight.exchange.images import IMAGE_SUFFIXES
from alight.frontends.editor.camera import OrbitCamera
from alight.frontends.editor.state import EditorState, History
from alight.ibl.bake import QUALITY

# The time a frame gives the environment bake at most (about one step more): the window stays
# responsive while a bake runs over several frames.
BAKE_SLICE_S = 0.03
# The panel is a side bar on the window's right (at most half the window): the view is the
# rest, so the panel never covers the mesh, and the view starts at the framebuffer's origin.
# 480 at 1280x720 (420 cut the labels of the widest rows there).
PANEL_WIDTH = 480
# Adaptive resolution while the camera moves: the view's scale follows the frame time toward
# this rate, in steps (a new size reallocates the view's targets), between these bounds.
TARGET_FPS = 30.0
ADAPTIVE_MIN_SCALE, ADAPTIVE_STEP = 0.25, 1.0 / 16.0
TARGET_CACHE = 4   # view framebuffers kept, by size
# The interactive loop (``run``) sleeps when nothing changes: a still editor redrew ~75 frames a
# second and kept a core 60-87% busy. Frames at full rate while input comes, the camera moves, a
# bake, screenshot or turntable runs, and for IDLE_AFTER_S after (imgui's hover and the view's
# sharp still frame settle); at most every BACKGROUND_FRAME_S while background work is pending
# (a child's job, thumbnails, the presets' prefetch; a text field's cursor does not blink); else none:
# the loop waits for events (glfw.wait_events_timeout), which input, a child's answer and a
# watched file's change end at once, and every IDLE_WAIT_S looks at the shaders (hot reload).
IDLE_AFTER_S = 0.5
BACKGROUND_FRAME_S = 0.08
IDLE_WAIT_S = 0.1
CHECKER_SQUARE = 8.0   # pixels a side of the checkerboard under a transparent background
# The status row's line for a ground that catches nothing (Renderer.last_ground_idle), in the
# panel's names where 'alight render' warns with its flags.
GROUND_IDLE = {
    "shadows off": "ground: nothing casts a shadow on it, so it changes nothing: 'shadows' is off (Environment)",
    "no light": "ground: nothing casts a shadow on it, so it changes nothing: no light, and no sun in the "
                "map that the IBL model shades exactly (add a light under Lights, or open a map with a sun)",
}



def wrote_message(path, detail: str, last: str = "") -> str:
    """'wrote NAME (DETAIL) in FOLDER' ('NAME ... LAST' for a series of files): the file's name
    first, where the status row (cut at the panel's edge) shows it; a new user saw 'wrote
    /long/folder/alight-screenshot-' twice and read the second screenshot as not taken."""
    folder, name = os.path.split(os.path.abspath(os.fspath(path)))
    return f"wrote {name}{f' ... {last}' if last else ''} ({detail}) in {folder}"

class EditorWindow:
    def __init__(self, state: EditorState, size: tuple[int, int] = (1280, 720), title: str = "alight",
                 show_panel: bool = True, ini_path=None, hosted: bool = False):
        """``hosted``: hello_imgui's runner owns the window, its GL context (current now) and the
        imgui context, polls, renders imgui and swaps (ui_test.py); this object then draws the
        scene and the panel in the runner's callbacks: ``build_frame``, ``render_scene``, ``after_swap``."""
        # PyOpenGL must pick GLX (X11/Xvfb) before the backend imports it.
        if os.environ.get("XDG_SESSION_TYPE") == "wayland":
            os.environ.setdefault("PYOPENGL_PLATFORM", "x11")
        # PyOpenGL calls glGetError after every call and raises on any pending error, including
        # one left by a ModernGL call on the shared context; off, it is also much cheaper per call.
        import OpenGL

        OpenGL.ERROR_CHECKING = False
        import glfw
        import moderngl
        from imgui_bundle import imgui, implot
        from imgui_bundle.python_backends.glfw_backend import GlfwRenderer

        from alight.render.renderer import ForwardRenderer

        self.glfw, self.imgui, self.implot = glfw, imgui, implot
        self.hosted = hosted
        if hosted:
            self._open_hosted(glfw)
        else:
            self._open_window(glfw, size, title)
        self.ctx = moderngl.create_context(require=450)
        self.renderer = ForwardRenderer(self.ctx)
        self.renderer.screen_ao_temporal = True   # GTAO refines over the frames of a still view
        # A session that visits environment after environment would keep every bake on the GPU:
        # the last few stay (the one shown and a step or two back), older ones reload from the
        # disk cache. The window holds no maps older than the one shown.
        self.renderer.max_bakes = 4
        # Whether the window has the depth buffer a scene pass needs (render_view draws into it).
        self._screen_depth = self._depth_bits() >= 16
        self._screen_srgb = self._screen_depth and self._screen_encodes_srgb()

        if hosted:   # the runner made imgui's context and renders its draw data; implot's is ours
            self.impl, self._native_imgui = None, False
        else:
            imgui.create_context()
        implot.create_context()
        if not hosted:
            # imgui's window layout lives in the user's config folder, never the working directory;
            # screenshots and benchmarks keep none, so they never depend on the last session.
            imgui.get_io().set_ini_filename(str(ini_path) if ini_path else "")
            self.impl = GlfwRenderer(self.window)   # input; and the Python renderer, where the native one cannot start
            # Keys as the layout labels them, a frame's worth at a time (keys.py: KeyEvents).
            from alight.frontends.editor.keys import KeyEvents

            self.key_events = KeyEvents()
            from alight.frontends.editor.press_guard import PressGuard

            self.press_guard = PressGuard()   # presses aimed at a layout gone are dropped (press_guard.py)
            glfw.set_key_callback(self.window, self._key_callback)
            glfw.set_char_callback(self.window, lambda _w, c: self.key_events.char(c))
            glfw.set_cursor_pos_callback(self.window, self._cursor_callback)   # each motion where it was
            # Buttons and the wheel through the same queue, so a Ctrl+click keeps its order.
            glfw.set_mouse_button_callback(self.window, self._button_callback)
            glfw.set_scroll_callback(self.window, lambda _w, dx, dy: self.key_events.scroll(dx, dy))
            self._native_imgui = self._start_native_imgui(imgui)
            self._watch_window_events(glfw)
        from alight.frontends.editor.panel_image import PanelImage

        # The side bar's pixels, drawn again only when imgui's draw data changes (panel_image.py);
        # False draws it every frame (the tests compare). The runner draws imgui itself.
        self.keep_panel_pixels = not hosted
        self._panel_image = PanelImage(self.ctx, self._render_imgui_direct)
        glfw.set_drop_callback(self.window, self._drop_callback)
        self._init_state(state, show_panel)
        # The probes above (depth bits, the sRGB pixel) may leave a GL error pending; hello_imgui
        # checks glGetError after its first frame and would report it as its own.
        _ = self.ctx.error

    def _open_window(self, glfw, size, title) -> None:
        """Our own glfw window with an OpenGL 4.5 core context, current on this thread."""
        import warnings

        # pyGLFW reports glfw's own error as a Python warning (two raw lines before ours): its
        # words go into the one error line instead.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ok = glfw.init()
        if not ok:
            import re

            # ("(65550) b'X11: Failed to open display :9'" -> "X11: Failed to open display :9")
            said = "; ".join(re.sub(r"^\(\d+\)\s*b?['\"]?|['\"]$", "", " ".join(str(w.message).split()))
                             for w in caught) or "no display?"
            raise AlightError(f"editor: cannot open a window ({said}; set DISPLAY, or run under xvfb-run -a)")
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        set_window_hints(glfw)   # (gl_window.py: the variant warm-up's hidden window has the same)
        self.window = glfw.create_window(size[0], size[1], title, None, None)
        self._size_cache: tuple[tuple[int, int], tuple[int, int]] | None = None   # _sizes
        if not self.window:
            glfw.terminate()
            raise AlightError("editor: cannot create an OpenGL 4.5 core window")
        glfw.make_context_current(self.window)
        glfw.swap_interval(0)  # frame times measure our work, not the display's refresh

    def _answer_came(self) -> None:
        """A child's answer or a watched file's change (called on another thread): the idle wait
        ends, and two frames follow (``tick``): one takes the answer, the next shows what it
        changed (the status row is drawn before the frame takes it) without waiting for input."""
        self._answered = 2
        self.glfw.post_empty_event()

    def _drop_callback(self, _window, paths) -> None:
        self._woken = True
        self.drop(list(paths))

    def _watch_window_events(self, glfw) -> None:
        """Window events that ask for a frame though they are no input (exposed, resized,
        focus, the pointer entering or leaving): they end an idle wait (``tick``). The
        callbacks imgui's backend installed are chained."""
        def chain(setter):
            previous = None

            def callback(*args):
                self._woken = True
                if previous is not None:
                    previous(*args)
            previous = setter(self.window, callback)

        for setter in (glfw.set_window_refresh_callback, glfw.set_framebuffer_size_callback,
                       glfw.set_window_focus_callback, glfw.set_cursor_enter_callback,
                       glfw.set_window_iconify_callback):
            chain(setter)

    def _open_hosted(self, glfw) -> None:
        """hello_imgui's glfw window, through pyGLFW on the same libglfw (imgui_bundle sets
        PYGLFW_LIBRARY when it is imported, before pyGLFW loads)."""
        from imgui_bundle.glfw_utils import glfw_window_hello_imgui

        self.window = glfw_window_hello_imgui()
        self._size_cache = None

    def _init_state(self, state, show_panel) -> None:
        self.state = state
        self.show_panel = show_panel
        self.history = History(state.look)
        self.orbit = OrbitCamera()
        self.frame_times: collections.deque[float] = collections.deque(maxlen=240)
        self.bake_seconds: dict[str, float] = {}
        self._maps_key = None
        self._maps = None
        self._bake_job = None          # (key, generator) of the bake in progress
        self._auto = None              # (key, alight.accuracy.auto_quality.Choice) for bake quality 'auto'
        self._auto_features = None     # (id of the environment, its EnvironmentFeatures)
        self.bake_progress = None      # (fraction, label) while a bake runs; the panel shows it
        self._last_swap = None
        self._framed_mesh = None
        self._drawn_key = self._drawn_targets = self._last_camera = self._drawn_maps = None
        self._target_cache: collections.OrderedDict = collections.OrderedDict()
        import moderngl

        self._linear = moderngl.LINEAR
        self.screenshot_request = ""   # set by the panel's button or F12; written after the frame
        from alight.frontends.editor.screenshot import ScreenshotSize

        self.screenshot_size = ScreenshotSize()   # the view's or a chosen size (the panel's)
        self.screenshot_job = None     # the PNG being written, a few strips a frame
        from alight.frontends.editor.turntable import TurntableSettings

        self.turntable = TurntableSettings()   # the panel's frames and file (turntable.py)
        self.turntable_request = False  # set by the panel's button or T; started after the frame
        self.turntable_job = None       # the turntable being drawn, a few frames a frame
        self.redraws = 0   # scene redraws so far (the Performance section shows it)
        self._frame_no = 0   # frames built so far (press_guard.py tells them apart)
        self.adaptive_scale = 0.5      # the adaptive motion scale now (see adapt_motion_scale)
        self._was_moving = False
        from alight.frontends.editor.hot_reload import ShaderWatcher
        from alight.frontends.editor.panel import Panel

        self.shader_watcher = ShaderWatcher(self.renderer.shaders.root)
        from alight.frontends.editor.hot_reload import FileWatcher

        self.file_watcher = FileWatcher()   # maps and the environment file changed on disk
        self._woken = False       # an event that needs a frame came during an idle wait (tick)
        self._answered = 0        # frames owed to a child's answer or a watched file's change (_answer_came)
        self._last_active = time.monotonic()   # the last input or change that needs frames at full rate
        self.idle_waits = 0       # the idle loop's waits so far (tests and the benchmark read it)
        if not self.hosted:   # (the test engine's runner draws every frame: no waits there)
            from alight.frontends.editor import worker_process

            worker_process.set_waker(self._answer_came)
            self.file_watcher.on_change = self._answer_came
            # A blinking text cursor would need a frame every half second for as long as a field
            # holds the focus (a new user saw a focused field keep the idle editor at a core):
            # the cursor stays lit instead, and typing brings its own frames.
            self.imgui.get_io().config_input_text_cursor_blink = False

        self.panel = Panel()
        # A dropped mesh file and --script open= are read on the panel's worker thread too.
        state.open_mesh_async = lambda spec, then=None, own_materials=True: self.panel.open_mesh(
            self.state, spec, then, own_materials)
        if not self.hosted:   # a finished open or export ends the idle wait (file_jobs.py)
            self.panel.file_jobs.wake = self._answer_came
        from alight.frontends.editor.compare_view import CompareView
        from alight.frontends.editor.thumbnails import Thumbnails

        self.compare_view = CompareView(self.ctx, self.renderer, self.new_targets)   # the A/B split view's GL side
        self.thumbnails = Thumbnails(self.ctx)   # the presets' and library's, a few a frame
        from alight.frontends.editor.variant_warmup import VariantWarmup

        self.variant_warmup = VariantWarmup()   # new shader variants compiled in a process of their own
        from alight.frontends.editor.variant_warmup import PresetPrefetch

        self.preset_prefetch = PresetPrefetch()   # the presets' variants drawn ahead, niced
        from alight.frontends.editor.occlusion_bake import OcclusionBake

        self.occlusion_bake = OcclusionBake()   # the visibility bake made in a process of its own
        from alight.frontends.editor.pass_warmup import PassWarmup

        self.pass_warmup = PassWarmup()   # the split view's passes drawn once at the start (Mesa's cache)

    # --- input --------------------------------------------------------------------------------

    def drop(self, paths: list[str]) -> None:
        """glfw's drop callback: each file by its suffix; a bad one keeps the previous state.
        Several image files dropped together are a texture set (``drop_texture_set``), and so is
        a dropped folder (its images, as the 'texture set' field reads a folder)."""
        mark = self.state.edit_mark()
        self._drop(paths)
        self.state.untick_own_for_edit(mark)   # a dropped map or preset is seen on every part

    def _drop(self, paths: list[str]) -> None:
        folders = [p for p in paths if os.path.isdir(p)]
        paths = [p for p in paths if p not in folders]
        images = [p for p in paths if os.path.splitext(p)[1].lower() in IMAGE_SUFFIXES]
        for path in paths:
            if len(images) < 2 or path not in images:
                self.state.open_file(path)
        if len(images) >= 2:
            self.drop_texture_set(images)
        for folder in folders:
            try:
                self.state.open_texture_folder(folder)
            except Exception as exc:   # one line in the panel, never a traceback
                self.state.fail(exc)

    def drop_texture_set(self, images: list[str]) -> None:
        """Images assigned to slots by their names (EditorState.open_texture_set), one undo step."""
        try:
            self.state.open_texture_set(images)
        except Exception as exc:   # one line in the panel, never a traceback
            self.state.fail(exc)

    def _key_callback(self, window, key, scancode, action, mods) -> None:
        """glfw's key event, with the key the layout prints (keys.translate_key), queued for
        imgui (``_deliver_keys``)."""
        from alight.frontends.editor.keys import translate_key

        name = self.glfw.get_key_name(key, scancode) if key != self.glfw.KEY_UNKNOWN else None
        self.key_events.key(translate_key(key, name), scancode, action, mods)

    def _button_callback(self, _window, button, action, mods) -> None:
        self.key_events.button(button, action, mods)
        if action == self.glfw.PRESS:
            self.press_guard.pressed(self.key_events.pending[-1])

    def _over_panel(self, x: float, y: float) -> bool:
        """Whether a press at (x, y) (window coordinates) is for the panel: over the side bar, or
        over a popup of it (imgui wanted the mouse last frame)."""
        return self.show_panel and (x >= self._sizes()[1][0] - self.panel_width()
                                    or self.imgui.get_io().want_capture_mouse)

    def _deliver_keys(self) -> None:
        """This frame's key and character events to imgui, in order (keys.KeyEvents says why
        not all of them), less the presses aimed at a panel layout gone (press_guard.py)."""
        io = self.imgui.get_io()
        if len(self.imgui.get_current_context().input_events_queue):
            # imgui kept events of the last batch for a frame of their own (its trickling): the
            # next batch waits, so no release joins motions queued before it (press_guard.sort).
            return
        guard = self.press_guard
        dropped = guard.dropped
        events, rest = guard.sort(self.key_events.take_frame(), self._frame_no, self._over_panel)
        self.key_events.pending[:0] = rest
        if guard.dropped != dropped and not self.state.error:
            self.state.message = "a click came as the panel's controls moved: not applied (click again)"
        for event in events:
            kind = event[0]
            if kind == "key":
                self.impl.keyboard_callback(self.window, *event[1:])
            elif kind == "char":
                self.impl.char_callback(self.window, event[1])
            elif kind == "button":
                self.impl.mouse_button_callback(self.window, *event[1:])
            elif kind == "cursor":
                io.add_mouse_pos_event(float(event[1]), float(event[2]))
            else:
                self.impl.scroll_callback(self.window, *event[1:])

    def _cursor_callback(self, window, x, y) -> None:
        """The motion's own position. (imgui_bundle's Python backend asks glfw for the cursor's
        position now: after a long frame every queued motion then lands where the mouse is at
        the end, the press and the release at one point, and the drag between them is lost.)"""
        if self.glfw.get_window_attrib(window, self.glfw.FOCUSED):
            self.key_events.cursor(x, y)
        else:
            self.key_events.cursor(-1.0, -1.0)

    def _released_drag(self, button) -> bool:
        """A drag whose last motion and release came in one frame, as the events queued during a
        long frame do (imgui then sees the button up already): that motion still counts."""
        io = self.imgui.get_io()
        return self.imgui.is_mouse_released(button) and \
            abs(io.mouse_delta.x) + abs(io.mouse_delta.y) >= io.mouse_drag_threshold

    def _camera_input(self) -> None:
        from alight.frontends.editor.compare import handle_mouse

        imgui, io = self.imgui, self.imgui.get_io()
        divider = handle_mouse(self)   # a left drag on the compare divider moves it, not the camera
        if not io.want_capture_mouse:
            dx, dy = io.mouse_delta.x, io.mouse_delta.y
            if divider:
                pass   # the left button drags the compare divider
            elif imgui.is_mouse_dragging(imgui.MouseButton_.left) or self._released_drag(imgui.MouseButton_.left):
                self.orbit.orbit(dx, dy)
            elif (imgui.is_mouse_dragging(imgui.MouseButton_.right) or self._released_drag(imgui.MouseButton_.right)) \
                    and io.key_shift:
                # Shift + right drag turns the environment (as Substance's viewers do): a view's
                # width of drag is a full turn, the lighting follows the hand.
                s = self.state
                turned = s.env_rotation_deg + dx * 360.0 / max(1, self._sizes()[1][0] - self.panel_width())
                s.env_rotation_deg = (turned + 180.0) % 360.0 - 180.0
            elif any(imgui.is_mouse_dragging(b) or self._released_drag(b)
                     for b in (imgui.MouseButton_.right, imgui.MouseButton_.middle)):
                self.orbit.pan(dx, dy, self.size[1])
            if io.mouse_wheel:
                self.orbit.zoom(io.mouse_wheel)
        # F12 is never text: it writes the screenshot whatever field has the keyboard (with a
        # field focused it did nothing and said nothing). Letters and Ctrl+Z stay the field's.
        if imgui.is_key_pressed(imgui.Key.f12):
            self.screenshot_request = self.next_screenshot_name()
        if not io.want_capture_keyboard:
            if imgui.is_key_pressed(imgui.Key.f):
                self.frame_mesh()
            if imgui.is_key_pressed(imgui.Key.home):
                self.frame_mesh(front=True)
            if imgui.is_key_pressed(imgui.Key.t) and not io.key_ctrl:
                self.turntable_request = True
            if io.key_ctrl and imgui.is_key_pressed(imgui.Key.z):
                s = self.state
                s.step_history(self.history, redo=io.key_shift)

    def _turn_lights_with_env(self) -> None:
        """Where the panel's box says so, the lights turn by the angle the environment turned
        since the last frame, whatever turned it (the drag, the slider: env_turn.py). The first
        frame only notes the rotation (a restored session's lights are already where they were)."""
        from alight.frontends.editor.env_turn import turn_lights, wrapped_delta

        s = self.state
        last, self._env_rotation_seen = getattr(self, "_env_rotation_seen", None), s.env_rotation_deg
        if s.lights_follow_env and last is not None and last != s.env_rotation_deg:
            delta = wrapped_delta(last, s.env_rotation_deg)
            s.lights = turn_lights(s.lights, delta)
            self.history.turn_lights(lambda lights: turn_lights(lights, delta))

    def frame_mesh(self, new: bool = False, front: bool = False) -> None:
        """Fit the mesh in the view from the current direction (F). ``front`` (Home, the panel's
        'front view'): from the mesh's front first, its face for a flat mesh, +Z, level, else.
        ``new`` (a mesh just opened): a flat mesh whose back would face the view is seen from the
        mirrored direction in front of it instead: a one-sided sheet opened after an orbit behind
        the last mesh was invisible, and F kept the direction."""
        mesh = self.state.mesh
        facing = front_normal(mesh) if mesh is not None and (new or front) else None
        if front:
            self.orbit.look_from(facing if facing is not None else (0.0, 0.0, 1.0))
        elif facing is not None and float(facing @ self.orbit.direction()) < 0.0:
            d = self.orbit.direction()
            self.orbit.look_from(d - 2.0 * float(facing @ d) * facing)
        if self.state.mesh is not None:
            center, radius = self.state.mesh.bounding_sphere()
            w, h = self.view_area()
            self.orbit.frame(center, radius, w / max(h, 1), corners=self.state.mesh.corners())
            # A flat mesh seen edge-on shows nothing: say so, as 'alight render' warns.
            normal = self.state.mesh.flat_normal()
            if normal is not None and abs(float(normal @ self.orbit.direction())) < 0.02 and not self.state.error:
                self.state.message = "the mesh is flat and seen edge-on: drag up or down to see it"
        self._framed_mesh = self.state.mesh

    def _depth_bits(self) -> int:
        """The window's depth buffer bits (0: none), as the GL reports them."""
        try:
            return int((self.ctx.screen.bits or {}).get("depth", 0))
        except Exception:   # a GL that cannot say: draw into the view image, then copy
            return 0

    @staticmethod
    def _start_native_imgui(imgui) -> bool:
        """Dear ImGui's C++ OpenGL 3 renderer (imgui-bundle's build), if it starts here."""
        try:
            return bool(imgui.backends.opengl3_init("#version 450"))
        except Exception:   # no loader for this GL: the Python renderer draws
            return False

    def _screen_encodes_srgb(self) -> bool:
        """Whether the window applies the sRGB curve to what is written with GL_FRAMEBUFFER_SRGB
        on: tried, not asked (the GL's answer for a default framebuffer varies by platform). One
        pixel of the back buffer, which the first frame overwrites, is cleared to 0.5: 188 back is
        sRGB-encoded (llvmpipe: 187), 128 is not."""
        from alight.render.renderer import GL_FRAMEBUFFER_SRGB

        screen = self.ctx.screen
        try:
            screen.use()
            self.ctx.enable_direct(GL_FRAMEBUFFER_SRGB)
            self.ctx.scissor = (0, 0, 1, 1)
            screen.clear(0.5, 0.5, 0.5, 1.0)
            value = screen.read(viewport=(0, 0, 1, 1), components=4)[0]
        except Exception:   # a GL that cannot: the shaders encode, as everywhere else
            return False
        finally:
            self.ctx.scissor = None
            self.ctx.disable_direct(GL_FRAMEBUFFER_SRGB)
        return value > 160

    def direct_target(self) -> tuple[moderngl.Framebuffer | None, bool]:
        """Where an orbiting frame at the view's full size is drawn: (the window, whether it
        encodes sRGB itself), or (None, False) where the window has no depth buffer (then into the
        view image, and copied)."""
        return (self.ctx.screen, self._screen_srgb) if self._screen_depth else (None, False)

    def poll_events(self) -> None:
        """GLFW's events; the window's sizes are read again after them (_sizes)."""
        self.glfw.poll_events()
        self._size_cache = None
        if not self.hosted:
            self._deliver_keys()

    def _sizes(self) -> tuple[tuple[int, int], tuple[int, int]]:
        """(framebuffer size, window size), read once between polls: each is a round trip to the X
        server (0.06-0.09 ms under Xvfb here), and a frame asked for them up to seven times."""
        if self._size_cache is None:
            self._size_cache = (tuple(self.glfw.get_framebuffer_size(self.window)),
                                tuple(self.glfw.get_window_size(self.window)))
        return self._size_cache

    @property
    def size(self) -> tuple[int, int]:
        return self._sizes()[0]

    def panel_width(self) -> int:
        """The side bar's width in window coordinates (imgui's), 0 without the panel."""
        if not self.show_panel:
            return 0
        return min(PANEL_WIDTH, self._sizes()[1][0] // 2)

    def view_area(self) -> tuple[int, int]:
        """The framebuffer pixels left of the side bar: where the view is drawn."""
        w, h = self.size
        window_w = max(1, self._sizes()[1][0])
        return max(1, w - round(self.panel_width() * w / window_w)), h

    def check_shaders(self, force: bool = False) -> bool:
        """Hot reload: rebuild the programs when a file under shaders/ changed (returns whether
        it did: an idle loop then draws a frame)."""
        from alight.frontends.editor.hot_reload import rebuild

        if not self.shader_watcher.changed(force):
            return False
        error = rebuild(self.renderer, self.shader_watcher.root)
        if error:
            self.state.error, self.state.message = error, ""
        else:
            self.state.error, self.state.message = "", "shaders reloaded"
            self._drawn_key = None   # redraw with the new programs
        return True

    def check_files(self) -> None:
        """Hot reload of the maps and the environment: what the watcher thread saw change is
        decoded again (a new image is uploaded, a new environment baked)."""
        changed = self.file_watcher.take_changed()
        if changed and self.state.reload_files(changed):
            self._drawn_key = None
        self.file_watcher.watch(self.state.watched_files())

    # --- rendering ----------------------------------------------------------------------------

    def maps(self):
        """The maps in use. A new environment or quality starts a bake that ``advance_bake`` runs
        a slice at a time between frames; until it completes the previous maps stay in use (the
        ForwardRenderer keeps the last few bakes, so going back to an environment costs nothing,
        and loads older ones from the disk cache)."""
        s = self.state
        if s.env is None:
            return None
        if s.quality == "auto":
            choice = self.auto_choice()
            key, quality = (id(s.env), "auto", choice.name, choice.quality.max_roughness), choice.quality
        else:
            key, quality = (id(s.env), s.quality), QUALITY[s.quality]
        if key != self._maps_key and (self._bake_job is None or self._bake_job[0] != key):
            if self._bake_job is not None:
                self._bake_job[1].close()    # superseded: frees its partial maps
            self._bake_job = (key, self.renderer.bake_steps(s.env, quality))
            self.bake_progress = (0.0, "starting")
        return self._maps

    def auto_choice(self):
        """Bake quality 'auto' (app/accuracy/auto_quality.py): the cheapest measured bake within the 2%
        budget for this environment and the material being edited: its kind (dielectric, metal
        or both) and its roughness band (a quarter wide: from the band's lower edge up to 1), so
        that dragging the roughness starts a new bake only when it crosses into another band.
        The panel shows the one-line reason. Cached per environment, kind and band."""
        from alight.accuracy.auto_quality import (
            MaterialNeed,
            choose_quality,
            environment_features,
            load_table,
            material_need,
            predicted_error,
            predicted_seconds,
        )

        s = self.state
        m = s.material
        maps_present = s.texture_maps.paths()
        roughness_map = "roughness" in maps_present or "metallic_roughness" in maps_present
        kind = material_need(m.metallic, m.roughness, roughness_map=roughness_map,
                             metallic_map="metallic" in maps_present or "metallic_roughness" in maps_present)
        band = 0.0 if roughness_map else min(0.75, math.floor(m.roughness / 0.25) * 0.25)
        need = MaterialNeed(kind.archetypes, band, 1.0)
        key = (id(s.env), need)
        if self._auto is None or self._auto[0] != key:
            if self._auto_features is None or self._auto_features[0] != id(s.env):
                self._auto_features = (id(s.env), environment_features(s.env.radiance))
            choice = choose_quality([need], self._auto_features[1])
            if not choice.meets_budget:
                # Nothing measured meets the budget (a metal below r = 0.25 under a sharp map):
                # the editor keeps the default bake rather than a many-second 'high'.
                err, _ = predicted_error(load_table(), "medium", [need], self._auto_features[1])
                choice = dataclasses.replace(
                    choice, quality=dataclasses.replace(QUALITY["medium"], name="auto:medium"), name="medium",
                    predicted_error=err, predicted_seconds=predicted_seconds(load_table(), "medium", 1.0,
                                                                             self._auto_features[1].has_compact_source),
                    reason=choice.reason.replace("so the most accurate one", "so the default, medium"))
            self._auto = (key, choice)
        return self._auto[1]

    def advance_bake(self, budget_s: float = BAKE_SLICE_S) -> None:
        """Run the pending bake's steps for about ``budget_s`` (at least one step)."""
        if self._bake_job is None:
            return
        key, job = self._bake_job
        start = time.perf_counter()
        try:
            while True:
                self.bake_progress = next(job)
                if time.perf_counter() - start >= budget_s:
                    return
        except StopIteration as done:
            self._maps, self._maps_key = done.value, key
            self.bake_seconds = dict(done.value.pass_seconds)
        except Exception as exc:    # one line in the panel; the editor keeps the old maps
            self.state.fail(exc)
            self._maps_key = key    # not retried until the environment or quality changes
        self._bake_job, self.bake_progress = None, None

    def finish_file_jobs(self) -> None:
        """Complete the mesh open and export that run now, here (the test engine's runner before
        its first test: a restored session's mesh in place, as the bake is)."""
        while self.panel.file_jobs.busy:
            self.panel.take_file_jobs(self.state, self.renderer)
            time.sleep(0.005)

    def finish_bake(self) -> None:
        """Complete the pending bake now (screenshots, scripts and the benchmark want the final maps)."""
        self.maps()
        while self._bake_job is not None:
            self.advance_bake(float("inf"))

    def adapt_motion_scale(self) -> None:
        """Move the adaptive scale toward TARGET_FPS from the last frames' time (swap to swap):
        the scene's cost is per pixel, so the scale goes with the square root of the time ratio,
        by at most one step a frame; the still view is always redrawn at full scale."""
        if not self.frame_times:
            return
        recent = sorted(list(self.frame_times)[-3:])   # the median of the last three: one slow frame is no trend
        ratio = (1.0 / TARGET_FPS) / max(recent[len(recent) // 2], 1e-6)
        want = self.adaptive_scale * ratio ** 0.5
        if abs(want - self.adaptive_scale) >= ADAPTIVE_STEP:
            step = ADAPTIVE_STEP if want > self.adaptive_scale else -ADAPTIVE_STEP
            self.adaptive_scale = min(1.0, max(ADAPTIVE_MIN_SCALE, self.adaptive_scale + step))

    def view_size(self, moving: bool) -> tuple[int, int]:
        """The view image's size: the view area's times the render scale, and times the motion scale
        while the camera moves (llvmpipe's cost is per pixel; a still view is redrawn sharp)."""
        w, h = self.view_area()
        motion = self.adaptive_scale if self.state.adaptive_motion else self.state.motion_scale
        scale = self.state.render_scale * (motion if moving else 1.0)
        return max(1, round(w * scale)), max(1, round(h * scale))

    def targets(self, size=None):
        """The view's framebuffers for a size, kept for the last few sizes: the adaptive scale
        moves between neighbouring sizes, and a reallocation per change would cost frame time."""
        from alight.render.targets import Targets

        w, h = size or self.size
        key = (w, h, self.state.aa)
        targets = self._target_cache.pop(key, None) or Targets(self.ctx, w, h, self.state.aa, 4)
        self._target_cache[key] = targets
        while len(self._target_cache) > TARGET_CACHE:
            self._target_cache.popitem(last=False)[1].release()
        return targets

    def last_view_image(self):
        """The targets the view was last drawn into as an image (not straight into the window),
        while still in the cache (their display image then holds that picture), else None."""
        image = getattr(self, "_view_image", None)
        return image if image is not None and any(t is image for t in self._target_cache.values()) else None

    def new_targets(self, size, aa):
        """Framebuffers of their own for an image of the view's kind (the compare view's half A),
        outside the view's cache."""
        from alight.render.targets import Targets

        return Targets(self.ctx, size[0], size[1], aa, 4)

    def _view_key(self, scene, maps, size) -> tuple:
        """Everything the view image depends on. Material, Camera, Light and Display are plain
        dataclasses compared by value; the mesh and the bake by identity (they are replaced, never
        mutated)."""
        return (id(scene.mesh), scene.material, tuple(map(dataclasses.astuple, scene.lights)), scene.camera,
                scene.display, scene.env_rotation_deg, scene.env_intensity, scene.ibl_enabled, id(maps),
                scene.ibl_model, scene.multiple_scattering, scene.occlusion, scene.shadows, scene.ground,
                size, self.state.aa, scene.debug_view, scene.debug_mip, scene.use_file_materials,
                scene.texture_maps, tuple(id(scene.texture_images.get(p)) for p in scene.texture_maps.paths().values()))

    def render_view(self, force: bool = False, full: bool = False):
        """Draw the scene, tone mapped as it is drawn, into the offscreen view image, but only when
        something it depends on changed; then put the tone-mapped image into the default framebuffer.
        (While the artist orbits every frame redraws; a still view costs only the copy.)
        ``full``: the window's size whatever the scales (screenshots)."""
        if self.state.mesh is not self._framed_mesh and _same_geometry(self.state.mesh, self._framed_mesh):
            self._framed_mesh = self.state.mesh   # another material variant of it: the view stays
        if self.state.mesh is not self._framed_mesh:
            if getattr(self.orbit, "restored", False):   # the last session's camera, kept once
                self.orbit.restored, self._framed_mesh = False, self.state.mesh
            else:
                view = getattr(self.state.mesh, "view", None)
                if view is not None:   # a built-in preview mesh: from its 3/4 view (Mesh.view)
                    self.orbit.yaw_deg, self.orbit.pitch_deg = float(view[0]), float(view[1])
                self.frame_mesh(new=True)   # a new mesh: frame it once
        if 0 in self.size:    # minimised
            return None
        window = self.size if full else self.view_area()   # the screenshot is the view at window size
        camera = self.orbit.camera()
        moving, self._last_camera = camera != self._last_camera, camera
        if moving and self._was_moving and not full:
            self.adapt_motion_scale()
        self._was_moving = moving
        size = window if full else self.view_size(moving)
        targets = self.targets(size)
        scene = self.state.scene(camera)
        maps = self.maps()
        # Occlusion once its bake is in the cache (made by a child process: occlusion_bake.py);
        # its answers first, so the frame that gets one draws the occluded picture.
        if self.occlusion_bake.step(self):
            self._drawn_key = None
        scene, hold_lighting = self.occlusion_bake.view_scene(self, scene, maps, whole=full)
        # For every draw of this view (the compare split's A half too) until the next frame says;
        # a screenshot or turntable clears it once the child has made the light terms (finish).
        self.renderer.visibility_parts.hold_lighting = hold_lighting
        # While the camera moves every frame is drawn anew: at the window's size straight into
        # the window, without the view image's copy (3 ms of a 860x720 frame on llvmpipe). The
        # view image is then stale, and the first still frame draws it.
        compare = self.state.compare.active   # two halves put together: never straight into the window
        # A transparent background is shown over a checkerboard, so never drawn straight in.
        checker = scene.display.background == "transparent" and not full
        into, into_srgb = self.direct_target() if (moving and not full and size == window and not compare
                                                   and not checker) \
            else (None, False)
        # (The key deep-copies the lights: 0.3 ms a frame, not spent where every frame redraws.)
        key = self._view_key(scene, maps, size) if into is None else None
        direct = False     # drawn into the window (the renderer may not: draw_display)
        if self.variant_warmup.step():   # a new variant compiled in the warm-up process: draw it now
            self._drawn_key = None
        # A still view is drawn again while the renderer refines it (screen-space GTAO's passes);
        # a screenshot is a still, with all its passes at once (ForwardRenderer.screen_ao_temporal).
        refining = not full and self.renderer.refining()
        if force or into is not None or key != self._drawn_key or targets is not self._drawn_targets or refining:
            try:   # the scene tone mapped as it is drawn: one pass into the 8-bit view
                # (a variant not compiled yet: the last picture's scene meanwhile, variant_warmup.py)
                self.renderer.screen_ao_temporal = not full
                try:
                    drawn_into, _complete = draw_view(self, scene, maps, targets, into, into_srgb, gated=not full)
                finally:
                    self.renderer.screen_ao_temporal = True
                direct = into is not None and drawn_into is into
            except ShaderCompileError as exc:   # a program first compiled now (a debug view)
                self.state.fail(exc)
                self.state.debug_view = 0
                return None
            if drawn_into is None:   # every program waits for the warm-up: the last view image again
                targets = self.last_view_image()
                size, into, self._drawn_key, self._drawn_targets = (targets.width, targets.height), None, None, None
            else:
                self._drawn_key, self._drawn_targets = (None, None) if direct else \
                    (key or self._view_key(scene, maps, size), targets)
                if not direct:
                    self._view_image = targets
            self.redraws += 1
            if scene.texture_maps != self._drawn_maps:   # uploaded maps no slot uses any more
                # (compare's A keeps the maps of its snapshot)
                keep = set(scene.texture_maps.paths().values()) | set(self.state.compare.a_texture_maps.paths().values())
                self.renderer.forget_map_textures(keep)
                self._drawn_maps = scene.texture_maps
        if not full:
            self.preset_prefetch.step(self, scene, maps, size)
        if compare:
            targets = self.compare_view.compose(self, scene, maps, targets, moving, finish=full)
        if direct:
            pass   # already in the window
        elif checker:
            self._show_over_checker(targets, window)
        elif size == window:
            self.ctx.copy_framebuffer(self.ctx.screen, targets.display_fbo)
        else:
            prog = self.renderer.program("render/fullscreen.vert", "render/upscale.frag")
            targets.display.filter = (self._linear, self._linear)
            targets.display.use(0)
            prog["u_image"] = 0
            self.ctx.screen.use()
            self.ctx.viewport = (0, 0) + window
            self.renderer.fullscreen(prog)
            self.ctx.viewport = (0, 0) + self.size
        # The copy leaves the last used framebuffer (display_fbo) bound; imgui draws into
        # whatever is bound, and must draw into the window, never into the view's image.
        self.ctx.screen.use()
        return targets

    def _show_over_checker(self, targets, window) -> None:
        """The view image over a checkerboard (render/checker.frag), stretched to the view area:
        what a transparent background shows in the window (the files keep the real alpha)."""
        prog = self.renderer.program("render/fullscreen.vert", "render/checker.frag")
        targets.display.filter = (self._linear, self._linear)
        targets.display.use(0)
        prog["u_image"] = 0
        prog["u_square"] = CHECKER_SQUARE
        prog["u_origin"] = (0.0, 0.0)
        self.ctx.screen.use()
        self.ctx.viewport = (0, 0) + window
        self.renderer.fullscreen(prog)
        self.ctx.viewport = (0, 0) + self.size

    def frame(self) -> None:
        self.draw()
        if not self.hosted:   # events that came while the last frame was shown (press_guard.py)
            self.glfw.poll_events()
        self.glfw.swap_buffers(self.window)
        self.after_swap()

    def after_swap(self) -> None:
        """After the frame is shown: the screenshot asked for during it, the frame time (from the
        last swap, or the end of the last wait for events: ``tick``)."""
        if not self.hosted:
            self.press_guard.shown = self._frame_no
        if self.screenshot_request and self.screenshot_job is None:
            path, self.screenshot_request = self.screenshot_request, ""
            try:
                self.screenshot_job = self.start_save_view(path)
            except AlightError as exc:
                self.state.fail(exc)
        if self.screenshot_job is not None:
            self._advance_screenshot()
        self._advance_turntable()
        now = time.perf_counter()
        if self._last_swap is not None:
            self.frame_times.append(now - self._last_swap)
        self._last_swap = now

    def draw(self) -> None:
        """One frame into the window's back buffer (events, panel, view, imgui), not yet shown:
        ``frame`` swaps it; tools can read the whole window first."""
        self.poll_events()
        self.begin_imgui_frame()
        self.build_frame()
        self.imgui.render()
        self.render_scene()
        if self.show_panel:
            self.render_imgui()

    def build_frame(self) -> None:
        """Between imgui's new frame and its render: the panel, the view's mouse and keys, the
        shader watcher, the undo history."""
        if self.hosted:
            self._size_cache = None   # the runner polled the events
        self._frame_no += 1
        # The panel's opens and exports (file_jobs.py), a step of a new mesh's upload: each frame,
        # the panel shown or not (--no-panel, a drop, --script open=).
        self.panel.take_file_jobs(self.state, self.renderer)
        if self.show_panel:
            mark = self.state.edit_mark()
            self.panel.draw(self)
            self.state.untick_own_for_edit(mark)   # a panel edit is seen, not hidden by the file's
            if not self.hosted:
                self.press_guard.built(self._frame_no, self.panel.layout)
        from alight.frontends.editor.compare import draw_overlay

        draw_overlay(self)   # the compare divider's line and the halves' names, over the view
        self._camera_input()
        self._turn_lights_with_env()
        self.check_shaders()
        self.check_files()
        committed = self.history.committed
        self.history.settle(self.state.look, self.imgui.is_any_item_active())
        if self.history.committed is not committed or self.history.settings_seen is None:
            # The settings a step was taken with: an undo after they changed says they stayed.
            self.history.settings_seen = self.state.settings()
        self.state.sync_map_images()   # undo/redo may bring back a map not decoded now

    def render_scene(self) -> None:
        """The view into the window's back buffer (under the panel), and a slice of a pending bake."""
        self.render_view()
        self._say_ground_idle()
        self.advance_bake()
        self.thumbnails.step()
        self.pass_warmup.step(self.state.display)

    def _say_ground_idle(self) -> None:
        """A ground that catches nothing, in the status row (``GROUND_IDLE``), once each time it
        comes to be so (the renderer's warning went to stderr alone, once a process, in the
        command line's words); the line goes when the ground catches a shadow again or is off."""
        idle = getattr(self.renderer, "last_ground_idle", "") if self.state.ground else ""
        said = getattr(self, "_ground_said", "")
        if idle == said:
            return
        self._ground_said = idle
        s = self.state
        if idle:
            s.message = GROUND_IDLE[idle]
        elif s.message == GROUND_IDLE.get(said):
            s.message = ""

    def begin_imgui_frame(self) -> None:
        """imgui's input and new frame (after poll_events)."""
        self.impl.process_inputs()
        if self._native_imgui:
            self.imgui.backends.opengl3_new_frame()   # its device objects, made on the first frame
        self.imgui.new_frame()

    def render_imgui(self) -> None:
        """imgui's draw data for this frame into the window, through the kept side-bar pixels
        where they serve (panel_image.PanelImage)."""
        draw_data = self.imgui.get_draw_data()
        if self.keep_panel_pixels:
            self._panel_image.draw(self.imgui, draw_data, self.size, self.view_area()[0])
        else:
            self._render_imgui_direct(draw_data)

    def _render_imgui_direct(self, draw_data) -> None:
        """imgui's draw data into the bound framebuffer."""
        if self._native_imgui:
            self.imgui.backends.opengl3_render_draw_data(draw_data)
        else:
            self.impl.render(draw_data)

    def screenshot(self, path: str) -> None:
        """The view without the panel, at window size: the last frame's radiance tone mapped again."""
        import numpy as np

        from alight.exchange.output import check_output_path, write_image

        out = check_output_path(path, (".png",))
        pixels = self.view_pixels(what=str(out))
        write_image(out, pixels, linear=False)

    def start_save_view(self, path: str):
        """F12 and the panel's button: the view as it is framed (the area left of the panel, at
        full resolution whatever the render and motion scales, or the size chosen in the panel),
        drawn again by the renderer's offline path; RGBA with the coverage as alpha when the
        background is transparent. Returns the screenshot.ScreenshotJob that writes it."""
        from alight.frontends.editor.screenshot import ScreenshotJob

        self.finish_bake()
        self.occlusion_bake.finish(self)   # (the renderer would bake what the child has not written yet)
        size = self.screenshot_size.size(self.view_area())
        scene = self.state.scene(self.orbit.camera())
        if self.state.compare.active:   # the split view, as shown: its halves put together whole
            from alight.frontends.editor.screenshot import WholeScreenshotJob

            maps, aa = self.maps(), self.saved_aa()

            def pixels():
                frame = self.renderer.render(scene, maps, size[0], size[1], aa=aa, read_linear=False, read_srgb=True)
                b = frame.srgb if scene.display.background == "transparent" else frame.srgb[:, :, :3]
                return self.compare_view.compose_frame(self, scene, maps, b, aa)

            return WholeScreenshotJob(pixels, size, path)
        return ScreenshotJob(self.renderer, scene, self.maps(), size, self.saved_aa(), path)

    def saved_aa(self) -> str:
        """The anti-aliasing of a file the view is saved to (screenshot, turntable): the view's,
        but at least MSAA over a transparent background, whose alpha is the cut-out a file is
        composited with (without it 0 or 1: stair steps over any backdrop). The view's 'none'
        is a choice of speed for live frames, not of what a file should hold."""
        if self.state.aa == "none" and self.state.display.background == "transparent":
            return "msaa"
        return self.state.aa

    def wait_for_thumbnails(self, timeout_s: float) -> float:
        """Draw frames until every thumbnail asked for has arrived (they render in a child
        process: seconds on a first start), at most ``timeout_s``; returns the seconds waited."""
        start = time.perf_counter()
        while self.thumbnails.pending() and time.perf_counter() - start < timeout_s:
            self.frame()
        return time.perf_counter() - start

    def _step_job(self, job) -> bool:
        """One step of a screenshot or turntable job; True once it is done or failed (the error
        in the panel). The jobs draw into their own targets: the window's framebuffer is bound again."""
        try:
            return job.step()
        except AlightError as exc:
            self.state.fail(exc)
            return True
        finally:
            self.ctx.screen.use()

    def _advance_screenshot(self) -> None:
        """A few strips of the screenshot being written; the panel's message says when it is."""
        job = self.screenshot_job
        if self._step_job(job):
            self.screenshot_job = None
            if os.path.isfile(job.path) and job.rows == job.height:
                self.state.error, self.state.message = "", wrote_message(job.path, f"{job.width}x{job.height}")

    def start_turntable(self):
        """The panel's turntable: the view's camera orbiting once about the vertical axis
        (turntable.py), at the view's size, the scene as it is now."""
        from alight.frontends.editor.turntable import TurntableJob, orbit_cameras

        self.finish_bake()
        self.occlusion_bake.finish(self)   # its frames drawn with occlusion, as 'alight render' draws them
        t = self.turntable
        cameras = orbit_cameras(self.orbit, t.frames)
        scene = self.state.scene(cameras[0])
        channels = 4 if scene.display.background == "transparent" else 3
        return TurntableJob(self.renderer, lambda camera: dataclasses.replace(scene, camera=camera), cameras,
                            self.maps(), self.view_area(), self.saved_aa(), t.path, channels)

    def _advance_turntable(self) -> None:
        """Start the turntable asked for, or draw a few more of its frames; the panel's message
        names the files once they are whole."""
        if self.turntable_request and self.turntable_job is None:
            self.turntable_request = False
            try:
                self.turntable_job = self.start_turntable()
            except AlightError as exc:
                self.state.fail(exc)
        job = self.turntable_job
        if job is None:
            return
        if self._step_job(job):
            self.turntable_job = None
            if job.rows == job.height:
                detail = f"{job.done} frames, {job.width}x{job.height}"
                self.state.error, self.state.message = "", (
                    wrote_message(job.path, detail) if job.webp else wrote_message(job.finals[0], detail, job.finals[-1].name))
                if job.mp4 and self.state.display.background == "transparent":
                    # H.264 in yuv420p has no alpha: said, not left to be found in the video.
                    self.state.message += ("; warning: an MP4 has no alpha: the transparent background is black "
                                           "in it (.webp or .png frames keep it)")

    def save_view(self, path: str) -> None:
        """``start_save_view`` run to the end now."""
        job = self.start_save_view(path)
        try:
            while not job.step(float("inf")):
                pass
        finally:
            self.ctx.screen.use()

    def view_pixels(self, what: str = "the view"):
        """The view without the panel at window size, top row first: uint8 (h, w, 3), sRGB."""
        import numpy as np

        self.finish_bake()
        targets = self.render_view(full=True)   # display_fbo holds the view, without the panel
        if targets is None:
            raise AlightError(f"{what}: the window has no area to capture")
        w, h = targets.width, targets.height
        pixels = np.frombuffer(targets.display_fbo.read(components=4, dtype="f1"), np.uint8).reshape(h, w, 4)
        return pixels[::-1, :, :3].copy()

    @staticmethod
    def next_screenshot_name() -> str:
        n = 1
        while os.path.exists(f"alight-screenshot-{n}.png"):
            n += 1
        return f"alight-screenshot-{n}.png"

    def should_close(self) -> bool:
        return bool(self.glfw.window_should_close(self.window))

    def run(self) -> None:
        """The interactive loop: ``tick`` until the window is closed."""
        while not self.should_close():
            self.tick()

    def tick(self) -> bool:
        """One turn of the interactive loop: a frame when something needs one, else a wait for
        events (IDLE_AFTER_S says when). Returns whether a frame was drawn."""
        now = time.monotonic()
        active = self._needs_full_rate()
        if active:
            self._last_active = now
        if now - self._last_active < IDLE_AFTER_S:
            shown = self._shown_key()
            self.frame()
            if active:
                # Counted from the frame's end: a click's frame that wrote a file on a loaded
                # machine outlasted IDLE_AFTER_S, and the loop waited for input before the frame
                # that shows what it changed (tests/editor_x_events_save_in_frame.py).
                self._last_active = time.monotonic()
            self._woken |= self._shown_key() != shown
            return True
        background = self._background_pending()
        if self._woken:
            # A callback in the last frame's after-draw poll (a drop, the pointer entering): its
            # frame now. Cleared unseen here, a dropped .hdr said "opened" and stayed off screen
            # until the mouse moved (tests/editor_x_events_drop_in_frame.py).
            self._woken = False
            self.frame()
            return True
        self.idle_waits += 1
        self.glfw.wait_events_timeout(BACKGROUND_FRAME_S if background else IDLE_WAIT_S)
        if self._last_swap is not None:
            # The next frame's time starts here: a wait for input is not the frame's (the
            # performance plot showed a 20 s idle stretch as a 20 000 ms frame).
            self._last_swap = max(self._last_swap, time.perf_counter())
        if self.key_events.pending:   # input: frames at full rate from this one
            self._last_active = time.monotonic()
        answered = self._answered > 0
        if answered:
            self._answered -= 1
        if self._woken or answered or self.key_events.pending or background or self.file_watcher.has_changed() \
                or self.check_shaders() or self.should_close():
            shown = self._shown_key()
            self.frame()
            self._woken |= self._shown_key() != shown
            return True
        return False

    def _shown_key(self) -> tuple:
        """What the panel draws before the work that may change it in a frame: the status row
        (drawn first) and the library's entries (a save rescans them after the box is drawn).
        A frame that changed them draws one more (``tick``), whatever changed them: a worker's
        result taken mid-frame, a click's save, a bake's end."""
        s = self.state
        return (s.error, s.message, len(self.panel.library.entries), self.panel.library.name)

    def _needs_full_rate(self) -> bool:
        """Input waiting, the camera moving, a job that advances a slice a frame, or a view that
        another frame refines (screen-space GTAO's passes, ForwardRenderer.refining)."""
        return bool(self.key_events.pending or len(self.imgui.get_current_context().input_events_queue)
                    or self._was_moving or self._bake_job is not None or self.screenshot_job is not None
                    or self.renderer.refining()
                    or self.screenshot_request or self.turntable_job is not None or self.turntable_request
                    or (self.imgui.is_any_item_active() and not self.imgui.get_io().want_text_input))

    def _background_pending(self) -> bool:
        """Work whose results come without input: a child's job, thumbnails asked for, the
        presets' prefetch, the split view's warm-up, a mesh opened or a glTF exported on the
        panel's worker thread. (A focused text field needs none: its cursor
        does not blink, and keys bring frames.)"""
        from alight.frontends.editor import worker_process

        return bool(worker_process.busy() or self.thumbnails.pending() or self.preset_prefetch.busy
                    or not self.pass_warmup.done or self.panel.file_jobs.busy)

    def close(self) -> None:
        # An export still writing is finished first: closing must not lose the file asked for.
        writing = self.panel.file_jobs.exporting
        if writing:
            print(f"alight: finishing the export of {writing} before closing", file=sys.stderr)
            self.panel.file_jobs.finish_export()
        if not self.hosted:
            from alight.frontends.editor import worker_process

            worker_process.set_waker(None)   # (no empty events posted to a glfw being closed)
        self.file_watcher.on_change = None
        self.file_watcher.stop()
        if self.turntable_job is not None:   # unfinished: its temporary files go
            self.turntable_job.cancel()
        for targets in self._target_cache.values():
            targets.release()
        self._target_cache.clear()
        self.compare_view.release()
        self.variant_warmup.close()
        self.preset_prefetch.close()
        self.occlusion_bake.close()
        self.pass_warmup.close()
        self._panel_image.release()
        self.thumbnails.release()
        if self.hosted:   # the runner closes imgui, the window and its context after this
            self.implot.destroy_context()
            self.renderer.release()
            return
        if self._native_imgui:
            self.imgui.backends.opengl3_shutdown()   # its textures first: the Python backend then finds them gone
        self.impl.shutdown()
        self.implot.destroy_context()
        self.imgui.destroy_context()
        self.renderer.release()
        self.ctx.release()
        self.glfw.destroy_window(self.window)
        self.glfw.terminate()


def front_normal(mesh):
    """The side a flat mesh shows its front faces to (the area-weighted sum of its
    counter-clockwise faces' normals, unit), or None for a mesh with depth or whose faces cancel."""
    import numpy as np

    if mesh.flat_normal() is None:
        return None
    total = np.zeros(3)
    for part in mesh.parts:
        p = part.positions.astype(np.float64)
        a, b, c = (p[part.indices[:, k]] for k in range(3))
        total += np.cross(b - a, c - a).sum(axis=0)
    norm = float(np.linalg.norm(total))
    return total / norm if norm > 0.0 else None


def _same_geometry(a, b) -> bool:
    """Whether two meshes are one geometry with other materials (alight.core.mesh.select_variant
    shares the parts' arrays): a variant switch keeps the artist's view rather than framing anew."""
    if a is None or b is None or len(a.parts) != len(b.parts):
        return False
    return all(p.positions is q.positions for p, q in zip(a.parts, b.parts))
