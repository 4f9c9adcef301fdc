"""The editor's A/B compare: one view split by a vertical divider, A on its left, B (the live
state) on its right, one camera, environment and lights for both.

What A is (``CompareState.mode``):

- ``material``: a snapshot of the material (the panel's ``snapshot A``) or a preset chosen for A;
  B is the material being edited.
- ``ibl model``: the live material under two IBL models (app/core/ibl_models.py); A's model is
  ``a_ibl_model``, B's the editor's own ``EditorState.ibl_model``.
- ``reference``: A is ``alight reference``'s exact sum (app/accuracy/reference.py) at the view's
  pixels, for the sphere (the reference has no shadows: other meshes would be wrong there).

This module is the plain part (no GL): the state, the scene each half draws, the divider's
mouse gesture, the session's dict and the panel's section (imgui imported inside). The GL part,
drawing A and putting the halves together, is compare_view.py.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from alight.core.ibl_models import IBL_MODELS
from alight.core.material import Material
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.frontends.editor.widgets import note, tooltip

MODES = ("off", "material", "ibl model", "reference")
# A left-button press this close to the divider (window pixels) drags it instead of orbiting.
GRAB_PX = 8.0
# The meshes the exact reference is drawn for: convex, so a sum without shadows is exact.
REFERENCE_MESHES = ("sphere",)


@dataclass
class CompareState:
    mode: str = "off"                 # one of MODES
    divider: float = 0.5              # where the halves meet, as a fraction of the view's width
    a_material: Material | None = None   # mode 'material': A's material (None: not chosen yet)
    a_label: str = ""                 # what A's material is ("snapshot of gold", "preset copper")
    # A's maps: a snapshot keeps the maps it was taken with (their decoded images too, so B's
    # later maps never reach A); a preset has none.
    a_texture_maps: TextureMaps = field(default_factory=TextureMaps)
    a_texture_images: dict = field(default_factory=dict)   # path -> decoded image (not saved)
    a_ibl_model: str = "lecture"      # mode 'ibl model': A's model
    reference_scale: float = 0.25     # mode 'reference': the sum's pixels per view pixel, each way
    dragging: bool = False            # the divider is held by the mouse now (not saved)

    @property
    def active(self) -> bool:
        """Whether the view is split now (material mode needs A chosen)."""
        return self.mode != "off" and not (self.mode == "material" and self.a_material is None)


def a_scene(compare: CompareState, scene):
    """The Scene half A draws: ``scene`` (B's) with A's material or A's IBL model. (The reference
    half is not a forward render; compare_view.py draws it.)"""
    if compare.mode == "material" and compare.a_material is not None:
        # A is a material, shown on every part even where B shows a mesh file's own materials.
        return dataclasses.replace(scene, material=compare.a_material, texture_maps=compare.a_texture_maps,
                                   texture_images=compare.a_texture_images, use_file_materials=False)
    if compare.mode == "ibl model":
        return dataclasses.replace(scene, ibl_model=compare.a_ibl_model)
    return scene


def reference_problem(state) -> str:
    """Why the reference half cannot be drawn for this state ('' when it can): one line."""
    if state.mesh_spec not in REFERENCE_MESHES:
        return (f"reference compare: the exact reference is for the sphere (the preview mesh is "
                f"'{state.mesh_spec}'; 'alight reference' traces paths for meshes that shadow themselves)")
    if state.use_file_materials:
        return "reference compare: uses the panel's material (untick the mesh file's own materials)"
    from alight.accuracy.reference import check_layer_lobes, check_layer_roughness, check_roughness

    m = state.material
    try:   # the reference's own limits, said with the panel's names (the CLI's name its flags)
        check_roughness(m.roughness, name=control_name)
        check_layer_roughness(m, name=control_name)
        check_layer_lobes(m, [m.roughness], name=control_name)
    except AlightError as exc:
        return f"reference compare: {exc}"
    return ""


def control_name(field: str) -> str:
    """The panel's control for a material field, as an error names it ('--roughness' is the
    CLI's): "'roughness' (Material)", "'clearcoat roughness' (Material, Clearcoat)"."""
    from alight.frontends.editor.layer_rows import SECTIONS

    for section in SECTIONS:
        for row in section.rows:
            if row.field == field:
                return f"'{row.label}' (Material, {section.title})"
    return f"'{field.replace('_', ' ')}' (Material)"


