"""``alight batch SPEC.toml|.json``: meshes x environments x materials x angles -> images.

A spec (paths are relative to the spec file's folder)::

    out = "renders"                 # output folder (default: the spec's stem)
    size = 256                      # or [W, H]
    quality = "low"                 # bake quality: low | medium | high
    meshes = ["sphere", "models/duck.glb"]
    environments = ["studio", "env/venice.hdr"]
    materials = ["gold", "my_preset.json", "model.glb", {name = "rough_gold", preset = "gold", roughness = 0.6},
                 {name = "rock", texture_set = "maps/rock", maps = {normal_dx = "maps/rock_n.png"}}]
    camera_angles = [0, 90]         # orbit about +Y, degrees (default [0])
    environment_angles = [0]        # environment rotation, degrees (default [0])
    contact_sheet = true            # contact_sheet.png with every still, labelled
    mesh_shading = "auto"           # or "forward", "vbuffer" (alight render --mesh-shading)
    [turntable]                     # optional: N frames per mesh x environment x material
    frames = 24
    rotate = "camera"               # or "environment"
    format = "gif"                  # or "apng"

Stills are named ``{mesh}__{env}__{material}__cam{deg}_env{deg}.png``; turntables go to
``turntable/{mesh}__{env}__{material}/frame_{i:03d}.png`` plus ``{...}.gif`` (or ``.apng``).
An output newer than the spec and every input file is up to date and skipped on a rerun.
A failed item is reported with its reason and the rest go on; the run ends with a summary.
Items run in a process pool (``spawn``: one GL context per worker process, created lazily).
"""

from __future__ import annotations

import concurrent.futures
import difflib
import itertools
import json
import math
import multiprocessing
import os
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from alight.errors import AlightError
from alight.frontends.batch_worker import MATERIAL_FIELDS, render_item
from alight.frontends.scene_setup import closest_environment

# The materials entry that draws each mesh file's own materials (the default material on a built-in).
OWN = "own"
BATCH_MAX_SIDE = 8192   # _size_and_quality says why it is below alight render's 16384
_KEYS = {"out", "size", "quality", "meshes", "environments", "materials", "camera_angles",
         "environment_angles", "contact_sheet", "turntable", "aa", "tonemap", "background", "shadows", "ground",
         "mesh_shading"}
_TURNTABLE_KEYS = {"frames", "rotate", "format", "fps"}


@dataclass
class Item:
    """One image to render; plain data so it pickles to a worker process."""

    name: str
    out: str
    mesh: str
    environment: str
    material: Any  # a string (preset name or file) or a dict with "preset"/"from" and fields
    camera_deg: float
    environment_deg: float
    size: tuple[int, int]
    quality: str
    aa: str = "msaa"
    tonemap: str = "aces"
    background: str = "env"
    shadows: str = "auto"     # alight.render.shadows
    ground: bool = False      # alight.render.ground
    mesh_shading: str = "auto"   # alight.render.vbuffer: auto, forward or vbuffer
    variant: str | None = None   # the meshes' material variant (KHR_materials_variants; --variant)
    inputs: list[str] = field(default_factory=list)  # files whose change makes the output stale
    label: str = ""


@dataclass
class Animation:
    out: Path
    frames: list[Path]
    fps: float


@dataclass
class Plan:
    spec_path: Path
    out_dir: Path
    stills: list[Item]
    frames: list[Item]
    animations: list[Animation]
    contact_sheet: bool


# --- the spec ------------------------------------------------------------------------------

def load_spec(path: str | os.PathLike) -> dict:
    p = Path(path)
    if p.suffix.lower() not in (".toml", ".json"):
        raise AlightError(f"{p}: a batch spec is .toml or .json, not '{p.suffix}'")
    try:
        data = p.read_bytes()
    except OSError as e:
        raise AlightError(f"{p}: cannot read ({e.strerror or e})") from None
    try:
        if p.suffix.lower() == ".toml":
            import tomllib

            spec = tomllib.loads(data.decode("utf-8"))
        else:
            spec = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:  # TOMLDecodeError and JSONDecodeError are ValueErrors
        raise AlightError(f"{p}: not valid {p.suffix[1:].upper()} ({' '.join(str(e).split())})") from None
    if not isinstance(spec, dict):
        raise AlightError(f"{p}: expected a table/object at the top")
    return spec


