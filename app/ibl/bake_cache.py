"""The bake cache: an environment's baked IBL maps kept on disk across processes, so a script
that renders one image per process (or a batch worker, or a test session) bakes each
environment once per machine.

Storage is ``diskcache`` (an SQLite index and one file per entry, in ``cache_dir()/bakes``):
safe between processes and threads, capped in size (past the cap, each write evicts the least
recently used entry: bakes are of similar sizes, so the cache stays near the cap), and an
entry's file is written in full before the index row that names it is committed, so a reader
sees a whole entry or none; a writer holds the index's lock only for that commit. Two processes
that miss the same entry both bake it and the second write wins (the same bytes): neither
waits on the other's bake.

An entry is the maps' texels, exactly as baked (float32, every mip of every cube), in an
uncompressed ``.npz`` (a zip: its CRC-32 catches a damaged file) with the key's description
inside. The key hashes everything the bake reads (``bake_key``): the environment's content, the
quality row, the bake shaders' expanded text, the Python that makes sample sets and finds the
compact sources, and the OpenGL renderer. A damaged or foreign entry (another format, another
key's bytes, a pickle) is deleted and baked again, with one warning line.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib.util
import io
import json
import os
import sqlite3
import time
from pathlib import Path

import diskcache
import numpy as np

from alight.errors import warn
from alight.paths import cache_dir

FORMAT = 1
FOLDER = "bakes"
# The cap on the cache's disk use; ALIGHT_BAKE_CACHE_MB overrides it. A medium bake of a map
# with a sun is 19 MiB (two source cubes), without one 10 MiB; high about 4x that.
DEFAULT_SIZE_LIMIT_MB = 1024
SIZE_LIMIT_ENV = "ALIGHT_BAKE_CACHE_MB"
# Past the size limit each write evicts the one least recently used entry (diskcache's default
# cull_limit of 10 would drop ten 10-20 MiB bakes to make room for one).
# SQLite's lock wait: a commit takes milliseconds, so a long wait means a stuck writer.
LOCK_TIMEOUT_S = 10.0

# What a bake runs, all in the key: editing any of it (or a shader's include) makes new keys.
BAKE_SHADERS = ("ibl/equirect_to_cube.comp", "ibl/cube_downsample.comp", "ibl/irradiance.comp",
                "ibl/sh9_project.comp", "ibl/sh9_to_cube.comp", "ibl/prefilter.comp")
BAKE_MODULES = ("alight.ibl.bake", "alight.ibl.sun", "alight.core.shading")

CUBES = ("environment", "lighting_environment", "irradiance", "prefiltered_radiance", "prefiltered_radiance_mid")


class BadEntry(Exception):
    """An entry that is not a whole bake of its key (damaged, foreign, or of another format)."""


@functools.lru_cache(maxsize=1)
def code_digest() -> str:
    """sha256 of the source of BAKE_MODULES."""
    h = hashlib.sha256()
    for name in BAKE_MODULES:
        h.update(Path(importlib.util.find_spec(name).origin).read_bytes())
    return h.hexdigest()


def bake_key(env_hash: str, quality, shaders, renderer: str) -> tuple[str, dict]:
    """The cache key of a bake and the description it hashes: ``(key, description)``.

    ``quality`` is a BakeQuality (every field counts), ``shaders`` the ShaderLibrary whose files
    the bake compiles, ``renderer`` the GL renderer and version (drivers round differently)."""
    description = {
        "format": FORMAT,
        "environment": env_hash,
        "quality": dataclasses.asdict(quality),
        "shaders": {name: shaders.digest(name) for name in BAKE_SHADERS},
        "code": code_digest(),
        "renderer": renderer,
    }
    text = json.dumps(description, sort_keys=True)
    return "alight-bake-" + hashlib.sha256(text.encode()).hexdigest(), description


def encode_entry(description: dict, arrays: dict[str, np.ndarray]) -> bytes:
    """An entry's bytes: the arrays and the key's description as an uncompressed .npz."""
    meta = json.dumps({"key": description, "written": time.time()}, sort_keys=True).encode()
    out = io.BytesIO()
    np.savez(out, meta=np.frombuffer(meta, np.uint8), **arrays)
    return out.getvalue()


def decode_entry(data, description: dict) -> dict[str, np.ndarray]:
    """The arrays of an entry's bytes (or open file); raises BadEntry unless it is a whole entry
    written for ``description``."""
    import zipfile

    try:
        with np.load(data if hasattr(data, "read") else io.BytesIO(data), allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}   # reading a member checks its CRC
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as exc:
        raise BadEntry(f"damaged ({' '.join(str(exc).split()) or type(exc).__name__})") from None
    try:
        meta = json.loads(arrays.pop("meta").tobytes())
    except (KeyError, ValueError):
        raise BadEntry("not an alight bake (no description)") from None
    if not isinstance(meta, dict) or meta.get("key") != json.loads(json.dumps(description)):
        raise BadEntry("written for another key")
    return arrays


class BakeCache:
    """The persistent store of bakes (see the module docstring). ``directory`` None: the user's
    cache folder (``alight.paths.cache_dir()/bakes``, looked up at each use, so
    ALIGHT_CACHE_DIR set later still counts); ``size_limit`` in bytes, None: DEFAULT_SIZE_LIMIT_MB
    or ALIGHT_BAKE_CACHE_MB. Every failure of the store itself (unwritable folder, a broken
    index) is one warning and the bake goes on uncached: a cache never stops a render."""

    def __init__(self, directory: str | os.PathLike | None = None, size_limit: int | None = None):
        self._directory = Path(directory) if directory is not None else None
        self._size_limit = size_limit
        self._store = None
        self._store_dir: Path | None = None

    @property
    def directory(self) -> Path:
        return self._directory if self._directory is not None else cache_dir() / FOLDER

    @property
    def size_limit(self) -> int:
        if self._size_limit is not None:
            return int(self._size_limit)
        text = os.environ.get(SIZE_LIMIT_ENV)
        try:
            megabytes = float(text) if text else DEFAULT_SIZE_LIMIT_MB
        except ValueError:
            warn(f"{SIZE_LIMIT_ENV}={text!r} is not a number of MiB; using {DEFAULT_SIZE_LIMIT_MB}")
            megabytes = DEFAULT_SIZE_LIMIT_MB
        return int(max(megabytes, 0.0) * 2**20)

    def _open(self):
        """The diskcache store for the current directory, or None (with a warning) if it cannot
        be opened."""
        directory = self.directory
        if self._store is not None and self._store_dir == directory:
            if self._store.size_limit != self.size_limit:
                self._store.reset("size_limit", self.size_limit)
            return self._store
        self.close()
        try:
            self._store = diskcache.Cache(str(directory), disk=_BytesOnlyDisk, timeout=LOCK_TIMEOUT_S,
                                          size_limit=self.size_limit, eviction_policy="least-recently-used",
                                          cull_limit=1)
            self._store_dir = directory
        except (OSError, sqlite3.Error, diskcache.Timeout) as exc:
            warn(f"bake cache: cannot open {directory} ({_reason(exc)}); bakes are not kept "
                 f"('alight cache clear' empties it)")
            self._store = None
        return self._store

    def load(self, key: str, description: dict, what: str) -> dict[str, np.ndarray] | None:
        """The arrays stored under ``key``, or None on a miss. A bad entry (``BadEntry``) is
        deleted with a warning naming ``what`` (the environment) and counts as a miss; so should
        one whose arrays the caller finds wrong (``reject``)."""
        store = self._open()
        if store is None:
            return None
        try:
            handle = store.get(key, read=True)
            if handle is None:
                return None
            try:
                return decode_entry(handle, description)
            finally:
                if hasattr(handle, "close"):
                    handle.close()
        except BadEntry as exc:
            self.reject(key, what, str(exc))
        except (OSError, sqlite3.Error, diskcache.Timeout) as exc:
            warn(f"bake cache: cannot read {self.directory} ({_reason(exc)}); baking {what}")
        return None

    def reject(self, key: str, what: str, reason: str) -> None:
        """Delete a bad entry, saying so once."""
        warn(f"bake cache: the entry for {what} in {self.directory} is {reason}; baking it again")
        store = self._open()
        if store is not None:
            try:
                store.delete(key)
            except (OSError, sqlite3.Error, diskcache.Timeout):
                pass

    def save(self, key: str, data: bytes) -> bool:
        """Store an entry's bytes (``encode_entry``); False (with one warning) if the store refused."""
        store = self._open()
        if store is None:
            return False
        try:
            return bool(store.set(key, data))
        except (OSError, sqlite3.Error, diskcache.Timeout) as exc:
            warn(f"bake cache: cannot write {self.directory} ({_reason(exc)}); bakes are not kept")
            return False

    def stats(self) -> tuple[int, int]:
        """(entries, bytes on disk including the index)."""
        store = self._open()
        if store is None:
            return 0, 0
        return len(store), int(store.volume())

    def clear(self) -> int:
        """Remove every entry; returns how many."""
        store = self._open()
        return 0 if store is None else int(store.clear())

    def close(self) -> None:
        if self._store is not None:
            self._store.close()
        self._store = None
        self._store_dir = None