def divider_from_mouse(mouse_x: float, view_width: float) -> float:
    """The divider's fraction for a mouse x in the view (window pixels), kept inside the view."""
    return min(1.0, max(0.0, mouse_x / max(view_width, 1.0)))


def near_divider(compare: CompareState, mouse_x: float, mouse_y: float, view_width: float,
                 view_height: float) -> bool:
    """Whether a press at (mouse_x, mouse_y) (window pixels) grabs the divider."""
    return (0.0 <= mouse_y < view_height and 0.0 <= mouse_x < view_width
            and abs(mouse_x - compare.divider * view_width) <= GRAB_PX)


def handle_mouse(win) -> bool:
    """The divider's gesture, before the camera's: a left press within GRAB_PX of the line grabs
    it, the drag moves it, the release lets go. Returns True while the divider has the mouse (the
    camera then ignores the left drag)."""
    imgui, c = win.imgui, win.state.compare
    if not c.active:
        c.dragging = False
        return False
    io = imgui.get_io()
    view_w = max(1.0, float(win._sizes()[1][0] - win.panel_width()))
    view_h = float(win._sizes()[1][1])
    x, y = io.mouse_pos.x, io.mouse_pos.y
    if imgui.is_mouse_clicked(imgui.MouseButton_.left) and not io.want_capture_mouse \
            and near_divider(c, x, y, view_w, view_h):
        c.dragging = True
    if c.dragging:
        if imgui.is_mouse_down(imgui.MouseButton_.left):
            if math.isfinite(x):
                c.divider = divider_from_mouse(x, view_w)
            return True
        c.dragging = False
    return False


def draw_overlay(win) -> None:
    """The divider's line and the halves' names over the view (imgui's background draw list: in
    the window only, never in the view's pixels or a screenshot)."""
    imgui, c = win.imgui, win.state.compare
    if not c.active:
        return
    view_w = float(win._sizes()[1][0] - win.panel_width())
    view_h = float(win._sizes()[1][1])
    x = c.divider * view_w
    draw = imgui.get_background_draw_list()
    colour = imgui.get_color_u32(imgui.ImVec4(1.0, 1.0, 1.0, 0.9 if c.dragging else 0.6))
    draw.add_line(imgui.ImVec2(x, 0.0), imgui.ImVec2(x, view_h), colour, 2.0)
    a, b = half_names(win.state)
    if c.mode == "reference":   # say what A's half shows while the sum is not there (B's pixels)
        progress = win.compare_view.reference_progress
        if progress is not None:
            a += f" (summing, {progress:.0%})"
        elif not win.compare_view.a_ready:
            a += " (not drawn: see the panel)" if win.state.error else " (when the view stands still)"
    a_left = x - 8.0 - imgui.calc_text_size(a).x
    # A's name where it fits left of the divider, else a row lower (never over B's)
    a_top = 4.0 if a_left >= 4.0 else 4.0 + imgui.get_text_line_height() + 2 * LABEL_PAD + 2.0
    label(draw, imgui, a, max(4.0, a_left), a_top)
    label(draw, imgui, b, min(view_w - 4.0 - imgui.calc_text_size(b).x, x + 8.0), 4.0)


# The halves' names on a solid box: readable over any picture (a checkerboard, a white ball).
LABEL_PAD = 3.0
LABEL_BOX = (0.08, 0.08, 0.08, 0.85)
LABEL_TEXT = (1.0, 1.0, 1.0, 1.0)


