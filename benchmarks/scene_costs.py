"""Every scene of ``projeq list``: which evaluator the default picks (compiled "fast",
"hub_beam", or an interpreted reference) and the cost of one s̈ against the compiled
``scenes.chain(k)``, k = the scene's number of minimal velocities, timed alternately in one
run (ratios, not absolute times, are what holds across machines); then the first-call
latency of the compiled kernel in a fresh process, with an empty and with a filled numba
cache (:mod:`projeq.studies.bench_scenes`).

    python benchmarks/scene_costs.py              # table and latency
    python benchmarks/scene_costs.py --json       # the same as JSON
    python benchmarks/scene_costs.py --quick      # two scenes, 0.01 s each, no latency (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import json

from projeq.studies.bench_scenes import first_call_latency, scene_costs, scene_row, table


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=float, default=0.5, help="seconds of timing per scene (default 0.5)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--quick", action="store_true",
                        help="chain and four_bar, 0.01 s each; no latency (its cold compile takes a minute)")
    args = parser.parse_args(argv)
    rows = [scene_row(name, 0.01) for name in ("chain", "four_bar")] if args.quick else \
        scene_costs(args.budget)[0]
    report = {"scenes": rows, "latency": {} if args.quick else first_call_latency()}
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(table(rows).to_text())
        print("\nfirst compiled s̈ in a fresh process (s): " + ", ".join(f"{k} {v:.2f}" for k, v in report["latency"].items()))
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
