"""``alight cache``: the bake cache (app/ibl/bake_cache.py) shown or cleared."""

from __future__ import annotations

from alight.frontends.cli.arguments import Command


def add_parser(sub) -> None:
    ca = sub.add_parser("cache", help="show or clear the bake cache (bakes reused across runs)",
                        description="The bakes kept between runs (app/ibl/bake_cache.py) and the BRDF LUTs, in "
                                    "ALIGHT_CACHE_DIR or the user's cache folder; the least recently used bakes "
                                    "go first past the size limit (ALIGHT_BAKE_CACHE_MB).")
    ca.add_argument("action", nargs="?", choices=("show", "clear"), default="show",
                    help="show: where it is, entries and size (default); clear: remove every bake and LUT")


def run(args) -> int:
    from alight.ibl.bake import LutCache
    from alight.ibl.bake_cache import BakeCache

    bakes = BakeCache()
    luts = LutCache.files()
    if args.action == "clear":
        removed = bakes.clear()
        for path in luts:
            path.unlink(missing_ok=True)
        print(f"removed {removed} bake{'s' * (removed != 1)} and {len(luts)} BRDF LUT{'s' * (len(luts) != 1)} "
              f"from {bakes.directory.parent}")
        return 0
    count, size = bakes.stats()
    lut_bytes = sum(p.stat().st_size for p in luts)
    print(f"bake cache: {bakes.directory}")
    print(f"  {count} bake{'s' * (count != 1)}, {size / 2**20:.1f} MiB of {bakes.size_limit / 2**20:.0f} MiB "
          f"(past it, the least recently used go first; ALIGHT_BAKE_CACHE_MB sets it)")
    print(f"  BRDF LUTs: {len(luts)} file{'s' * (len(luts) != 1)}, {lut_bytes / 2**20:.1f} MiB")
    return 0


COMMAND = Command("cache", add_parser, run)
