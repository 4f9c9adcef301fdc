"""The editor's watcher of map and environment files (alight.frontends.editor.hot_reload.FileWatcher):
a rewrite is seen, an unchanged file is not, a save by rename (the file gone for a moment) is
one change. The editor's reload through its real window is tests/editor_ui_checks.py's
test_hot_reload_of_a_map_and_the_environment."""

from __future__ import annotations

import os
import time

from alight.frontends.editor.hot_reload import FileWatcher


def test_rewrites_are_seen_and_nothing_else(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.hdr"
    a.write_bytes(b"one")
    b.write_bytes(b"sky")
    watcher = FileWatcher(interval_s=60.0)   # the test polls by hand
    try:
        watcher.watch([str(a), str(b), ""])
        watcher.poll()
        assert watcher.take_changed() == set()
        a.write_bytes(b"two!")                   # in place (size and mtime change)
        watcher.poll()
        assert watcher.take_changed() == {str(a)}
        assert watcher.take_changed() == set()   # taken once
        b.unlink()                               # a save by rename: gone, then back
        watcher.poll()
        assert watcher.take_changed() == set()
        temp = tmp_path / "b.tmp"
        temp.write_bytes(b"new sky")
        os.replace(temp, b)
        watcher.poll()
        assert watcher.take_changed() == {str(b)}
        watcher.watch([str(b)])                  # a no longer watched: its changes are not said
        a.write_bytes(b"three")
        watcher.poll()
        assert watcher.take_changed() == set()
    finally:
        watcher.stop()


def test_the_thread_polls_on_its_own(tmp_path):
    a = tmp_path / "a.png"
    a.write_bytes(b"one")
    watcher = FileWatcher(interval_s=0.05)
    try:
        watcher.watch([str(a)])
        a.write_bytes(b"two!")
        deadline = time.monotonic() + 2.0
        while not (changed := watcher.take_changed()) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert changed == {str(a)}
    finally:
        watcher.stop()