def _list(spec: dict, key: str, default: list, source: Path, kind: type | tuple = str) -> list:
    value = spec.get(key, default)
    if not isinstance(value, list) or not value:
        raise AlightError(f"{source}: '{key}' must be a non-empty list")
    for v in value:
        if not isinstance(v, kind) or isinstance(v, bool):
            raise AlightError(f"{source}: '{key}': {v!r} is not a {getattr(kind, '__name__', 'valid entry')}")
    return value


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "x"


def _resolve(base: Path, spec: str, builtins: tuple[str, ...]) -> str:
    return spec if spec in builtins else str((base / spec) if not Path(spec).is_absolute() else Path(spec))


def _material_label(m: Any, source: Path) -> str:
    if isinstance(m, str):
        return Path(m).stem if ("/" in m or "." in m) else m
    if isinstance(m, dict):
        unknown = set(m) - MATERIAL_FIELDS - {"name", "preset", "from", "texture_set", "maps"}
        if unknown:
            raise AlightError(f"{source}: material {m!r}: unknown field {sorted(unknown)[0]!r}")
        label = str(m.get("name") or m.get("preset") or Path(str(m.get("from", "material"))).stem)
        _check_fields(m, f"{source}: material {label!r}")
        return label
    raise AlightError(f"{source}: material {m!r} is not a name, a file or a table")


def _check_fields(m: dict, source: str) -> None:
    """The spec's field values checked against the model's ranges before anything renders (the
    same check the worker's Renderer.set_material applies), so a bad value stops the plan."""
    from alight.core.material import Material, with_overrides

    given = {k: (tuple(v) if isinstance(v, list) else v) for k, v in m.items() if k in MATERIAL_FIELDS}
    if given:
        with_overrides(Material(), source, **given)


def _material_inputs(m: Any, base: Path) -> tuple[Any, list[str]]:
    """The material with file paths made absolute, and the files it depends on."""
    from alight.paths import preset_dir

    if m == OWN:
        return m, []

    def one(text: str) -> tuple[str, str | None]:
        preset = preset_dir() / f"{text}.json"
        if preset.is_file():
            return text, str(preset)
        p = Path(text) if Path(text).is_absolute() else base / text
        return str(p), str(p)

    if isinstance(m, str):
        spec, dep = one(m)
        return spec, [dep] if dep else []
    m = dict(m)
    deps = []
    for key in ("preset", "from"):
        if key in m:
            m[key], dep = one(str(m[key]))
            deps += [dep] if dep else []
    # A texture set (a folder; its images are the inputs) and maps {slot: path} (the same slot
    # names as 'alight render --map'), relative to the spec's folder.
    if "texture_set" in m:
        folder = Path(str(m["texture_set"]))
        folder = folder if folder.is_absolute() else base / folder
        m["texture_set"] = str(folder)
        if folder.is_dir():
            deps += sorted(str(p) for p in folder.iterdir() if p.is_file())
    if "maps" in m:
        if not isinstance(m["maps"], dict) or not all(isinstance(v, str) for v in m["maps"].values()):
            raise AlightError(f"material {m.get('name', '')!r}: 'maps' must be a table of slot = \"path\"")
        m["maps"] = {k: str(Path(v) if Path(v).is_absolute() else base / v) for k, v in m["maps"].items()}
        deps += list(m["maps"].values())
    return m, deps


