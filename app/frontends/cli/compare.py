"""``alight compare``: a linear image's error against a reference (app/accuracy/metrics.py)."""

from __future__ import annotations

from alight.errors import AlightError
from alight.frontends.cli.arguments import Command, _number


def add_parser(sub) -> None:
    cp = sub.add_parser("compare", help="error of a linear image against a reference: relMAE and FLIP",
                        description="Compare two linear .exr images (e.g. 'alight render --view probe --out t.exr' "
                                    "against 'alight reference --out r.exr'): the relative mean absolute error "
                                    "sum|test-ref|/sum|ref| over the covered pixels (alpha > 0) and RGB, and NVIDIA's "
                                    "FLIP on the ACES-tone-mapped sRGB images.")
    cp.add_argument("test", metavar="TEST.exr")
    cp.add_argument("ref", metavar="REF.exr")
    cp.add_argument("--heatmap", metavar="OUT.png", help="write the per-pixel relative error as a heat map")
    cp.add_argument("--flip-heatmap", metavar="OUT.png", help="write the per-pixel FLIP error as a heat map")
    cp.add_argument("--exposure", type=_number("--exposure", -32.0, 32.0), default=0.0, metavar="EV",
                    help="exposure before tone mapping, for FLIP (default: 0)")
    cp.add_argument("--bin", type=int, default=1, metavar="N",
                    help="also print relMAE after summing both images over NxN blocks (the blocks covered in both): "
                         "against a path-traced reference it divides the reference's noise by N (default: 1, off)")


def run(args) -> int:
    from alight.exchange.output import check_output_path

    if not 1 <= args.bin <= 64:
        raise AlightError(f"--bin: {args.bin} must be from 1 to 64")
    for opt, path in (("--heatmap", args.heatmap), ("--flip-heatmap", args.flip_heatmap)):
        if path:
            check_output_path(path, (".png",))
    from alight.accuracy.metrics import (
        compare_linear,
        read_linear,
        write_flip_heatmap,
        write_relative_heatmap,
    )

    test, ref = read_linear(args.test), read_linear(args.ref)
    if test.shape[:2] != ref.shape[:2]:
        raise AlightError(f"{args.test}: {test.shape[1]}x{test.shape[0]} does not match {args.ref}'s "
                          f"{ref.shape[1]}x{ref.shape[0]}")
    c = compare_linear(test, ref, args.exposure)
    if c.covered == 0:
        raise AlightError(f"{args.ref}: no covered pixel (alpha is 0 everywhere)")
    print(f"relMAE {c.relative_mae * 100:.4g}%  FLIP {c.flip:.4g}  over {c.covered} covered pixels")
    if args.bin > 1:
        from alight.accuracy.binned import binned_relative_mae, covered_blocks

        blocks = int(covered_blocks(test, ref, args.bin).sum())
        if blocks == 0:
            raise AlightError(f"--bin: no {args.bin}x{args.bin} block is covered in both images")
        value = binned_relative_mae(test, ref, args.bin)
        print(f"binned {args.bin}x{args.bin} relMAE {value * 100:.4g}%  over {blocks} blocks")
    if args.heatmap:
        print(write_relative_heatmap(args.heatmap, c.relative_map))
    if args.flip_heatmap:
        print(write_flip_heatmap(args.flip_heatmap, c.flip_map))
    return 0


COMMAND = Command("compare", add_parser, run)
