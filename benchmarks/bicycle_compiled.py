"""The Whipple bicycle's s̈ in one compiled call against its numpy path and the compiled chain(3).

One run times, alternately (CPU time, :func:`projeq.studies.timing.time_per_call`): s̈ of the
default bicycle (:func:`projeq.scenes.whipple_bicycle`) by its default evaluator (the compiled
closure kernel: Φ, the Pfaffian rows A and the rear frame's relative motion compiled), by the
numpy path of the same model (Φ's and A's complex steps in numpy, the tree's compiled Gauss form,
numpy linear algebra), and the compiled ``scenes.chain(3)`` (k = 3 minimal velocities, issue 15's
yardstick); then the CPU time of a default ``simulate`` of 2 s by each path and the largest
difference of their final states, for the default (upright, straight) bicycle and after a
roll-rate kick of 0.5 rad/s (a weave). Ratios hold across machines, not the absolute times.

    PYTHONPATH=. python benchmarks/bicycle_compiled.py [--budget 2] [--json]
    PYTHONPATH=. python benchmarks/bicycle_compiled.py --quick   # 0.05 s of timing, one upright 0.02 s run
"""

from __future__ import annotations

import os
import argparse
import json
import time

import numpy as np

import projeq as pq
from projeq.studies.timing import time_per_call


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=float, default=2.0, help="seconds of timing (default 2)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of text")
    parser.add_argument("--quick", action="store_true", help="0.05 s of timing, one upright run of 0.02 s")
    args = parser.parse_args(argv)
    budget, t_end = (0.05, 0.02) if args.quick else (args.budget, 2.0)
    compiled, numpy_path = pq.scenes.whipple_bicycle(), pq.scenes.whipple_bicycle()
    numpy_path._compiled = None  # the path every model takes where the compiled call does not apply
    chain = pq.scenes.chain(3).evaluator("fast")
    chain_q, chain_s = np.random.default_rng(3).uniform(-1, 1, (2, 3))
    evaluators = {"compiled": compiled.evaluator(), "numpy path": numpy_path.evaluator()}
    q0, s_dot0 = compiled.q0, compiled.s_dot0
    seconds = time_per_call({
        **{name: (lambda _q, _s, ev=ev: ev.accelerations(q0, s_dot0, 0.0)) for name, ev in evaluators.items()},
        "chain(3)": lambda _q, _s: chain.accelerations(chain_q, chain_s, 0.0),
    }, None, None, budget)
    report = {"us_per_call": {k: v * 1e6 for k, v in seconds.items()},
              "ratio_to_chain3": {k: seconds[k] / seconds["chain(3)"] for k in evaluators}}
    for roll_rate in (0.0,) if args.quick else (0.0, 0.5):  # the default upright run, a weave after a kick
        finals, label = {}, f"roll_rate={roll_rate}"
        for name in ("compiled", "numpy path"):
            model = pq.scenes.whipple_bicycle(roll_rate=roll_rate)
            if name == "numpy path":
                model._compiled = None
            pq.simulate(model, min(0.05, t_end))  # warm-up (compilation)
            start = time.process_time()
            run = pq.simulate(model, t_end)
            report.setdefault(f"simulate_{t_end:g}s_cpu_s ({label})", {})[name] = time.process_time() - start
            finals[name] = np.concatenate((run.q[-1], run.s_dot[-1]))
        report[f"final_state_max_difference ({label})"] = float(np.abs(finals["compiled"] - finals["numpy path"]).max())
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        for key, value in report.items():
            print(f"{key}: {value}")
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