def plan(spec_path: str | os.PathLike, out: str | os.PathLike | None = None, variant: str | None = None) -> Plan:
    """Every item of a spec, named, with its inputs (no rendering). ``variant``: alight batch
    --variant, the material variant every mesh is drawn with (each mesh must have it; checked
    here from the files' JSON), its name added to the meshes' names in the outputs."""
    from alight.core.mesh import BUILTIN_MESHES

    source = Path(spec_path)
    spec = load_spec(source)
    unknown = set(spec) - _KEYS
    if unknown:
        key = sorted(unknown)[0]
        close = difflib.get_close_matches(str(key), sorted(_KEYS), n=1)
        hint = f"; did you mean {close[0]}?" if close else ""
        raise AlightError(f"{source}: unknown key {key!r}{hint} (known: {', '.join(sorted(_KEYS))})")
    base = source.resolve().parent
    size, quality = _size_and_quality(spec, source)
    meshes = _list(spec, "meshes", ["sphere"], source)
    envs = _list(spec, "environments", ["studio"], source)
    materials = _list(spec, "materials", [OWN] if variant is not None else ["gold"], source, (str, dict))
    cams = _list(spec, "camera_angles", [0], source, (int, float))
    env_angles = _list(spec, "environment_angles", [0], source, (int, float))
    options = _item_options(spec, source)
    out_dir = Path(out) if out is not None else base / str(spec.get("out", source.stem))
    mesh_names, env_names, mat_names = _output_names(meshes, envs, materials, source)
    if variant is not None:
        _check_variant(source, base, meshes, materials, variant)
        mesh_names = [f"{n}-{_slug(variant)}" for n in mesh_names]

    spec_deps = [str(source)]
    _check_inputs_exist(source, base, meshes, envs, materials)

    def item(mi, ei, ki, cam, env_deg, out_path: Path, label: str) -> Item:
        mesh = _resolve(base, meshes[mi], BUILTIN_MESHES)
        env = _resolve(base, envs[ei], ("studio",))
        material, mat_deps = _material_inputs(materials[ki], base)
        deps = spec_deps + mat_deps + [p for p in (mesh, env) if p not in BUILTIN_MESHES and p != "studio"]
        return Item(name=out_path.relative_to(out_dir).as_posix(), out=str(out_path), mesh=mesh, environment=env,
                    material=material, camera_deg=float(cam), environment_deg=float(env_deg),
                    size=(size[0], size[1]), quality=quality, inputs=deps, label=label, variant=variant,
                    **options)

    stills = []
    for (mi, ei, ki), cam, env_deg in itertools.product(
            itertools.product(range(len(meshes)), range(len(envs)), range(len(materials))), cams, env_angles):
        stem = f"{mesh_names[mi]}__{env_names[ei]}__{mat_names[ki]}"
        name = f"{stem}__cam{_deg(cam)}_env{_deg(env_deg)}.png"
        label = f"{mesh_names[mi]} / {env_names[ei]}\n{mat_names[ki]}  cam {cam:g} env {env_deg:g}"
        stills.append(item(mi, ei, ki, cam, env_deg, out_dir / name, label))

    frames, animations = [], []
    tt = spec.get("turntable")
    if tt is not None:
        n, rotate, fmt, fps = _turntable(tt, source)
        for mi, ei, ki in itertools.product(range(len(meshes)), range(len(envs)), range(len(materials))):
            stem = f"{mesh_names[mi]}__{env_names[ei]}__{mat_names[ki]}"
            paths = []
            for i in range(n):
                angle = 360.0 * i / n
                cam, env_deg = (angle, env_angles[0]) if rotate == "camera" else (cams[0], angle)
                p = out_dir / "turntable" / stem / f"frame_{i:03d}.png"
                frames.append(item(mi, ei, ki, cam, env_deg, p, stem))
                paths.append(p)
            animations.append(Animation(out_dir / "turntable" / f"{stem}.{fmt}", paths, float(fps)))
    return Plan(source, out_dir, stills, frames, animations, bool(spec.get("contact_sheet", True)))


def _check_variant(source: Path, base: Path, meshes: list, materials: list, variant: str) -> None:
    """--variant checked before anything renders: a material entry that draws the meshes' own
    materials ("own"), and every mesh a glTF file with a variant of that name. One line each."""
    from alight.core.mesh import BUILTIN_MESHES
    from alight.exchange.gltf import gltf_variant_names

    if OWN not in materials:
        raise AlightError(f"{source}: --variant {variant}: every material of the spec replaces the meshes' own "
                          f"materials, so no variant would show; add \"{OWN}\" to 'materials'")
    for i, m in enumerate(meshes):
        path = _resolve(base, m, BUILTIN_MESHES)
        where = f"{source}: meshes[{i}]: --variant {variant}"
        if m in BUILTIN_MESHES or Path(path).suffix.lower() not in (".gltf", ".glb"):
            raise AlightError(f"{where}: {m} has no material variants (KHR_materials_variants is glTF's)")
        names = gltf_variant_names(path)
        if not names:
            raise AlightError(f"{where}: {m} has no material variants (KHR_materials_variants)")
        if variant not in names:
            raise AlightError(f"{where}: {m} has no material variant named {variant!r}; its variants: "
                              + ", ".join(repr(n) for n in names))


