"""``alight edit``: open the editor, or take a screenshot / run the benchmark and exit."""

from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from alight.frontends.editor.state import EditorState


def build_state(args) -> EditorState:
    from alight.core.scene import parse_light
    from alight.errors import AlightError
    from alight.frontends.options import build_look

    if args.view != "camera":   # (refused before anything is loaded)
        raise AlightError("edit: --view probe is 'alight render''s; the editor shows the camera view")
    # --motion-scale fixes the scale while moving; without it the scale adapts to hold 30 FPS.
    state = EditorState(quality=args.quality or "medium", aa=args.aa or "none", motion_scale=args.motion_scale or 0.5,
                        adaptive_motion=args.motion_scale is None, occlusion=getattr(args, "occlusion", "auto"),
                        shadows=getattr(args, "shadows", "auto"), ground=getattr(args, "ground", False))
    material, _, maps = build_look(args)
    state.material = material
    _start_maps(state, maps, args)
    state.mark_saved()   # what 'revert' goes back to: the material and maps it started with
    state.load_mesh(args.mesh)
    mesh_warnings = state.warning_lines
    state.load_env(args.env)
    state.warning_lines = mesh_warnings + state.warning_lines
    if state.warning_lines:   # what the files are drawn without, in the status row from the start
        state.message = state.with_warnings(f"opened {args.mesh}, {args.env}")
    if args.no_ibl:
        state.ibl_enabled = False
    # As in 'alight render': a mesh file without --preset shows its own materials and maps.
    from alight.core.mesh import BUILTIN_MESHES

    state.use_file_materials = args.preset is None and maps is None and args.mesh not in BUILTIN_MESHES
    if getattr(args, "variant", None) is not None:   # as 'alight render --variant'
        try:
            state.set_variant(args.variant)
        except AlightError as e:
            raise AlightError(f"--variant {args.variant}: {e}") from None
    # The rest of 'alight render''s scene options, as it reads them. Lights: --light replaces the
    # editor's three (state.default_lights); without it a glTF's own lights do, as in 'render'.
    state.env_rotation_deg, state.env_intensity = args.env_rotation, args.env_intensity
    if args.light:
        state.lights = [parse_light(spec) for spec in args.light]
    elif state.mesh.lights and not args.no_file_lights:
        state.lights = list(state.mesh.lights)
    return state


def run(args) -> int:
    from alight.frontends.editor.window import EditorWindow

    ui_tests = None
    if getattr(args, "ui_test", None):   # the file is read before a window opens
        from alight.frontends.editor import ui_test

        if args.benchmark or args.screenshot or args.script or args.no_panel:
            from alight.errors import AlightError

            raise AlightError("--ui-test drives the panel: not with --benchmark, --screenshot, --script or --no-panel")
        ui_tests = ui_test.load_tests(args.ui_test)
    state = build_state(args)
    if ui_tests is not None:   # under hello_imgui's runner (ui_test.py says why)
        restore = not args.new and _no_scene_options(args)
        return ui_test.run(state, args.size, ui_tests,
                           restore=(lambda win: open_last_session(win, state, args)) if restore else None)
    size = (1280, 720) if args.benchmark else args.size
    # Interactive only (screenshots and benchmarks must not depend on the last session), and
    # only with no scene given on the command line.
    interactive = not (args.benchmark or args.screenshot or args.script)
    win = EditorWindow(state, size, show_panel=not args.no_panel, ini_path=_imgui_ini() if interactive else None)
    if interactive and not args.new and _no_scene_options(args):
        open_last_session(win, state, args)
    try:
        if args.benchmark:
            return _benchmark(win, args.frames or 120)
        for i, edit in enumerate(args.script):
            win.frame()            # one frame per edit: the editor runs between them
            started = win.panel.file_jobs.started
            state.apply_edit(edit)
            if win.panel.file_jobs.started != started:   # open= of a mesh: read on the panel's worker
                _finish_open(win)
        if args.screenshot:
            for _ in range(args.frames or 1):
                win.frame()
            win.screenshot(args.screenshot)
            if state.error:
                print(f"alight: panel error: {state.error}", file=sys.stderr)
            print(args.screenshot)
            return 0
        from alight.frontends.editor.session import save_session

        try:
            win.run()   # frames while something changes, a wait for events while nothing does
        except KeyboardInterrupt:
            # Ctrl+C, or SIGTERM (the CLI raises its Terminated, a KeyboardInterrupt: a logout,
            # a kill): the session is kept as after a normal close, then the CLI says which.
            save_session(state, win.orbit, win.turntable, win.panel)
            raise
        save_session(state, win.orbit, win.turntable, win.panel)
        return 0
    finally:
        win.close()


