"""Short runs of ``simulate`` at its defaults, warm: evaluations and CPU per run, per scene.

What a sweep or an interactive user pays per run: each scene's ``simulate(scene, t_end)`` with no
options (501 output rows with their energies and residuals), repeated; the least CPU per run over
``--rounds`` rounds, and the evaluations. Run it from two checkouts to compare them, alternately,
with ``farm-bench`` (whole processes) or by its own numbers:

    PYTHONPATH=<checkout> python benchmarks/short_runs.py            # 7 scenes, about 10 s of runs
    PYTHONPATH=<checkout> python benchmarks/short_runs.py --quick    # the double pendulum twice (a test runs it)
"""

from __future__ import annotations

import argparse
import os
import time

from projeq import scenes, simulate
from projeq.studies.table import Table

#: (scene, simulated seconds, runs per round)
CASES = (("double_pendulum", 0.5, 100), ("chain", 1.0, 20), ("four_bar", 2.0, 10), ("rolling_disk", 2.0, 10),
         ("flyball_governor", 2.0, 4), ("car", 2.0, 10), ("whipple_bicycle", 2.0, 10))


def row(name: str, t_end: float, runs: int, rounds: int) -> list:
    """[scene, t_end, method, evaluations, least CPU ms per run over the rounds]."""
    system = getattr(scenes, name)()
    result = simulate(system, t_end)  # warm: compiles (or loads) the model and the loop
    best = float("inf")
    for _ in range(rounds):
        started = time.process_time()
        for _ in range(runs):
            result = simulate(system, t_end)
        best = min(best, (time.process_time() - started) / runs)
    return [name, t_end, result.method, result.nfev, best * 1e3]


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds per scene (default 3)")
    parser.add_argument("--quick", action="store_true", help="the double pendulum, two runs, one round")
    args = parser.parse_args(argv)
    cases, rounds = ((("double_pendulum", 0.5, 2),), 1) if args.quick else (CASES, args.rounds)
    table = Table(["scene", "t_end", "method", "evaluations", "CPU per run"],
                  [row(name, t_end, runs, rounds) for name, t_end, runs in cases],
                  units={"t_end": "s", "CPU per run": "ms"}, formats={"CPU per run": ".2f"},
                  title="simulate(scene, t_end) at its defaults, warm: evaluations and CPU per run")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