def _check_inputs_exist(source: Path, base: Path, meshes: list, envs: list, materials: list) -> None:
    """Every file or folder the spec names, found before anything renders: a missing one stops
    the plan with one line naming the spec, the entry and the path (else each of its items
    would fail in turn, hundreds of lines for one typo)."""
    from alight.core.mesh import BUILTIN_MESHES

    named = [(f"meshes[{i}]", _resolve(base, m, BUILTIN_MESHES)) for i, m in enumerate(meshes)
             if m not in BUILTIN_MESHES]
    named += [(f"environments[{i}]", _resolve(base, e, ("studio",))) for i, e in enumerate(envs) if e != "studio"]
    for i, m in enumerate(materials):
        material, deps = _material_inputs(m, base)
        folder = material.get("texture_set") if isinstance(material, dict) else None
        named += [(f"materials[{i}]", d) for d in deps] + ([(f"materials[{i}]", folder)] if folder else [])
    for where, path in named:
        if not Path(path).exists():
            text = Path(path).name
            if where.startswith("materials") and "." not in text:   # a name, not a file: a preset?
                from alight.exchange.presets import did_you_mean
                from alight.paths import preset_dir

                names = ", ".join(sorted(p.stem for p in preset_dir().glob("*.json")))
                raise AlightError(f"{source}: {where}: {text!r} is neither a preset nor a file{did_you_mean(text)} "
                                  f"(presets: {names})")
            hint = closest_environment(path) if where.startswith("environments") else ""
            raise AlightError(f"{source}: {where}: {path}: no such file or folder{hint} "
                              f"(paths are relative to the spec's folder)")


def _size_and_quality(spec: dict, source: Path) -> tuple[list[int], str]:
    """The spec's size ([W, H]) and bake quality, checked."""
    size = spec.get("size", 256)
    size = [size, size] if isinstance(size, int) and not isinstance(size, bool) else size
    # Lower than alight render's 16384: a batch worker renders each image whole in memory
    # (Renderer.save) where alight render draws and writes strip by strip, and several workers run
    # at once; 16384x16384 float RGBA is 4 GiB per worker before the PNG's copy.
    if not (isinstance(size, list) and len(size) == 2
            and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= BATCH_MAX_SIDE for x in size)):
        raise AlightError(f"{source}: 'size' must be an integer or [W, H], 1..{BATCH_MAX_SIDE} (each batch worker "
                          f"holds its whole image in memory, 1 GiB of float RGBA at 8192x8192; 'alight render "
                          f"--size' writes strip by strip up to 16384)")
    quality = spec.get("quality", "medium")
    if quality not in ("low", "medium", "high"):
        raise AlightError(f"{source}: 'quality' must be low, medium or high")
    return size, quality


def _item_options(spec: dict, source: Path) -> dict:
    """The Item options the spec sets (aa, tonemap, background, shadows, ground, mesh_shading), checked."""
    options = {k: spec[k] for k in ("aa", "tonemap", "background", "shadows", "ground", "mesh_shading") if k in spec}
    if options.get("mesh_shading", "auto") not in ("auto", "forward", "vbuffer"):
        raise AlightError(f"{source}: 'mesh_shading' must be auto, forward or vbuffer")
    if options.get("shadows", "auto") not in ("auto", "on", "off"):
        raise AlightError(f"{source}: 'shadows' must be auto, on or off")
    if not isinstance(options.get("ground", False), bool):
        raise AlightError(f"{source}: 'ground' must be true or false")
    return options


def _output_names(meshes: list, envs: list, materials: list, source: Path) -> tuple[list[str], list[str], list[str]]:
    """The names of the meshes, environments and materials in output file names; two alike collide."""
    mesh_names = [Path(m).stem for m in meshes]
    env_names = [Path(e).stem for e in envs]
    mat_names = [_slug(_material_label(m, source)) for m in materials]
    for what, names in (("meshes", mesh_names), ("environments", env_names), ("materials", mat_names)):
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise AlightError(f"{source}: two {what} share the name {sorted(dup)[0]!r}; output names would collide")
    return mesh_names, env_names, mat_names


