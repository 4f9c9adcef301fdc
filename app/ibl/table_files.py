"""Baked lookup tables (BRDF, sheen, anisotropy and transmission LUTs) kept as .npy files in the
user's cache folder, so that a table is baked once per machine and shader version."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from alight.exchange.output import atomic_path


def load_table(path: str | os.PathLike, shape: tuple[int, ...]) -> np.ndarray | None:
    """The float32 table of ``shape`` stored at ``path``, or None where there is none or it is not
    that (another shape or type, a non-finite value, an unreadable or truncated file): the caller
    then bakes it again."""
    try:
        loaded = np.load(path, allow_pickle=False)
    except (OSError, ValueError):
        return None
    if loaded.shape != tuple(shape) or loaded.dtype != np.float32 or not np.isfinite(loaded).all():
        return None
    return loaded


def save_table(path: str | os.PathLike, table: np.ndarray) -> None:
    """Store ``table`` at ``path`` atomically (a temporary file renamed: readers in other processes
    never see half a file). An unwritable cache folder only costs a bake next time."""
    path = Path(path)
    try:
        os.makedirs(path.parent, exist_ok=True)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                np.save(f, np.asarray(table, np.float32))
    except OSError:
        pass
