"""The headless context's failure messages and the shader loader (#include, error lines)."""

import moderngl
import pytest

from alight.core import gpu
from alight.errors import AlightError
from tests.gpu import renderer


def test_missing_egl_names_the_debian_packages(monkeypatch):
    monkeypatch.setattr(gpu.ctypes.util, "find_library", lambda name: None)
    with pytest.raises(AlightError) as info:
        gpu.create_headless_context()
    message = str(info.value)
    assert "\n" not in message and "libEGL" in message
    assert "apt-get install" in message and "libegl1" in message and "libegl-mesa0" in message


def test_failed_context_is_one_line_with_the_packages(monkeypatch):
    def broken(**kwargs):
        raise Exception("eglInitialize failed\n  (0x3001)")

    monkeypatch.setattr(moderngl, "create_context", broken)
    with pytest.raises(AlightError) as info:
        gpu.create_headless_context()
    message = str(info.value)
    assert "\n" not in message and "eglInitialize failed (0x3001)" in message and "libgl1-mesa-dri" in message


def test_include_is_inlined_once_with_defines_after_version(tmp_path):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "a.glsl").write_text("float a() { return 1.0; }\n")
    (tmp_path / "common" / "b.glsl").write_text('#include "common/a.glsl"\nfloat b() { return a(); }\n')
    (tmp_path / "main.comp").write_text('#version 450 core\n#include "common/a.glsl"\n#include "common/b.glsl"\nvoid main() {}\n')
    src = gpu.load_source("main.comp", {"QUALITY": 2}, root=tmp_path)
    lines = src.text.splitlines()
    # The version first, then the shared names (app/core/shader_names.py), then the caller's defines.
    generated = len(gpu.glsl_header())
    assert lines[0] == "#version 450 core" and lines[1:1 + generated] == gpu.glsl_header()
    assert lines[1 + generated] == "#define QUALITY 2"
    assert src.text.count("float a()") == 1                 # included twice, inlined once
    assert [p.name for p in src.files] == ["main.comp", "a.glsl", "b.glsl"]


def test_compile_error_names_file_and_line(tmp_path):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "ok.glsl").write_text("float ok() { return 1.0; }\n")
    (tmp_path / "common" / "bad.glsl").write_text("float ok2() {\n  return undefined_name;\n}\n")
    (tmp_path / "broken.comp").write_text(
        '#version 450 core\nlayout(local_size_x = 1) in;\n#include "common/ok.glsl"\n#include "common/bad.glsl"\nvoid main() {}\n')
    library = gpu.ShaderLibrary(renderer().ctx, root=tmp_path)
    with pytest.raises(gpu.ShaderCompileError) as info:
        library.compute("broken.comp")
    message = str(info.value)
    assert "\n" not in message
    assert "common/bad.glsl:2:" in message and "undefined_name" in message, message


def test_digest_changes_with_an_include(tmp_path):
    (tmp_path / "common").mkdir()
    inc = tmp_path / "common" / "x.glsl"
    inc.write_text("float x() { return 1.0; }\n")
    (tmp_path / "m.comp").write_text('#version 450 core\n#include "common/x.glsl"\nvoid main() {}\n')
    library = gpu.ShaderLibrary(renderer().ctx, root=tmp_path)
    before = library.digest("m.comp")
    inc.write_text("float x() { return 2.0; }\n")
    assert library.digest("m.comp") != before