def label(draw, imgui, text: str, x: float, y: float) -> None:
    """``text`` at (x, y) (window pixels) over a dark box LABEL_PAD wider each side."""
    size = imgui.calc_text_size(text)
    draw.add_rect_filled(imgui.ImVec2(x - LABEL_PAD, y - LABEL_PAD),
                         imgui.ImVec2(x + size.x + LABEL_PAD, y + size.y + LABEL_PAD),
                         imgui.get_color_u32(imgui.ImVec4(*LABEL_BOX)), 3.0)
    draw.add_text(imgui.ImVec2(x, y), imgui.get_color_u32(imgui.ImVec4(*LABEL_TEXT)), text)


def half_names(state) -> tuple[str, str]:
    """The two halves' names as the view and the panel show them."""
    c = state.compare
    if c.mode == "material":
        return f"A: {c.a_label or 'not chosen'}", "B: live"
    if c.mode == "ibl model":
        return f"A: {c.a_ibl_model}", f"B: {state.ibl_model}"
    if c.mode == "reference":
        return "A: alight reference", "B: live"
    return "", ""


def take_snapshot(c: CompareState, state) -> None:
    """A becomes the material being edited as it is now, with its maps (EditorState)."""
    c.a_material, c.a_label = state.material, f"snapshot of {state.material.name}"
    c.a_texture_maps, c.a_texture_images = state.texture_maps, dict(state.map_images)


def set_preset(c: CompareState, material: Material, name: str) -> None:
    """A becomes a preset: its factors, no maps (as a preset click does to B)."""
    c.a_material, c.a_label = material, f"preset {name}"
    c.a_texture_maps, c.a_texture_images = TextureMaps(), {}


# --- the panel's section ----------------------------------------------------------------------

def draw_section(win, presets) -> None:
    """The Compare section's controls (inside the panel's collapsing header). ``presets``: the
    F0 table's (name, material, ...) rows, any of which can be A."""
    from imgui_bundle import imgui

    s, c = win.state, win.state.compare
    changed, i = imgui.combo("compare", MODES.index(c.mode), MODES)
    if changed:
        c.mode = MODES[i]
    if c.mode == "material":
        if imgui.button("snapshot A"):
            take_snapshot(c, s)
        if imgui.is_item_hovered():
            tooltip("A keeps the material as it is now; edit on, B follows the panel")
        names = [name for name, *_ in presets]
        current = next((k for k, (_, m, *_) in enumerate(presets) if m == c.a_material), -1)
        imgui.same_line()
        imgui.set_next_item_width(-80)
        # The preview says what A is (imgui.combo's, from the list's index, was empty whenever A
        # was no preset of the list: before any pick, a snapshot, a restored A).
        preview = names[current] if current >= 0 else (c.a_label if c.a_material is not None else "pick a preset")
        win.panel.shown_a_preview = preview   # (the checks read it)
        if imgui.begin_combo("A preset", preview):
            for k, name in enumerate(names):
                if imgui.selectable(name, k == current)[0]:
                    set_preset(c, presets[k][1], presets[k][0])
            imgui.end_combo()
        if c.a_material is None:
            note("A: press 'snapshot A' or pick a preset")
    elif c.mode == "ibl model":
        models = tuple(IBL_MODELS)
        changed, k = imgui.combo("A IBL model", models.index(c.a_ibl_model), models)
        if changed:
            c.a_ibl_model = models[k]
        changed, k = imgui.combo("B IBL model", models.index(s.ibl_model), models)
        if changed:
            s.ibl_model = models[k]
    elif c.mode == "reference":
        problem = reference_problem(s)
        if problem:
            imgui.text_wrapped(problem)
        changed, v = imgui.slider_float("reference scale", c.reference_scale, 0.05, 1.0)
        if imgui.is_item_hovered():
            tooltip("the reference's resolution relative to the view's (each summed pixel "
                              "a block): the exact sum costs per pixel, 46 s for 4400 on the sphere on llvmpipe")
        if changed:
            c.reference_scale = v
        view = win.compare_view
        if view.reference_progress is not None:
            imgui.progress_bar(view.reference_progress, imgui.ImVec2(-1, 0), "summing the reference")
        note("A: the exact sum, started when the view stands still"
                            + (f" (last: {view.reference_seconds:.1f} s)" if view.reference_seconds else ""))
    if c.mode != "off":
        changed, v = imgui.slider_float("divider", c.divider, 0.0, 1.0)
        if changed:
            c.divider = v
        a, b = half_names(s)
        note(f"{a} (left)   {b} (right)")
        note("move the divider: left drag on its line in the view")


