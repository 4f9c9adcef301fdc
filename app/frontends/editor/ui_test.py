"""``alight edit --ui-test FILE.py``: the editor's real window driven by the Dear ImGui Test Engine.

FILE defines ``test_*(ctx)`` functions; each is registered with the engine and run, in the order
written, against the editor's panel and view (``ctx`` is the engine's TestContext: set_ref,
item_click, item_input_value, mouse_drag_with_delta, key_press ... by label path, e.g.
``ctx.set_ref("alight"); ctx.item_click("**/copper")``). Exit 0 when every test passes, 1 with a
line per failure; the session is saved at the end as after a normal close.

Why hello_imgui's runner hosts this window: the engine runs Python test functions on a second
thread and hands the GIL back and forth from C++, which imgui-bundle's runner (hello_imgui,
``runner_params.use_imgui_test_engine``) does and a Python loop cannot (a probe driving the
engine from the editor's own glfw loop hung on its first test). The runner owns the window,
the GL context, imgui's context, the polling, imgui's rendering (its C++ OpenGL 3 renderer, as
the editor's own loop uses) and the swap; EditorWindow(hosted=True) draws the same panel and
the same view in its callbacks (show_gui, custom_background, after_swap).

A test function runs on the engine's thread, between frames, while the main thread waits: it
may read the editor's plain state (``editor().state``) but must not call GL; ``view(ctx)`` asks
the main thread for the view's pixels and waits for them.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import traceback
from pathlib import Path

from alight.errors import AlightError

WATCHDOG_S = 600.0   # seconds one test may run before the engine stops it
_window = None       # the EditorWindow the tests drive (set once the runner has a GL context)
_requests: list = []  # (function, result box) to run on the main thread after a frame


def editor():
    """The EditorWindow under test: ``.state`` (EditorState), ``.orbit``, ``.history``, ``.panel``."""
    if _window is None:
        raise RuntimeError("the editor's window is not open yet")
    return _window


def on_main_thread(ctx, function):
    """``function()`` run on the main thread (where the GL context is current) after the next
    frame; the test waits frames for it. Its result is returned, its exception raised here."""
    box: list = []
    _requests.append((function, box))
    while not box:
        ctx.yield_()
    ok, value = box[0]
    if not ok:
        raise value
    return value


def view(ctx):
    """The view without the panel, as F12 writes it: uint8 (h, w, 3) sRGB, top row first
    (the pending environment bake is finished first)."""
    return on_main_thread(ctx, lambda: editor().view_pixels())


def files_done(ctx, frames: int = 20000) -> int:
    """Frames until the panel's 'open mesh' and 'export glTF' (run on a worker thread:
    file_jobs.py) have finished and a frame has taken their result; their count."""
    jobs = editor().panel.file_jobs
    ctx.yield_()   # the frame that starts a job asked for by the last key or click
    for n in range(frames):
        if not jobs.busy:
            ctx.yield_()   # the frame that took it has drawn the status row
            return n
        ctx.yield_()
    raise AssertionError(f"the panel's file job still runs after {frames} frames")


def load_tests(path: str) -> list[tuple[str, object]]:
    """The ``test_*`` functions of a Python file, in the order written. Errors: AlightError,
    one line naming the file (missing, does not import, no test functions)."""
    file = Path(path)
    if not file.is_file():
        raise AlightError(f"{path}: --ui-test: no such file")
    spec = importlib.util.spec_from_file_location(f"alight_ui_test_{file.stem}", file)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as exc:   # a user's test file: say where, in one line
        line = next((f.lineno for f in reversed(traceback.extract_tb(exc.__traceback__))
                     if f.filename == str(file)), getattr(exc, "lineno", None))
        where = f" line {line}:" if line else ""
        raise AlightError(f"{path}:{where} --ui-test file does not import "
                          f"({type(exc).__name__}: {' '.join(str(exc).split())})") from None
    tests = [(name, fn) for name, fn in vars(module).items() if name.startswith("test_") and callable(fn)]
    if not tests:
        raise AlightError(f"{path}: --ui-test file defines no test_*(ctx) function")
    return tests


def run(state, size: tuple[int, int], tests, restore=None) -> int:
    """Open the editor under hello_imgui's runner with the test engine, run ``tests`` (pairs of
    name and function), save the session, close. ``restore``: None, or ``f(window)`` reopening
    the last session as `alight edit` does (run.open_last_session). Returns 0 if all passed,
    else 1 (a line per failure on stderr)."""
    global _window
    from imgui_bundle import hello_imgui, imgui

    te = imgui.test_engine
    params = hello_imgui.RunnerParams()
    params.app_window_params.window_title = "alight"
    params.app_window_params.window_geometry.size = size
    params.app_window_params.restore_previous_geometry = False
    # The panel is the editor's own top-level window "alight", as in the editor's own loop.
    params.imgui_window_params.default_imgui_window_type = hello_imgui.DefaultImGuiWindowType.no_default_window
    params.ini_disable = True   # the layout never depends on an earlier run
    params.fps_idling.enable_idling = False
    params.fps_idling.vsync_to_monitor = False
    params.callbacks.load_additional_fonts = lambda: None   # imgui's own font, as the editor's loop draws
    gl = params.renderer_backend_options.open_gl_options
    gl.major_version, gl.minor_version, gl.use_core_profile, gl.use_forward_compat = 4, 5, True, True
    params.use_imgui_test_engine = True

    registered: list = []            # (name, engine Test)
    raised: dict[str, str] = {}      # name -> the Python exception a test raised
    results: list[tuple[str, str]] = []   # (name, '' or the failure), once all have run
    startup_error: list = []

    def post_init() -> None:
        global _window
        from alight.frontends.editor.window import EditorWindow

        try:
            _window = EditorWindow(state, size, hosted=True)
        except Exception as exc:   # no usable GL here: stop the runner, say why
            traceback.print_exc()
            startup_error.append(exc)
            params.app_shall_exit = True
            return
        if restore is not None:
            restore(_window)
        # The restored mesh, read on the panel's worker, in place before the first test.
        _window.finish_file_jobs()
        # The environment's first bake done before the tests start: while it runs, its progress
        # bar tops the panel and every row below moves up a line when it ends, under a click the
        # engine is making (on a loaded machine it clicked the row after the one asked for).
        _window.finish_bake()

    def wrap(name, fn):
        def test_func(ctx) -> None:
            try:
                fn(ctx)
            except BaseException as exc:   # a failed check: its message, for the report
                raised[name] = f"{type(exc).__name__}: {' '.join(str(exc).split())}" if str(exc) \
                    else type(exc).__name__
                code = getattr(fn, "__code__", None)   # the line in the user's file that raised
                lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__)
                         if code is not None and f.filename == code.co_filename]
                if lines:
                    raised[name] += f" (line {lines[-1]})"
        return test_func

    def register_tests() -> None:
        engine = hello_imgui.get_imgui_test_engine()
        io = te.get_io(engine)
        io.config_run_speed = te.TestRunSpeed.fast
        io.config_no_throttle = True
        io.config_log_to_tty = False
        # The engine stops a test after 60 s by default; a software GL under load can take that
        # for a handful of transmissive frames. Ten minutes, then the test fails as timed out.
        io.config_watchdog_warning, io.config_watchdog_kill_test = 300.0, WATCHDOG_S
        for name, fn in tests:
            test = te.register_test(engine, "alight", name)
            test.test_func = wrap(name, fn)
            registered.append((name, test))
        for _, test in registered:
            te.queue_test(engine, test)

    def show_gui() -> None:
        if _window is not None:
            _window.build_frame()

    def custom_background() -> None:
        if _window is not None:
            _window.render_scene()

    def after_swap() -> None:
        if _window is None:
            return
        _window.after_swap()
        while _requests:
            function, box = _requests.pop(0)
            try:
                box.append((True, function()))
            except Exception as exc:
                box.append((False, exc))

    def before_imgui_render() -> None:
        if results or not registered or _window is None:
            return
        engine = hello_imgui.get_imgui_test_engine()
        if not te.is_test_queue_empty(engine):
            return
        if any(test.output.status in (te.TestStatus.queued, te.TestStatus.running, te.TestStatus.unknown)
               for _, test in registered):
            return
        for name, test in registered:   # read now: the engine owns the tests and goes at exit
            # The engine's own errors (an item not found, ...) first: after one it ignores the
            # test's further actions, so a later check fails for that reason.
            failure = ""
            if test.output.status != te.TestStatus.success:
                log = test.output.log.get_text()
                if os.environ.get("ALIGHT_UI_TEST_LOG"):
                    print(log, file=sys.stderr)
                errors = [line for line in log.splitlines() if "error" in line.lower()]
                failure = " ".join(" ".join(errors[:2]).split()) or f"engine status {test.output.status.name}"
            if name in raised:
                failure = f"{failure}; {raised[name]}" if failure else raised[name]
            results.append((name, failure))
        params.app_shall_exit = True

    def before_exit() -> None:
        if _window is None:
            return
        from alight.frontends.editor.session import save_session

        save_session(state, _window.orbit, _window.turntable, _window.panel)   # as after a normal close
        _window.close()

    cb = params.callbacks
    cb.post_init, cb.register_tests, cb.show_gui = post_init, register_tests, show_gui
    cb.custom_background, cb.after_swap = custom_background, after_swap
    cb.before_imgui_render, cb.before_exit = before_imgui_render, before_exit
    try:
        hello_imgui.run(params)
    finally:
        _window = None
    if startup_error:
        raise AlightError(f"editor: {' '.join(str(startup_error[0]).split())}")
    if not results:
        print("alight: --ui-test: the window closed before the tests finished", file=sys.stderr)
        return 1
    failed = [(name, why) for name, why in results if why]
    for name, why in results:
        print(f"{'FAIL' if why else 'ok  '} {name}")
    for name, why in failed:
        print(f"alight: ui test {name} failed: {why}", file=sys.stderr)
    print(f"{len(results) - len(failed)} passed, {len(failed)} failed")
    return 1 if failed else 0
