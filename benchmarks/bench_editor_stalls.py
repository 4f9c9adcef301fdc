"""The editor's frame times while the compare view's exact reference sums, and while a new
shader variant (a layer switched on) compiles: this checkout against another one, the two
alternated (before, after, before, after ...), each run a fresh process. Not a test.

    git archive main | tar -x -C /tmp/base_src && mkdir /tmp/base && ln -s /tmp/base_src/app /tmp/base/alight
    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python benchmarks/bench_editor_stalls.py --base /tmp/base

``--base``: a folder whose ``alight`` is the other checkout's app/ (put first on PYTHONPATH for
the "before" runs). Each run is an EditorWindow (its own loop, the panel, 800x720 by default)
on the built-in sphere in the built-in studio:

- reference: plastic_high at roughness 0.5, compare 'reference' at ``--scale``; frames are timed
  (``win.frame()`` then ``ctx.finish()``) from the switch until A's half is whole; then compare
  off for 10 frames and on again: the frames until A's half is whole again.
- split: 20 frames, then frames until the start's pass warm-up (pass_warmup.py) is done where
  the build has one; the tone map changed to agx (set on the state) until the view shows it and 10
  more; then compare 'reference' at ``--scale`` until A's half is whole and 10 more (the composite
  pass and the reference's tone map pass drawn first); then the tone map changed to neutral. Each
  run has an empty Mesa shader cache of its own. The longest frame of each step.
- preset: this checkout on both sides, "before" with the presets' prefetch cancelled: velvet's
  first click after the view settled, frames until the view shows it (``child_preset``).
- variant: gold, 20 frames, then clearcoat 1.0 (set on the state); frames timed until the view
  shows the clearcoat picture and 10 more. Each run has an empty Mesa shader cache of its own
  (MESA_SHADER_CACHE_DIR), as a first switch on a new machine.

Prints one line a run and, a side, the median and range over its runs of the median and the
longest frame.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _window(size):
    from alight.exchange.presets import load_preset
    from alight.frontends.editor.state import EditorState
    from alight.frontends.editor.window import EditorWindow

    state = EditorState()
    state.material = state.saved_material = load_preset("plastic_high")
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, size)
    win.finish_bake()
    for _ in range(10):
        win.frame()
    return state, win


def _timed_frame(win) -> float:
    t0 = time.perf_counter()
    win.frame()
    win.ctx.finish()
    return time.perf_counter() - t0


def child_reference(size, scale: float, limit_s: float) -> dict:
    from alight.frontends.editor.compare import CompareState

    state, win = _window(size)
    state.material = dataclasses.replace(state.material, roughness=0.5)
    for _ in range(3):
        win.frame()
    try:
        state.compare = CompareState(mode="reference", reference_scale=scale)
        times, start = [], time.perf_counter()
        while time.perf_counter() - start < limit_s:
            times.append(_timed_frame(win))
            if win.compare_view.a_ready and win.compare_view.reference_progress is None:
                break
        whole = time.perf_counter() - start
        state.compare = CompareState(mode="off", reference_scale=scale)
        for _ in range(10):
            win.frame()
        state.compare = CompareState(mode="reference", reference_scale=scale)
        again, start = [], time.perf_counter()
        while time.perf_counter() - start < limit_s:
            again.append(_timed_frame(win))
            if win.compare_view.a_ready and win.compare_view.reference_progress is None:
                break
        return {"frames": len(times), "median_ms": 1000 * statistics.median(times), "max_ms": 1000 * max(times),
                "whole_s": whole, "reopen_frames": len(again), "reopen_s": sum(again)}
    finally:
        win.close()


def child_variant(size) -> dict:
    state, win = _window(size)
    from alight.exchange.presets import load_preset

    state.material = load_preset("gold")
    try:
        for _ in range(20):
            win.frame()
        steady = [_timed_frame(win) for _ in range(5)]
        state.material = dataclasses.replace(state.material, clearcoat=1.0)
        times, start, shown, after = [], time.perf_counter(), None, 0
        warm = getattr(win, "variant_warmup", None)
        while time.perf_counter() - start < 300 and after < 10:
            times.append(_timed_frame(win))
            done = warm is None or (not warm.pending and win._last_complete_scene.material == state.material)
            if shown is None and done:
                shown = time.perf_counter() - start
            after += shown is not None
        return {"frames": len(times), "steady_ms": 1000 * statistics.median(steady),
                "median_ms": 1000 * statistics.median(times), "max_ms": 1000 * max(times), "shown_s": shown}
    finally:
        win.close()


def child_occlusion(size) -> dict:
    """DamagedHelmet with occlusion off, then 'on' (set on the state, as the combo sets it), the
    bake cache and Mesa's shader cache empty: frames until the view shows the occluded picture
    (the bake's child done, no variant held back) and 10 more. Each frame's wall time and the
    main thread's CPU time (``time.thread_time``: on a shared machine a frame's wall time also
    holds the time other processes took the cores). "send": the frame that handed the occluded
    variant to the warm-up process; "switch": the frame that first drew the occluded picture
    (each [wall, main thread's CPU, the process's CPU: llvmpipe's threads too] in ms);
    "other": the longest of the rest. The camera orbits 1 degree a frame throughout, as an
    artist's drag does, so every frame draws the helmet."""
    state, win = _window(size)
    state.load_mesh(os.path.join(REPO, "..", "shared", "data", "models", "DamagedHelmet", "DamagedHelmet.gltf"))
    state.occlusion = "off"
    warm, bake = win.variant_warmup, win.occlusion_bake
    try:
        _frames_until(win, lambda: not warm.pending and not warm.showing_old, after=20)
        steady = []
        for _ in range(10):
            win.orbit.yaw_deg += 1.0
            steady.append(_timed_frame(win))
        state.occlusion = "on"
        frames, start, shown, after = [], time.perf_counter(), None, 0
        send = switch = None
        while time.perf_counter() - start < 600 and after < 10:
            win.orbit.yaw_deg += 1.0
            jobs, cpu0, proc0 = warm.jobs, time.thread_time(), time.process_time()
            t = _timed_frame(win)
            frames.append((t, time.thread_time() - cpu0, time.process_time() - proc0))
            if warm.jobs > jobs and send is None:
                send = len(frames) - 1
            last = win._last_complete_scene
            done = (not bake.status and not warm.pending and not warm.showing_old
                    and last is not None and last.occlusion == "on")
            if shown is None and done:
                shown, switch = time.perf_counter() - start, len(frames) - 1
            after += shown is not None
        rest = [f for i, f in enumerate(frames) if i not in (send, switch)]
        ms = lambda i: [round(1000 * v, 1) for v in frames[i]] if i is not None else None
        return {"frames": len(frames), "steady_ms": 1000 * statistics.median(steady),
                "median_ms": 1000 * statistics.median(f[0] for f in frames), "max_ms": 1000 * max(f[0] for f in frames),
                "median_process_cpu_ms": 1000 * statistics.median(f[2] for f in frames),
                "send_ms": ms(send), "switch_ms": ms(switch),
                "other_max_wall_ms": 1000 * max(f[0] for f in rest), "other_max_cpu_ms": 1000 * max(f[1] for f in rest),
                "other_max_process_cpu_ms": 1000 * max(f[2] for f in rest),
                "shown_s": shown}
    finally:
        win.close()


def child_preset(size, with_prefetch: bool) -> dict:
    """The built-in sphere in the studio with plastic_high; the view settles (and, with
    ``with_prefetch``, the presets' prefetch finishes: variant_warmup.PresetPrefetch; without, it is
    cancelled); then velvet (a sheen layer: a new variant) is set as the panel's click sets it.
    Frames until the view shows velvet, each frame's wall and main-thread CPU time."""
    from alight.exchange.presets import load_preset

    state, win = _window(size)
    warm, prefetch = win.variant_warmup, win.preset_prefetch
    try:
        if not with_prefetch:
            prefetch.cancel()
        _frames_until(win, lambda: not warm.pending and not warm.showing_old and prefetch.done, after=20,
                      limit_s=600.0)
        state.material = load_preset("velvet")
        frames, start, shown = [], time.perf_counter(), None
        while time.perf_counter() - start < 300 and shown is None:
            cpu0 = time.thread_time()
            t = _timed_frame(win)
            frames.append((t, time.thread_time() - cpu0))
            if not warm.pending and not warm.showing_old and win._last_complete_scene.material == state.material:
                shown = time.perf_counter() - start
        return {"prefetch": prefetch.done and bool(prefetch.keys), "frames": len(frames), "shown_s": shown,
                "max_ms": 1000 * max(f[0] for f in frames), "max_cpu_ms": 1000 * max(f[1] for f in frames),
                "warmup_jobs": warm.jobs}
    finally:
        win.close()


def _frames_until(win, done, after: int = 10, limit_s: float = 300.0) -> list[float]:
    """Timed frames until ``done()`` and ``after`` more."""
    times, start, extra = [], time.perf_counter(), 0
    while time.perf_counter() - start < limit_s and extra < after:
        times.append(_timed_frame(win))
        extra += bool(done())
    return times


def child_split(size, scale: float) -> dict:
    """The artist's first split view and first tone map changes, the Mesa cache empty: the tone
    map changed in the plain view, then compare 'reference' opened (the composite pass, the
    reference's tone map pass), then the tone map changed while it shows."""
    from alight.frontends.editor.compare import CompareState

    state, win = _window(size)
    warm = getattr(win, "variant_warmup", None)

    def settled():
        return warm is None or (not warm.pending and win._last_complete_scene.display == state.display)

    try:
        for _ in range(20):
            win.frame()
        out = {}
        # The start's pass warm-up (pass_warmup.py, where the build has one) drawn to its end
        # first, as by an artist who opens the split some seconds after the start.
        passes, start = getattr(win, "pass_warmup", None), time.perf_counter()
        while passes is not None and not passes.done and time.perf_counter() - start < 300:
            win.frame()
        out["pass_warmup_s"] = time.perf_counter() - start
        state.display = dataclasses.replace(state.display, tonemap="agx")
        t = _frames_until(win, settled)
        out["plain_tonemap_max_ms"] = 1000 * max(t)
        state.compare = CompareState(mode="reference", reference_scale=scale)
        t = _frames_until(win, lambda: win.compare_view.a_ready and win.compare_view.reference_progress is None)
        out["split_open_max_ms"], out["split_open_frames"] = 1000 * max(t), len(t)
        out["split_open_first_ms"] = 1000 * t[0]
        state.display = dataclasses.replace(state.display, tonemap="neutral")
        t = _frames_until(win, lambda: settled() and win.compare_view.a_ready)
        out["split_tonemap_max_ms"] = 1000 * max(t)
        return out
    finally:
        win.close()


def run(side: str, what: str, args) -> dict:
    env = dict(os.environ)
    child = what
    if what == "preset":   # this checkout both sides: "before" without the presets' prefetch
        child = "preset" if side == "after" else "preset-noprefetch"
    elif side == "before":
        env["PYTHONPATH"] = args.base + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory(prefix="alight-bench-stalls-", ignore_cleanup_errors=True) as tmp:
        env["MESA_SHADER_CACHE_DIR"] = os.path.join(tmp, "mesa")
        env["ALIGHT_CACHE_DIR"] = os.path.join(tmp, "cache")
        cmd = [sys.executable, os.path.abspath(__file__), "--child", child, "--size", args.size,
               "--scale", str(args.scale), "--limit", str(args.limit)]
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=tmp)
    if out.returncode != 0:
        raise SystemExit(f"{side} {what}: {out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", help="a folder whose 'alight' is the other checkout's app/")
    ap.add_argument("--what", choices=("reference", "variant", "split", "occlusion", "preset", "both"), default="both")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--size", default="800x720")
    ap.add_argument("--scale", type=float, default=0.25)
    ap.add_argument("--limit", type=float, default=600.0, help="seconds a reference run waits at most")
    ap.add_argument("--child", choices=("reference", "variant", "split", "occlusion", "preset", "preset-noprefetch"))
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    if args.child == "reference":
        print(json.dumps(child_reference(size, args.scale, args.limit)))
        return
    if args.child == "split":
        print(json.dumps(child_split(size, args.scale)))
        return
    if args.child in ("preset", "preset-noprefetch"):
        print(json.dumps(child_preset(size, args.child == "preset")))
        return
    if args.child == "occlusion":
        print(json.dumps(child_occlusion(size)))
        return
    if args.child == "variant":
        print(json.dumps(child_variant(size)))
        return
    if not args.base and args.what != "preset":
        raise SystemExit("--base is required (the 'before' checkout)")
    whats = ("reference", "variant") if args.what == "both" else (args.what,)
    for what in whats:
        results = {"before": [], "after": []}
        for r in range(args.rounds):
            for side in ("before", "after"):
                res = run(side, what, args)
                results[side].append(res)
                print(f"{what} round {r + 1} {side}: " + ", ".join(
                    f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}" for k, v in res.items()), flush=True)
        for side, runs in results.items():
            for field in (("shown_s", "max_ms", "max_cpu_ms") if what == "preset" else
                          ("median_ms", "max_ms") if what not in ("split", "occlusion") else
                          ("other_max_wall_ms", "other_max_cpu_ms", "other_max_process_cpu_ms") if what == "occlusion" else
                          ("plain_tonemap_max_ms", "split_open_max_ms", "split_tonemap_max_ms")):
                xs = [x[field] for x in runs]
                print(f"{what} {side} {field}: median {statistics.median(xs):.1f} (range {min(xs):.1f}-{max(xs):.1f})")


if __name__ == "__main__":
    main()