# --- the session ------------------------------------------------------------------------------

def to_dict(c: CompareState) -> dict:
    return {"mode": c.mode, "divider": c.divider, "a_label": c.a_label, "a_ibl_model": c.a_ibl_model,
            "reference_scale": c.reference_scale,
            "a_material": None if c.a_material is None else c.a_material.to_dict(),
            "a_texture_maps": c.a_texture_maps.to_dict()}


def from_dict(data, source: str) -> CompareState:
    """A CompareState from a session's "compare". Errors: AlightError, one line naming the field."""
    from alight.core.material import material_from_dict

    if not isinstance(data, dict):
        raise AlightError(f"{source}: compare: expected an object")
    mode, divider, model = data.get("mode"), data.get("divider"), data.get("a_ibl_model", "lecture")
    if mode not in MODES:
        raise AlightError(f"{source}: compare: mode '{mode}' is not one of {', '.join(MODES)}")
    if isinstance(divider, bool) or not isinstance(divider, (int, float)) or not math.isfinite(divider):
        raise AlightError(f"{source}: compare: divider is not a finite number")
    if model not in IBL_MODELS:
        raise AlightError(f"{source}: compare: a_ibl_model '{model}' is not one of {', '.join(IBL_MODELS)}")
    material = data.get("a_material")
    scale = data.get("reference_scale", 0.25)
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not 0.0 < scale <= 1.0:
        raise AlightError(f"{source}: compare: reference_scale is not a number in (0, 1]")
    maps = TextureMaps.from_dict(data.get("a_texture_maps") or {}, f"{source}: compare: a_texture_maps")
    return CompareState(mode=mode, divider=min(1.0, max(0.0, float(divider))), a_ibl_model=model,
                        reference_scale=float(scale),
                        a_material=None if material is None else material_from_dict(material, f"{source}: compare"),
                        a_label=str(data.get("a_label", "")), a_texture_maps=maps,
                        a_texture_images=_map_images(maps, source))


def _map_images(maps: TextureMaps, source: str) -> dict:
    """A restored snapshot's images, decoded again; a file gone since is one warning and A
    goes without that map."""
    from alight.errors import warn
    from alight.exchange.texture_sets import load_slot_image

    images = {}
    for slot, path in maps.paths().items():
        try:
            images[path] = load_slot_image(maps, slot)
        except AlightError as exc:
            warn(f"{source}: compare: A's {slot} map: {exc}; A is drawn without it")
    return images


def apply_edit(c: CompareState, state, key: str, value: str) -> None:
    """``--script``: compare=MODE, compare_divider=F, compare_a=snapshot|PRESET, compare_a_ibl_model=NAME."""
    from alight.exchange.presets import load_preset

    if key == "compare":
        if value not in MODES:
            raise AlightError(f"--script: compare '{value}' is not one of {', '.join(MODES)}")
        c.mode = value
    elif key == "compare_divider":
        x = float(value)
        if not math.isfinite(x):
            raise AlightError(f"--script: compare_divider '{value}' is not finite")
        c.divider = min(1.0, max(0.0, x))
    elif key == "compare_a":
        if value == "snapshot":
            take_snapshot(c, state)
        else:
            set_preset(c, load_preset(value), value)
    elif key == "compare_reference_scale":
        x = float(value)
        if not 0.0 < x <= 1.0:
            raise AlightError(f"--script: compare_reference_scale '{value}' is not in (0, 1]")
        c.reference_scale = x
    elif key == "compare_a_ibl_model":
        if value not in IBL_MODELS:
            raise AlightError(f"--script: compare_a_ibl_model '{value}' is not one of {', '.join(IBL_MODELS)}")
        c.a_ibl_model = value
    else:
        raise AlightError(f"--script: unknown field '{key}'")
