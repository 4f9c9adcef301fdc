"""The OpenGL context (headless EGL) and shader programs read from ``shaders/`` with #include."""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import hashlib
import re
from dataclasses import dataclass, field
from pathlib import Path

import moderngl

from alight.core.shader_names import SHADER_OPTIONS, glsl_header
from alight.errors import AlightError
from alight.paths import shader_dir

# What to install when EGL or Mesa is missing; the message names them on one line.
EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1"

GL_VERSION = 450


def create_headless_context() -> moderngl.Context:
    """An OpenGL 4.5 core context through EGL, with no window and no display server.

    Mesa's llvmpipe answers on a machine without a GPU; NVIDIA's EGL on a machine with one.
    """
    if ctypes.util.find_library("EGL") is None:
        raise AlightError(f"OpenGL: libEGL is not installed: apt-get install {EGL_PACKAGES}")
    try:
        return moderngl.create_context(standalone=True, backend="egl", require=GL_VERSION)
    except Exception as exc:  # glcontext raises plain Exceptions with multi-line text
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise AlightError(
            f"OpenGL: no EGL context with OpenGL {GL_VERSION // 100}.{GL_VERSION % 100 // 10} ({reason}); "
            f"on Debian install {EGL_PACKAGES}"
        ) from None


def release_objects(ctx: moderngl.Context, *objects) -> None:
    """Release GL objects (None skipped), unbinding first a framebuffer among them that is bound.

    moderngl keeps the bound framebuffer to restore it after creating another, reading one or
    clearing: restoring a deleted one is GL_INVALID_OPERATION, and once the driver hands its name
    to a new framebuffer it silently binds that one instead. Every framebuffer alight releases
    goes through here."""
    bound = ctx.fbo
    if bound is not None and any(obj is bound for obj in objects):
        # Framebuffer 0: the window's, or in a context without one, the name that is never deleted.
        (ctx.screen or ctx.detect_framebuffer(0)).use()
    for obj in objects:
        if obj is not None:
            obj.release()


def describe(ctx: moderngl.Context) -> str:
    return f"{ctx.info['GL_RENDERER']} / OpenGL {ctx.info['GL_VERSION']}"


_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
# Line numbers carry the file: line = file_index * LINE_STRIDE + line_in_file. Drivers disagree
# on the source-string number of #line (Mesa reports 0 for some errors), never on the line.
LINE_STRIDE = 100000
_VERSION = re.compile(r"^\s*#\s*version\b")


@dataclass
class ShaderSource:
    """A shader's text with its includes resolved, and the files it came from (for error lines)."""

    text: str
    files: list[Path] = field(default_factory=list)

    def digest(self) -> str:
        return hashlib.sha256(self.text.encode()).hexdigest()


class ShaderCompileError(AlightError):
    pass


def load_source(name: str, defines: dict[str, object] | None = None, root: Path | None = None) -> ShaderSource:
    """Read ``shaders/<name>``, inline each ``#include "path"`` once (relative to shaders/), and put
    ``#define``s after ``#version``: first the names both languages share
    (``app/core/shader_names.py``'s ``glsl_defines``), then ``defines``. ``#line`` directives carry a
    file number so that compiler messages can be mapped back to the file and line (see
    ``translate_log``). For alight's own shaders (``root`` None) a define that
    ``shader_names.SHADER_OPTIONS`` does not declare is refused (ShaderCompileError): a misspelt
    option would otherwise compile the default silently."""
    if root is None:
        unknown = sorted(set(defines or {}) - set(SHADER_OPTIONS))
        if unknown:
            raise ShaderCompileError(f"{name}: shader option(s) {', '.join(unknown)} not declared in "
                                     "app/core/shader_names.py SHADER_OPTIONS")
    root = root or shader_dir()
    files: list[Path] = []
    included: set[Path] = set()

    def expand(path: Path) -> list[str]:
        try:
            lines = path.read_text(encoding="utf-8").splitlines()
        except OSError as exc:
            raise ShaderCompileError(f"{path}: cannot read shader ({exc.strerror})") from None
        files.append(path)
        index = len(files) - 1
        # Each file's lines carry its own number, so compiler messages name the right file.
        out: list[str] = [f"#line {index * LINE_STRIDE + 1}"] if index > 0 else []
        for number, line in enumerate(lines, start=1):
            match = _INCLUDE.match(line)
            if match:
                target = (root / match.group(1)).resolve()
                if target not in included:
                    included.add(target)
                    out.extend(expand(target))
                out.append(f"#line {index * LINE_STRIDE + number + 1}")
            else:
                out.append(line)
        return out

    top = (root / name).resolve()
    included.add(top)
    body = expand(top)
    header: list[str] = []
    first_line = 1
    if body and _VERSION.match(body[0]):
        header.append(body.pop(0))
        first_line = 2
    else:
        header.append(f"#version {GL_VERSION} core")
    header.extend(glsl_header())
    for key, value in (defines or {}).items():
        header.append(f"#define {key} {value}" if value is not None else f"#define {key}")
    header.append(f"#line {first_line}")
    return ShaderSource("\n".join(header + body) + "\n", files)


