"""The documentation: the MkDocs site builds with no warning (``mkdocs build --strict``: a broken
link or anchor, a page missing from the nav or a docstring the API reference cannot read fails
it), and every repository path that README.md and the pages name in their prose exists."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

# The pages whose prose is checked: the front page, the site, the shaders' guide.
PAGES = sorted([REPO / "README.md", REPO / "shaders" / "README.md", *(REPO / "docs").rglob("*.md")])

# A token naming a repository path starts with one of these folders.
ROOTS = ("app/", "shaders/", "docs/", "benchmarks/", "tools/", "tests/", "presets/", ".ci/")
# Shader paths are often named from inside shaders/ (common/brdf.glsl) and module paths from
# inside the package (ibl/bake.py); those are checked there.
SHADER_RELATIVE = re.compile(r"^(common|ibl|render|accuracy)/[\w/]+\.(glsl|comp|frag|vert)$")
PACKAGE_RELATIVE = re.compile(r"^(core|exchange|ibl|render|accuracy|frontends)/[\w/]+\.py$")

FENCE = re.compile(r"^(```|~~~).*?^\1", re.M | re.S)
CODE_SPAN = re.compile(r"`([^`\n]+)`")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _prose(text: str) -> str:
    """The page without its fenced code blocks: commands there name files they write."""
    return FENCE.sub("", text)


def _candidates(token: str) -> list[str]:
    """Repository-relative paths a code-span token names (none if it names no path)."""
    out = []
    for word in re.split(r"[\s,;()]+", token):
        word = word.strip(".:'\"")
        if not word or "{" in word or "://" in word:
            continue
        if word.startswith(ROOTS):
            out.append(word)
        elif SHADER_RELATIVE.match(word):
            out.append("shaders/" + word)
        elif PACKAGE_RELATIVE.match(word):
            out.append("app/" + word)
        elif word.startswith("alight/") and word.endswith(".py"):
            out.append("app/" + word.removeprefix("alight/"))
    return out


def _exists(path: Path) -> bool:
    return any(path.parent.glob(path.name)) if "*" in path.name else path.exists()


def named_paths(page: Path) -> list[tuple[str, Path]]:
    """(as written, resolved path) for each repository path the page's prose names."""
    text = _prose(page.read_text(encoding="utf-8"))
    found = []
    for span in CODE_SPAN.findall(text):
        found += [(word, REPO / word) for word in _candidates(span)]
    for target in LINK.findall(text):
        if re.match(r"^[a-z]+:", target) or target.startswith("#"):
            continue
        target = target.split("#")[0]
        found.append((target, (page.parent / target).resolve()))
    return found


def test_the_path_check_finds_paths():
    # The check itself: it must see the paths this front page names, and refuse a made-up one.
    names = {written for written, _ in named_paths(REPO / "README.md")}
    assert {"docs/presets.png", "docs/conventions.md", "tools/readme_image.py"} <= names, names
    assert _candidates("app/no_such_module.py: f")[0] == "app/no_such_module.py"
    assert not _exists(REPO / "app/no_such_module.py")
    assert _candidates("common/brdf.glsl") == ["shaders/common/brdf.glsl"]
    assert _candidates("ibl/bake.py") == ["app/ibl/bake.py"]


@pytest.mark.parametrize("page", PAGES, ids=[p.relative_to(REPO).as_posix() for p in PAGES])
def test_every_path_named_in_prose_exists(page):
    missing = sorted({written for written, path in named_paths(page) if not _exists(path)})
    assert not missing, f"{page.relative_to(REPO)} names paths that do not exist: {missing}"


def test_no_page_mentions_an_issue_number():
    offenders = [f"{p.relative_to(REPO)}:{n}: {line.strip()}"
                 for p in PAGES for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
                 if re.search(r"\bissues? #?\d+", line, re.I)]
    assert not offenders, "\n".join(offenders)


