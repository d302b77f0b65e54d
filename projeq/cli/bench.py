"""``projeq bench``: quick chain scaling, then the quick derivation and beam studies within a
total wall-time budget (:func:`projeq.studies.bench.quick_suite`); tables or one JSON
document. Exit code 1 when a study failed or was stopped by the budget. ``--peers``: the
comparisons with other codes instead (:func:`projeq.studies.bench_peers.peers_report`)."""

from __future__ import annotations

import argparse
import json
import os

from projeq.cli.options import plain
from projeq.studies import bench, bench_peers
from projeq.studies.bench import EXACT_UP_TO, QUICK_SIZES, TOTAL_BUDGET


def bench_arguments(parser) -> None:
    parser.description = plain(bench.__doc__)
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of tables")
    parser.add_argument("--budget", type=_non_negative_seconds, default=0.5, help="seconds of timing per chain length (default 0.5)")
    parser.add_argument("--sizes", type=_sizes, default=QUICK_SIZES, metavar="N,N,...",
                        help=f"chain lengths (default {','.join(map(str, QUICK_SIZES))})")
    parser.add_argument("--total", type=_seconds, default=TOTAL_BUDGET,
                        help=f"wall-time budget in s for everything; the quick studies share what the chain part "
                             f"leaves and stop when it is spent (default {TOTAL_BUDGET:g})")
    parser.add_argument("--no-peers", action="store_true", help="skip Pinocchio and MuJoCo")
    exact_option(parser)
    parser.add_argument("--chain-only", action="store_true", help="skip the quick derivation and beam studies")
    parser.add_argument("--peers", action="store_true",
                        help="instead: projeq's defaults against Pinocchio, MuJoCo (chain of --sizes), sympy's "
                             "KanesMethod (rolling disk) and Exudyn (spin-up beam), each checked to compute the "
                             "same first (projeq.studies.bench_peers; in full benchmarks/peers.py)")
    parser.set_defaults(execute=run_benchmarks)


def exact_option(parser: argparse.ArgumentParser) -> None:
    """``--exact-up-to N`` (for ``projeq bench`` and ``benchmarks/chain_scaling.py``)."""
    parser.add_argument("--exact-up-to", type=_chain_length, default=EXACT_UP_TO, metavar="N",
                        help=f"compare with the exact s̈ (projeq.studies.bench_exact) for n <= N (default {EXACT_UP_TO}; "
                             f"it costs about 0.5 s at n = 100, 4 s at n = 300)")


def run_benchmarks(args) -> int:
    os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: they measure the compiled path
    if args.peers:
        report = bench_peers.peers_report(args.sizes, args.budget, show=None if args.json else _show)
        if args.json:
            print(json.dumps(report, indent=2))
        return 0
    document = bench.quick_suite(args.sizes, args.budget, args.total, not args.no_peers, args.exact_up_to,
                                 args.chain_only, show=None if args.json else _show)
    if args.json:
        print(json.dumps(document, indent=2))
    return int(any(p["status"] != "ok" for p in document["parts"]))


def _show(text: str) -> None:
    print(text, flush=True)


def _seconds(text: str) -> float:
    """A positive, finite number of seconds; argparse names the option in its error (exit code 2)."""
    try:
        seconds = _non_negative_seconds(text)
        if seconds == 0.0:
            raise argparse.ArgumentTypeError
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}") from None
    return seconds


def _non_negative_seconds(text: str) -> float:
    """A finite number of seconds ≥ 0 (0: time each evaluator once)."""
    try:
        seconds = float(text)
        if not 0.0 <= seconds < float("inf"):
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds >= 0, got {text!r}") from None
    return seconds


def _chain_length(text: str) -> int:
    """A chain length ≥ 0 (0: no comparison with the exact s̈); argparse names the option."""
    try:
        n = int(text)
        if n < 0:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a chain length >= 0, got {text!r}") from None
    return n


def _sizes(text: str) -> tuple:
    """``"10,30"`` -> (10, 30); argparse prints the error as a bad --sizes (exit code 2)."""
    try:
        sizes = tuple(int(n) for n in text.split(","))
        if min(sizes) < 1:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected chain lengths >= 1 separated by commas, got {text!r}") from None
    return sizes
