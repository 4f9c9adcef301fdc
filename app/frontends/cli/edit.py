"""``alight edit``: the interactive editor's command line; everything else lives in app/frontends/editor/."""

from __future__ import annotations

from alight.errors import AlightError
from alight.frontends.cli.arguments import (
    QUALITIES,
    Command,
    _add_occlusion_option,
    _add_scene_options,
    _add_shadow_options,
    _number,
    _size,
)


def add_parser(sub) -> None:
    e = sub.add_parser("edit", help="open the interactive material editor (needs a display)",
                       description="The material editor: a window with a live preview and a panel. "
                                   "Drop .hdr/.exr, mesh or preset .json files on it.")
    _add_scene_options(e, views=False)
    # --quality and --aa default to None so that one given wins over the last session's (run.py).
    e.add_argument("--quality", choices=QUALITIES + ("auto",), default=None,
                   help="bake quality; auto: the cheapest measured bake within 2%% for the environment and "
                        "the kind of material, shown in the panel (default: medium)")
    _add_occlusion_option(e, editor=True)
    _add_shadow_options(e, editor=True)
    e.add_argument("--size", type=_size, default=(1280, 720), metavar="W|WxH", help="window size (default: 1280x720)")
    e.add_argument("--aa", choices=("none", "msaa"), default=None,
                   help="anti-aliasing of the preview (default: none; msaa costs ~2x on llvmpipe)")
    e.add_argument("--motion-scale", type=_number("--motion-scale", 0.25, 1.0), default=None, metavar="X",
                   help="the view's resolution while the camera moves, relative to the view area; a still "
                        "view is redrawn at full resolution (default: adaptive, the scale that holds 30 FPS)")
    e.add_argument("--screenshot", metavar="FILE.png",
                   help="render --frames frames, write the view (without the panel) at window size, exit")
    e.add_argument("--frames", type=int, default=0, metavar="N", help="frames before --screenshot (default 1), "
                                                                       "or measured by --benchmark (default 120)")
    e.add_argument("--benchmark", action="store_true",
                   help="1280x720, the material ball, IBL, 3 lights and the panel: print median and p95 frame times")
    e.add_argument("--script", action="append", default=[], metavar="FIELD=VALUE",
                   help="an edit applied after a frame (repeatable), e.g. roughness=0.9, preset=water, open=FILE. "
                        "FIELD: roughness, metallic, ior, base_color, emissive, specular_f0 (R,G,B linear), the "
                        "layers' fields (clearcoat, clearcoat_roughness, sheen_color, ..., as the material flags), "
                        "preset, open, mesh, env (a name or path), exposure, tonemap, env_rotation, env_intensity, "
                        "ibl (0/1), ibl_model, multiple_scattering (0/1), occlusion, shadows, ground (0/1), quality, debug_view, debug_mip, "
                        "map_SLOT (an image path, '' clears; SLOT: base_color, metallic_roughness, metallic, roughness, normal, emissive, occlusion), "
                        "uv_scale, uv_offset (U,V)")
    e.add_argument("--ui-test", metavar="FILE.py",
                   help="run FILE's test_*(ctx) functions with the Dear ImGui Test Engine against the real "
                        "window (ctx.set_ref('alight'); ctx.item_click('**/copper')); exit 0 when all pass, "
                        "1 with each failure; the session is saved as after a normal close")
    e.add_argument("--no-panel", action="store_true", help="draw the view only")
    e.add_argument("--new", action="store_true",
                   help="do not reopen the last session (it is reopened when no scene option is given)")


def run(args) -> int:
    import os

    if args.view != "camera":
        raise AlightError("--view: the editor shows the camera view")
    if args.frames < 0:
        raise AlightError(f"--frames: {args.frames} is negative")
    if args.screenshot:   # refuse a bad path before a window opens
        from alight.exchange.output import check_output_path

        check_output_path(args.screenshot, (".png",))
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        raise AlightError("editor: no display (DISPLAY is unset); run under xvfb-run -a, or use 'alight render'")
    from alight.frontends.editor.run import run

    return run(args)


COMMAND = Command("edit", add_parser, run)