def translate_log(log: str, files: list[Path], root: Path | None = None) -> str:
    """Turn Mesa's ``S:L(C): error`` and NVIDIA's ``S(L) : error`` into ``file:line: error``,
    the file being encoded in L (see LINE_STRIDE)."""
    root = root or shader_dir()

    def where(line: str) -> str:
        index, number = divmod(int(line), LINE_STRIDE)
        if 0 <= index < len(files):
            try:
                name = str(files[index].relative_to(root.parent))
            except ValueError:
                name = str(files[index])
        else:
            name = f"<source {index}>"
        return f"{name}:{number}:"

    log = re.sub(r"\b\d+:(\d+)\(\d+\):", lambda m: where(m.group(1)), log)
    log = re.sub(r"\b\d+\((\d+)\) :", lambda m: where(m.group(1)), log)
    return log


def first_error_line(log: str) -> str:
    for line in log.splitlines():
        if "error" in line.lower():
            return line.strip()
    return " ".join(log.split())[:300]


class ProgramPending(Exception):
    """A program the library's ``gate`` held back (not compiled yet): the caller draws something
    else meanwhile. ``key``: the program's key (``ShaderLibrary.program_key``)."""

    def __init__(self, key: tuple):
        super().__init__(f"program not compiled yet: {key[1]} + {key[2]}")
        self.key = key


class ShaderLibrary:
    """Compiles programs from ``shaders/`` on demand and keeps them until ``reload``.

    Programs are keyed by their stage files and defines, so asking twice costs nothing.
    ``gate``: None (compile whatever is asked), or a function of a program's key that says
    whether it may be compiled now; where it says no, ``program`` raises ProgramPending (the
    editor compiles new variants in a process of its own first: a software GL's first draw of a
    variant takes seconds, and the driver's shader cache then makes it fast here).
    """

    def __init__(self, ctx: moderngl.Context, root: Path | None = None):
        self.ctx = ctx
        self.root = root or shader_dir()
        self._programs: dict[tuple, moderngl.Program | moderngl.ComputeShader] = {}
        self.gate = None

    @staticmethod
    def program_key(vertex: str, fragment: str, defines: dict[str, object] | None = None) -> tuple:
        return ("program", vertex, fragment, tuple(sorted((defines or {}).items())))

    def compiled_keys(self) -> list[tuple]:
        """The keys of the programs compiled so far."""
        return [k for k in self._programs if k[0] == "program"]

    def _compile(self, key, build):
        if key not in self._programs:
            self._programs[key] = build()
        return self._programs[key]

    def program(self, vertex: str, fragment: str, defines: dict[str, object] | None = None) -> moderngl.Program:
        defines = defines or {}
        key = self.program_key(vertex, fragment, defines)
        if self.gate is not None and key not in self._programs and not self.gate(key):
            raise ProgramPending(key)

        def build():
            vs = load_source(vertex, defines, self.root)
            fs = load_source(fragment, defines, self.root)
            try:
                return self.ctx.program(vertex_shader=vs.text, fragment_shader=fs.text)
            except Exception as exc:
                # Both stages share file indices only by accident; try each stage's file list.
                log = str(exc)
                files = fs.files if "fragment" in log.lower() else vs.files
                raise ShaderCompileError(first_error_line(translate_log(log, files, self.root))) from None

        return self._compile(key, build)

    def compute(self, name: str, defines: dict[str, object] | None = None) -> moderngl.ComputeShader:
        defines = defines or {}
        key = ("compute", name, tuple(sorted(defines.items())))

        def build():
            src = load_source(name, defines, self.root)
            try:
                return self.ctx.compute_shader(src.text)
            except Exception as exc:
                raise ShaderCompileError(first_error_line(translate_log(str(exc), src.files, self.root))) from None

        return self._compile(key, build)

    def digest(self, name: str, defines: dict[str, object] | None = None) -> str:
        """Hash of a shader's fully expanded text: changes whenever it or an include changes."""
        return load_source(name, defines, self.root).digest()

    def reload(self) -> None:
        """Forget compiled programs; the next request recompiles from the files."""
        for prog in self._programs.values():
            prog.release()
        self._programs.clear()