def open_last_session(win, state, args=None) -> None:
    """The last session reopened into the window's state; its mesh file is read on the panel's
    worker (the window draws meanwhile, session.restore_session). ``args``: the command line,
    whose view options given (--aa, --quality, --motion-scale) win over the session's."""
    from alight.frontends.editor.session import restore_session

    warning = restore_session(state, win.orbit, win.turntable, win.panel)
    if warning:
        state.error = " ".join(warning.split())
    if args is not None:   # (the session kept the last ones; a flag typed now is what is wanted)
        if args.aa is not None:
            state.aa = args.aa
        if args.quality is not None:
            state.quality = args.quality
        if args.motion_scale is not None:
            state.motion_scale, state.adaptive_motion = args.motion_scale, False
    win.history.committed = state.look


def _finish_open(win) -> None:
    """Frames until the mesh a script's ``open=`` asked for is read and on screen (the next edit
    or the screenshot sees it); a file that fails stops the script, as it did when read here."""
    from alight.errors import AlightError

    while win.panel.file_jobs.busy:
        win.frame()
    if win.state.error:
        raise AlightError(win.state.error)


def _imgui_ini():
    """imgui's layout file in the user's config folder (made if missing); None if it cannot be."""
    from alight.paths import config_dir

    try:
        config_dir().mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return config_dir() / "imgui.ini"


def _start_maps(state: EditorState, maps, args) -> None:
    """--texture-set, --map and a .gltf --preset's maps, as 'alight render' draws them; a
    --texture-set without --preset names the material after the set, as the panel's row does."""
    if maps is not None:
        from alight.exchange.texture_sets import load_map_images, set_name
        from alight.paths import absolute_maps

        maps = absolute_maps(maps)   # kept by absolute paths, as the panel's loads are (state.set_map)
        state.map_images = load_map_images(maps)
        state.texture_maps = maps
        texture_set = getattr(args, "texture_set", None)
        if texture_set:   # the 'texture set' field names the folder, as for one loaded in the panel
            from alight.paths import absolute

            state.texture_set_folder = absolute(texture_set)
        if texture_set and args.preset is None:
            name = set_name([], texture_set)
            if name and name.isprintable():
                state.material = dataclasses.replace(state.material, name=name)


def _no_scene_options(args) -> bool:
    from alight.core.material import LAYER_FIELDS

    material_flags = (args.preset, args.base_color, args.metallic, args.roughness, args.specular_f0,
                      args.emissive, args.ior, *(getattr(args, f) for f in LAYER_FIELDS))
    return (args.mesh, args.env) == ("sphere", "studio") and all(x is None for x in material_flags) \
        and not args.light and (args.env_rotation, args.env_intensity) == (0.0, 1.0) \
        and not getattr(args, "texture_set", None) and not getattr(args, "map", None) \
        and getattr(args, "occlusion", "auto") == "auto" \
        and getattr(args, "shadows", "auto") == "auto" and not getattr(args, "ground", False)