def test_mkdocs_builds_strict(tmp_path):
    # strict: every warning (a link to a missing page or anchor, a page not in the nav, a
    # reference mkdocstrings cannot collect) fails the build.
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                           cwd=REPO, env=env, capture_output=True, text=True, timeout=600)
    log = built.stdout + built.stderr
    assert built.returncode == 0, log[-6000:]
    warnings = [line for line in log.splitlines() if line.startswith(("WARNING", "ERROR"))]
    assert not warnings, "\n".join(warnings)
    api = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    assert api.count("set_material") > 0
    # The docstrings are Markdown (mkdocstrings' google style): a Sphinx role such as :meth:`render`
    # showed on the page as written (the Renderer's own docstring did).
    assert not re.search(r":(meth|func|class|attr|mod):", api), re.findall(r".{40}:(?:meth|func|class):.{40}", api)


def test_no_docstring_uses_a_sphinx_role():
    """mkdocstrings renders docstrings as Markdown, where :meth:`x` is literal text: the package's
    docstrings say ``x`` (or link) instead, on the reference pages and off them."""
    role = re.compile(r":(meth|func|class|attr|mod|obj|data|exc):`")
    found = [f"{path.relative_to(REPO)}:{n}" for path in sorted((REPO / "app").rglob("*.py"))
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if role.search(line)]
    assert not found, found


def test_the_shaders_readme_lists_every_shader():
    # shaders/README.md has a table per folder ("## `common/`"); its first column names files.
    text = (REPO / "shaders" / "README.md").read_text(encoding="utf-8")
    listed: dict[str, set[str]] = {}
    for folder, body in re.findall(r"^## `(\w+)/`\n(.*?)(?=^## |\Z)", text, re.M | re.S):
        cells = [row.split("|")[1] for row in body.splitlines() if row.startswith("| `")]
        listed[folder] = {name for cell in cells for name in re.findall(r"`([\w.]+)`", cell)}
    on_disk = {d.name: {f.name for f in d.iterdir() if f.is_file()}
               for d in (REPO / "shaders").iterdir() if d.is_dir() and d.name != "__pycache__"}
    assert set(listed) == set(on_disk), (sorted(listed), sorted(on_disk))
    for folder, files in on_disk.items():
        assert listed[folder] == files, (f"shaders/README.md, {folder}/: not listed {sorted(files - listed[folder])}, "
                                         f"no such file {sorted(listed[folder] - files)}")


def test_the_readme_links_every_page_of_the_site():
    """The front page is the way in: every page of docs/ is one link from it."""
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    linked = {target.split("#")[0] for target in LINK.findall(readme)}
    pages = {p.relative_to(REPO).as_posix() for p in (REPO / "docs").rglob("*.md")}
    assert pages - linked == set(), "README.md does not link: " + ", ".join(sorted(pages - linked))


