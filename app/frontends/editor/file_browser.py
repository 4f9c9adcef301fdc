"""File picking for the panel: the desktop's native dialog where one exists (imgui-bundle's
portable file dialogs run zenity, kdialog or matedialog on Linux), else a small built-in imgui
browser. Either way the window keeps running: the native dialog is polled each frame, the
built-in one is an imgui window drawn each frame. Plain data in, a path out; no GL."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Callable

NATIVE_TOOLS = ("zenity", "kdialog", "matedialog", "qarma")


def native_dialog_available() -> bool:
    return any(shutil.which(tool) for tool in NATIVE_TOOLS)


class FileBrowser:
    """One pending pick at a time: ``open`` it, call ``draw`` every frame; the chosen file goes
    to the callback given to ``open``."""

    def __init__(self, native: bool | None = None):
        self.native = native_dialog_available() if native is None else native
        self.dialog = None            # a pending native dialog
        self.visible = False          # the built-in browser is shown
        self.title = ""
        self.directory = Path.cwd()
        self.suffixes: tuple[str, ...] = ()
        self.typed = ""
        self.on_pick: Callable[[str], None] | None = None
        self.accept: Callable[[str], bool] | None = None

    @property
    def busy(self) -> bool:
        return self.dialog is not None or self.visible

    def open(self, title: str, suffixes: tuple[str, ...], on_pick: Callable[[str], None],
             start: str = "", accept: Callable[[str], bool] | None = None) -> None:
        """``accept``: a finer test than the suffix for the built-in browser's list (a native
        dialog filters by suffix alone)."""
        if self.busy:
            return
        self.title, self.suffixes, self.on_pick = title, tuple(s.lower() for s in suffixes), on_pick
        self.accept = accept
        if start and Path(start).expanduser().parent.is_dir():
            self.directory = Path(start).expanduser().resolve().parent
        if self.native:
            try:
                from imgui_bundle import portable_file_dialogs as pfd

                pattern = " ".join(f"*{s}" for s in self.suffixes) or "*"
                self.dialog = pfd.open_file(title, str(self.directory), [title, pattern])
                return
            except Exception:
                self.native = False     # fall through to the built-in browser
        self.visible, self.typed = True, ""

    def entries(self) -> tuple[list[str], list[str]]:
        """Sub-folders and matching files of the current folder, sorted; hidden ones left out."""
        folders, files = [], []
        try:
            with os.scandir(self.directory) as it:
                for entry in it:
                    if entry.name.startswith("."):
                        continue
                    try:
                        if entry.is_dir():
                            folders.append(entry.name)
                        elif (not self.suffixes or entry.name.lower().endswith(self.suffixes)) \
                                and (self.accept is None or self.accept(entry.path)):
                            files.append(entry.name)
                    except OSError:
                        continue
        except OSError:
            pass
        return sorted(folders, key=str.lower), sorted(files, key=str.lower)

    def pick(self, path: str) -> None:
        self.visible, self.dialog = False, None
        if self.on_pick is not None:
            self.on_pick(path)

    def draw(self) -> None:
        if self.dialog is not None:
            if self.dialog.ready(0):
                paths, self.dialog = self.dialog.result(), None
                for path in paths[:1]:
                    self.pick(path)
            return
        if not self.visible:
            return
        from imgui_bundle import imgui

        imgui.set_next_window_size(imgui.ImVec2(460, 420), imgui.Cond_.first_use_ever)
        opened, self.visible = imgui.begin(f"{self.title}###file browser", True)
        if opened:
            imgui.text_wrapped(str(self.directory))
            if imgui.button("up") and self.directory.parent != self.directory:
                self.directory = self.directory.parent
            imgui.same_line()
            if imgui.button("home"):
                self.directory = Path.home()
            imgui.same_line()
            if imgui.button("cancel"):
                self.visible = False
            imgui.text_disabled("files: " + (" ".join(self.suffixes) or "all"))
            folders, files = self.entries()
            if imgui.begin_child("entries", imgui.ImVec2(0, -30)):
                for name in folders:
                    if imgui.selectable(f"[{name}]", False)[0]:
                        self.directory = self.directory / name
                for name in files:
                    if imgui.selectable(name, False)[0]:
                        self.pick(str(self.directory / name))
            imgui.end_child()
            entered, self.typed = imgui.input_text("path", self.typed, imgui.InputTextFlags_.enter_returns_true)
            if entered and self.typed.strip():
                typed = Path(self.typed.strip()).expanduser()
                typed = typed if typed.is_absolute() else self.directory / typed
                if typed.is_dir():
                    self.directory = typed.resolve()
                else:
                    self.pick(str(typed))
        imgui.end()