# ---- what moderngl does not expose: a cube's mip levels allocated and written directly ----
# moderngl allocates only level 0 of a cube (build_mipmaps allocates the rest by filtering
# level 0: on llvmpipe about 65 ms per float cube, thrown away when a pass then writes every
# level) and writes only level 0. These call glTexImage2D on the cube's own GL name.
GL_TEXTURE_CUBE_MAP = 0x8513
GL_TEXTURE_CUBE_MAP_POSITIVE_X = 0x8515
GL_TEXTURE_BASE_LEVEL = 0x813C
GL_TEXTURE_MAX_LEVEL = 0x813D
GL_RGBA32F = 0x8814
GL_RGBA = 0x1908
GL_FLOAT = 0x1406
GL_TEXTURE_2D = 0x0DE1
GL_RGBA8 = 0x8058
GL_SRGB8_ALPHA8 = 0x8C43
GL_UNSIGNED_BYTE = 0x1401


@functools.lru_cache(maxsize=1)
def _gl():
    """glTexImage2D and glTexParameteri of the current EGL context (core functions, so
    eglGetProcAddress returns them on every EGL 1.5 driver, Mesa's and NVIDIA's)."""
    egl = ctypes.CDLL(ctypes.util.find_library("EGL"))
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

    def function(name: str, *argtypes):
        address = egl.eglGetProcAddress(name.encode())
        if not address:
            raise AlightError(f"OpenGL: {name} is missing from the driver")
        return ctypes.CFUNCTYPE(None, *argtypes)(address)

    u, i, p = ctypes.c_uint, ctypes.c_int, ctypes.c_void_p
    return {"TexImage2D": function("glTexImage2D", u, i, i, i, i, i, u, u, p),
            "TexParameteri": function("glTexParameteri", u, u, i),
            "TexSubImage2D": function("glTexSubImage2D", u, i, i, i, i, i, u, u, p),
            "GetTexImage": function("glGetTexImage", u, i, u, u, p)}


def float_cube(ctx: moderngl.Context, size: int, levels: int, data=None) -> moderngl.TextureCube:
    """An RGBA float32 cube with ``levels`` mip levels allocated (complete at that range).
    ``data``: None (contents undefined: a pass writes every level), or per level a
    (6, size >> level, size >> level, 4) float32 array in OpenGL's face order, row 0 first in
    memory (as ``alight.ibl.bake.read_cube`` returns them)."""
    import numpy as np

    tex = ctx.texture_cube((size, size), 4, dtype="f4")
    gl = _gl()
    tex.use(ctx.default_texture_unit)     # binds it on moderngl's own scratch unit
    for level in range(levels):
        s = max(1, size >> level)
        faces = None
        if data is not None:
            faces = np.ascontiguousarray(data[level], dtype=np.float32)
            if faces.shape != (6, s, s, 4):
                tex.release()
                raise ValueError(f"level {level}: shape {faces.shape}, expected {(6, s, s, 4)}")
        for face in range(6):
            if faces is None and level == 0:
                continue   # moderngl allocated level 0
            pointer = faces[face].ctypes.data if faces is not None else None
            gl["TexImage2D"](GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, level, GL_RGBA32F, s, s, 0, GL_RGBA, GL_FLOAT,
                             pointer)
    gl["TexParameteri"](GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BASE_LEVEL, 0)
    gl["TexParameteri"](GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, levels - 1)
    tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR if levels > 1 else moderngl.LINEAR, moderngl.LINEAR)
    return tex


