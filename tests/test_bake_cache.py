"""The bake cache (app/ibl/bake_cache.py): a bake made by one process is loaded, not baked, by
the next; what is loaded is exactly what was baked; a damaged or foreign entry is baked again
with one warning; the size cap evicts the least recently used; two processes write at once.

Bakes are counted, never timed: ForwardRenderer.bakes_run / bakes_loaded, and the bake
functions themselves are wrapped to count their calls."""

from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
import time
from pathlib import Path

import diskcache
import numpy as np
import pytest

import alight.ibl.bake
import alight.render.renderer
from alight.ibl.bake import QUALITY, read_cube
from alight.ibl.bake_cache import (
    BakeCache,
    bake_key,
    cube_layout,
    decode_entry,
    encode_entry,
)
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer
from tests.warned import alight_warnings

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _restore_current_context():
    """These tests open their own GL contexts; the shared one (tests/gpu.py) is current again after."""
    from alight.frontends.api import _keep_current_context

    with _keep_current_context():
        yield


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    """A private, empty ALIGHT_CACHE_DIR for the test."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(folder))
    return folder


@pytest.fixture
def bake_calls(monkeypatch):
    """Every call of the bake (in steps: ForwardRenderer.bake runs them to their end) and of the
    LUT bake, by name."""
    calls = []
    steps, lut = alight.render.renderer.bake_steps, alight.ibl.bake.LutCache._bake

    def counted(name, real):
        def wrapper(*args, **kwargs):
            calls.append(name)
            return real(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(alight.render.renderer, "bake_steps", counted("bake_steps", steps))
    monkeypatch.setattr(alight.ibl.bake.LutCache, "_bake", counted("lut", lut))
    return calls


def _maps_equal(r: ForwardRenderer, a, b) -> None:
    for name, (_, levels) in cube_layout(a.quality).items():
        ta, tb = getattr(a, name), getattr(b, name)
        assert (ta is None) == (tb is None), name
        if ta is None:
            continue
        for level in range(levels):
            assert np.array_equal(read_cube(r.shaders, ta, level), read_cube(r.shaders, tb, level)), (name, level)
    assert len(a.suns) == len(b.suns)
    for sa, sb in zip(a.suns, b.suns):
        assert np.array_equal(sa.direction, sb.direction) and np.array_equal(sa.power, sb.power)
        assert (sa.fraction, sa.texels, sa.spread) == (sb.fraction, sb.texels, sb.spread)
    assert a.sun_prefilter_scale == b.sun_prefilter_scale


def test_a_new_renderer_loads_the_bake_and_bakes_nothing(cache_dir, bake_calls, shared_data):
    """The second renderer (a new GL context, as a new process has) runs no bake pass, not even
    the LUT's, and its maps and image are exactly the first's. quarry_01 has a sun, so the entry
    holds both source cubes and the compact-source table."""
    env = load_environment(str(shared_data / "env" / "quarry_01_1k.hdr"))
    q = QUALITY["low"]
    with ForwardRenderer() as first:
        baked = first.bake(env, q)
        assert (first.bakes_run, first.bakes_loaded) == (1, 0)
        assert bake_calls == ["bake_steps", "lut"]
        assert baked.suns and baked.lighting_environment is not None
        with ForwardRenderer() as second:
            bake_calls.clear()
            loaded = second.bake(env, q)
            assert (second.bakes_run, second.bakes_loaded) == (1 - 1, 1)
            assert bake_calls == []
            assert set(loaded.pass_seconds) == {"cache load"}
            second.ctx.__enter__()
            _maps_equal(second, loaded, second.bake(env, q))
        first.ctx.__enter__()
        _maps_equal(first, baked, first.bake(env, q))


def test_the_loaded_bake_renders_the_same_pixels(cache_dir, bake_calls):
    import alight

    with alight.Renderer(48, quality="low") as r:
        r.set_material("gold", roughness=0.3)
        baked = r.render(linear=True)
        assert r.bakes_done == 1
    with alight.Renderer(48, quality="low") as r:
        r.set_material("gold", roughness=0.3)
        loaded = r.render(linear=True)
        assert r.bakes_done == 0 and r._renderer.bakes_loaded == 1
    assert bake_calls.count("bake_steps") == 1
    np.testing.assert_array_equal(baked, loaded)


def test_the_editor_stepwise_bake_uses_the_cache_too(cache_dir, bake_calls):
    env = load_environment("studio")
    with ForwardRenderer() as r:
        r.bake(env, "low")
    bake_calls.clear()
    with ForwardRenderer() as r:
        steps = r.bake_steps(env, "low")
        with pytest.raises(StopIteration):
            next(steps)          # loaded in the first step: no bake steps to spread over frames
        assert r.bakes_loaded == 1 and r.bakes_run == 0
    assert bake_calls.count("bake_steps") == 0


def test_a_second_cli_run_bakes_nothing(cache_dir, tmp_path):
    """Two processes of the same command: the second's --verbose bake passes are the cache load
    alone, and it writes the same PNG."""
    outputs = []
    for i in range(2):
        out = tmp_path / f"run{i}.png"
        p = subprocess.run([sys.executable, "-m", "alight", "render", "--size", "48", "--preset", "gold",
                            "--quality", "low", "--verbose", "--out", str(out)],
                           cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        passes = next(line for line in p.stderr.splitlines() if line.startswith("bake passes:"))
        outputs.append((passes, out.read_bytes()))
    assert "prefilter" in outputs[0][0] and "brdf_lut (baked)" in outputs[0][0]
    assert outputs[1][0].startswith("bake passes: cache load ") and "," not in outputs[1][0]
    assert outputs[0][1] == outputs[1][1]


def _entry_file(folder: Path) -> Path:
    files = [p for p in (folder / "bakes").rglob("*.val")]
    assert len(files) == 1, files
    return files[0]


@pytest.mark.parametrize("damage", ["truncate", "flip", "garbage"])
def test_a_damaged_entry_is_baked_again_with_one_warning(cache_dir, bake_calls, capfd, damage):
    env = load_environment("studio")
    with ForwardRenderer() as r:
        r.bake(env, "low")
    path = _entry_file(cache_dir)
    data = bytearray(path.read_bytes())
    if damage == "truncate":
        data = data[: len(data) // 2]
    elif damage == "flip":
        data[len(data) // 2] ^= 0xFF      # inside a cube's texels: only the zip's CRC-32 sees it
    else:
        data = bytearray(b"not a zip at all" * 100)
    path.write_bytes(bytes(data))
    capfd.readouterr()
    with ForwardRenderer() as r, alight_warnings() as lines:
        r.bake(env, "low")
        assert (r.bakes_run, r.bakes_loaded) == (1, 0)
    err = capfd.readouterr().err
    assert len(lines) == 1 and "bake cache" in lines[0] and "studio" in lines[0] and "baking it again" in lines[0]
    assert "Traceback" not in err
    with ForwardRenderer() as r:     # the rebake replaced the bad entry
        r.bake(env, "low")
        assert (r.bakes_run, r.bakes_loaded) == (0, 1)


def test_foreign_entries_are_baked_again(cache_dir, bake_calls):
    """A pickle under our key (another program's value; never unpickled) and another key's
    bytes under it (a swapped file) are both refused with one warning each."""
    env = load_environment("studio")
    q = QUALITY["low"]
    with ForwardRenderer() as r:
        key, description = bake_key(env.content_hash, q, r.shaders, alight.core.gpu.describe(r.ctx))
        store = diskcache.Cache(str(cache_dir / "bakes"))
        store.set(key, {"something": "else"})          # pickled by diskcache
        store.close()
        with alight_warnings() as said:
            r.bake(env, q)
        assert (r.bakes_run, r.bakes_loaded) == (1, 0)
        assert len(said) == 1 and "not an alight bake" in said[0], said
        good = diskcache.Cache(str(cache_dir / "bakes"))
        entry = good.get(key)
        other = encode_entry({**description, "environment": "0" * 64}, decode_entry(entry, description))
        good.set(key, other)
        good.close()
    with ForwardRenderer() as r, alight_warnings() as said:
        r.bake(env, q)
        assert (r.bakes_run, r.bakes_loaded) == (1, 0)
    assert len(said) == 1 and "written for another key" in said[0], said


def test_the_key_changes_with_every_bake_input(cache_dir, tmp_path):
    from alight.core.gpu import ShaderLibrary, describe
    from alight.paths import shader_dir

    r = ForwardRenderer(bake_cache=None)
    try:
        q = QUALITY["low"]
        base = bake_key("a" * 64, q, r.shaders, describe(r.ctx))[0]
        assert bake_key("a" * 64, q, r.shaders, describe(r.ctx))[0] == base
        assert bake_key("b" * 64, q, r.shaders, describe(r.ctx))[0] != base
        assert bake_key("a" * 64, QUALITY["medium"], r.shaders, describe(r.ctx))[0] != base
        from dataclasses import replace

        assert bake_key("a" * 64, replace(q, max_roughness=0.5), r.shaders, describe(r.ctx))[0] != base
        assert bake_key("a" * 64, q, r.shaders, "another GPU")[0] != base
        # An edited include of a bake shader (a copy of shaders/ with one comment added).
        import shutil

        edited = tmp_path / "shaders"
        shutil.copytree(shader_dir(), edited)
        with open(edited / "common" / "brdf.glsl", "a", encoding="utf-8") as f:
            f.write("\n// edited\n")
        assert bake_key("a" * 64, q, ShaderLibrary(r.ctx, edited), describe(r.ctx))[0] != base
    finally:
        r.release()


def _arrays(seed: int, megabytes: float = 1.0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {"x": rng.random(int(megabytes * 2**20 / 4), dtype=np.float32)}


def test_the_size_cap_evicts_the_least_recently_used(tmp_path):
    cache = BakeCache(tmp_path / "bakes", size_limit=int(3.6 * 2**20))
    description = {"test": True}
    for i in range(3):
        assert cache.save(f"k{i}", encode_entry(description, _arrays(i)))
        time.sleep(0.01)
    assert cache.load("k0", description, "k0") is not None     # k0 is now the most recently used
    time.sleep(0.01)
    cache.save("k3", encode_entry(description, _arrays(3)))
    present = {k for k in ("k0", "k1", "k2", "k3") if cache.load(k, description, k) is not None}
    assert "k1" not in present and {"k0", "k3"} <= present
    count, volume = cache.stats()
    assert volume <= 3.6 * 2**20 and count == len(present)
    cache.close()


def _writer(folder: str, worker: int, rounds: int, queue) -> None:
    """One process of the concurrency test: writes shared and own keys, and reads them back."""
    cache = BakeCache(folder)
    slowest = 0.0
    try:
        for i in range(rounds):
            for key, seed in ((f"shared{i % 3}", i % 3), (f"own{worker}-{i}", 100 * worker + i)):
                data = encode_entry({"seed": seed}, _arrays(seed, 0.25))
                start = time.perf_counter()
                assert cache.save(key, data)
                slowest = max(slowest, time.perf_counter() - start)
                got = cache.load(key, {"seed": seed}, key)
                assert got is not None and np.array_equal(got["x"], _arrays(seed, 0.25)["x"])
        queue.put((worker, "ok", slowest))
    except BaseException as exc:  # reported to the parent, which fails the test
        queue.put((worker, repr(exc), slowest))


def test_two_processes_writing_at_once_neither_corrupt_nor_block(tmp_path, capfd):
    folder = str(tmp_path / "bakes")
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    procs = [ctx.Process(target=_writer, args=(folder, w, 12, queue)) for w in range(2)]
    for p in procs:
        p.start()
    results = [queue.get(timeout=240) for _ in procs]
    for p in procs:
        p.join(timeout=60)
    assert all(status == "ok" for _, status, _ in results), results
    # A commit holds the index's lock for milliseconds; nobody waited anywhere near the timeout.
    assert max(slowest for _, _, slowest in results) < 5.0, results
    cache = BakeCache(folder)
    with alight_warnings() as said:
        for key, seed in [(f"shared{i}", i) for i in range(3)] + [(f"own{w}-{i}", 100 * w + i)
                                                                   for w in range(2) for i in range(12)]:
            got = cache.load(key, {"seed": seed}, key)
            assert got is not None and np.array_equal(got["x"], _arrays(seed, 0.25)["x"]), key
    err = capfd.readouterr().err   # (the writers' own warnings: Python's, on their stderr)
    assert not said and "alight: warning" not in err and "AlightWarning" not in err, (said, err)
    cache.close()


def test_an_unusable_cache_folder_warns_once_and_renders(tmp_path, monkeypatch, capfd):
    """The API says it once however many renders (the cache is opened once), and carries on."""
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(blocker))
    import alight

    with alight.Renderer(16, quality="low") as r, alight_warnings() as said:
        image = r.render()
        r.set_material("gold").render()
    assert image.shape == (16, 16, 4)
    assert [x for x in said if x.startswith("bake cache")] == said and len(said) == 1, said
    assert "Traceback" not in capfd.readouterr().err


def test_alight_cache_shows_and_clears(cache_dir):
    def cli(*args):
        p = subprocess.run([sys.executable, "-m", "alight", *args], cwd=REPO, env=dict(os.environ),
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        return p.stdout

    with ForwardRenderer() as r:
        r.bake(load_environment("studio"), "low")
    shown = cli("cache")
    assert str(cache_dir / "bakes") in shown and "1 bake," in shown and "BRDF LUTs: 1 file" in shown
    assert "removed 1 bake and 1 BRDF LUT" in cli("cache", "clear")
    assert "0 bakes," in cli("cache", "show")


def test_batch_workers_load_the_bake_another_process_made(cache_dir, tmp_path):
    """alight batch's worker processes use the cache: after a first batch has baked the studio,
    a second (forced, so every item renders again, in new worker processes) leaves the entry
    untouched. A rebake would store a new entry: diskcache writes each value to a new file."""
    spec = tmp_path / "spec.toml"
    spec.write_text('size = [24, 24]\nquality = "low"\nmeshes = ["sphere"]\nenvironments = ["studio"]\n'
                    'materials = ["gold", "copper"]\n')

    def batch():
        p = subprocess.run([sys.executable, "-m", "alight", "batch", str(spec), "--workers", "2", "--force"],
                           cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr

    batch()
    entry = _entry_file(cache_dir)
    written = entry.stat().st_mtime_ns
    batch()
    assert _entry_file(cache_dir) == entry and entry.stat().st_mtime_ns == written


def test_lut_tables_round_trip_and_refuse_what_they_are_not(tmp_path):
    """The LUTs' .npy files (alight.ibl.table_files): a table comes back as stored; a truncated
    file, another shape or a non-finite value reads as absent (the LUT is baked again)."""
    from alight.ibl.table_files import load_table, save_table

    table = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    path = tmp_path / "sub" / "lut.npy"
    save_table(path, table)
    np.testing.assert_array_equal(load_table(path, (2, 3, 4)), table)
    assert load_table(path, (3, 2, 4)) is None
    path.write_bytes(path.read_bytes()[:-8])
    assert load_table(path, (2, 3, 4)) is None
    bad = table.copy()
    bad[0, 0, 0] = np.nan
    save_table(path, bad)
    assert load_table(path, (2, 3, 4)) is None
    assert load_table(tmp_path / "none.npy", (2, 3, 4)) is None
    assert [p.name for p in path.parent.iterdir()] == ["lut.npy"]     # no temporary left
