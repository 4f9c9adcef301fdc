"""The editor's panel operated as an artist does, by the Dear ImGui Test Engine: run by
tests/test_editor_ui.py as ``alight edit --new --ui-test tests/editor_ui_checks.py`` (a real
window under Xvfb); not collected by pytest. Each function clicks, types, drags or presses keys
through the engine and checks the effect on the rendered view or on the file written; none sets
the editor's state itself.

The engine runs these on its own thread between frames: they read the editor's plain state
(editor().state) and ask the main thread for the view's pixels (view(ctx))."""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from alight.frontends.editor.ui_test import editor, files_done, view

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))   # this file is loaded by path
from editor_ui_helpers import ball, capture, changed, checker_levels, contrast, type_path, until_seconds  # noqa: E402

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # where files written by the panel go


def void(ctx) -> None:
    """A click on the view (no window there): the panel lets go of the keyboard."""
    ctx.mouse_click_on_void()


# --- the F0 table, revert, undo and redo -----------------------------------------------------------

def test_preset_click_revert_undo_redo(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/water")
    assert s.material.name == "water", s.material.name
    water = ball(view(ctx))
    ctx.item_click("**/copper")
    assert s.material.name == "copper", s.material.name
    copper = ball(view(ctx)).mean(axis=0)
    # Copper's F0 is red over green over blue; water's grey.
    w = water.mean(axis=0)
    assert copper[0] > copper[1] > copper[2] and copper[0] / copper[2] > w[0] / w[2] + 0.15, (copper, w)
    # The highlighted row is the preset the material equals: edited, none is; revert brings it back.
    ctx.item_input_value("**/roughness", 0.8)
    assert abs(s.material.roughness - 0.8) < 1e-6 and s.material.name == "copper"
    assert not any(s.material == preset for _, preset, *_ in editor().panel.presets)
    ctx.item_click("**/revert")
    assert any(s.material == preset and name == "copper" for name, preset, *_ in editor().panel.presets)
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), copper, atol=0.5)
    # Ctrl+Z goes back through revert, the roughness edit and the click; Ctrl+Shift+Z forward.
    void(ctx)
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert abs(s.material.roughness - 0.8) < 1e-6, s.material
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert s.material.name == "copper" and s.material.roughness != 0.8
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert s.material.name == "water", s.material.name
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), water.mean(axis=0), atol=0.5)
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("mod_shift") | imgui_key("z"))
    assert s.material.name == "copper", s.material.name
    # The panel's undo and redo buttons do the same.
    ctx.item_click("**/undo")
    assert s.material.name == "water"
    ctx.item_click("**/redo")
    assert s.material.name == "copper"


def imgui_key(name: str):
    from imgui_bundle import imgui

    return getattr(imgui.Key, name)


# --- material sliders, colour, fields --------------------------------------------------------------

