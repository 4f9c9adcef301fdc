"""The imgui panel. It edits the plain EditorState (and asks the window for a few actions such
as 'frame the mesh'); it never touches a GL object, and the ForwardRenderer never sees imgui."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np

from alight.accuracy.auto_quality import DEFAULT_ERROR_BUDGET
from alight.core.ibl_models import IBL_MODELS
from alight.core.visibility import OCCLUSION_MODES
from alight.core.mesh import BUILTIN_MESHES
from alight.core.material import validate_material, with_overrides
from alight.core.scene import BACKGROUNDS, TONEMAPS
from alight.core.shading import linear_to_srgb, srgb_to_linear
from alight.core.texture_maps import MAP_SLOTS, SLOT_LABELS
from alight.errors import AlightError
from alight.exchange.images import IMAGE_SUFFIXES
from alight.exchange.meshes import MESH_EXTENSIONS, is_builtin
from alight.exchange.presets import list_presets, load_preset
from alight.frontends.editor.file_browser import FileBrowser
from alight.frontends.editor.layer_rows import FINITE_START, SECTIONS, LayerRow
from alight.frontends.editor.library_panel import ICON, LibraryPanel
from alight.frontends.editor.press_guard import PanelLayout
from alight.frontends.editor.state import DEBUG_VIEWS
from alight.frontends.editor.widgets import note, text_field, tooltip
from alight.ibl.bake import QUALITY
from alight.render.shadows import SHADOW_MODES

AA_CHOICES = ("none", "msaa")
# The status row's colours: an error, a success (a message); bright on the dark theme, told apart.
ERROR_RGBA = (1.0, 0.35, 0.3, 1.0)
MESSAGE_RGBA = (0.45, 0.85, 0.45, 1.0)
# A slider's handle: imgui's is 12 px of opaque blue under the value's centred digits, which it
# hid (0.5 put it over the 5). A thin, half-transparent one leaves the digits readable.
SLIDER_GRAB_PX, SLIDER_GRAB_ALPHA = 4.0, 0.45
LONGEST_LIGHT_LABEL = "direction (light travels)"
# The panel's longest labels beside a widget outside the lights and layer sections (which size
# their own): at a 700 px window (a 350 px panel) imgui's 65% widgets left them ~90 px and
# 'turntable frames' read 'turntable fram' (a trial); the widgets narrow to leave them room.
LONG_LABELS = ("base colour (sRGB)", "scale while moving", "screenshot size", "turntable frames")
_DRAG_MAX = 1e9   # imgui's bound for a drag whose range is open above (an inf bound is not safe in imgui)


def _srgb(c) -> list[float]:
    return [float(x) for x in np.clip(linear_to_srgb(np.asarray(c, np.float64)), 0.0, 1.0)]


def _edited(m, **fields):
    """An edit of specular F0 or ior with the rule applied (alight.core.material.with_overrides);
    a value out of range keeps the material as it was (the caller validates and reports)."""
    try:
        return with_overrides(m, "", **fields)   # (no prefix: _fail)
    except AlightError:
        return dataclasses.replace(m, **fields)


def _f0_edited(m, f0):
    """Specular F0 typed or dragged (a channel or all): the ior follows by the rule
    (alight.core.material: the F0's luminance), a coloured F0 kept as typed, its tint the
    specular colour (KHR_materials_specular's specularColorFactor, F0 / F0(ior))."""
    from alight.core.material import ior_from_f0, luminance

    f0 = tuple(min(max(float(x), 0.0), 1.0) for x in f0)
    return _edited(m, specular_f0=f0, ior=max(ior_from_f0(luminance(f0)), 1.0))


def _ior_edited(m, ior):
    """The ior typed or dragged: the specular F0 of the rule, its tint kept (``_f0_edited``'s
    inverse)."""
    from alight.core.material import specular_f0_for_ior

    ior = max(float(ior), 1.0)
    return _edited(m, ior=ior, specular_f0=specular_f0_for_ior(ior, m.specular_f0))


def _short_float(x):
    """A widget's float32 as the shortest decimal that reads back as it (0.6, not 0.6000000238)."""
    return float(str(np.float32(x))) if np.isfinite(x) else x


def tidy_edit(old, new):
    """``new`` with each field that differs from ``old`` rounded as ``_short_float`` (imgui's
    widgets are float32: typed 0.6 comes back 0.6000000238418579, and presets and sessions
    saved it so); fields not edited keep their exact values."""
    changes = {}
    for f in dataclasses.fields(new):
        a, b = getattr(old, f.name), getattr(new, f.name)
        if a == b or isinstance(b, (str, bool)):
            continue
        if isinstance(b, float):
            changes[f.name] = _short_float(b)
        elif isinstance(b, tuple) and all(isinstance(x, float) for x in b):
            changes[f.name] = tuple(_short_float(x) for x in b)
    return dataclasses.replace(new, **changes) if changes else new


def _linear(c) -> tuple[float, float, float]:
    return tuple(float(x) for x in np.clip(srgb_to_linear(np.asarray(c, np.float64)), 0.0, 1.0))


def layer_row(row: LayerRow, m):
    """Draw one layer field's widget (layer_rows.py says which) with the field's help as its
    tooltip; returns ``m`` with the edit, clamped to the field's range."""
    from imgui_bundle import imgui

    value = getattr(m, row.field)
    if row.widget == "color":
        changed, col = imgui.color_edit3(row.label, _srgb(value))
        new = _linear(col)
    elif row.widget == "angle":
        changed, new = imgui.slider_angle(row.label, value, -180.0, 180.0)
    elif row.widget == "slider":
        # (Typed values clamped to the field's range, as metallic's and roughness's sliders.)
        changed, new = imgui.slider_float(row.label, value, row.low, row.high, row.fmt,
                                          imgui.SliderFlags_.always_clamp)
    else:
        if row.switch:   # the field's infinite default is 'off': a checkbox, then the drag when on
            changed, on = imgui.checkbox(row.switch, value != float("inf"))
            if imgui.is_item_hovered():
                tooltip(row.help)
            if changed:
                return dataclasses.replace(m, **{row.field: FINITE_START if on else float("inf")})
            if not on:
                return m
        # imgui clamps a drag to a finite range only; an open end is clamped here.
        changed, new = imgui.drag_float(row.label, value, row.speed, row.low,
                                        row.high if np.isfinite(row.high) else _DRAG_MAX, row.fmt)
        new = min(max(new, row.low), row.high)
    if imgui.is_item_hovered():
        tooltip(row.help)
    return dataclasses.replace(m, **{row.field: new}) if changed else m


def close_popup_on_escape() -> None:
    """Escape closes the open popup (the colour picker, a combo's list). imgui does so only with
    keyboard navigation on (io.ConfigFlags NavEnableKeyboard), which the editor's own loop leaves
    off: with it, imgui keeps the keyboard after any click in the panel, and F, F12 and Ctrl+Z
    would reach the view only after a click on it. A modal (a file dialog) stays."""
    from imgui_bundle import imgui

    every = imgui.PopupFlags_.any_popup_id | imgui.PopupFlags_.any_popup_level
    if imgui.is_key_pressed(imgui.Key.escape, False) and imgui.is_popup_open("", every):
        imgui.internal.close_popups_except_modals()


# The variant list's first entry: no variant, each part's own material.
VARIANT_OWN = "(each part's own)"
# The path fields kept across sessions (the others follow what is loaded: mesh, env, maps).
KEPT_PATH_FIELDS = ("preset_path", "gltf_path")
# Their defaults: names in the working folder of the moment, kept so in the session (an editor
# started from another folder writes there, not into the first launch's folder).
DEFAULT_PATHS = {"preset_path": "material.json", "gltf_path": "material.gltf"}


def preset_file_name(name: str) -> str:
    """A material's name as a preset file in the working folder: 'gold' -> gold.json; the
    characters a file name cannot safely hold as '_'; the default material's material.json."""
    stem = "".join(c if c.isalnum() or c in "._- " else "_" for c in name.strip()).strip(". ")
    return f"{stem if stem and name != 'default' else 'material'}.json"


def fit_text(text: str, width: float) -> str:
    """``text`` as it fits in ``width`` pixels of the current font: whole, or its start and its
    end with "..." between them (a long path's middle goes: the error's problem at the end of
    the row, 'no such file', stays in view)."""
    from imgui_bundle import imgui

    if imgui.calc_text_size(text).x <= width:
        return text

    def longest(make, n: int, room: float) -> int:   # the largest k <= n with make(k) in room (0 if none)
        lo, hi = 0, n
        while lo < hi:
            mid = (lo + hi + 1) // 2
            lo, hi = (mid, hi) if imgui.calc_text_size(make(mid)).x <= room else (lo, mid - 1)
        return lo

    # The end takes up to half the room, the start what is left.
    tail = longest(lambda k: text[len(text) - k:], len(text), width / 2.0)
    end = text[len(text) - tail:] if tail else ""
    head = longest(lambda k: text[:k] + "..." + end, len(text) - tail, width)
    return text[:head] + "..." + end


def read_for_upload(spec: str):
    """On the file-jobs thread: the mesh (EditorState's read_mesh) and the CPU side of its GPU
    upload (alight.render.mesh_upload.prepare_upload)."""
    from alight.frontends.editor.state import read_mesh
    from alight.render.mesh_upload import prepare_upload

    mesh = read_mesh(spec)
    return mesh, prepare_upload(mesh)


class Panel:
    def __init__(self):
        # The F0 table, read once: (name, material, linear F0, sRGB F0).
        self.presets = []
        for name in list_presets():
            try:
                m = load_preset(name)
            except AlightError:
                continue   # a broken extra file in presets/ must not stop the editor
            f0 = m.f0()
            self.presets.append((name, m, f0, _srgb(f0)))
        self.env_path = ""
        self.mesh_path = ""
        self.preset_path = DEFAULT_PATHS["preset_path"]
        self.gltf_path = DEFAULT_PATHS["gltf_path"]
        self.map_path = ""
        self.set_path = ""      # the 'texture set' field: a folder, or image files separated by ';'
        self._specs_shown = (None, None)   # the mesh and environment the path fields were last set from
        self._set_shown = ""    # the texture set the 'texture set' field was last set from
        self.shown_error = ""   # the error line drawn last frame (what the artist sees; tests read it)
        self.shown_status = ""  # the status row's text drawn last frame (tests read it)
        self.shown_row = ""     # ... as drawn: a long one's middle as "..." to fit the row (tests read it)
        self.status_tooltip = ""   # the status row's tooltip shown last (the whole row; tests read it)
        self.shown_f0 = ""      # the F0 line drawn last frame (tests read it)
        self.preset_columns, self.preset_overflow = 3, 0.0   # the preset table drawn last frame (tests read it)
        self.shown_job_status = ""   # the status row's last "opening .../exporting ..." (tests read it)
        self.sections_open = {}         # each section header's open state, drawn last (the session keeps it)
        self._sections_restored = {}    # the last session's, applied as the headers are next drawn
        self.browser = FileBrowser()   # native dialog, or the built-in browser where none exists
        self._sections_for = None      # the loaded material the layer sections were opened for
        self.library = LibraryPanel()  # saved materials with thumbnails (library_panel.py)
        self.layout = None   # the scroll, each section header's height, the content's end (draw)
        self._removed = []   # (index, light, height): removed lights' places, kept while the pointer is there
        self._place_tops = {}   # each place's top on screen in the frame drawn last (its index in _removed)
        self._pointer_kept = (0.0, 0.0)   # where the pointer was when last inside the list with places kept
        self._steps_seen = 0   # EditorState.history_steps when the lights were drawn last
        # Each path field's last path that worked (_attempt): a failed one is not left showing.
        self._good = {"preset_path": self.preset_path, "gltf_path": self.gltf_path}
        # The 'preset file' field follows the material's name (gold.json) until the artist types
        # in it: left at material.json, 'save preset' renamed the aluminium it saved to
        # 'material' and asked to replace the library's 'material' (a new user's trial).
        self._auto_preset_path = self.preset_path
        from alight.frontends.editor.file_jobs import FileJobs

        self.file_jobs = FileJobs()   # 'open mesh' and 'export glTF' on a worker thread (file_jobs.py)

    def draw(self, win) -> None:
        from imgui_bundle import imgui

        s = win.state
        # A side bar on the right, the full height: the view beside it stays uncovered.
        display = imgui.get_io().display_size
        width = win.panel_width()
        imgui.set_next_window_pos(imgui.ImVec2(display.x - width, 0), imgui.Cond_.always)
        imgui.set_next_window_size(imgui.ImVec2(width, display.y), imgui.Cond_.always)
        imgui.push_style_var(imgui.StyleVar_.grab_min_size, SLIDER_GRAB_PX)
        for col in (imgui.Col_.slider_grab, imgui.Col_.slider_grab_active):
            c = imgui.get_style_color_vec4(col)
            imgui.push_style_color(col, imgui.ImVec4(c.x, c.y, c.z, SLIDER_GRAB_ALPHA))
        # Opaque popups: a combo's open list showed the rows under it through its 0.94 alpha.
        c = imgui.get_style_color_vec4(imgui.Col_.popup_bg)
        imgui.push_style_color(imgui.Col_.popup_bg, imgui.ImVec4(c.x, c.y, c.z, 1.0))
        # The status row is the window's menu bar: it stays in view whatever the panel's scroll.
        imgui.begin("alight", None, imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
                    | imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.menu_bar)
        self.shown_error = s.error   # (file jobs: taken by EditorWindow.build_frame before, with or without the panel)
        self.shown_status = self._status_line(s, win)
        imgui.push_item_width(self.item_width())
        self._follow_loaded(s)
        self._follow_maps(s)
        headers = []   # each section header's height: the layout's signature (press_guard.py)

        collapsed = []   # a header closed by a click this frame (the slack below keeps the scroll)

        def header(label, flags=0):
            if label in self._sections_restored:   # as the last session left it (session.py)
                imgui.set_next_item_open(self._sections_restored.pop(label), imgui.Cond_.always)
            opened = imgui.collapsing_header(label, flags)
            self.sections_open[label] = bool(opened)
            headers.append(round(imgui.get_item_rect_min().y))
            if imgui.is_item_toggled_open() and not opened:
                collapsed.append(label)
            return opened

        if header("Material", imgui.TreeNodeFlags_.default_open):
            self._material(s, win)
        if header("Environment"):
            self._environment(s, win)
        if header("Lights"):
            self._lights(s)
        else:
            self._removed = []   # a closed section keeps no removed lights' places
        if header("Display & camera"):
            self._display(s, win)
        if header("Compare"):   # the A/B split view (app/frontends/editor/compare.py)
            from alight.frontends.editor.compare import draw_section

            draw_section(win, self.presets)
        if header("Performance", imgui.TreeNodeFlags_.default_open):
            self._performance(win)
        if header("Accuracy chart"):   # the latest 'alight chart' (app/frontends/editor/chart_view.py)
            from alight.frontends.editor.chart_view import ChartView

            self.chart_view = getattr(self, "chart_view", None) or ChartView()
            self.chart_view.draw()
        imgui.pop_item_width()
        self._keep_scroll(imgui, bool(collapsed))
        # Where the controls are this frame: a press aimed at another layout is not delivered.
        self.layout = PanelLayout(round(imgui.get_scroll_y()), tuple(headers), round(imgui.get_cursor_pos_y()))
        imgui.end()
        imgui.pop_style_color(3)
        imgui.pop_style_var()
        self.library.draw_confirm(s)
        self.browser.draw()
        close_popup_on_escape()

    @staticmethod
    def item_width() -> float:
        """The panel's widget width: imgui's default (65% of the panel), less where the panel is
        too narrow for LONG_LABELS beside it (not below 40% of the row)."""
        from imgui_bundle import imgui

        avail = imgui.get_content_region_avail().x
        room = max(imgui.calc_text_size(label).x for label in LONG_LABELS) + imgui.get_style().item_inner_spacing.x
        return max(min(0.65 * imgui.get_window_width(), avail - room), 0.4 * avail)

    def _keep_scroll(self, imgui, collapsed: bool) -> None:
        """Empty space at the panel's end as tall as the content a header's collapse took away,
        while the scroll needs it: collapsing a section near the bottom of the scrolled panel
        shrank the content, imgui clamped the scroll, and every control (the clicked header
        too) moved down ~160 px under the pointer; the artist's next click opened the wrong
        dropdown. Kept so, the header stays under the pointer (as file managers and Blender
        do); the space goes as the artist scrolls up into the content."""
        end = imgui.get_cursor_pos_y()
        last_end, last_slack = getattr(self, "_content_end", None), getattr(self, "_slack", 0.0)
        slack = 0.0
        scroll = imgui.get_scroll_y()
        if scroll > 0.0 and last_end is not None:
            # imgui's scroll limit, from last frame's content, less what the content lost since:
            # the limit this frame without the space. What the scroll is past it, the space keeps.
            limit = imgui.get_scroll_max_y() - (last_end + last_slack - end)
            slack = max(0.0, scroll - limit)
            if not collapsed:   # (it only shrinks, as the artist scrolls up: no other change grows it)
                slack = min(slack, last_slack)
        if slack > 0.0:
            imgui.dummy(imgui.ImVec2(1.0, slack))
        self._slack, self._content_end = slack, end

    def _status_line(self, s, win) -> str:
        """The panel's menu bar, one row of a fixed height that never scrolls: the error (red),
        else a file job's, the IBL bake's or the turntable's progress, else the last message
        (green) followed by what runs in the background (grey: the occlusion bake, a new look's
        shaders compiling), else nothing; so a save or an
        error is seen wherever the panel is scrolled, and the rows below never move when one
        appears or goes. A line longer than the row is drawn with its middle as "..." (its start and
        its end in view); hovering it shows it whole.
        Returns the row's text."""
        from imgui_bundle import imgui

        if not imgui.begin_menu_bar():
            return ""
        shown, hovered = "", False
        jobs = self.file_jobs.status()
        # The row's right end: a text longer than the room is drawn with "..." for its middle
        # (it was cut silently at the edge: an artist read a cut path as the whole error, its
        # 'no such file' out of view), whole in the tooltip on hover.
        right = imgui.get_window_pos().x + imgui.get_window_width() - imgui.get_style().window_padding.x
        drawn = []   # the texts as drawn (tests read them: shown_row)
        if s.error:
            shown = f"error: {s.error}"
            drawn.append(fit_text(shown, right - imgui.get_cursor_screen_pos().x))
            imgui.text_colored(imgui.ImVec4(*ERROR_RGBA), drawn[-1])
        elif jobs:   # 'open mesh' or 'export glTF' on its worker thread (file_jobs.py)
            shown = self.shown_job_status = jobs
            drawn.append(fit_text(shown, right - imgui.get_cursor_screen_pos().x))
            imgui.text_colored(imgui.ImVec4(*MESSAGE_RGBA), drawn[-1])
        elif win.bake_progress is not None:   # the bake runs between frames; the old maps light the view
            fraction, label = win.bake_progress
            shown = f"baking {s.quality}: {label}"
            imgui.progress_bar(fraction, imgui.ImVec2(-1, 0), shown)
        elif getattr(win, "turntable_job", None) is not None:   # its frames, then "writing NAME..."
            shown = win.turntable_job.progress()
            imgui.text_colored(imgui.ImVec4(*MESSAGE_RGBA), shown)
        else:
            # The last message first (green: a file's warnings are not seen again later), then
            # what runs in the background (grey): the child's occlusion bake, a new look's
            # shaders compiling in the warm-up process (the view holds the last picture
            # meanwhile, which must not pass for the new one). A new user saw both cut at the
            # panel's edge with the message last. The shaders' note is short: another saw
            # "compiling sha" cut off after a preset's message, the view still glossy 3 s on.
            baking = getattr(getattr(win, "occlusion_bake", None), "status", "")
            compiling = "compiling shaders (view: last look)" \
                if getattr(getattr(win, "variant_warmup", None), "showing_old", False) else ""
            parts = [(text, kind) for text, kind in ((s.message, "message"), (compiling, "note"), (baking, "note"))
                     if text]
            # The notes keep their room after the message (cut first where there is none).
            spacing = imgui.get_style().item_spacing.x
            notes = sum(imgui.calc_text_size(text).x + spacing for text, kind in parts if kind == "note")
            for i, (text, kind) in enumerate(parts):
                if i:
                    imgui.same_line()
                room = right - imgui.get_cursor_screen_pos().x
                if kind == "message":
                    drawn.append(fit_text(text, max(room - notes, 0.5 * room)))
                    imgui.text_colored(imgui.ImVec4(*MESSAGE_RGBA), drawn[-1])
                else:
                    drawn.append(fit_text(text, room))
                    imgui.text_disabled(drawn[-1])
                hovered = hovered or imgui.is_item_hovered()
            shown = " | ".join(text for text, _ in parts)
        self.shown_row = " | ".join(drawn)
        hovered = hovered or imgui.is_item_hovered()
        if shown and hovered:
            # The line whole, wrapped to the window's width (a set's assignment outgrew it); a
            # file's several warnings, and each background note, one a line.
            width = imgui.get_io().display_size.x
            imgui.set_next_window_pos(imgui.ImVec2(0.0, imgui.get_item_rect_max().y + 2.0))
            imgui.begin_tooltip()
            imgui.push_text_wrap_pos(width - 2.0 * imgui.get_style().window_padding.x)
            self.status_tooltip = f"error: {s.error}" if s.error else shown.replace(" | ", "\n")
            imgui.text_unformatted(self.status_tooltip)
            imgui.pop_text_wrap_pos()
            imgui.end_tooltip()
        imgui.end_menu_bar()
        return shown

    def _follow_loaded(self, s) -> None:
        """The mesh and env path fields show what is loaded (a restored session, a drop, the
        'preview mesh' list, the 'studio' button), not what was typed before it: a file's path,
        a built-in mesh's name (which the field opens too), and no file for the studio."""
        specs = (s.mesh_spec, s.env_spec)
        if specs == self._specs_shown:
            return
        if s.mesh_spec != self._specs_shown[0]:
            self.mesh_path = self._good["mesh_path"] = s.mesh_spec or ""
        if s.env_spec != self._specs_shown[1]:
            self.env_path = self._good["env_path"] = "" if s.env_spec == "studio" else (s.env_spec or "")
        self._specs_shown = specs

    def _follow_maps(self, s) -> None:
        """The 'texture set' field shows the set loaded (a drop, a folder typed into 'map file',
        undo), and both map fields empty once no map is loaded (a preset click): a field never
        names maps that are not what is drawn. Typing changes nothing loaded, so it stays."""
        text = s.texture_set_text()
        if text == self._set_shown:
            return
        self.set_path = self._good["set_path"] = text
        if not text:
            self.map_path = self._good["map_path"] = ""
        self._set_shown = text

    # --- sections -------------------------------------------------------------------------------

    def _material(self, s, win) -> None:
        from imgui_bundle import imgui

        # Every widget below edits this local copy; it is written back once, after the last of
        # them. Nothing in between may assign s.material: the write-back would undo it (a preset
        # click once did, and 'revert' then applied the click of the frame before).
        m = s.material
        picked = None   # the preset clicked this frame: it also becomes what 'revert' goes back to
        _, s.use_file_materials = imgui.checkbox("mesh file's own materials and maps", s.use_file_materials)
        # The names' column as wide as the longest name and its swatch; the F0 columns where the
        # panel has room for their digits (a narrow window drew "0.02 0.02 0.0.15 0.15 0", the
        # columns over each other): sRGB goes first, then linear, each then in the name's tooltip.
        style = imgui.get_style()
        longest = max((name for name, *_ in self.presets), key=len, default="preset")
        name_width = imgui.calc_text_size(longest).x + ICON + style.item_spacing.x
        digits = imgui.calc_text_size("0.00 0.00 0.00").x + 2.0 * style.cell_padding.x + style.item_spacing.x
        room = imgui.get_content_region_avail().x - name_width - 2.0 * style.cell_padding.x
        f0_columns = [c for c, fits in (("F0 linear", room >= digits), ("F0 sRGB", room >= 2.0 * digits)) if fits]
        overflow = 0.0   # how far the widest F0 text ran past its cell's right edge (px)
        if imgui.begin_table("presets", 1 + len(f0_columns), imgui.TableFlags_.borders_inner_h):
            imgui.table_setup_column("preset", imgui.TableColumnFlags_.width_fixed, name_width)
            for column in f0_columns:
                imgui.table_setup_column(column)
            imgui.table_headers_row()
            for name, preset, f0, f0_srgb in self.presets:
                imgui.table_next_row()
                imgui.table_next_column()
                self.library.icon(win, f"##sw{name}", preset, fallback_rgb=f0_srgb)   # its thumbnail
                imgui.same_line()
                # Highlighted: the preset the material is now (none once any field is edited or a map loaded).
                if imgui.selectable(name, m == preset and not s.texture_maps.paths(), 0, imgui.ImVec2(0, ICON))[0]:
                    m = picked = preset
                if len(f0_columns) < 2 and imgui.is_item_hovered():
                    tooltip(f"F0 linear {' '.join(f'{x:.2f}' for x in f0)}, "
                            f"sRGB {' '.join(f'{x:.2f}' for x in f0_srgb)}")
                for column, values in zip(f0_columns, (f0, f0_srgb)):
                    imgui.table_next_column()
                    right = imgui.get_cursor_screen_pos().x + imgui.get_content_region_avail().x
                    imgui.text(" ".join(f"{x:.2f}" for x in values))
                    overflow = max(overflow, imgui.get_item_rect_max().x - right)
            imgui.end_table()
        self.preset_columns, self.preset_overflow = 1 + len(f0_columns), overflow   # (the checks read them)
        self.library.draw(s, win)   # saved materials; a click is applied after the write-back below
        # Base colour is stored linear (docs/conventions.md) and shown sRGB, as artists pick colours.
        changed, col = imgui.color_edit3("base colour (sRGB)", _srgb(m.base_color))
        if changed:
            m = dataclasses.replace(m, base_color=_linear(col))
        # A number typed into a slider (Ctrl+click) is clamped to its range, as imgui's AlwaysClamp
        # sliders do: a slider's ends are the model's, so -0.3 means 0, not an error to retype.
        clamp = imgui.SliderFlags_.always_clamp
        changed, v = imgui.slider_float("metallic", m.metallic, 0.0, 1.0, flags=clamp)
        if changed:
            m = dataclasses.replace(m, metallic=v)
        changed, v = imgui.slider_float("roughness", m.roughness, 0.0, 1.0, flags=clamp)
        if changed:
            m = dataclasses.replace(m, roughness=v)
        # specular F0 and ior are one interface (alight.core.material's rule): editing one sets the other.
        changed, v = imgui.drag_float3("specular F0", list(m.specular_f0), 0.002, 0.0, 1.0)
        if imgui.is_item_hovered():
            tooltip("the dielectric's reflectance at normal incidence (linear RGB); the ior follows its "
                    "luminance, and a coloured F0 is kept as the specular colour (KHR_materials_specular)")
        if changed:
            m = _f0_edited(m, v)
        changed, v = imgui.drag_float("ior", m.ior, 0.005, 1.0, 4.0)
        if imgui.is_item_hovered():
            tooltip("index of refraction (KHR_materials_ior): F0 = ((ior-1)/(ior+1))^2 times the "
                              "specular colour; the ior and the specular F0's luminance follow each other")
        if changed:
            m = _ior_edited(m, v)
        changed, v = imgui.drag_float3("emissive", list(m.emissive), 0.01, 0.0, 100.0)
        if changed:
            m = dataclasses.replace(m, emissive=tuple(max(x, 0.0) for x in v))
        changed, name = imgui.input_text("name", m.name)
        if changed and name.strip() and name.isprintable():
            m = dataclasses.replace(m, name=name)
            s.typed_name = name   # a texture set loaded later keeps it
        m = self._layers(s, m)
        if picked is not None and m is picked:   # a click and no other edit: the preset, without maps
            s.apply_preset(picked)
        elif m != s.material:
            try:
                s.material = validate_material(tidy_edit(s.material, m), "")   # (no prefix: _fail)
                # A valid edit is a success: the error a refused value left (-0.3 typed) goes.
                s.error = ""
            except AlightError as exc:
                s.fail(exc)
        self.library.apply_click(s)
        if imgui.tree_node_ex("texture maps", imgui.TreeNodeFlags_.default_open):
            self._texture_maps(s)
            imgui.tree_pop()
        # The factors' F0; where a map scales it (base colour, metallic), the map's texels times it.
        f0 = ' '.join(f'{x:.3f}' for x in s.material.f0())
        mapped = any(getattr(s.texture_maps, slot) for slot in ("base_color", "metallic_roughness", "metallic"))
        self.shown_f0 = f"F0 (factors) = {f0} x maps" if mapped else f"F0 = {f0}"   # (the checks read it)
        imgui.text_disabled(f"{self.shown_f0}   "
                            f"undo {len(win.history.undo_stack)}  redo {len(win.history.redo_stack)}")
        if imgui.button("revert"):
            s.revert()
        imgui.same_line()
        if imgui.button("undo"):
            s.step_history(win.history)
        imgui.same_line()
        if imgui.button("redo"):
            s.step_history(win.history, redo=True)
        # A file to write (save, export): Enter does nothing here (widgets.text_field says why).
        if self._follow_material_name(s.material.name) and imgui.get_id("preset file") == imgui.internal.get_active_id():
            # The field in use (clicked, nothing typed) shows imgui's copy of the old name and
            # hands it back: a texture set dropped then put material.json back and the field
            # never followed again ('save preset' wrote material.json and a library
            # 'material'). Let go of it, so it shows the new name.
            imgui.internal.clear_active_id()
        changed, typed = imgui.input_text("preset file", self.preset_path)
        if changed:   # (typed: from now on the field is the artist's)
            self.preset_path = typed
        if imgui.button("save preset"):
            self._attempt(s, "preset_path", lambda: self._save_preset(s))
        imgui.same_line()
        if imgui.button("load preset"):
            self._attempt(s, "preset_path", lambda: s.open_file(self.preset_path))
        imgui.same_line()
        self._browse("browse files", (".hdr", ".exr", ".obj", ".gltf", ".glb", ".ply", ".stl", ".json"),
                     s.open_file, start=self.preset_path)
        _, self.gltf_path = imgui.input_text("glTF file", self.gltf_path)
        if imgui.button("export glTF"):   # the mesh with the material and its maps (.gltf or .glb)
            self._export_gltf(s)

    def _follow_material_name(self, name: str) -> bool:
        """The 'preset file' field as ``preset_file_name(name)`` while it holds the name it was
        last given so (not typed, not restored from a session as another name). Returns whether
        the field's text changed."""
        if self.preset_path != self._auto_preset_path:
            return False
        auto = preset_file_name(name)
        if self._good.get("preset_path") == self.preset_path:
            self._good["preset_path"] = auto   # (a failed save goes back to what is shown)
        changed = auto != self.preset_path
        self.preset_path = self._auto_preset_path = auto
        return changed

    def _save_preset(self, s) -> None:
        """'save preset': the file (a .json with maps loaded: the factors that look closest
        without them, and the status row says the maps were left out), then a copy of what the
        file holds into the library under the file's name."""
        stem = Path(self.preset_path).stem
        if stem and stem.isprintable() and s.material.name not in (stem, s.typed_name):
            # The file and its library entry are named by the file: the material inside takes
            # that name too (unless the artist typed one), so a click on the entry and a later
            # 'save to library' name the same entry, not the preset the work started from.
            s.material = dataclasses.replace(s.material, name=stem)
        try:
            note = s.save_material(self.preset_path)
        except AlightError as exc:
            s.fail(exc)
            return
        from alight.exchange.material_files import is_gltf

        # A saved material is in the library too, as the file holds it (a .json: no maps).
        saved = self.library.save(s, self.preset_path, rename=False, factors_only=not is_gltf(self.preset_path))
        if not s.error:
            done = f"saved {self.preset_path}{f' ({note})' if note else ''}"
            s.message = f"{done} and {s.message.removeprefix('saved ')}" if saved else f"{done}; {s.message}"

    def _export_gltf(self, s) -> None:
        """'export glTF': written by a worker thread (file_jobs.py) from what is shown now; the
        frame that takes its end says so (``take_file_jobs``). One export at a time: a second
        click while one writes is refused in the status row, the field keeps its text."""
        busy = self.file_jobs.exporting
        if busy:
            s.error = (f"{self.gltf_path}: not exported: {busy} is still being written "
                       f"(export again when the status row says it is done)")
            s.message = ""
            return
        s.error = ""
        self.file_jobs.export(self.gltf_path, s.export_job(self.gltf_path))

    def _variant_row(self, s) -> None:
        """The mesh file's material variants (KHR_materials_variants), a list shown only when the
        mesh has some: its parts' own materials, then each variant by name (alight edit --variant)."""
        from imgui_bundle import imgui

        names = list(getattr(s.mesh, "variants", None) or [])
        if not names:
            return
        items = [VARIANT_OWN, *names]
        current = 0 if s.mesh.variant is None else 1 + names.index(s.mesh.variant)
        changed, i = imgui.combo("variant", current, items)
        if changed and 0 <= i < len(items) and i != current:
            try:
                s.set_variant(None if i == 0 else names[i - 1])
                s.error, s.message = "", f"variant: {items[i]}" + (
                    "" if s.use_file_materials else " (shown with 'mesh file's own materials and maps' ticked)")
            except AlightError as exc:
                s.fail(exc)
        if imgui.is_item_hovered():
            tooltip("the glTF file's material variants (KHR_materials_variants): each part drawn with the "
                    "material the variant gives it, its own where the variant gives none")

    def _open_mesh(self, s) -> None:
        """'open mesh' (or Enter in its field): the file read by a worker thread (file_jobs.py),
        assigned when a frame takes it; a second open while one runs wins."""
        self.open_mesh(s, self.mesh_path)

    def _browsed_mesh(self, s, path: str) -> None:
        """The file picked in 'browse mesh': shown in the 'mesh' field and opened as 'open mesh'
        opens it (a failure puts the field back on the mesh that last opened)."""
        self.mesh_path = path
        self._open_mesh(s)

    def open_mesh(self, s, spec: str, then=None, own_materials: bool = True) -> None:
        """``spec`` read on the worker thread: the button, a dropped mesh file, --script open= and
        mesh=, and the last session's mesh at start-up (EditorState.open_mesh_async; ``then``:
        FileJobs.open_mesh). Besides the read, the thread does the CPU side of the
        mesh's upload (alight.render.mesh_upload: the textures' mip levels, the self-shadowing
        test), which the frame that took the mesh used to do on the GL thread (1.2 s for
        DamagedHelmet, no frame drawn)."""
        s.error = ""
        self.file_jobs.open_mesh(spec, read_for_upload, then, own_materials)

    def take_file_jobs(self, s, renderer=None) -> None:
        """The worker thread's finished opens and exports, taken on the GL thread once a frame
        (before the panel is drawn). A mesh read is put on the GPU over the next frames, a few MiB
        of texture levels a frame (``renderer.upload_step``), and assigned to the state in the
        frame that completes it: until then the previous mesh stays on screen and the status row
        says "opening NAME..." (an artist sees the new mesh whole at once, never a bare grey
        helmet whose maps pop in one by one). A failure is the one-line error with the previous
        mesh kept and the field back on the path that last worked, as ``_attempt`` does."""
        for done in self.file_jobs.take():
            field = "mesh_path" if done.kind == "open" else "gltf_path"
            if done.error is not None:
                if done.kind == "open":
                    self.file_jobs.then = None
                s.fail(done.error)
                if getattr(self, field) == done.target:   # (a path typed since stays)
                    setattr(self, field, self._good.get(field, ""))
                continue
            if done.kind == "open":
                mesh, upload = done.value
                self.file_jobs.staged = (done.target, mesh, upload)
                continue
            note = done.value
            s.error, s.message = "", f"exported {done.target}{f' ({note})' if note else ''}"
            self._good[field] = done.target
        staged = self.file_jobs.staged
        if staged is not None and (renderer is None or renderer.upload_step(staged[2])):
            spec, mesh, _ = staged
            self.file_jobs.staged = None
            s.apply_mesh(spec, mesh)
            s.error, s.message = "", s.with_warnings(f"opened mesh {spec}")
            self._good["mesh_path"] = spec
            then, self.file_jobs.then = self.file_jobs.then, None
            if then is not None:
                then()

    def kept_sections(self) -> dict:
        """Which of the panel's sections (Material, Environment, ...) are open, for the next
        session: as drawn last, and a restored one not drawn since as it was restored."""
        return {**self._sections_restored, **self.sections_open}

    def restore_sections(self, sections: dict) -> None:
        """A saved session's open sections (``kept_sections``), applied as the panel is next
        drawn; entries that are not a true or false are skipped."""
        self._sections_restored.update({k: v for k, v in sections.items()
                                        if isinstance(k, str) and isinstance(v, bool)})

    def kept_paths(self) -> dict:
        """The 'preset file' and 'glTF file' fields for the next session: the paths that last
        worked (a typed path that failed is not kept, as it is not left showing)."""
        kept = {field: self._good[field] for field in KEPT_PATH_FIELDS}
        if self.preset_path == self._auto_preset_path == kept["preset_path"]:
            kept["preset_path"] = DEFAULT_PATHS["preset_path"]   # (following the name: the next session too)
        return kept

    def restore_paths(self, paths: dict) -> None:
        """The fields of a saved session (``kept_paths``); entries that are not text are skipped."""
        for field in KEPT_PATH_FIELDS:
            if isinstance(paths.get(field), str) and paths[field]:
                setattr(self, field, paths[field])
                self._good[field] = paths[field]

    def _attempt(self, s, field: str, action, keep_typed: bool = False) -> None:
        """Run a path field's action (open, load, save); where it fails the field goes back to
        the path that last worked (what is loaded or saved), and the status row names the path
        that failed: a field never shows a file that is not what the editor holds. With
        ``keep_typed`` (the 'map file' field, whose slot rows name the loaded maps) the typed
        path stays for the artist to fix."""
        typed = getattr(self, field)
        s.error = ""
        action()
        if not s.error:
            self._good[field] = typed
        elif not keep_typed:
            setattr(self, field, self._good.get(field, ""))

    def _layers(self, s, m):
        """A collapsible section per layer of the material-field registry (layer_rows.py), open
        where the material uses the layer: the open state follows the material whenever another
        one is loaded (a preset, a file, revert), and the artist's clicks otherwise."""
        from imgui_bundle import imgui

        reset = s.saved_material is not self._sections_for
        self._sections_for = s.saved_material
        used = m.layers()
        for section in SECTIONS:
            if reset:
                imgui.set_next_item_open(section.layer in used, imgui.Cond_.always)
            opened = imgui.tree_node_ex(f"{section.title}{' (on)' if section.layer in used else ''}"
                                        f"###layer_{section.layer}")
            if imgui.is_item_hovered():
                tooltip(section.extension)
            if opened:
                if section.note:
                    imgui.text_disabled(section.note)
                # Widgets narrow enough for the section's longest label to fit beside them
                # ('clearcoat roughness' was cut at the panel's edge), but not below 40% of the row.
                label = max(imgui.calc_text_size(row.label).x for row in section.rows)
                avail = imgui.get_content_region_avail().x
                imgui.push_item_width(max(avail - label - imgui.get_style().item_inner_spacing.x, 0.4 * avail))
                for row in section.rows:
                    m = layer_row(row, m)
                imgui.pop_item_width()
                imgui.tree_pop()
        return m

    def _browse(self, label: str, suffixes: tuple[str, ...], on_pick, accept=None, start: str = "") -> None:
        """A button opening the file browser (file_browser.py: native dialog or built-in) in the
        folder of ``start`` (the file the row holds now; '' keeps the browser's last folder: it
        opened in the working directory, four clicks from the user's maps)."""
        from imgui_bundle import imgui

        if imgui.button(label):
            self.browser.open(label, suffixes, on_pick, start=start, accept=accept)

    def _texture_maps(self, s) -> None:
        """A row per slot: the drop target (radio), the file, load and clear; then the tiling."""
        from imgui_bundle import imgui

        def loader(slot):
            def load(path: str) -> None:
                try:
                    s.set_map(slot, path)
                    s.error, s.message = "", f"{SLOT_LABELS[slot]}: {path}"
                except AlightError as exc:
                    s.fail(exc)    # the slot keeps its previous map
            return load

        maps = s.texture_maps
        if s.use_file_materials:
            note("parts with a material of their own use the file's maps")
        # A whole set at once, each file to its slot by its name (as a drop of several files).
        self.set_path, set_entered = text_field("texture set", self.set_path)
        if imgui.is_item_hovered():
            listing = s.texture_set_listing()
            tooltip((listing + "\n\n" if listing else "")
                    + "a folder of maps, or image files separated by ';' (or drop them on the view "
                      "together): each goes to its slot by its name (NAME_BaseColor, _Normal, "
                      "_Roughness, _Metallic, _AO, _ORM, ...); the material takes the set's name")
        if (imgui.button("load set") or set_entered) and self.set_path.strip():
            # The field as the set filled it names several files by their shared name and count,
            # which no path reads: loaded again, it is those files.
            typed = s.texture_set_spec() if self.set_path == self._set_shown else self.set_path
            self._attempt(s, "set_path", lambda: self._load_texture_set(s, typed))
        imgui.same_line()
        if imgui.button("browse set"):   # any image of the set: its folder is loaded
            self.browser.open("texture set: pick any of its maps", IMAGE_SUFFIXES,
                              lambda path: self._browsed_set(s, os.path.dirname(path)),
                              start=os.path.join(s.texture_set_folder, "any") if s.texture_set_folder else "")
        imgui.same_line()
        note("a folder, files split by ';', or a drop")
        for slot in MAP_SLOTS:
            imgui.push_id(slot)
            if imgui.radio_button("##armed", s.armed_slot == slot):
                s.armed_slot = slot
            if imgui.is_item_hovered():
                tooltip("a dropped image file goes into this slot")
            imgui.same_line()
            if imgui.small_button("load"):
                # (in the folder of this slot's map, or of any map already loaded)
                near = getattr(maps, slot) or next(iter(maps.paths().values()), "")
                self.browser.open(f"load {SLOT_LABELS[slot]} map", IMAGE_SUFFIXES, loader(slot),
                                  start=near.split("#images[")[0])
            imgui.same_line()
            path = getattr(maps, slot)
            if imgui.small_button("clear") and path:
                s.clear_map(slot)
            imgui.same_line()
            imgui.text(SLOT_LABELS[slot])
            if path:
                imgui.same_line()
                imgui.text_disabled(os.path.basename(path))
            imgui.pop_id()
        self.map_path, entered = text_field("map file", self.map_path)
        if imgui.is_item_hovered():
            tooltip("an image goes into the armed slot; a folder is read as a texture set by its "
                              "files' names (NAME_BaseColor, _Normal, _Roughness, ...)")
        imgui.same_line()
        if (imgui.button("load##typed") or entered) and self.map_path:
            # A path that fails stays typed (a new user's typo was wiped with the error, to be
            # typed again); the slot keeps its last good map, whose name the slot's row shows.
            if os.path.isdir(self.map_path):
                self._attempt(s, "map_path", lambda: self._load_texture_set(s, self.map_path), keep_typed=True)
            else:
                self._attempt(s, "map_path", lambda: loader(s.armed_slot)(self.map_path), keep_typed=True)
        changed, v = imgui.drag_float2("UV tiling", list(maps.uv_scale), 0.02, -64.0, 64.0)
        if changed:
            s.texture_maps = dataclasses.replace(s.texture_maps, uv_scale=tuple(v))
        changed, v = imgui.drag_float2("UV offset", list(maps.uv_offset), 0.005, -8.0, 8.0)
        if changed:
            s.texture_maps = dataclasses.replace(s.texture_maps, uv_offset=tuple(v))

    def _browsed_set(self, s, folder: str) -> None:
        """The folder of the map picked in 'browse set': loaded, and shown in the field."""
        self.set_path = folder
        self._load_texture_set(s, folder)

    @staticmethod
    def _load_texture_set(s, text: str) -> None:
        """A folder, or image files separated by ';' (the 'texture set' field; a folder typed
        into 'map file' too): the images assigned to slots by name, as a drop of several files
        is (one undo step; the panel's message lists the assignment)."""
        entries = [p.strip() for p in text.split(";") if p.strip()]
        folder = entries[0] if len(entries) == 1 and os.path.isdir(entries[0]) else ""
        try:
            if folder:
                s.open_texture_folder(folder)
                return
            for path in entries:
                if not os.path.isfile(path):
                    raise AlightError(f"{path}: texture set: no such file (a folder, or image files "
                                      f"separated by ';')")
            s.open_texture_set(entries)
        except (AlightError, OSError) as exc:
            s.fail(exc if isinstance(exc, AlightError) else AlightError(f"{text}: {exc.strerror}"))

    def _environment(self, s, win) -> None:
        from imgui_bundle import imgui

        imgui.text(f"environment: {s.env_spec}")
        self.env_path, entered = text_field("env file", self.env_path)
        if imgui.button("open env") or entered:
            self._attempt(s, "env_path", lambda: s.open_environment(self.env_path))
        imgui.same_line()
        # (an LDR image is an environment too, display-referred, as `alight render --env` takes it)
        from alight.exchange.images import IMAGE_SUFFIXES

        from alight.exchange.environment_files import may_be_equirect

        # (only 2:1 pictures among the 8-bit ones: the user's screenshots were listed too)
        self._browse("browse env", (".hdr", ".exr", *(x for x in IMAGE_SUFFIXES if x != ".exr")), s.open_environment,
                     accept=may_be_equirect, start="" if s.env_spec == "studio" else s.env_spec)
        imgui.same_line()
        if imgui.button("studio"):
            try:
                s.load_env("studio")
                s.error, s.message = "", "environment: studio"
            except AlightError as exc:
                s.fail(exc)
        names = list(BUILTIN_MESHES)
        current = names.index(s.mesh_spec) if s.mesh_spec in names else -1   # -1: a file, none shown
        changed, i = imgui.combo("preview mesh", current, names)
        if changed and 0 <= i < len(names):
            self.file_jobs.drop_open()   # the list's pick is the latest: a file still being read is not shown
            try:
                s.load_mesh(names[i])
                s.error, s.message = "", f"mesh: {names[i]}"
            except AlightError as exc:
                s.fail(exc)
        if imgui.is_item_hovered():
            tooltip("a built-in mesh, framed from its 3/4 view; or type a mesh file below")
        self.mesh_path, entered = text_field("mesh", self.mesh_path)
        if imgui.button("open mesh") or entered:
            self._open_mesh(s)
        imgui.same_line()
        # A mesh picked in the browser opens as a typed one does (on the file-jobs thread).
        self._browse("browse mesh", MESH_EXTENSIONS, lambda path: self._browsed_mesh(s, path),
                     start="" if is_builtin(s.mesh_spec) else s.mesh_spec)
        imgui.same_line()
        # The way back from an orbit that lost the mesh (a one-sided sheet seen from behind shows
        # nothing, and F frames it from the same direction).
        if imgui.button("front view") and s.mesh is not None:
            win.frame_mesh(front=True)
        if imgui.is_item_hovered():
            tooltip("frame the mesh from its front (a flat mesh: its face; else +Z, level); key Home")
        self._variant_row(s)
        _, s.env_rotation_deg = imgui.slider_float("rotation", s.env_rotation_deg, -180.0, 180.0)
        if imgui.is_item_hovered():
            tooltip("or Shift + right drag in the view")
        note("turn the environment: Shift + right drag in the view")
        _, s.lights_follow_env = imgui.checkbox("lights turn with the environment", s.lights_follow_env)
        if imgui.is_item_hovered():
            tooltip("the drag and the rotation slider turn every light about the vertical axis "
                              "by the same angle, so a key light stays on the environment's sun")
        _, s.env_intensity = imgui.slider_float("intensity", s.env_intensity, 0.0, 4.0)
        d = s.display
        changed, i = imgui.combo("background", BACKGROUNDS.index(d.background), BACKGROUNDS)
        if changed:
            s.display = dataclasses.replace(d, background=BACKGROUNDS[i])
        models = list(IBL_MODELS)
        changed, i = imgui.combo("IBL model", models.index(s.ibl_model), models)
        if changed:
            s.ibl_model = models[i]
        if imgui.is_item_hovered():
            tooltip(IBL_MODELS[s.ibl_model])
        _, s.multiple_scattering = imgui.checkbox("multiple scattering", s.multiple_scattering)
        if imgui.is_item_hovered():
            tooltip("Fdez-Aguera 2019: the energy single scattering loses on rough surfaces "
                              "(a white furnace gives 1; the single-scattering ground truth does not)")
        changed, i = imgui.combo("occlusion", OCCLUSION_MODES.index(s.occlusion), list(OCCLUSION_MODES))
        if changed:
            s.occlusion = OCCLUSION_MODES[i]
        if imgui.is_item_hovered():
            tooltip("occlusion of the environment light and one bounce, from a per-vertex bake as "
                              "'alight render --occlusion' makes (auto: where the mesh occludes itself; "
                              "baked in the background, the view drawn without it meanwhile)")
        _, s.ground = imgui.checkbox("ground", s.ground)
        if imgui.is_item_hovered():
            tooltip("a ground under the model's bounding box that catches its shadow (the lights' and "
                              "the environment's suns'), as 'alight render --ground' draws it over the background; "
                              "it needs shadows (not 'off')")
        changed, i = imgui.combo("shadows", SHADOW_MODES.index(s.shadows), list(SHADOW_MODES))
        if changed:
            s.shadows = SHADOW_MODES[i]
        if imgui.is_item_hovered():
            tooltip("shadow maps for the lights and the environment's suns, as 'alight render "
                              "--shadows' draws them (auto: where something can be shadowed, the ground included; "
                              "not on a convex mesh alone such as the sphere)")
        names = list(QUALITY) + ["auto"]
        changed, i = imgui.combo("bake quality", names.index(s.quality), names)
        if changed:
            s.quality = names[i]
        if s.quality == "auto" and s.env is not None:
            # What auto chose and why, with the predicted error (app/accuracy/auto_quality.py).
            imgui.text_wrapped(win.auto_choice().line(DEFAULT_ERROR_BUDGET))
        if win.bake_seconds:
            imgui.text(f"last bake: {sum(win.bake_seconds.values()) * 1000:.0f} ms")


    def _lights(self, s) -> None:
        from imgui_bundle import imgui

        _, s.ibl_enabled = imgui.checkbox("image-based lighting", s.ibl_enabled)
        # The fields narrower here, so the longest label ends at the panel's edge, not past it.
        imgui.push_item_width(-(imgui.calc_text_size(LONGEST_LIGHT_LABEL).x + imgui.get_style().item_inner_spacing.x))
        if s.history_steps != self._steps_seen:
            # An undo or redo put the lights as they were: a removed light's 'restore' would bring
            # back one the step may have restored already (the history holds removals now).
            self._steps_seen, self._removed, self._place_tops = s.history_steps, [], {}
        remove = None
        top = imgui.get_cursor_screen_pos().y
        # Lights are replaced, not mutated, so the renderer's "lights changed?" check stays honest.
        for i, light in enumerate(s.lights):
            self._removed_places(s, i)
            imgui.push_id(i)
            start = imgui.get_cursor_pos_y()
            imgui.separator()
            imgui.text(f"{i}: {light.kind}")
            imgui.same_line()
            if imgui.small_button("remove"):
                remove = i
            label = "direction (light travels)" if light.kind == "directional" else "position"
            # Drag speeds in proportion: an added light sits and shines by the mesh's size.
            c1, vec = imgui.drag_float3(label, list(light.vector), max(0.05, 0.01 * max(map(abs, light.vector))))
            # Linear RGB, shown as 0-1 floats: 0-255 bytes would read as sRGB, as the base colour's do.
            c2, col = imgui.color_edit3("colour", list(light.color), imgui.ColorEditFlags_.float)
            if imgui.is_item_hovered():
                tooltip("the light's colour, linear RGB (times its intensity)")
            c3, inten = imgui.drag_float("intensity", light.intensity, max(0.1, 0.005 * light.intensity), 0.0, 1e6)
            if c1 or c2 or c3:
                if light.kind == "directional" and not any(vec):
                    vec = list(light.vector)   # a zero direction has no meaning
                # replace, not rebuild: a spot keeps its direction, cones and range; and only the
                # field edited (the widgets hand back float32s: an intensity edit changed the
                # position in its last digits, and undo said so)
                light = dataclasses.replace(light, vector=tuple(vec) if c1 else light.vector,
                                            color=tuple(max(0.0, x) for x in col) if c2 else light.color,
                                            intensity=max(0.0, inten) if c3 else light.intensity)
            if light.kind == "spot":
                c4, axis = imgui.drag_float3("direction (spot points)", list(light.direction), 0.02)
                c5, inner = imgui.slider_float("inner cone", light.inner_cone_deg, 0.0, 90.0, "%.1f deg")
                c6, outer = imgui.slider_float("outer cone", light.outer_cone_deg, 0.0, 90.0, "%.1f deg")
                if (c4 and any(axis)) or c5 or c6:
                    if not c4 or not any(axis):
                        axis = light.direction
                    if not (c5 or c6):
                        inner, outer = light.inner_cone_deg, light.outer_cone_deg
                    light = dataclasses.replace(light, direction=tuple(axis),
                                                inner_cone_deg=min(inner, outer), outer_cone_deg=max(outer, 1e-3))
            if light != s.lights[i]:
                s.lights[i] = light
            if remove == i:
                height = imgui.get_cursor_pos_y() - start
            imgui.pop_id()
        self._removed_places(s, len(s.lights))
        imgui.pop_item_width()
        k, self._restore = getattr(self, "_restore", None), None
        if k is not None:
            j, light, _ = self._removed[k]
            s.lights.insert(j, light)
            self._removed = [(i + (i > j or (i == j and n > k)), lt, h)
                             for n, (i, lt, h) in enumerate(self._removed) if n != k]
            self._place_tops = {}   # (indexed by place: drawn again next frame)
        if remove is not None:
            # Its place stays (a row 'removed', 'restore') while the pointer is in the section: the
            # lights below do not move up under a second click aimed at this one's 'remove'.
            self._removed = [(j - (j > remove), lt, h) for j, lt, h in self._removed]
            self._removed.append((remove, s.lights[remove], height))
            self._place_tops = {}
            del s.lights[remove]
        io = imgui.get_io()
        x0 = imgui.get_window_pos().x
        pointer = (io.mouse_pos.x, io.mouse_pos.y)
        inside = x0 <= pointer[0] < x0 + imgui.get_window_width() and \
            top <= pointer[1] < imgui.get_cursor_screen_pos().y
        if inside or not self._removed:
            self._pointer_kept = pointer
        # The list closes up once the pointer has moved out of it: a wheel scroll that carries the
        # list from under a still pointer is not leaving (the rows closed up under it mid-scroll).
        elif pointer != self._pointer_kept and not imgui.is_any_mouse_down():
            self._close_up_places()
        added = None
        if imgui.button("add point"):
            added = s.added_light("point")
        imgui.same_line()
        if imgui.button("add directional"):
            added = s.added_light("directional")
        imgui.same_line()
        if imgui.button("add spot"):   # above and in front, pointing at the mesh
            added = s.added_light("spot")
        if added is not None:   # (the status row kept saying the last material step)
            s.lights.append(added)
            s.error, s.message = "", f"added light {len(s.lights) - 1}: {added.kind}"
        if remove is not None:
            s.error, s.message = "", f"removed light {remove} ('restore' while the pointer is here)"

    def _close_up_places(self) -> None:
        """The removed lights' places go, keeping what the panel shows where it is: the part of a
        place scrolled above the panel's top is taken off the scroll too (the rows below stayed
        put only where imgui's clamp at the content's end happened to make up for it; elsewhere
        all of them jumped up by the place's height); a place in view is filled by the rows after
        it, the next light's row where the removed one was."""
        from imgui_bundle import imgui

        visible_top = imgui.get_window_draw_list().get_clip_rect_min().y
        above = sum(min(height, max(0.0, visible_top - self._place_tops.get(k, visible_top)))
                    for k, (_, _, height) in enumerate(self._removed))
        if above > 0:
            imgui.set_scroll_y(max(0.0, imgui.get_scroll_y() - above))
        self._removed, self._place_tops = [], {}

    def _removed_places(self, s, index: int) -> None:
        """The places of the lights removed just before list position ``index``: as tall as the
        light was, with its kind and a 'restore' button at the row's start (not under 'remove')."""
        from imgui_bundle import imgui

        for k, (j, light, height) in enumerate(list(self._removed)):
            if j != index:
                continue
            imgui.push_id(f"removed{k}")
            self._place_tops[k] = imgui.get_cursor_screen_pos().y
            start = imgui.get_cursor_pos_y()
            imgui.separator()
            if imgui.small_button("restore"):
                self._restore = k   # put back after the list is drawn
            imgui.same_line()
            imgui.text_disabled(f"{light.kind} light removed")
            imgui.dummy(imgui.ImVec2(1.0, max(0.0, height - (imgui.get_cursor_pos_y() - start)
                                              - imgui.get_style().item_spacing.y)))
            imgui.pop_id()

    def _display(self, s, win) -> None:
        from imgui_bundle import imgui

        d = s.display
        changed, i = imgui.combo("tone map", TONEMAPS.index(d.tonemap), TONEMAPS)
        if changed:
            s.display = d = dataclasses.replace(d, tonemap=TONEMAPS[i])
        changed, ev = imgui.slider_float("exposure (EV)", d.exposure, -8.0, 8.0)
        if changed:
            s.display = dataclasses.replace(d, exposure=ev)
        _, s.debug_view = imgui.combo("debug view", s.debug_view, DEBUG_VIEWS)
        if DEBUG_VIEWS[s.debug_view] == "prefiltered radiance at mip":
            _, s.debug_mip = imgui.slider_float("mip", s.debug_mip, 0.0, 8.0)
        changed, i = imgui.combo("anti-aliasing", AA_CHOICES.index(s.aa), AA_CHOICES)
        if changed:
            s.aa = AA_CHOICES[i]
        _, s.render_scale = imgui.slider_float("render scale", s.render_scale, 0.25, 1.0)
        # (A fixed ID: the label's number changes while the view moves.)
        _, s.adaptive_motion = imgui.checkbox(f"adaptive scale while moving ({win.adaptive_scale:.2f})"
                                              "###adaptive_motion", s.adaptive_motion)
        if not s.adaptive_motion:
            _, s.motion_scale = imgui.slider_float("scale while moving", s.motion_scale, 0.25, 1.0)
        _, win.orbit.fov_y_deg = imgui.slider_float("field of view", win.orbit.fov_y_deg, 10.0, 90.0)
        if imgui.button("frame mesh (F)"):
            win.frame_mesh()
        imgui.same_line()
        if imgui.button("copy camera as flags"):
            # The view's camera and size for `alight render` (the editor frames a mesh for its
            # own aspect: a new user could not make the command line draw the view's picture).
            import shlex

            text = shlex.join(win.orbit.render_flags(win.view_area()) + s.render_flags())
            imgui.set_clipboard_text(text)
            s.error, s.message = "", f"copied to the clipboard: {text}"
        if imgui.is_item_hovered():
            tooltip("the view's camera and size as `alight render` flags (--orbit --elevation --distance "
                    "--fov --target --size), with its lights (--light) and each setting that is not the "
                    "command line's default (environment turn and intensity, tone map, exposure, ground, "
                    "shadows, occlusion, IBL model, anti-aliasing), onto the clipboard; add --mesh, --env "
                    "and the material")
        from alight.frontends.editor.screenshot import draw_controls

        draw_controls(win)   # size, the button (F12), progress
        from alight.frontends.editor import turntable

        turntable.draw_controls(win)   # frames, file, the button (T), progress
        note("orbit: left drag  pan: right/middle drag  zoom: wheel")
        note("turn the environment: Shift + right drag")

    def _performance(self, win) -> None:
        from imgui_bundle import imgui, implot

        times = np.asarray(win.frame_times, np.float32) * 1000.0
        if len(times):
            imgui.text(f"frame {np.median(times):.1f} ms median, {1000.0 / max(np.median(times), 1e-6):.0f} FPS; "
                       f"{win.redraws} scene redraws")
        if implot.begin_plot("frame time (ms)", imgui.ImVec2(-1, 140)):
            implot.setup_axes("frame", "ms")
            implot.setup_axes_limits(0, 240, 0, max(50.0, float(times.max()) if len(times) else 50.0),
                                     imgui.Cond_.always)
            if len(times):
                implot.plot_line("frame", times)
            implot.end_plot()
        for name, seconds in win.bake_seconds.items():
            imgui.text(f"{name}: {seconds * 1000:.1f} ms")