def _turntable(tt, source: Path) -> tuple[int, str, str, float]:
    """The spec's [turntable] table, checked: (frames, rotate, format, fps)."""
    if not isinstance(tt, dict) or set(tt) - _TURNTABLE_KEYS:
        raise AlightError(f"{source}: 'turntable' takes {', '.join(sorted(_TURNTABLE_KEYS))}")
    n = tt.get("frames", 24)
    rotate, fmt, fps = tt.get("rotate", "camera"), tt.get("format", "gif"), tt.get("fps", 12)
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= 3600:
        raise AlightError(f"{source}: turntable 'frames' must be an integer 1..3600")
    if rotate not in ("camera", "environment") or fmt not in ("gif", "apng"):
        raise AlightError(f"{source}: turntable 'rotate' is camera|environment and 'format' gif|apng")
    if not isinstance(fps, (int, float)) or not 0 < fps <= 100:
        raise AlightError(f"{source}: turntable 'fps' must be in (0, 100]")
    return n, rotate, fmt, fps


def _deg(x: float) -> str:
    return f"{x:03.0f}" if float(x).is_integer() else f"{x:g}".replace(".", "p")


# --- up to date ----------------------------------------------------------------------------

def up_to_date(item: Item) -> bool:
    """The output exists and is newer than the spec and every input file."""
    try:
        made = os.stat(item.out).st_mtime_ns
    except OSError:
        return False
    for dep in item.inputs:
        try:
            if os.stat(dep).st_mtime_ns >= made:
                return False
        except OSError:
            return False  # a missing input: let the render report it
    return True


# --- running -------------------------------------------------------------------------------

@dataclass
class Result:
    rendered: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: list[tuple[str, str]] = field(default_factory=list)
    seconds: float = 0.0


def run(plan_: Plan, executor: str = "local", workers: int | None = None, force: bool = False,
        log: TextIO = sys.stderr) -> Result:
    """Render every stale item, then the animations and the contact sheet."""
    result = Result()
    start = time.perf_counter()
    todo = []
    for item in plan_.stills + plan_.frames:
        if not force and up_to_date(item):
            result.skipped.append(item.name)
        else:
            todo.append(item)
    if result.skipped:
        print(f"alight batch: {len(result.skipped)} up to date, {len(todo)} to render", file=log)
    plan_.out_dir.mkdir(parents=True, exist_ok=True)
    progress = _Progress(len(todo), log)
    warned: set[str] = set()
    for name, error, _, warnings in _execute(todo, executor, workers):
        for line in warnings:     # each once, whichever worker met it first
            if line not in warned:
                warned.add(line)
                print(f"alight: warning: {line}", file=log)
        if error is None:
            result.rendered.append(name)
        else:
            result.failed.append((name, error))
        progress.step(name, error)
    for anim in plan_.animations:
        try:
            _animation(anim, force or any(str(f) in {i.out for i in todo} for f in anim.frames))
        except AlightError as e:
            result.failed.append((anim.out.name, str(e)))
    if plan_.contact_sheet and plan_.stills:
        try:
            _contact_sheet(plan_, force or bool(todo) or not (plan_.out_dir / "contact_sheet.png").exists())
        except AlightError as e:
            result.failed.append(("contact_sheet.png", str(e)))
    result.seconds = time.perf_counter() - start
    return result


def _execute(items: list[Item], executor: str, workers: int | None):
    if not items:
        return
    if executor == "inline":  # in this process: for debugging and for callers that own a context
        for item in items:
            yield render_item(item)
        return
    if executor == "ray":
        from alight.frontends.batch_ray import execute

        yield from execute(items, workers, os.environ.get("ALIGHT_RAY_ADDRESS"))
        return
    if executor != "local":
        raise AlightError(f"--executor: {executor!r} is not one of local, ray, inline")
    n = max(1, min(workers or os.cpu_count() or 1, len(items)))
    # 'spawn': a forked child would inherit the parent's GL/EGL state, which is not fork-safe.
    ctx = multiprocessing.get_context("spawn")
    # Items sorted by environment so each worker meets few environments (one bake each).
    ordered = sorted(items, key=lambda i: (i.environment, i.quality, i.mesh))
    with concurrent.futures.ProcessPoolExecutor(max_workers=n, mp_context=ctx) as pool:
        futures = [pool.submit(render_item, item) for item in ordered]
        for fut in concurrent.futures.as_completed(futures):
            try:
                yield fut.result()
            except Exception as e:  # the worker process died (e.g. killed): report, go on
                yield "?", f"worker failed: {type(e).__name__}: {' '.join(str(e).split())}", 0.0


