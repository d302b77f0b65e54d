"""Two processes started together on one empty numba cache, each running a model whose kernels compile at
first use (``PROJEQ_COMPILE=now``), with projeq's compile lock (one process compiles a kernel, the other
waits and loads it: :func:`projeq.assembly.compilation._one_at_a_time`) and without it (numba's own
compile, each process compiling every kernel), side by side, alternating A B A B: the pair's wall time
and the CPU of each process.

    python benchmarks/compile_lock.py            # the four-bar simulated for 0.1 s, two rounds (~5 min)
    python benchmarks/compile_lock.py --quick    # a one-line kernel, one round (seconds)

Measured 2026-12-07 (2 cores, nothing else running; the four-bar, benchmarks/results/2026-12-07/
compile_lock.txt): the pair's CPU 147 and 156 s without the lock, 85 and 75 s with it (ratios 0.58 and
0.48: the second process spends 2.5–3 s, loading what the first compiled); wall 1.10 and 0.92 of
without's (the waiting process idles while the first compiles: one core compiles, where two did the same
work side by side).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: a child's code that runs without the lock: numba's own compile is installed in its place
WITHOUT = "from projeq.assembly import compilation; compilation._one_at_a_time = lambda compile: compile\n"
FOUR_BAR = "import projeq as pq; pq.simulate(pq.scenes.four_bar(), 0.1)"
#: the quick model: a kernel in a module named as projeq's generated ones (projeq_generated_*)
PROBE = "import numba\n\n@numba.njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n"
QUICK = "from projeq.assembly import kernels; kernels.numba_module(); import projeq_generated_probe as m; m.twice(1.5)"


def pair(code: str, folder: Path) -> dict:
    """Two processes of ``code`` started together on a new numba cache: wall seconds and each one's CPU
    seconds (user + system, from ``os.wait4``)."""
    env = dict(os.environ, PROJEQ_COMPILE="now", NUMBA_CACHE_DIR=tempfile.mkdtemp(dir=folder),
               PYTHONPATH=os.pathsep.join([str(folder), str(ROOT)]))
    started = time.perf_counter()
    children = [subprocess.Popen([sys.executable, "-c", code], cwd=folder, env=env, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True) for _ in range(2)]
    cpu = []
    for child in children:
        errors = child.stderr.read()
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode:
            raise RuntimeError(f"a child failed ({child.returncode}): {errors[-2000:]}")
        cpu.append(usage.ru_utime + usage.ru_stime)
    return {"wall": time.perf_counter() - started, "cpu": cpu}


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=2, help="A B rounds (default 2; --quick: 1)")
    parser.add_argument("--quick", action="store_true", help="a one-line kernel, one round")
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error("--rounds must be ≥ 1")
    rounds, code = (1, QUICK) if args.quick else (args.rounds, FOUR_BAR)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        (folder / "projeq_generated_probe.py").write_text(PROBE)
        print(f"{'round':>5} {'lock':>7} {'wall s':>8} {'CPU s (both)':>13} {'CPU s (each)':>16}")
        for k in range(rounds):
            for lock, prelude in (("without", WITHOUT), ("with", "")):
                found = pair(prelude + code, folder)
                rows.append({"round": k, "lock": lock, **found})
                each = " + ".join(f"{c:.1f}" for c in found["cpu"])
                print(f"{k:>5} {lock:>7} {found['wall']:>8.1f} {sum(found['cpu']):>13.1f} {each:>16}", flush=True)
    for measure, of in (("CPU", lambda r: sum(r["cpu"])), ("wall", lambda r: r["wall"])):
        ratios = [of(rows[i + 1]) / of(rows[i]) for i in range(0, len(rows), 2)]
        print(f"{measure} with / without the lock: " + ", ".join(f"{r:.2f}" for r in ratios))
    return rows


if __name__ == "__main__":
    main()