def test_roughness_and_metallic_sliders(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_input_value("**/roughness", 0.05)
    sharp = view(ctx)
    ctx.item_input_value("**/roughness", 0.9)
    assert abs(s.material.roughness - 0.9) < 1e-6
    rough = view(ctx)
    assert contrast(sharp) > 1.5 * contrast(rough), (contrast(sharp), contrast(rough))
    # Metallic 0 on gold's base colour: a yellow diffuse ball with a white rim of reflection;
    # metallic 1: the reflection itself is yellow. The blue channel tells them apart.
    ctx.item_input_value("**/metallic", 0.0)
    assert s.material.metallic == 0.0
    dielectric = ball(view(ctx)).mean(axis=0)
    ctx.item_input_value("**/metallic", 1.0)
    metal = ball(view(ctx)).mean(axis=0)
    assert s.material.metallic == 1.0
    assert metal[2] / metal[0] < 0.8 * dielectric[2] / dielectric[0], (metal, dielectric)


def test_base_colour_edit(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.6)
    # The colour edit's three sRGB components, typed as an artist types them (0-255).
    ctx.item_input_value("base colour (sRGB)/##X", 40)
    ctx.item_input_value("base colour (sRGB)/##Y", 200)
    ctx.item_input_value("base colour (sRGB)/##Z", 40)
    r, g, b = s.material.base_color
    assert g > 5 * r and abs(r - b) < 1e-6, s.material.base_color
    green = ball(view(ctx)).mean(axis=0)
    assert green[1] > 1.6 * green[0] and green[1] > 1.6 * green[2], green


def test_hex_colour_entry(ctx):
    """The colour's picker (a click on its swatch) takes a hex code: typed, it applies."""
    from imgui_bundle import imgui

    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_click("base colour (sRGB)/##ColorButton")
    ctx.item_input_value("//$FOCUSED/##picker/##hex/##Text", "#2040E0")
    ctx.key_press(imgui.Key.escape)
    r, g, b = s.material.base_color   # stored linear: sRGB 0x20, 0x40, 0xE0
    np.testing.assert_allclose((r, g, b), (0.0144, 0.0513, 0.7454), atol=2e-3)
    blue = ball(view(ctx)).mean(axis=0)
    assert blue[2] > 1.5 * blue[0], blue


def test_emissive_and_name_fields(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    before = ball(view(ctx)).mean()
    ctx.item_input_value("emissive/$$0", 4.0)
    assert s.material.emissive[0] == 4.0, s.material.emissive
    glowing = ball(view(ctx)).mean(axis=0)
    assert glowing[0] > 200 and glowing.mean() > before, glowing
    ctx.item_input_value("emissive/$$0", 0.0)
    ctx.item_input_value("**/name", "my_plastic")
    assert s.material.name == "my_plastic", s.material.name


# --- saving -----------------------------------------------------------------------------------------

def _save_preset_through_panel(ctx, preset: str, roughness: float, name: str) -> str:
    """Click ``preset``, type ``roughness`` and a preset file under OUT, press "save preset";
    returns the file's path."""
    path = os.path.join(OUT, name)
    ctx.set_ref("alight")
    ctx.item_click(f"**/{preset}")
    ctx.item_input_value("**/roughness", roughness)
    ctx.item_input_value("**/preset file", path)
    ctx.item_click("**/save preset")
    return path


def test_save_preset_button_writes_the_material(ctx):
    from alight.exchange.presets import load_preset

    s = editor().state
    path = _save_preset_through_panel(ctx, "copper", 0.42, "from_panel.json")
    assert os.path.isfile(path), (s.error, s.message, editor().panel.preset_path)
    assert load_preset(path) == s.material
    assert abs(json.loads(open(path, encoding="utf-8").read())["roughness"] - 0.42) < 1e-6
    assert s.message.startswith(f"saved {path} and to the library: "), s.message
    from alight.frontends.editor.library import library_dir   # a saved material is in the library too

    assert (library_dir() / "from_panel.glb").is_file() and "from_panel" in [e.name for e in editor().panel.library.entries]


def test_export_gltf_button_writes_a_gltf(ctx):
    path = os.path.join(OUT, "from_panel.gltf")
    ctx.set_ref("alight")
    ctx.item_input_value("**/glTF file", path)
    ctx.item_click("**/export glTF")
    files_done(ctx)
    data = json.loads(open(path, encoding="utf-8").read())
    assert data["asset"]["version"] == "2.0" and data["materials"], data


# --- environment, lights, display -------------------------------------------------------------------

def test_image_based_lighting_checkbox(ctx):
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    lit = ball(view(ctx)).mean()
    ctx.item_open("**/Lights")
    ctx.item_uncheck("**/image-based lighting")
    assert not editor().state.ibl_enabled
    unlit = ball(view(ctx)).mean()
    ctx.item_check("**/image-based lighting")
    assert editor().state.ibl_enabled
    assert unlit < 0.7 * lit, (unlit, lit)
    ctx.item_close("**/Lights")


def test_add_and_remove_a_light(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Lights")
    n = len(s.lights)
    before = view(ctx).astype(np.float64)
    ctx.item_click("**/add point")
    assert len(s.lights) == n + 1 and s.lights[-1].kind == "point"
    assert view(ctx).astype(np.float64).mean() > before.mean() + 0.5
    ctx.item_click(f"$${n}/remove")
    assert len(s.lights) == n
    ctx.item_close("**/Lights")


def test_tone_map_and_exposure(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.combo_click("tone map/none")
    assert s.display.tonemap == "none"
    clipped = view(ctx).astype(np.float64)
    ctx.combo_click("tone map/aces")
    assert s.display.tonemap == "aces"
    aces = view(ctx).astype(np.float64)
    assert np.abs(aces - clipped).mean() > 0.5
    ctx.item_input_value("**/exposure (EV)", 2.0)
    assert s.display.exposure == 2.0
    assert view(ctx).astype(np.float64).mean() > aces.mean() + 10
    ctx.item_input_value("**/exposure (EV)", 0.0)
    ctx.combo_click("tone map/neutral")
    ctx.item_close("**/Display & camera")


def test_debug_view_combo(ctx):
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.combo_click("debug view/normal")
    image = view(ctx)
    h, w = image.shape[:2]
    # The ball's centre faces the camera: n = (0, 0, 1) is shown as (0.5, 0.5, 1).
    centre = image[h // 2 - 2:h // 2 + 2, w // 2 - 2:w // 2 + 2].astype(np.float64)
    assert np.abs(centre - [128, 128, 255]).max() <= 4, centre.mean(axis=(0, 1))
    ctx.combo_click("debug view/shaded")
    assert editor().state.debug_view == 0
    ctx.item_close("**/Display & camera")


def test_environment_rotation_and_background(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    before = view(ctx).astype(np.float64)
    ctx.item_input_value("**/rotation", 90.0)
    assert s.env_rotation_deg == 90.0
    assert np.abs(view(ctx).astype(np.float64) - before).mean() > 1.0
    ctx.item_input_value("**/rotation", 0.0)
    ctx.combo_click("background/color")
    assert s.display.background == "color"
    corner = view(ctx)[:8, :8].astype(np.float64)
    assert np.abs(corner - corner.mean(axis=(0, 1))).max() < 1.0   # a flat colour, not the studio
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")


# --- the view: keys and the mouse ------------------------------------------------------------------

def test_orbit_drag_frame_key_and_f12(ctx):
    from imgui_bundle import imgui

    win = editor()
    void(ctx)
    yaw = win.orbit.yaw_deg
    w, h = imgui.get_io().display_size.x, imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(w * 0.2, h * 0.5))
    ctx.mouse_drag_with_delta(imgui.ImVec2(60, 0))
    assert win.orbit.yaw_deg != yaw, "a left drag in the view did not orbit"
    # F frames the mesh again: the same distance as before the drag.
    ctx.key_press(imgui.Key.f)
    names = set(os.listdir("."))
    ctx.key_press(imgui.Key.f12)
    ctx.yield_(3)
    shots = [n for n in set(os.listdir(".")) - names if n.startswith("alight-screenshot-")]
    assert shots, editor().state.error


def test_f12_saves_the_view_with_alpha_on_a_transparent_background(ctx):
    """F12 writes the view as framed (the area left of the panel, not the window), RGB; with the
    transparent background RGBA: the ball opaque, the corners clear."""
    import OpenImageIO as oiio
    from imgui_bundle import imgui

    win = editor()
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/transparent")
    ctx.item_close("**/Environment")
    void(ctx)
    names = set(os.listdir("."))
    ctx.key_press(imgui.Key.f12)
    ctx.yield_(3)
    shot = [n for n in set(os.listdir(".")) - names if n.startswith("alight-screenshot-")]
    assert shot, win.state.error
    image = oiio.ImageBuf(shot[0]).get_pixels(oiio.UINT8)
    w, h = win.view_area()
    assert image.shape == (h, w, 4), (image.shape, (w, h), win.size)
    assert image[h // 2, w // 2, 3] == 255 and image[:4, :4, 3].max() == 0, (image[h // 2, w // 2], image[0, 0])
    # The view draws without anti-aliasing by default; the file's alpha is still graded at the
    # silhouette (a cut-out of 0 or 255 alone is stair-stepped over any backdrop).
    alpha = image[..., 3]
    assert win.state.aa == "none" and ((alpha > 0) & (alpha < 255)).sum() > 20, np.unique(alpha)
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.item_click("**/screenshot (F12)")   # the button does the same, RGB once the background is back
    ctx.item_close("**/Display & camera")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")


def test_shift_right_drag_turns_the_environment(ctx):
    from imgui_bundle import imgui

    s = editor().state
    void(ctx)
    before, target = s.env_rotation_deg, editor().orbit.target
    w, h = imgui.get_io().display_size.x, imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(w * 0.2, h * 0.5))
    ctx.key_down(imgui.Key.left_shift)
    ctx.mouse_drag_with_delta(imgui.ImVec2(40, 0), imgui.MouseButton_.right)
    ctx.key_up(imgui.Key.left_shift)
    assert s.env_rotation_deg != before, "Shift + right drag did not turn the environment"
    assert editor().orbit.target == target, "Shift + right drag panned"
    turned = view(ctx).astype(np.float64)
    ctx.mouse_move_to_pos(imgui.ImVec2(w * 0.2, h * 0.5))
    ctx.mouse_drag_with_delta(imgui.ImVec2(40, 0), imgui.MouseButton_.right)   # without Shift: a pan
    assert editor().orbit.target != target
    assert np.abs(turned - view(ctx)).mean() > 0.5
    ctx.key_press(imgui.Key.f)   # framed again: the next checks see the ball in the middle
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.item_input_value("**/rotation", before)
    ctx.item_close("**/Environment")


def test_add_a_spot_light_and_aim_it(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Lights")
    n = len(s.lights)
    before = ball(view(ctx)).mean()
    ctx.item_click("**/add spot")
    assert len(s.lights) == n + 1 and s.lights[-1].kind == "spot", s.lights
    lit = ball(view(ctx)).mean()
    assert lit > before + 0.5, (lit, before)
    ctx.item_input_value(f"$${n}/outer cone", 60.0)
    assert s.lights[-1].outer_cone_deg == 60.0 and s.lights[-1].direction != (0.0, 0.0, -1.0)
    # Aimed away from the ball, it no longer lights it.
    ctx.item_input_value(f"$${n}/direction (spot points)/$$1", 1.0)
    ctx.item_input_value(f"$${n}/direction (spot points)/$$2", 1.0)
    assert ball(view(ctx)).mean() < lit - 0.5
    ctx.item_click(f"$${n}/remove")
    ctx.item_close("**/Lights")


# --- more of the panel: layers, lighting settings, display, files ------------------------------------

# (normalized: the editor keeps a path absolute and normalized, as os.path.abspath makes it)
SHARED = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data"))


def test_an_added_light_shows_on_a_large_mesh_far_away_under_a_bright_map(ctx):
    """'add spot' gave a fixed intensity at a fixed place aimed at the origin: under a bright map
    it barely showed, and on a mesh elsewhere or of another size not at all. It is now placed
    about the mesh and gives it twice the map's mean irradiance."""
    from editor_ui_checks_ground import SETTLE_LIMIT_S, _settled

    win = editor()
    s = win.state
    cube = os.path.join(OUT, "large_far_cube.obj")
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = ["1 2 4 3", "5 7 8 6", "1 5 6 2", "3 4 8 7", "1 3 7 5", "2 6 8 4"]
    with open(cube, "w") as f:
        f.writelines(f"v {40 + 10 * x} {10 * y} {10 * z}\n" for x, y, z in corners)
        f.writelines(f"f {face}\n" for face in faces)
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    n = len(s.lights)
    try:
        type_path(ctx, "**/env file", os.path.join(SHARED, "env", "royal_esplanade_1k.hdr"))
        ctx.item_click("**/open env")
        type_path(ctx, "**/mesh", cube)
        ctx.item_click("**/open mesh")
        files_done(ctx)
        assert s.mesh_spec == cube, (s.mesh_spec, s.error)
        ctx.item_close("**/Environment")
        ctx.item_open("**/Lights")
        # (the bake, the occlusion bake of the new mesh and its variants change the view)
        until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
        before = ball(view(ctx)).mean()
        ctx.item_click("**/add spot")
        assert len(s.lights) == n + 1 and s.lights[-1].kind == "spot", s.lights
        until_seconds(ctx, lambda: _settled(win), SETTLE_LIMIT_S)
        lit = ball(view(ctx)).mean()
        print(f"added spot on the far cube under royal_esplanade: {before:.1f} -> {lit:.1f}")
        # (+16% on the earlier checks' metal, +32% on the default material; 0 before: the spot
        # at (0, 3, 3) aimed at the origin missed the cube)
        assert lit > 1.1 * before, (lit, before)
    finally:   # the next checks start from the studio and the sphere
        ctx.item_open("**/Lights")
        if len(s.lights) > n:
            ctx.item_click(f"$${n}/remove")
        ctx.item_close("**/Lights")
        ctx.item_open("**/Environment")
        ctx.item_click("**/studio")
        ctx.combo_click("preview mesh/sphere")
        ctx.item_close("**/Environment")
    assert s.env_spec == "studio" and s.mesh_spec == "sphere", (s.env_spec, s.mesh_spec)


def test_clearcoat_layer_section(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.7)
    dull = view(ctx)
    ctx.item_open("**/###layer_clearcoat")
    ctx.item_input_value("**/clearcoat", 1.0)
    ctx.item_input_value("**/clearcoat roughness", 0.03)
    assert (s.material.clearcoat, s.material.clearcoat_roughness) == (1.0, np.float32(0.03)), s.material
    coated = view(ctx)
    # The coat's sharp reflections over the rough copper: more local contrast, a changed ball.
    assert contrast(coated) > 1.1 * contrast(dull), (contrast(coated), contrast(dull))
    assert np.abs(ball(coated) - ball(dull)).mean() > 2.0
    ctx.item_close("**/###layer_clearcoat")
    ctx.item_click("**/revert")
    assert s.material.clearcoat == 0.0


def test_intensity_multiple_scattering_and_ibl_model(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_input_value("**/roughness", 0.9)
    ctx.item_open("**/Environment")
    base = ball(view(ctx)).mean()
    ctx.item_check("**/multiple scattering")
    assert s.multiple_scattering
    brighter = ball(view(ctx)).mean()
    assert brighter > base + 1.0, (brighter, base)   # a rough metal gets back the energy single scattering loses
    ctx.item_uncheck("**/multiple scattering")
    ctx.combo_click("IBL model/lecture")
    assert s.ibl_model == "lecture"
    assert np.abs(ball(view(ctx)).mean() - base) > 0.2
    ctx.combo_click("IBL model/alight")
    ctx.item_input_value("**/intensity", 2.0)
    assert s.env_intensity == 2.0
    assert ball(view(ctx)).mean() > base + 10
    ctx.item_input_value("**/intensity", 1.0)
    ctx.item_close("**/Environment")


def test_open_env_typed_and_studio_button(ctx):
    s = editor().state
    path = os.path.join(SHARED, "env", "venice_sunset_1k.hdr")
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    studio = view(ctx).astype(np.float64)
    type_path(ctx, "**/env file", path)
    ctx.item_click("**/open env")
    assert s.env_spec == path, (s.env_spec, s.error)
    assert np.abs(view(ctx).astype(np.float64) - studio).mean() > 5.0
    ctx.item_click("**/studio")
    assert s.env_spec == "studio"
    np.testing.assert_allclose(view(ctx).astype(np.float64).mean(), studio.mean(), atol=0.5)
    # A 2:1 PNG typed there is the environment too (it went to the base colour map by its suffix).
    png = os.path.join(SHARED, "cases", "with_controls", "ldr_srgb.png")
    type_path(ctx, "**/env file", png)
    ctx.item_click("**/open env")
    assert s.env_spec == png and "as the environment" in s.message, (s.env_spec, s.message, s.error)
    assert not (s.texture_maps and s.texture_maps.base_color), s.texture_maps
    ctx.item_click("**/studio")
    ctx.item_close("**/Environment")


def test_open_mesh_typed(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    type_path(ctx, "**/mesh", "cube")
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.mesh_spec == "cube", s.error
    cube = view(ctx)
    type_path(ctx, "**/mesh", "sphere")
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.mesh_spec == "sphere" and np.abs(view(ctx).astype(np.float64) - cube).mean() > 1.0
    ctx.item_close("**/Environment")


def test_preview_mesh_combo_picks_the_shader_ball(ctx):
    """The 'preview mesh' combo loads a built-in and frames it from its 3/4 view: the shader
    ball's pedestal and groove change the view, and the camera looks down on it."""
    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("preview mesh/sphere")
    assert s.mesh_spec == "sphere", s.error
    before = view(ctx).astype(np.float64)
    ctx.combo_click("preview mesh/shader_ball")
    assert s.mesh_spec == "shader_ball", s.error
    after = view(ctx).astype(np.float64)
    assert np.abs(after - before).mean() > 2.0, np.abs(after - before).mean()
    assert (win.orbit.yaw_deg, win.orbit.pitch_deg) == s.mesh.view == (35.0, 25.0)
    ctx.combo_click("preview mesh/sphere")
    assert s.mesh_spec == "sphere"
    ctx.item_close("**/Environment")


def test_field_of_view_aa_and_render_scale(ctx):
    win = editor()
    ctx.set_ref("alight")
    ctx.item_open("**/Display & camera")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/color")   # a flat background: the ball is what differs from it
    ctx.item_close("**/Environment")
    ctx.item_click("**/frame mesh (F)")

    def ball_pixels(image):
        return int((np.abs(image.astype(np.float64) - image[2, 2]).sum(axis=2) > 30).sum())

    fov = win.orbit.fov_y_deg
    framed = ball_pixels(view(ctx))
    ctx.item_input_value("**/field of view", fov + 20.0)
    assert win.orbit.fov_y_deg == fov + 20.0
    assert ball_pixels(view(ctx)) < 0.8 * framed, (ball_pixels(view(ctx)), framed)
    ctx.item_input_value("**/field of view", fov)
    ctx.item_open("**/Environment")
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")
    ctx.item_click("**/frame mesh (F)")
    ctx.combo_click("anti-aliasing/msaa")
    assert win.state.aa == "msaa"
    ctx.combo_click("anti-aliasing/none")
    ctx.item_input_value("**/render scale", 0.5)
    assert win.state.render_scale == 0.5
    ctx.item_input_value("**/render scale", 1.0)
    ctx.item_close("**/Display & camera")


def test_a_blended_part_is_see_through_without_anti_aliasing_as_with_msaa(ctx):
    """With anti-aliasing 'none' (the editor's default) the view is drawn tone mapped in one
    pass, which wrote alphaMode BLEND parts opaque: cases/gltf_alpha_blend.glb's half-transparent
    plane was solid orange until msaa was picked. Both now show it over what is behind."""
    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    try:
        type_path(ctx, "**/mesh", os.path.join(SHARED, "cases", "gltf_alpha_blend.glb"))
        ctx.item_click("**/open mesh")
        files_done(ctx)
        assert s.mesh_spec.endswith("gltf_alpha_blend.glb"), (s.mesh_spec, s.error)
        ctx.item_close("**/Environment")
        ctx.item_open("**/Display & camera")
        ctx.combo_click("anti-aliasing/none")
        plain = ball(view(ctx))
        ctx.combo_click("anti-aliasing/msaa")
        assert s.aa == "msaa"
        resolved = ball(view(ctx))
        print(f"blended plane, mean of the middle: none {plain.mean(axis=0)}, msaa {resolved.mean(axis=0)}")
        assert np.abs(plain.mean(axis=0) - resolved.mean(axis=0)).max() < 3.0, (plain.mean(axis=0), resolved.mean(axis=0))
    finally:
        ctx.item_open("**/Display & camera")
        ctx.combo_click("anti-aliasing/none")
        ctx.item_close("**/Display & camera")
        ctx.item_open("**/Environment")
        ctx.combo_click("preview mesh/sphere")
        ctx.item_close("**/Environment")


def test_base_colour_map_typed_load_and_clear(ctx):
    import OpenImageIO as oiio

    s = editor().state
    path = os.path.join(OUT, "red.png")
    red = np.zeros((16, 16, 3), np.uint8)
    red[..., 0] = 230
    oiio.ImageBuf(red).write(path)
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/base colour (sRGB)/##X", 255)
    ctx.item_input_value("**/base colour (sRGB)/##Y", 255)
    ctx.item_input_value("**/base colour (sRGB)/##Z", 255)
    white = ball(view(ctx)).mean(axis=0)
    ctx.item_click("texture maps/base_color/##armed")
    type_path(ctx, "**/map file", path)
    ctx.item_click("**/load##typed")
    assert s.texture_maps.paths().get("base_color") == path, (s.texture_maps, s.error)
    mapped = ball(view(ctx)).mean(axis=0)
    assert mapped[0] > 2 * mapped[1] and white[0] < 1.3 * white[1], (mapped, white)
    ctx.item_click("texture maps/base_color/clear")
    assert "base_color" not in s.texture_maps.paths()
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), white, atol=0.5)


def test_texture_set_folder_typed_into_the_map_field(ctx):
    """A folder typed into "map file" and loaded: its Substance-named maps go to their slots by
    name (not all into the armed slot), their factors become 1, and the ball takes the red map."""
    import OpenImageIO as oiio

    s = editor().state
    folder = os.path.join(OUT, "wood_set")
    os.makedirs(folder, exist_ok=True)
    red = np.zeros((16, 16, 3), np.uint8)
    red[..., 0] = 230
    grey = np.full((16, 16, 3), 128, np.uint8)
    oiio.ImageBuf(red).write(os.path.join(folder, "wood_BaseColor.png"))
    oiio.ImageBuf(grey).write(os.path.join(folder, "wood_Roughness.png"))
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    gold = ball(view(ctx)).mean(axis=0)
    type_path(ctx, "**/map file", folder)
    ctx.item_click("**/load##typed")
    paths = s.texture_maps.paths()
    assert paths.get("base_color", "").endswith("wood_BaseColor.png"), (paths, s.error)
    assert paths.get("roughness", "").endswith("wood_Roughness.png"), (paths, s.error)
    assert s.material.roughness == 1.0 and tuple(s.material.base_color) == (1.0, 1.0, 1.0), s.material
    mapped = ball(view(ctx)).mean(axis=0)
    assert mapped[0] > 1.5 * mapped[1] and not np.allclose(mapped, gold, atol=2.0), (mapped, gold)
    for slot in ("base_color", "roughness"):
        s.clear_map(slot)


def _write_atomically(path: str, pixels: np.ndarray) -> None:
    """As image editors and exporters save: a new file renamed over the old one."""
    import OpenImageIO as oiio

    temp = path + ".tmp" + os.path.splitext(path)[1]
    assert oiio.ImageBuf(pixels).write(temp)
    os.replace(temp, path)


def test_hot_reload_of_a_map_and_the_environment(ctx):
    """A map file rewritten on disk while the editor runs is drawn anew within a second, and so
    is an environment file (then baked again)."""
    s = editor().state
    path = os.path.join(OUT, "hot.png")
    _write_atomically(path, np.full((16, 16, 3), (230, 20, 20), np.uint8))
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_click("texture maps/base_color/##armed")
    type_path(ctx, "**/map file", path)
    ctx.item_click("**/load##typed")
    assert s.texture_maps.paths().get("base_color") == path, (s.texture_maps, s.error)
    red = ball(view(ctx)).mean(axis=0)
    assert red[0] > 2 * red[2], red
    before = s.map_images[path]
    _write_atomically(path, np.full((16, 16, 3), (20, 20, 230), np.uint8))
    seconds = until_seconds(ctx, lambda: s.map_images.get(path) is not before, 1.0)
    blue = ball(view(ctx)).mean(axis=0)
    assert blue[2] > 2 * blue[0], (blue, red)
    print(f"hot reload: the map was reloaded {seconds:.2f} s after the rewrite")
    ctx.item_click("texture maps/base_color/clear")
    # The environment: a uniform warm sky, then a uniform cold one.
    env = os.path.join(OUT, "hot.hdr")
    _write_atomically(env, np.full((32, 64, 3), (1.0, 0.6, 0.3), np.float32))
    ctx.item_open("**/Environment")
    type_path(ctx, "**/env file", env)
    ctx.item_click("**/open env")
    assert s.env_spec == env, (s.env_spec, s.error)
    warm = ball(view(ctx)).mean(axis=0)
    old_env = s.env
    _write_atomically(env, np.full((32, 64, 3), (0.3, 0.6, 1.0), np.float32))
    seconds = until_seconds(ctx, lambda: s.env is not old_env, 1.0)
    cold = ball(view(ctx)).mean(axis=0)
    assert cold[2] > cold[0] + 20 and warm[0] > warm[2] + 20, (warm, cold)
    print(f"hot reload: the environment was reloaded {seconds:.2f} s after the rewrite")
    ctx.item_click("**/studio")
    ctx.item_close("**/Environment")


def test_anisotropy_and_sheen_sections(ctx):
    s = editor().state

    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.4)
    image = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_anisotropy")
    ctx.item_input_value("**/anisotropy strength", 0.9)
    assert abs(s.material.anisotropy_strength - 0.9) < 1e-6
    image = changed(ctx, image, "anisotropy strength")
    ctx.item_input_value("**/anisotropy rotation", 60.0)   # degrees, stored in radians
    assert abs(s.material.anisotropy_rotation - np.radians(60.0)) < 1e-4, s.material.anisotropy_rotation
    image = changed(ctx, image, "anisotropy rotation")
    ctx.item_close("**/###layer_anisotropy")
    ctx.item_click("**/plastic_high")
    image = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_sheen")
    ctx.item_input_value("###layer_sheen/sheen colour (sRGB)/##X", 255)
    ctx.item_input_value("**/sheen roughness", 0.5)
    assert s.material.sheen_color[0] == 1.0 and abs(s.material.sheen_roughness - 0.5) < 1e-6, s.material
    image = changed(ctx, image, "sheen")
    ctx.item_close("**/###layer_sheen")
    ctx.item_click("**/revert")
    assert s.material.sheen_color == (0.0, 0.0, 0.0)


def test_transmission_and_volume_sections(ctx):
    s = editor().state

    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    image = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_transmission")
    ctx.item_input_value("**/transmission", 1.0)
    assert s.material.transmission == 1.0
    image = changed(ctx, image, "transmission")
    ctx.item_close("**/###layer_transmission")
    ctx.item_open("**/###layer_volume")
    ctx.item_input_value("**/thickness", 1.0)
    ctx.item_check("**/attenuate")
    ctx.item_input_value("###layer_volume/attenuation colour (sRGB)/##Y", 40)
    assert s.material.thickness == 1.0 and s.material.attenuation_distance == 1.0, s.material
    changed(ctx, image, "volume")
    ctx.item_close("**/###layer_volume")
    ctx.item_click("**/revert")
    assert s.material.transmission == 0.0 and s.material.thickness == 0.0


def test_iridescence_dispersion_and_diffuse_transmission_sections(ctx):
    """The sections made from the material-field registry (app/frontends/editor/layer_rows.py):
    each edit through its widget changes the ball and is one undo step."""
    s = editor().state

    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.3)
    plain = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_iridescence")
    ctx.item_input_value("**/iridescence", 1.0)
    assert s.material.iridescence == 1.0 and "iridescence" in s.material.layers(), s.material
    filmed = changed(ctx, plain, "iridescence")
    ctx.item_input_value("**/iridescence thickness maximum", 250.0)   # a drag, in nm
    assert s.material.iridescence_thickness_maximum == 250.0, s.material
    changed(ctx, filmed, "iridescence thickness maximum")
    # Each edit one undo step: Ctrl+Z twice takes the film off, and the ball is copper again.
    void(ctx)
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert s.material.iridescence == 1.0 and s.material.iridescence_thickness_maximum == 400.0, s.material
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert s.material.iridescence == 0.0, s.material
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), ball(plain).mean(axis=0), atol=0.5)
    ctx.item_close("**/###layer_iridescence")
    # Diffuse transmission: a red diffuse ball lets blue light through from behind.
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("base colour (sRGB)/##Y", 40)
    ctx.item_input_value("base colour (sRGB)/##Z", 40)
    image = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_diffuse_transmission")
    ctx.item_input_value("**/diffuse transmission", 1.0)
    ctx.item_input_value("###layer_diffuse_transmission/diffuse transmission colour (sRGB)/##X", 20)
    assert s.material.diffuse_transmission == 1.0 and s.material.diffuse_transmission_color[0] < 0.01, s.material
    changed(ctx, image, "diffuse transmission")
    ctx.item_close("**/###layer_diffuse_transmission")
    # Dispersion acts on a volume's refraction: transmission, thickness and a high ior first,
    # through white (plastic_high's dark blue hides the fringes: 0.15 at 10 in one run).
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.2)
    for component in "XYZ":
        ctx.item_input_value(f"base colour (sRGB)/##{component}", 255)
    ctx.item_input_value("**/ior", 3.0)
    ctx.item_open("**/###layer_transmission")
    ctx.item_input_value("**/transmission", 1.0)
    ctx.item_close("**/###layer_transmission")
    ctx.item_open("**/###layer_volume")
    ctx.item_input_value("**/thickness", 1.0)
    ctx.item_close("**/###layer_volume")
    image = view(ctx).astype(np.float64)
    ctx.item_open("**/###layer_dispersion")
    ctx.item_input_value("**/dispersion", 20.0)   # Abbe number 1: the fringes at the horizon's edge
    assert s.material.dispersion == 20.0 and "dispersion" in s.material.layers(), s.material
    changed(ctx, image, "dispersion")
    ctx.item_close("**/###layer_dispersion")
    ctx.item_click("**/revert")
    assert s.material.dispersion == 0.0 and s.material.transmission == 0.0


def test_bake_quality_combo(ctx):
    win = editor()
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    ctx.combo_click("bake quality/low")
    assert win.state.quality == "low"
    view(ctx)   # (the bake is finished for the view)
    assert win._maps_key[1:] == ("low",), win._maps_key
    ctx.combo_click("bake quality/medium")
    view(ctx)
    assert win._maps_key[1:] == ("medium",)
    ctx.item_close("**/Environment")


def test_a_lights_position_colour_and_intensity(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_open("**/Lights")
    ctx.item_uncheck("**/image-based lighting")   # the punctual lights alone
    first = s.lights[0]
    image = view(ctx).astype(np.float64)
    ctx.item_input_value("$$0/intensity", 0.0)
    assert s.lights[0].intensity == 0.0
    darker = view(ctx).astype(np.float64)
    assert ball(darker).mean() < ball(image).mean() - 1.0
    ctx.item_input_value("$$0/intensity", first.intensity)
    ctx.item_input_value("$$0/colour/##X", 0)
    ctx.item_input_value("$$0/colour/##Y", 0)
    assert s.lights[0].color[:2] == (0.0, 0.0), s.lights[0]
    blue, white = ball(view(ctx)).mean(axis=0), ball(image).mean(axis=0)
    assert blue[0] < white[0] - 0.5 and blue[0] - blue[2] < white[0] - white[2], (blue, white)
    ctx.item_input_value("$$0/position/$$0", -first.vector[0])
    assert s.lights[0].vector[0] == np.float32(-first.vector[0]), s.lights[0]
    assert np.abs(view(ctx).astype(np.float64) - image).mean() > 0.3
    ctx.item_input_value("$$0/colour/##X", first.color[0])
    ctx.item_input_value("$$0/colour/##Y", first.color[1])
    ctx.item_input_value("$$0/position/$$0", first.vector[0])
    ctx.item_check("**/image-based lighting")
    ctx.item_close("**/Lights")


def test_file_materials_checkbox_and_motion_settings(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_open("**/Environment")
    type_path(ctx, "**/mesh", os.path.join(SHARED, "models", "Duck.glb"))
    ctx.item_click("**/open mesh")
    files_done(ctx)
    assert s.use_file_materials, s.error
    own = ball(view(ctx)).mean(axis=0)
    assert own[0] > own[2] + 30, own   # the duck's own yellow texture
    ctx.item_uncheck("**/mesh file's own materials and maps")
    ctx.item_click("**/water")
    panel = ball(view(ctx)).mean(axis=0)
    assert panel[0] < own[0] - 20, (panel, own)
    type_path(ctx, "**/mesh", "sphere")
    ctx.item_click("**/open mesh")
    files_done(ctx)
    ctx.item_close("**/Environment")
    ctx.item_open("**/Display & camera")
    adaptive = s.adaptive_motion
    ctx.item_click("**/###adaptive_motion")
    assert s.adaptive_motion != adaptive
    if not s.adaptive_motion:
        ctx.item_input_value("**/scale while moving", 0.5)
        assert s.motion_scale == 0.5
        ctx.item_click("**/###adaptive_motion")
    ctx.item_close("**/Display & camera")


def test_uv_tiling_of_a_map(ctx):
    import OpenImageIO as oiio

    s = editor().state
    path = os.path.join(OUT, "halves.png")
    halves = np.zeros((16, 16, 3), np.uint8)
    halves[:, :8, 0] = 230
    halves[:, 8:, 1] = 230
    oiio.ImageBuf(halves).write(path)
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    type_path(ctx, "**/map file", path)
    ctx.item_click("texture maps/base_color/##armed")
    ctx.item_click("**/load##typed")
    assert s.texture_maps.paths().get("base_color") == path, (s.texture_maps, s.error)
    once = view(ctx).astype(np.float64)
    ctx.item_input_value("texture maps/UV tiling/$$0", 8.0)
    assert s.texture_maps.uv_scale[0] == 8.0, s.texture_maps
    assert np.abs(view(ctx).astype(np.float64) - once).mean() > 1.0
    ctx.item_input_value("texture maps/UV offset/$$1", 0.25)
    assert s.texture_maps.uv_offset[1] == 0.25
    ctx.item_input_value("texture maps/UV tiling/$$0", 1.0)
    ctx.item_input_value("texture maps/UV offset/$$1", 0.0)
    ctx.item_click("texture maps/base_color/clear")


def test_ior_and_specular_f0_follow_each_other(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    before = ball(view(ctx)).mean()
    ctx.item_input_value("**/ior", 1.2)   # F0 = ((ior - 1) / (ior + 1))^2 = 0.0083: a fainter reflection
    assert abs(s.material.ior - 1.2) < 1e-6
    f0 = s.material.f0()
    assert abs(float(np.mean(f0)) - (0.2 / 2.2) ** 2) < 2e-3, f0
    assert ball(view(ctx)).mean() < before - 0.3
    ctx.item_input_value("specular F0/$$0", 0.08)
    ctx.item_input_value("specular F0/$$1", 0.08)
    ctx.item_input_value("specular F0/$$2", 0.08)
    assert s.material.ior > 1.5, s.material   # the ior follows the F0 typed


# --- compare: the A/B split view (app/frontends/editor/compare.py) ----------------------------------

def _halves(image: np.ndarray, divider: float) -> tuple[np.ndarray, np.ndarray]:
    from alight.frontends.editor.compare_view import split_column

    col = split_column(divider, image.shape[1])
    return image[:, :col].astype(np.int32), image[:, col:].astype(np.int32)


def _same(a: np.ndarray, b: np.ndarray) -> int:
    """The largest difference of two images of one shape (0-255)."""
    assert a.shape == b.shape, (a.shape, b.shape)
    return int(np.abs(a.astype(np.int32) - b.astype(np.int32)).max()) if a.size else 0


def _ball_half(image: np.ndarray, left: bool) -> np.ndarray:
    """The ball's pixels in the left or right half of the image (the divider at 0.5)."""
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    side = x < w // 2 - 2 if left else x >= w // 2 + 2
    return image[((x - w / 2) ** 2 + (y - h / 2) ** 2 < (0.2 * h) ** 2) & side].astype(np.float64)


def test_compare_snapshot_a_against_the_live_material_and_drag_the_divider(ctx):
    from imgui_bundle import imgui

    win = editor()
    s = win.state
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.3)
    copper = view(ctx)                      # the plain view, before the split
    ctx.item_click("**/silver")
    silver = view(ctx)
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.3)
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/material")
    assert s.compare.mode == "material" and not s.compare.active   # A not chosen: one view
    ctx.item_click("**/snapshot A")
    assert s.compare.active and s.compare.a_material == s.material, s.compare
    assert _same(view(ctx), copper) <= 1        # the same material both sides: the plain view
    ctx.item_click("**/silver")                 # the live material changes; A keeps copper
    assert s.material.name == "silver" and s.compare.a_material.name == "copper"
    split = view(ctx)
    a, b = _halves(split, s.compare.divider)
    assert _same(a, _halves(copper, s.compare.divider)[0]) <= 1, "A's half is not the snapshot's render"
    assert _same(b, _halves(silver, s.compare.divider)[1]) <= 1, "B's half is not the live material's render"
    left, right = _ball_half(split, True).mean(axis=0), _ball_half(split, False).mean(axis=0)
    assert left[0] / left[2] > right[0] / right[2] + 0.15, (left, right)   # copper's red left, silver's grey right
    # A left drag on the divider's line moves it (and does not orbit); elsewhere it orbits.
    void(ctx)
    yaw = win.orbit.yaw_deg
    view_w = imgui.get_io().display_size.x - win.panel_width()
    h = imgui.get_io().display_size.y
    ctx.mouse_move_to_pos(imgui.ImVec2(s.compare.divider * view_w, h * 0.5))
    ctx.mouse_drag_with_delta(imgui.ImVec2(-0.25 * view_w, 0))
    assert abs(s.compare.divider - 0.25) < 0.03, s.compare.divider
    assert win.orbit.yaw_deg == yaw, "the divider's drag orbited the camera"
    moved = view(ctx)
    a, b = _halves(moved, s.compare.divider)
    assert _same(a, _halves(copper, s.compare.divider)[0]) <= 1
    assert _same(b, _halves(silver, s.compare.divider)[1]) <= 1
    # Between the old boundary and the new one the pixels are now silver's, not copper's.
    from alight.frontends.editor.compare_view import split_column

    w = moved.shape[1]
    band = slice(split_column(0.27, w), split_column(0.48, w))
    assert _same(moved[:, band], silver[:, band]) <= 1 and _same(moved[:, band], copper[:, band]) > 10
    ctx.set_ref("alight")
    ctx.item_input_value("**/divider", 0.5)
    assert s.compare.divider == 0.5
    # A preset chosen for A instead of the snapshot.
    ctx.combo_click("A preset/gold")
    assert s.compare.a_material.name == "gold" and s.compare.a_label == "preset gold"
    ctx.combo_click("compare/off")
    assert not s.compare.active
    assert _same(view(ctx), silver) <= 1        # off: the plain live view again
    ctx.item_close("**/Compare")


def test_compare_two_ibl_models(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    ctx.item_input_value("**/roughness", 0.9)
    ctx.item_open("**/Environment")
    ctx.combo_click("IBL model/lecture")
    lecture = view(ctx)
    ctx.combo_click("IBL model/alight")
    alight = view(ctx)
    ctx.item_close("**/Environment")
    ctx.set_ref("alight")
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/ibl model")
    ctx.combo_click("A IBL model/lecture")
    ctx.combo_click("B IBL model/alight")
    assert (s.compare.a_ibl_model, s.ibl_model) == ("lecture", "alight")
    split = view(ctx)
    a, b = _halves(split, s.compare.divider)
    assert _same(a, _halves(lecture, s.compare.divider)[0]) <= 1, "A's half is not the lecture model's render"
    assert _same(b, _halves(alight, s.compare.divider)[1]) <= 1, "B's half is not the alight model's render"
    assert np.abs(_ball_half(split, True).mean() - _ball_half(alight, True).mean()) > 0.2
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_compare_against_the_exact_reference(ctx):
    s = editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/plastic_high")
    ctx.item_input_value("**/roughness", 0.5)
    live = view(ctx)
    ctx.item_open("**/Compare")
    ctx.combo_click("compare/reference")
    ctx.item_input_value("**/reference scale", 0.1)   # 64 x 40 sums: seconds on a software GL
    assert abs(s.compare.reference_scale - 0.1) < 1e-6, s.compare.reference_scale
    split = view(ctx)                            # (the view waits for the whole sum)
    assert editor().compare_view.reference_seconds, s.error
    a, b = _halves(split, s.compare.divider)
    la, lb = _halves(live, s.compare.divider)
    assert _same(b, lb) <= 1                     # B: the live view
    ball_a, ball_live = _ball_half(split, True), _ball_half(live, True)
    assert _same(ball_a, ball_live) > 0, "the reference half is the live render"
    # The split-sum forward render is within a few percent of the exact sum on a rough dielectric.
    assert np.abs(ball_a.mean(axis=0) - ball_live.mean(axis=0)).max() < 8, (ball_a.mean(axis=0), ball_live.mean(axis=0))
    corner = slice(0, 8)
    assert _same(a[corner, corner], la[corner, corner]) <= 1   # around the sphere: B's background
    # Below the reference's minimum roughness: one line in the panel, not a wrong half.
    ctx.item_input_value("**/roughness", 0.02)
    view(ctx)
    assert "reference compare:" in s.error and "roughness" in s.error, s.error
    ctx.item_input_value("**/roughness", 0.5)
    ctx.combo_click("compare/off")
    ctx.item_close("**/Compare")


def test_load_preset_button(ctx):
    from alight.exchange.presets import load_preset

    s = editor().state
    path = _save_preset_through_panel(ctx, "iron", 0.66, "to_load.json")
    saved = load_preset(path)
    ctx.item_click("**/water")
    assert s.material != saved
    ctx.item_click("**/load preset")
    assert s.material == saved, (s.material, s.error)


# --- the library: saved materials with thumbnails, the presets' thumbnails ------------------------

def _same_material(a, b) -> bool:
    """Field by field within float32 rounding (a glTF file holds float32 and derives F0 from ior)."""
    import dataclasses

    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, str) or x == y:
            continue
        if not np.allclose(np.asarray(x, np.float64), np.asarray(y, np.float64), rtol=1e-6, atol=1e-6):
            return False
    return True


def _wait_for_thumbnails(ctx, seconds: float = 400.0) -> None:
    """Frames until no thumbnail the panel asked for is still to be made (each is an 'alight
    render' in a child process; on a loaded machine a layered material's takes many seconds)."""
    import time

    thumbs = editor().thumbnails
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        ctx.yield_()
        if not thumbs.pending():
            assert not thumbs.failures(), thumbs.failures()
            return
    raise AssertionError(f"{thumbs.pending()} thumbnails still pending after {seconds} s")


def _icon_pixels(ctx, shot: np.ndarray, ref: str) -> np.ndarray:
    """The thumbnail drawn left of a list row (a preset's or a library entry's), from a capture."""
    from alight.frontends.editor.library_panel import ICON

    rect = ctx.item_info(ref).rect_full
    y0 = int(rect.min.y + (rect.max.y - rect.min.y - ICON) / 2)
    x1 = int(rect.min.x) - 2
    return shot[y0 + 4:y0 + ICON - 4, x1 - ICON + 4:x1 - 4, :3].astype(np.float64)


def test_presets_show_rendered_thumbnails(ctx):
    """Each F0 preset's row shows its rendered ball (cached as a PNG under its content key):
    copper's thumbnail is red over blue where silver's is grey, in the files and on screen."""
    import OpenImageIO as oiio

    from alight.core.texture_maps import TextureMaps
    from alight.frontends.editor.thumbnails import thumbnail_dir

    win = editor()
    ctx.set_ref("alight")
    _wait_for_thumbnails(ctx)
    presets = {name: m for name, m, *_ in win.panel.presets}
    def centre(name):
        file = thumbnail_dir() / f"{win.thumbnails.key(presets[name], TextureMaps())}.png"
        assert file.is_file(), file
        px = oiio.ImageBuf(str(file)).get_pixels(oiio.UINT8).astype(np.float64)
        return px[24:40, 24:40, :3].mean(axis=(0, 1))
    copper, silver = centre("copper"), centre("silver")
    assert copper[0] / copper[2] > 1.15 * silver[0] / silver[2], (copper, silver)
    ctx.item_make_visible("**/copper", 0)   # earlier checks leave the panel scrolled down
    ctx.item_make_visible("**/silver", 0)
    shot = capture(ctx, "thumbnails.png")
    on_screen = {name: _icon_pixels(ctx, shot, f"**/{name}").mean(axis=(0, 1)) for name in ("copper", "silver")}
    c, g = on_screen["copper"], on_screen["silver"]
    assert c[0] / max(c[2], 1) > 1.15 * g[0] / max(g[2], 1), on_screen
    assert np.ptp(_icon_pixels(ctx, shot, "**/copper").mean(axis=2)) > 20, "a flat swatch, not a rendered ball"


def test_library_save_thumbnail_and_click_applies_undoably(ctx):
    """'save to library' writes NAME.glb into the library folder; the entry appears with its
    thumbnail; clicking it after another preset applies it (the same view), Ctrl+Z goes back."""
    from alight.exchange.material_files import load_material_file
    from alight.frontends.editor.library import library_dir

    s, win = editor().state, editor()
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    ctx.item_input_value("**/roughness", 0.3)
    ctx.item_input_value("**/metallic", 0.5)
    saved = s.material
    shown = ball(view(ctx)).mean(axis=0)
    ctx.item_input_value("**/library name", "ui copper")
    ctx.item_click("**/save to library")
    path = library_dir() / "ui_copper.glb"
    assert path.is_file(), (s.error, s.message)
    assert str(path) in s.message, s.message
    assert _same_material(load_material_file(str(path))[0], saved)
    ctx.yield_(2)
    names = [e.name for e in win.panel.library.entries]
    assert "ui_copper" in names, names
    ctx.item_click("**/silver")
    assert s.material.name == "silver"
    ctx.item_click("**/ui_copper##library")
    assert _same_material(s.material, saved), s.material
    np.testing.assert_allclose(ball(view(ctx)).mean(axis=0), shown, atol=0.5)
    _wait_for_thumbnails(ctx)
    ctx.item_make_visible("**/ui_copper##library", 0)
    icon = _icon_pixels(ctx, capture(ctx, "library.png"), "**/ui_copper##library").mean(axis=(0, 1))
    assert icon[0] > icon[2] + 10, icon   # copper's ball, not the grey placeholder
    void(ctx)
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    assert s.material.name == "silver", s.material


# --- a transparent background over a checkerboard --------------------------------------------------

def test_transparent_background_shows_a_checkerboard(ctx):
    """With the transparent background the window shows the view over light and dark grey
    squares (8 px) where nothing covers it, the ball opaque over them; the env background none."""
    win = editor()
    ctx.set_ref("alight")
    ctx.item_click("**/gold")
    void(ctx)
    w, h = win.view_area()
    middle = (slice(h // 2 - 4, h // 2 + 4), slice(w // 2 - 4, w // 2 + 4))
    over_env = capture(ctx, "over_env.png")[middle][:, :, :3].mean(axis=(0, 1))
    ctx.item_open("**/Environment")
    ctx.combo_click("background/transparent")
    ctx.item_close("**/Environment")
    void(ctx)
    shot = capture(ctx, "checker.png")[:, :, :3]
    light, dark = checker_levels(shot[:32, :32])
    assert light > 0.3 and dark > 0.3, (light, dark, shot[:2, :10, 0])
    row = shot[2, :32, 0].astype(np.int32)
    assert abs(row[:8].mean() - row[8:16].mean()) > 40, row   # the squares alternate every 8 px
    np.testing.assert_allclose(shot[middle].mean(axis=(0, 1)), over_env, atol=2)   # the ball: opaque over it
    ctx.item_open("**/Environment")
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")
    light, dark = checker_levels(capture(ctx, "no_checker.png")[:32, :32, :3])
    assert light + dark < 0.5, (light, dark)


# --- screenshots at a chosen size ------------------------------------------------------------------

def _shoot(ctx, frames: int = 3000) -> str:
    """Click the screenshot button; the new PNG once the window has written it."""
    names = set(os.listdir("."))
    ctx.item_click("**/screenshot (F12)")
    for _ in range(frames):
        ctx.yield_()
        new = [n for n in set(os.listdir(".")) - names if n.startswith("alight-screenshot-") and n.endswith(".png")]
        if new and editor().screenshot_job is None:
            return new[0]
    raise AssertionError(f"no screenshot written: {editor().state.error}")


def test_screenshot_at_a_chosen_size(ctx):
    """Unchecking 'at the view's size' and typing a size: the button writes a PNG that size (the
    view's framing, the copper ball in the middle), and the panel's message names the file;
    with the transparent background it is RGBA, clear around the ball. Sides clamp to 16384."""
    import OpenImageIO as oiio

    win, s = editor(), editor().state
    ctx.set_ref("alight")
    ctx.item_click("**/copper")
    h = view(ctx).shape[0]   # the view at window size: the same vertical field of view, centred
    middle = view(ctx)[h // 2 - 3:h // 2 + 3, view(ctx).shape[1] // 2 - 3:view(ctx).shape[1] // 2 + 3]
    ctx.item_open("**/Display & camera")
    ctx.item_uncheck("**/###shot_view_size")
    ctx.item_input_value("screenshot size/$$0", 1000)
    ctx.item_input_value("screenshot size/$$1", 300)
    name = _shoot(ctx)
    image = oiio.ImageBuf(name).get_pixels(oiio.UINT8)
    assert image.shape == (300, 1000, 3), image.shape
    assert s.message == f"wrote {os.path.basename(name)} (1000x300) in {os.path.dirname(os.path.abspath(name))}", \
        s.message   # (the name first: the row is cut at the panel's edge)
    centre = image[148:152, 498:502].astype(np.float64).mean(axis=(0, 1))
    np.testing.assert_allclose(centre, middle.reshape(-1, 3).mean(axis=0), atol=16)   # the view's centre
    ctx.item_close("**/Display & camera")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/transparent")
    ctx.item_close("**/Environment")
    ctx.item_open("**/Display & camera")
    image = oiio.ImageBuf(_shoot(ctx)).get_pixels(oiio.UINT8)
    assert image.shape == (300, 1000, 4) and image[150, 500, 3] == 255 and image[:4, :4, 3].max() == 0, image.shape
    ctx.item_input_value("screenshot size/$$0", 20000)
    assert win.screenshot_size.width == 16384, win.screenshot_size
    ctx.item_check("**/###shot_view_size")
    assert win.screenshot_size.size(win.view_area()) == win.view_area()
    ctx.item_close("**/Display & camera")
    ctx.item_open("**/Environment")
    ctx.combo_click("background/env")
    ctx.item_close("**/Environment")


def test_typed_values_are_kept_without_float_noise(ctx):
    """A value typed into a float widget is kept as typed (0.6, not float32's 0.6000000238...),
    in the state and in the preset file saved."""
    import re

    s = editor().state
    path = _save_preset_through_panel(ctx, "gold", 0.6, "tidy.json")
    assert s.material.roughness == 0.6, repr(s.material.roughness)
    text = open(path, encoding="utf-8").read()
    assert re.search(r'"roughness": 0\.6\b', text) and "0.6000000" not in text, text


def test_an_error_line_does_not_move_the_panel(ctx):
    """The status row at the panel's top keeps its height: a long error replacing a message
    leaves every control where it was (the next click lands where the artist aimed)."""
    s = editor().state
    _save_preset_through_panel(ctx, "gold", 0.5, "before_error.json")
    assert s.message and not s.error, (s.message, s.error)
    ctx.item_input_value("**/preset file", os.path.join(OUT, "no_such_preset_" * 8 + ".json"))
    ctx.yield_(2)
    before = ctx.item_info("**/load preset").rect_full.min.y
    ctx.item_click("**/load preset")
    ctx.yield_(2)
    assert s.error and editor().panel.shown_error == s.error, s.error
    after = ctx.item_info("**/load preset").rect_full.min.y
    assert after == before, (before, after, s.error)


def test_ctrl_a_selects_a_text_field(ctx):
    """Ctrl+A in a text field selects all of it: what is typed next replaces the text."""
    from imgui_bundle import imgui

    ctx.set_ref("alight")
    ctx.item_input_value("**/preset file", "some_long_name.json")
    ctx.item_click("**/preset file")
    ctx.key_press(imgui.Key.mod_ctrl | imgui.Key.a)
    ctx.key_chars("material.json")
    ctx.key_press(imgui.Key.enter)
    ctx.yield_(2)
    assert editor().panel.preset_path == "material.json", editor().panel.preset_path