class _Progress:
    """One line per finished item: count, percent, time left (from the mean time so far)."""

    def __init__(self, total: int, log: TextIO):
        self.total, self.done, self.log, self.start = total, 0, log, time.perf_counter()

    def step(self, name: str, error: str | None) -> None:
        self.done += 1
        elapsed = time.perf_counter() - self.start
        left = elapsed / self.done * (self.total - self.done)
        width = len(str(self.total))
        bar = "#" * round(20 * self.done / self.total)
        status = "ok" if error is None else f"FAILED: {error}"
        print(f"[{bar:20s}] {self.done:{width}d}/{self.total} {_clock(elapsed)} elapsed, {_clock(left)} left  "
              f"{name} {status}", file=self.log, flush=True)


def _clock(seconds: float) -> str:
    s = int(math.ceil(seconds))
    return f"{s // 60}:{s % 60:02d}"


def _animation(anim: Animation, stale: bool) -> None:
    from PIL import Image

    from alight.exchange.output import atomic_path

    if not stale and anim.out.exists():
        return
    missing = [f for f in anim.frames if not f.exists()]
    if missing:
        raise AlightError(f"{anim.out}: not written, {len(missing)} frame(s) failed")
    images = [Image.open(f).convert("RGBA") for f in anim.frames]
    duration = int(round(1000.0 / anim.fps))
    fmt = "GIF" if anim.out.suffix == ".gif" else "PNG"
    with atomic_path(anim.out) as tmp:
        images[0].save(tmp, format=fmt, save_all=True, append_images=images[1:], duration=duration, loop=0,
                       **({"disposal": 2} if fmt == "GIF" else {}))


def _contact_sheet(plan_: Plan, stale: bool) -> None:
    """Every still as a thumbnail in a grid, each labelled with its mesh, environment, material
    and angles (Pillow's default font); missing stills (failed items) are left blank."""
    from PIL import Image, ImageDraw, ImageFont

    from alight.exchange.output import atomic_path

    out = plan_.out_dir / "contact_sheet.png"
    if not stale:
        return
    thumb = 160
    font = ImageFont.load_default()
    label_h = 28
    cols = max(1, min(len(plan_.stills), math.ceil(math.sqrt(len(plan_.stills)))))
    rows = math.ceil(len(plan_.stills) / cols)
    sheet = Image.new("RGB", (cols * thumb, rows * (thumb + label_h)), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    for i, item in enumerate(plan_.stills):
        x, y = (i % cols) * thumb, (i // cols) * (thumb + label_h)
        if Path(item.out).exists():
            with Image.open(item.out) as im:
                im = im.convert("RGB")
                scale = thumb / max(im.size)  # small renders are enlarged too, so labels fit under them
                im = im.resize((max(1, round(im.width * scale)), max(1, round(im.height * scale))), Image.LANCZOS)
                sheet.paste(im, (x + (thumb - im.width) // 2, y + (thumb - im.height) // 2))
        else:
            draw.text((x + 4, y + thumb // 2), "FAILED", fill=(255, 80, 80), font=font)
        draw.multiline_text((x + 3, y + thumb + 2), item.label, fill=(230, 230, 230), font=font, spacing=2)
    with atomic_path(out) as tmp:
        sheet.save(tmp, format="PNG")


def summary(result: Result) -> str:
    lines = [f"alight batch: {len(result.rendered)} rendered, {len(result.skipped)} up to date, "
             f"{len(result.failed)} failed in {result.seconds:.1f}s"]
    lines += [f"  FAILED {name}: {reason}" for name, reason in result.failed]
    return "\n".join(lines)


def main(spec: str, executor: str = "local", workers: int | None = None, force: bool = False,
         out: str | None = None, log: TextIO = sys.stderr, variant: str | None = None) -> int:
    """The CLI's entry: 0 when everything was written, 1 when an item failed."""
    result = run(plan(spec, out, variant), executor, workers, force, log)
    print(summary(result), file=log)
    return 1 if result.failed else 0