def _benchmark(win, frames: int) -> int:
    """Frame times as the user sees them (swap to swap) while the camera orbits (every frame
    redraws the scene): at full resolution, then at the motion scale; then a still view; then
    each stage alone with a finish() after it, to say where the time goes."""
    state = win.state
    motion_scale = state.motion_scale
    for _ in range(10):   # warm up: shader compiles, the bake, imgui's font atlas
        win.frame()
    win.finish_bake()
    # The presets' thumbnails render in a child process on a first start (cached after): on two
    # cores it takes the frames' CPU. The phases time the editor once it is done; how long it
    # took is printed.
    print(f"background work before timing (the presets' thumbnails): {win.wait_for_thumbnails(300.0):.1f} s")
    w, h = win.size
    print(f"editor benchmark {w}x{h}, material ball, IBL, {len(state.lights)} lights, panel, aa={state.aa}")

    def measure(label: str, n: int, orbit: bool) -> None:
        win.frame_times.clear()
        for _ in range(n):
            if orbit:
                win.orbit.orbit(3.0, 0.0)   # the camera moves every frame, as while the artist orbits
            win.frame()
        t = np.asarray(win.frame_times) * 1000.0
        median, p95 = float(np.median(t)), float(np.percentile(t, 95))
        print(f"{label}: {len(t)} frames, median {median:.1f} ms, p95 {p95:.1f} ms; "
              f"{1000.0 / median:.1f} FPS median, {1000.0 / p95:.1f} FPS at p95")

    adaptive = state.adaptive_motion
    state.motion_scale, state.adaptive_motion = 1.0, False
    measure("orbiting, full resolution", frames, True)
    if motion_scale < 1.0:
        state.motion_scale = motion_scale
        measure(f"orbiting, view at {motion_scale:g} x window while moving", frames, True)
    state.adaptive_motion = True
    scales = []
    win.frame_times.clear()
    for _ in range(frames):
        win.orbit.orbit(3.0, 0.0)
        win.frame()
        scales.append(win.adaptive_scale)
    t = np.asarray(win.frame_times) * 1000.0
    median, p95 = float(np.median(t)), float(np.percentile(t, 95))
    print(f"orbiting, adaptive scale (target 30 FPS; scale median {np.median(scales):.2f}, "
          f"range {min(scales):.2f}-{max(scales):.2f}): {len(t)} frames, median {median:.1f} ms, p95 {p95:.1f} ms; "
          f"{1000.0 / median:.1f} FPS median, {1000.0 / p95:.1f} FPS at p95")
    state.adaptive_motion = adaptive
    measure("still view (scene not redrawn)", frames // 2, False)
    state.motion_scale, state.adaptive_motion = 1.0, False
    stages = _profile(win, 30)
    print("full resolution, per stage (median, GL finished after each): "
          + ", ".join(f"{k} {v:.1f} ms" for k, v in stages.items()))
    return 0


def _profile(win, frames: int) -> dict[str, float]:
    imgui, ctx, r = win.imgui, win.ctx, win.renderer
    times: dict[str, list[float]] = {k: [] for k in ("panel build", "scene (tone mapped)", "copy to window",
                                                     "imgui draw", "swap")}
    for _ in range(frames):
        win.orbit.orbit(3.0, 0.0)
        t0 = time.perf_counter()
        win.poll_events()
        win.begin_imgui_frame()
        win.panel.draw(win)
        imgui.render()
        t1 = time.perf_counter()
        targets = win.targets(win.view_area())
        scene = win.state.scene(win.orbit.camera())
        # As an orbiting frame is drawn (EditorWindow.render_view): straight into the window
        # where it has a depth buffer, else into the view image and then copied.
        into, into_srgb = win.direct_target()
        drawn = r.draw_display(scene, win.maps(), targets, into=into, into_encodes_srgb=into_srgb)
        ctx.finish()
        t2 = time.perf_counter()
        if drawn is not ctx.screen:
            ctx.copy_framebuffer(ctx.screen, targets.display_fbo)
        ctx.screen.use()
        ctx.finish()
        t3 = time.perf_counter()
        win.render_imgui()
        ctx.finish()
        t4 = time.perf_counter()
        win.glfw.swap_buffers(win.window)
        t5 = time.perf_counter()
        for k, a, b in zip(times, (t0, t1, t2, t3, t4), (t1, t2, t3, t4, t5)):
            times[k].append((b - a) * 1000.0)
    return {k: float(np.median(v)) for k, v in times.items()}
