"""No module of the package outside app/render/ reaches into the renderer's privates: it neither
imports a private name (one leading underscore, not a dunder) from alight.render.* nor calls or
reads a private attribute of the renderer or of an object made by alight.render. Read from the
source (ast), so a new caller of ``renderer._x`` fails here, not after the next split.

What counts as a render object, per module: a name imported from alight.render.*, an alias of
such a module, a name or attribute assigned from a call to one of those (``r = ForwardRenderer()``,
``targets = Targets(...)``) or to a method of one, and any name or attribute named like a
renderer (``self.renderer``, ``self._renderer``). What such an object holds (``renderer.shaders``,
a core.gpu ShaderLibrary) is another layer's and not checked here."""

from __future__ import annotations

import ast
import re
from pathlib import Path

APP = Path(__file__).resolve().parents[1] / "app"
RENDER = APP / "render"
RENDERER_NAME = re.compile("renderer", re.IGNORECASE)


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _is_render_module(module: str | None) -> bool:
    return module is not None and (module == "alight.render" or module.startswith("alight.render."))


class _Checker(ast.NodeVisitor):
    def __init__(self):
        self.bound: set[str] = set()     # source text of the expressions that are render objects
        self.found: list[tuple[int, str]] = []

    def _render_object(self, node: ast.AST) -> bool:
        if isinstance(node, ast.Call):   # made by alight.render, or returned by a render object's method
            func = node.func
            return self._render_object(func) or (isinstance(func, ast.Attribute) and self._render_object(func.value))
        text = ast.unparse(node)
        if text in self.bound or text.startswith("alight.render."):
            return True
        if isinstance(node, ast.Attribute):
            # (not what the renderer holds: its ctx and shaders belong to other layers)
            return bool(RENDERER_NAME.search(node.attr))
        if isinstance(node, ast.Name):
            return bool(RENDERER_NAME.search(node.id))
        return False

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            if _is_render_module(alias.name) and alias.asname:
                self.bound.add(alias.asname)

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if _is_render_module(node.module):
            for alias in node.names:
                if _private(alias.name):
                    self.found.append((node.lineno, f"from {node.module} import {alias.name}"))
                self.bound.add(alias.asname or alias.name)

    def _assign(self, targets, value) -> None:
        if value is not None and any(isinstance(n, ast.Call) and self._render_object(n) for n in ast.walk(value)):
            for target in targets:
                self.bound.add(ast.unparse(target))

    def visit_Assign(self, node: ast.Assign) -> None:
        self.generic_visit(node)
        self._assign(node.targets, node.value)

    def visit_AnnAssign(self, node: ast.AnnAssign) -> None:
        self.generic_visit(node)
        self._assign([node.target], node.value)

    def visit_Attribute(self, node: ast.Attribute) -> None:
        if _private(node.attr) and self._render_object(node.value):
            self.found.append((node.lineno, ast.unparse(node)))
        self.generic_visit(node)


def private_uses(source: str) -> list[tuple[int, str]]:
    """(line, expression) of each private use of alight.render in ``source``. Names are bound in
    source order, so a module is read twice: once to learn its render objects, once to check."""
    tree = ast.parse(source)
    learn = _Checker()
    learn.visit(tree)
    check = _Checker()
    check.bound = learn.bound
    check.visit(tree)
    return check.found


def test_no_module_outside_render_uses_a_private_of_render():
    found = []
    for path in sorted(APP.rglob("*.py")):
        if RENDER in path.parents:
            continue
        for line, text in private_uses(path.read_text(encoding="utf-8")):
            found.append(f"{path.relative_to(APP.parent)}:{line}: {text}")
    assert not found, "private uses of alight.render:\n" + "\n".join(found)


def test_the_check_finds_the_calls_the_split_removed():
    """The calls outside app/render/ before the renderer was split (each must be found), and
    their public replacements (none may be)."""
    before = '''
from alight.render.renderer import ForwardRenderer, _rotation_cos_sin, _set, _set_material

class Reference:
    def __init__(self):
        self.renderer = ForwardRenderer()

    def lights(self, scene, part):
        m = self.renderer._part_material(scene, part)[0]
        self.renderer._write_lights(scene)

def geometry(scene, part):
    return ForwardRenderer._part_material(scene, part)

class Window:
    def draw(self, prog):
        from alight.render.renderer import _Targets
        self.renderer._fullscreen(prog)
        r = ForwardRenderer()
        t = r.render_targets()
        return t._display_draw
'''
    found = {text for _, text in private_uses(before)}
    assert found == {
        "from alight.render.renderer import _rotation_cos_sin", "from alight.render.renderer import _set",
        "from alight.render.renderer import _set_material", "from alight.render.renderer import _Targets",
        "self.renderer._part_material", "self.renderer._write_lights", "ForwardRenderer._part_material",
        "self.renderer._fullscreen", "t._display_draw"}, found
    after = '''
from alight.render.bindings import set_uniform as _set
from alight.render.variants import part_material
from alight.render.targets import Targets

class Window:
    def __init__(self):
        self._renderer = None
        self._cache = {}

    def draw(self, scene, part, prog):
        part_material(scene, part)
        self.renderer.lights.write(scene)
        self.renderer.fullscreen(prog)
        return self._cache, self._renderer
'''
    assert private_uses(after) == []
