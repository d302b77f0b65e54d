"""What a new user's first runs cost: process CPU (user + system, the whole process) of README's
example and of ``projeq run`` (the default scene), each in fresh processes on an empty numba
cache (``NUMBA_CACHE_DIR`` a new folder), run after run on that cache.

Two policies side by side: the default (the compiled kernels not in the cache yet, the reference
evaluators run until 10 s of interpreted CPU are spent over the runs of one cache, then the
kernels compile: :mod:`projeq.assembly.compilation`) and ``PROJEQ_COMPILE=now`` (compiled at
the first call, the behaviour before). The issue's bound: each ≤ 10 s on the first run.

    PYTHONPATH=. python benchmarks/cold_start.py [--runs 3] [--now]   # --now: also the compile-now policy (≈ 2 min)
    PYTHONPATH=. python benchmarks/cold_start.py --quick              # one cold run of projeq run --t-end 1
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

from projeq.studies.table import Table

ROOT = Path(__file__).resolve().parents[1]


def readme_example() -> str:
    """README's first Python block (its example), as README shows it."""
    return re.search(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)


def process_cpu(command: list, cache: str, policy: str, folder: str) -> tuple[float, int]:
    """(CPU seconds of the child process, its return code), run in ``folder`` on numba cache ``cache``."""
    env = {k: v for k, v in os.environ.items() if k != "PROJEQ_COMPILE"}
    env.update(NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    if policy == "now":
        env["PROJEQ_COMPILE"] = "now"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    code = subprocess.run(command, env=env, cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, code


def commands(quick: bool) -> dict:
    run = [sys.executable, "-m", "projeq", "run", "--quiet", "--out", "runs"]
    if quick:
        return {"projeq run --t-end 1": run + ["--t-end", "1"]}
    return {"README's example": [sys.executable, "-c", readme_example()], "projeq run": run}


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs per command on one cache (default 3)")
    parser.add_argument("--now", action="store_true", help="also the PROJEQ_COMPILE=now policy")
    parser.add_argument("--quick", action="store_true", help="one cold run of projeq run --t-end 1")
    args = parser.parse_args(argv)
    runs = 1 if args.quick else args.runs
    policies = ("default", "now") if args.now else ("default",)
    rows = []
    for name, command in commands(args.quick).items():
        for policy in policies:
            with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as folder:
                measured = [process_cpu(command, cache, policy, folder) for _ in range(runs)]
            rows.append([name, policy, *[cpu for cpu, _ in measured], " ".join(str(c) for _, c in measured)])
    table = Table(["command", "policy", *[f"run {i + 1}" for i in range(runs)], "exit codes"], rows,
                  units={f"run {i + 1}": "s CPU" for i in range(runs)}, formats={f"run {i + 1}": ".1f" for i in range(runs)},
                  title="First runs on an empty numba cache, one after another on that cache: process CPU")
    print(table.to_text())
    return table


if __name__ == "__main__":
    main()
