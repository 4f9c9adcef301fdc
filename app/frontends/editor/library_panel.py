"""The panel's library: the saved materials with their thumbnails, a click applies one (an undo
step, as a preset click), 'save to library'; and the thumbnails beside the F0 table's presets.
imgui only: the files are library.py's, the thumbnails' GL is thumbnails.py's (the window's)."""

from __future__ import annotations

import dataclasses
import time

from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.frontends.editor import library
from alight.frontends.editor.widgets import tooltip

ICON = 24              # a thumbnail's side in the list, pixels
LIST_ROWS = 4          # the entries' box shows this many rows and scrolls beyond them
RESCAN_S = 0.5         # how often the library folder is looked at for new or removed entries
_NO_MAPS = TextureMaps()


class LibraryPanel:
    def __init__(self):
        # The 'library name' field: '' follows the material's name (a preset's, a texture set's,
        # one typed in 'name'); a name typed here is kept until the entry is saved.
        self.name = ""
        self.entries: list[library.Entry] = []
        self.problems: list[str] = []
        self.clashes: list[str] = []      # entries named as a built-in preset (library.preset_clashes)
        self._stamp = None
        self._scanned = -1e9
        self.clicked = None               # the entry clicked this frame, applied by apply_click
        self._renamed = None              # the name of the entry a save wrote, for the material (ditto)
        self.pending = ""                 # an entry's name to replace once the artist confirms
        self.pending_factors_only = False   # ... and whether it is a .json preset's copy (``save``)

    def rescan(self, force: bool = False) -> None:
        now = time.monotonic()
        if not force and now - self._scanned < RESCAN_S:
            return
        self._scanned = now
        stamp = library.folder_stamp()
        if force or stamp != self._stamp:
            self._stamp = stamp
            self.entries, self.problems = library.list_entries()
            from alight.errors import warn
            from alight.exchange.presets import list_presets

            self.clashes = library.preset_clashes(self.entries, list_presets())
            for line in self.clashes:
                warn(line)   # on stderr, once per process; the box shows it too

    def label(self, entry) -> str:
        """The entry's name in the list: 'NAME (library)' where a built-in preset has that name."""
        clash = any(line.startswith(f"{entry.path}: ") for line in self.clashes)
        return f"{entry.name} (library)" if clash else entry.name

    def icon(self, win, label: str, material, maps=_NO_MAPS, fallback_rgb=None) -> None:
        """The thumbnail, or (until it is rendered) a swatch of ``fallback_rgb`` the same size.
        The swatch is painted, not a colour button: a framed item lowers the row's text by the
        frame padding, so each arriving thumbnail moved every control below it up 3 px."""
        from imgui_bundle import imgui

        thumbs = getattr(win, "thumbnails", None)
        texture = thumbs.texture_id(material, maps) if thumbs is not None else None
        if texture is not None:
            imgui.image(imgui.ImTextureRef(texture), imgui.ImVec2(ICON, ICON))
        else:
            pos = imgui.get_cursor_screen_pos()
            imgui.dummy(imgui.ImVec2(ICON, ICON))
            imgui.get_window_draw_list().add_rect_filled(
                pos, imgui.ImVec2(pos.x + ICON, pos.y + ICON),
                imgui.get_color_u32(imgui.ImVec4(*(fallback_rgb or (0.3, 0.3, 0.3)), 1.0)))

    def draw(self, s, win) -> None:
        """The library section, under the F0 table. A click is kept in ``clicked``: the panel's
        material widgets write their copy back after this, and ``apply_click`` comes after them."""
        from imgui_bundle import imgui

        self.rescan()
        if not imgui.tree_node_ex("library", imgui.TreeNodeFlags_.default_open):
            return
        # The entries scroll in a box of a fixed height: a save adds a row, and a list that grew
        # moved every control below it under the pointer (a trial's next click missed its field).
        spacing = imgui.get_style().item_spacing.y
        imgui.begin_child("##library_entries", imgui.ImVec2(0, LIST_ROWS * (ICON + spacing) + spacing),
                          imgui.ChildFlags_.borders)
        for entry in self.entries:
            self.icon(win, f"##lib_icon_{entry.name}", entry.material, entry.maps)
            imgui.same_line()
            current = s.material == entry.material and s.texture_maps == entry.maps
            shown = self.label(entry)
            if imgui.selectable(f"{shown}##library", current, 0, imgui.ImVec2(0, ICON))[0]:
                self.clicked = entry
            if imgui.is_item_hovered():
                tooltip(entry.path)
        if not self.entries:
            imgui.text_disabled("empty: 'save to library' or\n'save preset' adds the material")
        for line in self.problems:
            imgui.text_disabled(line)
        for line in self.clashes:   # wrapped: the box's width, the line whole
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(imgui.ImVec4(0.95, 0.75, 0.3, 1.0), f"warning: {line}")
            imgui.pop_text_wrap_pos()
        imgui.end_child()
        changed, typed = imgui.input_text("library name", self.name or s.material.name)
        if changed:
            self.name = typed
        if imgui.button("save to library"):
            self.save(s, self.name or s.material.name)
        imgui.tree_pop()

    def apply_click(self, s) -> None:
        """The entry clicked this frame becomes the material, with its maps (one undo step, as a
        preset click; 'revert' goes back to it)."""
        renamed, self._renamed = self._renamed, None
        if renamed is not None:
            if s.material.name != renamed:
                s.material = dataclasses.replace(s.material, name=renamed)
            s.mark_saved()
        entry, self.clicked = self.clicked, None
        if entry is None:
            return
        try:
            s.load_material(entry.path)
            s.error, s.message = "", s.with_warnings(f"applied {entry.name} from the library")
        except AlightError as exc:
            s.fail(exc)

    def save(self, s, name: str, replace: bool = False, rename: bool = True, factors_only: bool = False) -> bool:
        """The material and its maps into the library as NAME.glb; the panel's message says where.
        An entry of that name holding another material is replaced only once the artist says so
        (``draw_confirm``'s dialog, then ``replace``): a save is not undoable. Returns whether it
        was written now. ``factors_only`` ('save preset' to a .json): the entry holds what the
        preset file holds, no maps (with them, a 15 MB .glb of DamagedHelmet's maps appeared
        beside a 1 KB preset, unasked)."""
        try:
            stem = library.entry_name(name)
            material, maps = (s.preset_material(), TextureMaps()) if factors_only else (s.material, s.texture_maps)
            # The entry's material is named as the entry: a click on it later names the material
            # so, and the next save goes back to this entry, not to the name the work began with.
            # ('save preset' names it itself: a name typed into 'name' stays, rename False.)
            named = dataclasses.replace(material, name=stem) if rename and material.name != stem else material
            existing = library.library_dir() / f"{stem}{library.LIBRARY_SUFFIX}"
            same = any(e.name == stem and library.holds(e, named, maps) for e in self.entries)
            if existing.is_file() and not same and not replace:
                self.pending, self.pending_factors_only = stem, factors_only
                s.error, s.message = "", f"'{stem}' is in the library already: replace it?"
                return False
            path = library.save_entry(named, maps, name)
        except AlightError as exc:
            s.fail(exc)
            self.name = ""   # the field shows the material's name again, not the name that failed
            return False
        # The rename waits for apply_click: the panel's material widgets, drawn after this, write
        # their copy of the material back in this frame.
        self._renamed = named.name
        self.name = ""
        s.error, s.message = "", f"saved to the library: {path}"
        self.rescan(force=True)
        return True

    def draw_confirm(self, s) -> None:
        """The dialog asking whether to replace a library entry (``save``), while one is pending:
        a modal, so a click aimed at anything else does nothing until it is answered."""
        from imgui_bundle import imgui

        title = "replace library entry"
        if self.pending and not imgui.is_popup_open(title):
            imgui.open_popup(title)
        if not imgui.begin_popup_modal(title, None, imgui.WindowFlags_.always_auto_resize)[0]:
            return
        imgui.text(f"The library has a material named '{self.pending}'. Replace it with this one?")
        if imgui.button(f"replace {self.pending}"):
            name, self.pending = self.pending, ""
            self.save(s, name, replace=True, factors_only=self.pending_factors_only)
            imgui.close_current_popup()
        imgui.same_line()
        if imgui.button("keep the old one") or imgui.is_key_pressed(imgui.Key.escape, False):
            s.error, s.message = "", f"kept the library's '{self.pending}'"
            self.pending = ""
            imgui.close_current_popup()
        imgui.end_popup()
