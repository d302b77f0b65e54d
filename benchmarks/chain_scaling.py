"""Cost of one evaluation of s̈ for ``projeq.scenes.chain(n)``: recursive vs dense.

Prints a table (time per call, time per body, dense/recursive ratio) and the fitted
log-log slope of each evaluator; ``--json`` prints the same numbers as JSON. The two
evaluators are timed alternately in one run and each entry is the minimum over repeats,
so the ratios are robust on a noisy machine; absolute times are this machine's only.

    python benchmarks/chain_scaling.py            # n = 10, 30, 100, 300, 1000
    python benchmarks/chain_scaling.py --quick    # n = 10, 30, 100
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import projeq as pq

SIZES = (10, 30, 100, 300, 1000)
QUICK_SIZES = (10, 30, 100)


def time_per_call(evaluators: dict, q, s_dot, budget: float) -> dict:
    """Minimum wall time of one ``accelerations`` call per evaluator, alternating them
    until ``budget`` seconds are spent (at least 3 rounds)."""
    best = dict.fromkeys(evaluators, np.inf)
    for ev in evaluators.values():
        ev.accelerations(q, s_dot, 0.0)  # warm-up: plans, caches
    started, rounds = time.perf_counter(), 0
    while rounds < 3 or time.perf_counter() - started < budget:
        for name, ev in evaluators.items():
            t0 = time.perf_counter()
            ev.accelerations(q, s_dot, 0.0)
            best[name] = min(best[name], time.perf_counter() - t0)
        rounds += 1
    return best


def measure(sizes, budget: float = 1.0) -> list[dict]:
    """One row per chain length: seconds per call of each evaluator and their agreement."""
    rng = np.random.default_rng(0)
    rows = []
    for n in sizes:
        system = pq.scenes.chain(n)
        q, s_dot = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        evaluators = {m: system.evaluator(m) for m in ("recursive", "dense")}
        best = time_per_call(evaluators, q, s_dot, budget)
        a, b = (evaluators[m].accelerations(q, s_dot, 0.0) for m in ("recursive", "dense"))
        rows.append({
            "n": n,
            "recursive_s": best["recursive"],
            "dense_s": best["dense"],
            "dense_over_recursive": best["dense"] / best["recursive"],
            "max_relative_difference": float(np.abs(a - b).max() / max(1.0, np.abs(b).max())),
            # the two solutions are backward stable; they differ by about cond(M)·ε
            "cond_M_eps": float(np.linalg.cond(system.mass_matrix(q)) * np.finfo(float).eps),
        })
    return rows


def slope(rows, key: str) -> float:
    """Least-squares slope of log(time) against log(n)."""
    n = np.array([r["n"] for r in rows], dtype=float)
    return float(np.polyfit(np.log(n), np.log([r[key] for r in rows]), 1)[0])


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="n = 10, 30, 100 only")
    parser.add_argument("--budget", type=float, default=1.0, help="seconds of timing per size (default 1)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    rows = measure(QUICK_SIZES if args.quick else SIZES, args.budget)
    report = {
        "rows": rows,
        "slope_recursive": slope(rows, "recursive_s"),
        "slope_dense": slope(rows, "dense_s"),
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return report
    print(f"{'n':>6} {'recursive ms':>13} {'dense ms':>10} {'µs/body rec':>12} {'dense/rec':>10} {'max rel diff':>13} {'cond(M)·ε':>10}")
    for r in rows:
        print(
            f"{r['n']:>6} {r['recursive_s'] * 1e3:>13.3f} {r['dense_s'] * 1e3:>10.3f} "
            f"{r['recursive_s'] / r['n'] * 1e6:>12.1f} {r['dense_over_recursive']:>10.2f} {r['max_relative_difference']:>13.1e} {r['cond_M_eps']:>10.1e}"
        )
    print(f"log-log slope: recursive {report['slope_recursive']:.3f}, dense {report['slope_dense']:.3f}")
    return report


if __name__ == "__main__":
    main()
