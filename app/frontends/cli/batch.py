"""``alight batch``: the command line of app/frontends/batch.py (meshes x environments x materials x angles)."""

from __future__ import annotations

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command


def add_parser(sub) -> None:
    bt = sub.add_parser("batch", help="render meshes x environments x materials x angles from a spec",
                        description="Render every combination in a .toml/.json spec (docs/guides/batch.md), a "
                                    "labelled contact sheet and optional turntables. Up-to-date outputs are "
                                    "skipped; failed items are reported and the rest go on (exit 1).")
    bt.add_argument("spec", metavar="SPEC.toml|SPEC.json")
    bt.add_argument("--executor", choices=("local", "ray", "inline"), default="local",
                    help="local: a process pool, one GL context per process; ray: Ray actors, each with its "
                         "own GL context and bake cache (RAY_ADDRESS or --ray-address picks the cluster; "
                         "none: a local one); inline: this process (default: local)")
    bt.add_argument("--ray-address", metavar="ADDR", help="Ray cluster address, e.g. auto or HEAD:6379")
    bt.add_argument("--workers", type=int, default=None, metavar="N", help="worker processes (default: CPU count)")
    bt.add_argument("--force", action="store_true", help="render every item even if its output is up to date")
    bt.add_argument("--out", metavar="DIR", help="output folder (default: the spec's 'out')")
    bt.add_argument("--variant", metavar="NAME",
                    help="draw every mesh with its glTF material variant NAME (KHR_materials_variants; each mesh "
                         "must have it), with the spec's \"own\" material entry (the default then); NAME is "
                         "added to the meshes' output names")


def run(args) -> int:
    if args.workers is not None and args.workers < 1:
        raise AlightError(f"--workers: {args.workers} must be at least 1")
    import os

    from alight.frontends.batch import main as batch_main

    if args.ray_address:
        os.environ["ALIGHT_RAY_ADDRESS"] = args.ray_address

    return batch_main(args.spec, args.executor, args.workers, args.force, args.out, variant=args.variant)


COMMAND = Command("batch", add_parser, run)