def _reason(exc: BaseException) -> str:
    return " ".join(str(getattr(exc, "strerror", None) or exc).split()) or type(exc).__name__


class _BytesOnlyDisk(diskcache.Disk):
    """diskcache's Disk that refuses to unpickle: a pickled value under our key is foreign
    (and loading pickles from a shared folder would run whatever they hold)."""

    def fetch(self, mode, filename, value, read):
        if mode not in (diskcache.core.MODE_RAW, diskcache.core.MODE_BINARY):
            raise BadEntry("not an alight bake (a pickled or text value)")
        return super().fetch(mode, filename, value, read)


# --------------------------------------------------------------------------------------------
# Baked maps <-> arrays
# --------------------------------------------------------------------------------------------

def cube_layout(quality) -> dict[str, tuple[int, int]]:
    """Each cube of a bake at ``quality``: name -> (level 0 face size, mip levels)."""
    source_levels = int(np.log2(quality.cube_size)) + 1
    levels = quality.prefiltered_levels
    return {
        "environment": (quality.cube_size, source_levels),
        "lighting_environment": (quality.cube_size, source_levels),
        "irradiance": (quality.irradiance_size, 1),
        "prefiltered_radiance": (quality.prefiltered_size, levels),
        "prefiltered_radiance_mid": (quality.prefiltered_size // 2, levels - 1),
    }


# A compact source's fields (app/ibl/sun.py Sun) and their widths.
SUN_FIELDS = {"direction": 3, "power": 3, "fraction": 1, "texels": 1, "spread": 1}


def maps_to_arrays(shaders, maps) -> dict[str, np.ndarray]:
    """Every texel of a bake (``<cube>.<level>``: (6, size, size, 4) float32) and its compact
    sources (``sun_<field>``, ``sun_prefilter_scale``), for ``encode_entry``."""
    from alight.ibl.bake import read_cube

    arrays: dict[str, np.ndarray] = {}
    for name, (_, levels) in cube_layout(maps.quality).items():
        tex = getattr(maps, name)
        if tex is None:
            continue
        for level in range(levels):
            arrays[f"{name}.{level}"] = read_cube(shaders, tex, level)
    for f, width in SUN_FIELDS.items():
        arrays[f"sun_{f}"] = np.array([getattr(s, f) for s in maps.suns], dtype=np.float64).reshape(len(maps.suns), width)
    arrays["sun_prefilter_scale"] = np.asarray(maps.sun_prefilter_scale, np.float64)
    return arrays


def maps_from_arrays(ctx, shaders, arrays: dict[str, np.ndarray], quality, lut) -> "IBLMaps":  # noqa: F821
    """The IBLMaps ``maps_to_arrays`` read, uploaded again; raises BadEntry (and makes nothing)
    if the arrays are not a whole, finite bake at ``quality``."""
    from alight.core.gpu import float_cube
    from alight.ibl.bake import IBLMaps
    from alight.ibl.sun import Sun

    layout = cube_layout(quality)
    suns_count = len(arrays.get("sun_fraction", ()))
    for name, (size, levels) in layout.items():
        if name == "lighting_environment" and suns_count == 0:
            continue
        for level in range(levels):
            a = arrays.get(f"{name}.{level}")
            s = max(1, size >> level)
            if a is None or a.dtype != np.float32 or a.shape != (6, s, s, 4):
                raise BadEntry(f"incomplete ({name} level {level})")
            if not np.isfinite(a).all():
                raise BadEntry(f"damaged ({name} level {level} is not finite)")
    try:
        fields = {f: arrays[f"sun_{f}"] for f in SUN_FIELDS}
        scale = arrays["sun_prefilter_scale"]
    except KeyError:
        raise BadEntry("incomplete (no compact-source table)") from None
    if any(v.shape != (suns_count, SUN_FIELDS[f]) for f, v in fields.items()) or scale.ndim != 1:
        raise BadEntry("incomplete (compact-source table)")
    suns = [Sun(direction=fields["direction"][i].copy(), power=fields["power"][i].copy(),
                fraction=float(fields["fraction"][i, 0]), texels=int(fields["texels"][i, 0]),
                spread=float(fields["spread"][i, 0])) for i in range(suns_count)]
    cubes = {}
    try:
        for name, (size, levels) in layout.items():
            if name == "lighting_environment" and suns_count == 0:
                cubes[name] = None
                continue
            cubes[name] = float_cube(ctx, size, levels, [arrays[f"{name}.{level}"] for level in range(levels)])
    except BaseException:
        for tex in cubes.values():
            if tex is not None:
                tex.release()
        raise
    return IBLMaps(cubes["environment"], cubes["irradiance"], cubes["prefiltered_radiance"],
                   cubes["prefiltered_radiance_mid"], lut, quality, {}, suns, [float(x) for x in scale],
                   cubes["lighting_environment"])


# --------------------------------------------------------------------------------------------
# What the renderer calls
# --------------------------------------------------------------------------------------------

def load_bake(cache: BakeCache, ctx, shaders, env, quality, luts):
    """The bake of ``env`` at ``quality`` from the cache, uploaded, or None on a miss (a bad
    entry is a miss, with one warning). Its pass_seconds hold one entry, 'cache load'."""
    from alight.core.gpu import describe

    start = time.perf_counter()
    key, description = bake_key(env.content_hash, quality, shaders, describe(ctx))
    arrays = cache.load(key, description, env.name)
    if arrays is None:
        return None
    try:
        maps = maps_from_arrays(ctx, shaders, arrays, quality, luts.get(quality.lut_size, quality.lut_samples))
    except BadEntry as exc:
        cache.reject(key, env.name, str(exc))
        return None
    ctx.finish()
    maps.pass_seconds["cache load"] = time.perf_counter() - start
    return maps


def save_bake(cache: BakeCache, shaders, env, maps) -> bool:
    """Keep a bake in the cache; False if the store refused it (said in a warning)."""
    from alight.core.gpu import describe

    key, description = bake_key(env.content_hash, maps.quality, shaders, describe(shaders.ctx))
    return cache.save(key, encode_entry(description, maps_to_arrays(shaders, maps)))