def rgba8_texture(ctx: moderngl.Context, size: tuple[int, int], levels: int, srgb: bool) -> moderngl.Texture:
    """An RGBA8 (or SRGB8_ALPHA8) 2D texture with ``levels`` mip levels allocated, contents
    undefined: the caller writes each with ``write_rgba8`` (in pieces if it likes; moderngl's own
    write refuses a level it did not make).
    For levels made on the CPU beforehand (alight.render.mesh_upload) instead of build_mipmaps,
    which on llvmpipe filters on the GL thread (about 0.1 s a 2048² map)."""
    w, h = size
    tex = ctx.texture((w, h), 4, None, internal_format=GL_SRGB8_ALPHA8 if srgb else None)
    if levels > 1:
        gl = _gl()
        tex.use(ctx.default_texture_unit)     # binds it on moderngl's own scratch unit
        for n in range(1, levels):
            gl["TexImage2D"](GL_TEXTURE_2D, n, GL_SRGB8_ALPHA8 if srgb else GL_RGBA8, max(1, w >> n), max(1, h >> n),
                             0, GL_RGBA, GL_UNSIGNED_BYTE, None)
        gl["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0)
        gl["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels - 1)
    return tex


def rgba32f_texture(ctx: moderngl.Context, size: tuple[int, int], levels: int) -> moderngl.Texture:
    """An RGBA float32 2D texture with ``levels`` mip levels allocated (complete at that range),
    contents undefined: a compute pass writes each level as an image (alight.render.normal_spread_pass).
    moderngl would allocate the levels only by build_mipmaps, a filter pass over garbage."""
    w, h = size
    tex = ctx.texture((w, h), 4, None, dtype="f4")
    gl = _gl()
    tex.use(ctx.default_texture_unit)     # binds it on moderngl's own scratch unit
    for n in range(1, levels):
        gl["TexImage2D"](GL_TEXTURE_2D, n, GL_RGBA32F, max(1, w >> n), max(1, h >> n), 0, GL_RGBA, GL_FLOAT, None)
    gl["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0)
    gl["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels - 1)
    tex.filter = (moderngl.NEAREST_MIPMAP_NEAREST if levels > 1 else moderngl.NEAREST, moderngl.NEAREST)
    return tex


def write_rgba8(ctx: moderngl.Context, tex: moderngl.Texture, level: int, y0: int, rows) -> None:
    """``rows`` ((n, w, 4) uint8, bottom row first) into level ``level`` of ``tex`` (made by
    ``rgba8_texture``) from row ``y0`` up."""
    import numpy as np

    data = np.ascontiguousarray(rows, dtype=np.uint8)
    tex.use(ctx.default_texture_unit)     # binds it on moderngl's own scratch unit
    _gl()["TexSubImage2D"](GL_TEXTURE_2D, level, 0, y0, data.shape[1], data.shape[0], GL_RGBA, GL_UNSIGNED_BYTE,
                           data.ctypes.data)


def read_rgba8(ctx: moderngl.Context, tex: moderngl.Texture, level: int):
    """Level ``level`` of an RGBA8 2D texture as an (h, w, 4) uint8 array, bottom row first: also a
    level moderngl did not make (``rgba8_texture``'s, which its own read refuses). For tests."""
    import numpy as np

    w, h = max(1, tex.width >> level), max(1, tex.height >> level)
    out = np.empty((h, w, 4), np.uint8)
    tex.use(ctx.default_texture_unit)     # binds it on moderngl's own scratch unit
    _gl()["GetTexImage"](GL_TEXTURE_2D, level, GL_RGBA, GL_UNSIGNED_BYTE, out.ctypes.data)
    return out
