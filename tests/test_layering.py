"""The package's architecture, checked from the source: no import cycles, and the layers of
alight/__init__.py's docstring import only downwards (front ends -> ... -> core, never back).

Every import counts, lazy ones inside functions too: a cycle that only closes at run time is
still a cycle for a reader."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

APP = Path(__file__).resolve().parents[1] / "app"

# Lowest first. errors and paths stand under everything.
LAYERS = ["errors", "paths", "core", "exchange", "ibl", "render", "accuracy", "frontends"]


def module_name(path: Path) -> str:
    parts = list(path.relative_to(APP).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["alight", *parts])


def alight_imports(path: Path) -> set[str]:
    """The alight modules a file imports (``from alight.x import y`` counts as alight.x.y when
    that is a module, else alight.x)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.split(".")[0] == "alight"}
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}: relative import (use alight.…)"
            if node.module and node.module.split(".")[0] == "alight":
                for a in node.names:
                    found.add(f"{node.module}.{a.name}")
                    found.add(node.module)
    return found


def graph() -> dict[str, set[str]]:
    modules = {module_name(p): p for p in APP.rglob("*.py")}
    edges = {}
    for name, path in modules.items():
        targets = {t for t in alight_imports(path) if t in modules and t != name}
        # A package's __init__ is imported on the way to any of its modules; it is not a
        # dependency of its own modules, so only the imported module itself is kept.
        edges[name] = {t for t in targets if not any(o != t and o.startswith(t + ".") for o in targets)}
    return edges


def layer(module: str) -> int:
    parts = module.split(".")
    if len(parts) == 1 or parts[1] == "__main__":   # the public names (lazy) and python -m alight
        return len(LAYERS)
    return LAYERS.index(parts[1])


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    colour: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        colour[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if colour.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if colour.get(nxt) is None:
                found = visit(nxt)
                if found:
                    return found
        colour[node] = 2
        stack.pop()
        return None

    for node in sorted(edges):
        if node not in colour:
            found = visit(node)
            if found:
                return found
    return None


def test_every_module_is_in_a_layer():
    for name in graph():
        if layer(name) < len(LAYERS):
            assert name.split(".")[1] in LAYERS, f"{name} is in no layer of LAYERS"


def test_no_import_cycles():
    cycle = find_cycle(graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_layers_import_only_downwards():
    wrong = [f"{a} imports {b}" for a, targets in graph().items() for b in targets if layer(b) > layer(a)]
    assert not wrong, "; ".join(wrong)


@pytest.mark.parametrize("broken", ["cycle", "upward"])
def test_the_checks_fail_on_a_broken_graph(broken):
    """The checks themselves catch what they are for (a test that cannot fail proves nothing)."""
    edges = {k: set(v) for k, v in graph().items()}
    if broken == "cycle":
        edges["alight.core.material"].add("alight.core.scene")   # scene already imports material
        assert find_cycle(edges) is not None
    else:
        edges["alight.core.scene"].add("alight.frontends.cli")
        assert any(layer(b) > layer(a) for a, t in edges.items() for b in t)
