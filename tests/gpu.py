"""One headless GL context and renderer shared by the GPU tests (creating one costs ~0.3 s)."""

from __future__ import annotations

import functools
import re

import numpy as np

from alight.render.renderer import ForwardRenderer


@functools.lru_cache(maxsize=1)
def renderer() -> ForwardRenderer:
    return ForwardRenderer()


def bake(env, quality: str = "medium"):
    """The shared renderer's bake of ``env`` (the renderer keeps it per environment and quality)."""
    return renderer().bake(env, quality)


def probe(material, maps, width: int = 32, **scene):
    """The probe view of ``material`` (docs/conventions.md): linear RGB (width, width, 3), the
    mask of pixels on the sphere and their normals (alight.core.shading.probe_normals)."""
    from alight.core import shading
    from alight.core.scene import Scene

    n, inside = shading.probe_normals(width)
    image = renderer().render(Scene(material=material, view="probe", **scene), maps, width, width).linear
    return image[..., :3], inside, n


def relative(a, b) -> float:
    """Relative mean absolute error of ``a`` against ``b`` (sums over every element)."""
    return float(np.abs(a - b).sum() / np.abs(b).sum())


@functools.lru_cache(maxsize=None)
def term_indices(shader: str = "accuracy/evaluate_terms.comp") -> dict[str, int]:
    """An evaluator's term names and indices, read from its ``const int TERM_<NAME> = <i>;``
    lines, so the tests' names cannot drift from the shader's switch."""
    from alight.paths import shader_dir
    text = (shader_dir() / shader).read_text(encoding="utf-8")
    found = {name: int(i) for name, i in re.findall(r"^const int TERM_(\w+) = (\d+);", text, re.M)}
    assert found, f"{shader} declares no TERM_ constants"
    return found


TERMS = term_indices()


def evaluate(term: str | int, inputs: np.ndarray, uniforms: dict | None = None,
             shader: str = "accuracy/evaluate_terms.comp", defines: dict | None = None) -> np.ndarray:
    """Run an evaluator compute shader on rows of up to 4 inputs; returns (N, 4) outputs.

    ``shader`` and ``defines`` pick another evaluator with the same interface (u_inputs,
    u_outputs, u_count, u_term: each layer has its own, shaders/accuracy/evaluate_<layer>.comp);
    ``term`` is then its index there."""
    r = renderer()
    ctx = r.ctx
    rows = np.zeros((len(inputs), 4), np.float32)
    inputs = np.asarray(inputs, np.float32).reshape(len(inputs), -1)
    rows[:, : inputs.shape[1]] = inputs
    prog = r.shaders.compute(shader, defines)
    src = ctx.buffer(rows.tobytes())
    dst = ctx.buffer(reserve=rows.nbytes)
    src.bind_to_storage_buffer(0)
    dst.bind_to_storage_buffer(1)
    prog["u_count"] = len(rows)
    prog["u_term"] = term_indices(shader)[term] if isinstance(term, str) else int(term)
    for name, value in (uniforms or {}).items():
        if name in prog:
            prog[name] = value
    prog.run((len(rows) + 63) // 64)
    ctx.finish()
    out = np.frombuffer(dst.read(), np.float32).reshape(-1, 4).copy()
    src.release()
    dst.release()
    return out