def test_the_accuracy_pages_worked_example_prints_what_it_says(tmp_path):
    """docs/explanation/accuracy.md's render / reference / compare example quotes its output; a
    new user ran it and got another number (the page still quoted an older default IBL model).
    Run the page's three commands as written and compare with the quoted relMAE."""
    page = (REPO / "docs" / "explanation" / "accuracy.md").read_text()
    block = page[page.index("## Error measures and the chart"):]
    env = re.search(r"^E=(\S+)$", block, re.M).group(1)
    quoted = float(re.search(r"^#\s+relMAE ([0-9.]+)%", block, re.M).group(1))
    lines = [ln for ln in block.splitlines() if ln.startswith(".venv/bin/alight ")][:3]
    assert [ln.split()[1] for ln in lines] == ["render", "reference", "compare"]
    printed = ""
    for line in lines:
        words = [w.replace("$E", str((REPO / env).resolve())) for w in line.split()[1:]]
        words = [w.split("#")[0] for w in words if not w.startswith("#")]
        run = subprocess.run([sys.executable, "-m", "alight", *words], cwd=tmp_path, capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        printed = run.stdout
    got = float(re.search(r"relMAE ([0-9.]+)%", printed).group(1))
    assert abs(got - quoted) < 0.05, f"the page quotes {quoted}%, the commands print {got}%"


# The prose that names Python objects by their dotted path: the pages above, every folder's
# README, and pyproject.toml's comments.
DOTTED_SOURCES = sorted({*PAGES, *REPO.glob("*/README.md")})
DOTTED = re.compile(r"\balight(?:\.\w+)+")


def _dotted_names() -> dict[str, set[str]]:
    """Each dotted alight name (alight.exchange.presets.load_preset) -> the files naming it."""
    found: dict[str, set[str]] = {}
    texts = [(p.relative_to(REPO).as_posix(), p.read_text(encoding="utf-8")) for p in DOTTED_SOURCES]
    comments = [line for line in (REPO / "pyproject.toml").read_text(encoding="utf-8").splitlines()
                if line.lstrip().startswith("#")]
    texts.append(("pyproject.toml", "\n".join(comments)))
    for where, text in texts:
        for name in DOTTED.findall(text):
            found.setdefault(name, set()).add(where)
    return found


def _resolves(name: str) -> bool:
    """Whether a dotted name imports: the longest importable module, then attributes."""
    import importlib
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def test_every_dotted_name_in_the_docs_imports():
    """A newcomer grepped for alight.core.material.load_preset (presets/README.md) and
    alight.ibl.environment.box_reduce; both had moved. Every alight.x.y the docs, the READMEs and
    pyproject.toml's comments name must import."""
    names = _dotted_names()
    assert "alight.exchange.presets.load_preset" in names      # the check sees what it should
    assert not _resolves("alight.core.material.load_preset")
    stale = {name: sorted(where) for name, where in names.items() if not _resolves(name)}
    assert not stale, f"dotted names that do not import: {stale}"


FROM_IMPORT = re.compile(r"^[ \t]*from[ \t]+(alight(?:\.\w+)*)[ \t]+import[ \t]+(?:\(([\w\s,]+)\)|([\w \t,]+))", re.M)


def test_every_from_import_in_the_docs_imports():
    """A new user pasted docs/guides/gltf-export.md's `from alight.exchange.gltf_material import
    ..., export_mesh_glb` and got an ImportError (the function lives in gltf_export); the dotted
    names check above does not see names after `import`. Every `from alight.x import a, b` in the
    docs and READMEs must import each name."""
    bad = []
    for path in DOTTED_SOURCES:
        for module, grouped, names in FROM_IMPORT.findall(path.read_text(encoding="utf-8")):
            for name in (n.strip() for n in (grouped or names).split(",")):
                if name and name.isidentifier() and not _resolves(f"{module}.{name}"):
                    bad.append(f"{path.relative_to(REPO).as_posix()}: from {module} import {name}")
    assert FROM_IMPORT.findall("from alight.x import (a,\n  b)\nfrom alight.y import c  # d\n") == [
        ("alight.x", "a,\n  b", ""), ("alight.y", "", "c  ")]
    assert not bad, bad


def _nav_pages(nav) -> set[str]:
    """Every page file in mkdocs.yml's nav (nested sections included)."""
    if isinstance(nav, str):
        return {nav}
    if isinstance(nav, dict):
        return {page for value in nav.values() for page in _nav_pages(value)}
    return {page for item in nav for page in _nav_pages(item)}


def test_the_home_page_links_every_page_of_the_nav():
    """docs/index.md sorts the pages by reader (Use it / Understand it / Look it up / Change it);
    a newcomer found 17 of 33 pages missing from it. Every page in the nav is linked from it."""
    import yaml
    text = (REPO / "mkdocs.yml").read_text(encoding="utf-8")
    nav = yaml.safe_load(text[text.index("\nnav:"):])["nav"]
    pages = _nav_pages(nav) - {"index.md"}
    linked = {target.split("#")[0] for target in LINK.findall((REPO / "docs" / "index.md").read_text(encoding="utf-8"))}
    assert pages - linked == set(), "docs/index.md does not link: " + ", ".join(sorted(pages - linked))


def test_the_pages_that_list_the_layers_name_every_layer():
    """The front page, the home page and the layers guide list the glTF layers; each listed only
    the first five after iridescence, dispersion and diffuse transmission came."""
    from alight.core.material import LAYERS
    for page in ("README.md", "docs/index.md", "docs/guides/material-layers.md"):
        text = " ".join((REPO / page).read_text(encoding="utf-8").split())
        missing = [layer for layer in LAYERS if layer.replace("_", " ") not in text and f"_{layer}" not in text]
        assert not missing, f"{page} does not name the layers {missing}"


def test_the_presets_readme_names_every_layer_field():
    """presets/README.md's field table lists the layers' fields a preset file may carry."""
    from alight.core.material import LAYER_FIELDS
    text = (REPO / "presets" / "README.md").read_text(encoding="utf-8")
    row = next(line for line in text.splitlines() if line.startswith("| the layers' fields"))
    assert set(re.findall(r"`(\w+)`", row)) == set(LAYER_FIELDS)


def layout_block() -> dict[str, str]:
    """docs/development.md's layout block, the app/ tree: each entry's path under app/ (as
    "core/layers/", "core/gpu.py") -> its line. An entry is a line indented by two spaces per
    level, its first word the name; deeper-indented lines continue the one above."""
    text = (REPO / "docs" / "development.md").read_text(encoding="utf-8")
    block = text[text.index("```\napp/ ") + 4:]
    block = block[:block.index("```")]
    entries: dict[str, str] = {}
    stack: list[str] = []                       # the folders open at each depth
    for line in block.splitlines():
        indent = len(line) - len(line.lstrip(" "))
        if not line.strip() or indent >= 24:    # a continuation of the line above
            continue
        if indent == 0 and stack and line.split()[0] != "app/":
            break                               # shaders/, presets/, ...: outside the package
        depth, name = indent // 2, line.split()[0]
        if indent == 0:
            stack = []
            continue
        stack = stack[:depth - 1]
        entries["".join(stack) + name] = line
        if name.endswith("/"):
            stack.append(name)
    return entries


def test_the_layout_names_every_module():
    """A newcomer found 26 modules missing from the layout block: a module added without a line
    there fails this, and so does a line whose module is gone."""
    app = REPO / "app"
    on_disk = set()
    for path in app.rglob("*"):
        rel = path.relative_to(app).as_posix()
        if "__pycache__" in rel:
            continue
        if path.is_dir():
            on_disk.add(rel + "/")
        elif path.suffix == ".py" and path.name not in ("__init__.py", "__main__.py"):
            on_disk.add(rel)
    listed = layout_block()
    assert "core/layers/stack.py" in listed and "frontends/editor/" in listed     # the parser works
    missing = sorted(on_disk - set(listed))
    gone = sorted(name for name in listed if not (app / name).exists())
    assert not missing, f"docs/development.md's layout has no line for {missing}"
    assert not gone, f"docs/development.md's layout names what app/ does not hold: {gone}"


def test_the_benchmarks_readme_lists_every_script():
    """benchmarks/README.md's "Every script" table names exactly the bench_*.py files on disk (a
    newcomer found 24 of 51 undescribed, while docs/performance.md said every one was)."""
    text = (REPO / "benchmarks" / "README.md").read_text(encoding="utf-8")
    section = re.search(r"^## Every script\n(.*?)(?=^## |\Z)", text, re.M | re.S).group(1)
    listed = set(re.findall(r"^\| `(bench_\w+\.py)` \|", section, re.M))
    on_disk = {p.name for p in (REPO / "benchmarks").glob("bench_*.py")}
    assert listed == on_disk, f"not listed: {sorted(on_disk - listed)}, no such script: {sorted(listed - on_disk)}"
