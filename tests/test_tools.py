"""The scripts under tools/ (the README's images, the sheets, the measurements) are run by hand,
not by the tests; a rename in alight must not leave one broken. Each ``from alight... import
name`` in them, at any depth (most import inside their functions), names a module and an
attribute that exist."""

from __future__ import annotations

import ast
import importlib
import importlib.util
from pathlib import Path

import pytest

TOOLS = sorted((Path(__file__).resolve().parents[1] / "tools").glob("*.py"))


@pytest.mark.parametrize("path", TOOLS, ids=[p.name for p in TOOLS])
def test_every_alight_import_in_a_tool_resolves(path):
    found = 0
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "alight":
            module = importlib.import_module(node.module)
            for alias in node.names:
                assert hasattr(module, alias.name) or importlib.util.find_spec(f"{node.module}.{alias.name}"), \
                    f"{path.name}:{node.lineno}: {node.module} has no {alias.name}"
                found += 1
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "alight":
                    importlib.import_module(alias.name)
                    found += 1
    assert found, f"{path.name} imports nothing from alight: is it still a tool of this project?"
