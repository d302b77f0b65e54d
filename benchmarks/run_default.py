"""``projeq run`` with no arguments (the spin-up beam, Ωs = 6 rad/s, 20 s): where its time
goes, the accuracy of its default integrator setting, and the first-call latency of the
compiled kernel.

In fresh processes, as a user starts them (CPU and wall time of each whole process): the
Python interpreter alone, importing the CLI, ``python -m projeq run`` (all of it: imports,
build, simulation, the NPZ, CSV and ParaView files), the same with ``--plots`` (the PNG plots,
matplotlib's import included) and with the CLI's former defaults (DOP853, rtol 1e-9, atol
1e-11); the simulation's own CPU time and evaluations from its run.json; the writing is the
rest. The in-plane tip deflection of the default run at 5, 10, 15, 20 s is compared with the
converged reference of ``benchmarks/beam_convergence.py`` (8 clamped–free functions, DOP853 at
rtol 1e-10) at the scene's Ωs; with the former defaults likewise (both carry the error of the
scene's 4 polynomial functions).

First-call latency (a scene on the compiled kernel, ``chain(5)``; numba's on-disk cache
filled): in a fresh process, numba's import, numba's own initialisation of its compiler target
(which it does on loading the first cached function; here called first, to time it apart),
the first s̈ (the loads of projeq's kernels from the cache), the second s̈, and per kernel the specialisations loaded and those in its cache index (each
specialisation a compilation of its own when the cache is empty).

    python benchmarks/run_default.py            # ~1 min: the reference costs ~25 s
    python benchmarks/run_default.py --quick    # the default run over 1 s alone, no reference
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from projeq import Result, scenes
from projeq.studies.bench_beam import REFERENCE, TIMES, tip_deflection

#: what ``projeq run`` imports: the CLI, the scenes, the simulation driver (scipy.integrate)
IMPORT = "import projeq.cli.commands, projeq.cli.run, projeq.scenes, projeq.simulation.driver"

#: the first compiled s̈ in a fresh process, by phase (JSON on standard output)
FIRST_CALL = """
import json, time
clock = lambda: (time.process_time(), time.perf_counter())
marks = [clock()]
from projeq import scenes
system = scenes.chain(5)
marks.append(clock())
import numba
marks.append(clock())
from numba.core.registry import cpu_target
cpu_target.target_context.refresh()  # what numba does on loading its first cached function
marks.append(clock())
from projeq.assembly import kernels
evaluator = system.evaluator()
evaluator.accelerations(system.q0, system.s_dot0, 0.0)
marks.append(clock())
evaluator.accelerations(system.q0, system.s_dot0, 0.0)
marks.append(clock())
dispatchers = [*kernels._compiled().values(), *kernels._compiled_gauss_form(False)]
kernels_ = {d.__name__: {"loaded": len(d.signatures), "in_cache_index": len(d._cache._cache_file._load_index()),
                         "cache_misses": sum(d.stats.cache_misses.values())} for d in dispatchers}
phases = ["import projeq, build chain(5)", "import numba", "numba's target initialisation",
          "first s̈ (projeq's kernels loaded)", "second s̈"]
print(json.dumps({"evaluator": evaluator.name, "kernels": kernels_,
                  "phases": {p: [b[0] - a[0], b[1] - a[1]] for p, a, b in zip(phases, marks, marks[1:])}}))
"""


def child(argv: list) -> tuple[float, float, str]:
    """(CPU s, wall s, standard output) of one fresh Python process."""
    before, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    done = subprocess.run([sys.executable, *argv], capture_output=True, text=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, time.perf_counter() - wall, done.stdout


def projeq_run(out: Path, *options: str) -> dict:
    """``python -m projeq run [options] --json`` in a fresh process: its run.json, the process's
    CPU and wall time, and the tip deflection at TIMES from its NPZ."""
    cpu, wall, stdout = child(["-m", "projeq", "run", *options, "--out", str(out), "--json"])
    record = json.loads(stdout)
    result = Result.load(Path(record["folder"]) / "spin_up_beam.npz")
    beam = scenes.spin_up_beam().subsystem("beam")
    rows = [int(np.argmin(np.abs(result.t - t))) for t in TIMES]
    tip = beam.deflection(result.q[rows], beam.length)[:, 1]
    return {"process_cpu_s": cpu, "process_wall_s": wall, "simulation_cpu_s": record["cpu_time"],
            "nfev": record["nfev"], "method": record["method"], "tolerances": record["tolerances"], "tip_m": tip,
            "files": len(record["files"])}


def first_call(fill: bool = True) -> dict:
    """:data:`FIRST_CALL` in a fresh process (with ``fill`` run once before, so that numba's cache is
    filled)."""
    if fill:
        child(["-c", FIRST_CALL])
    return json.loads(child(["-c", FIRST_CALL])[2])


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="the default run over 1 s alone (its tip at 1 s), no reference, first call once")
    args = parser.parse_args(argv)
    omega_s = next(p.default for p in scenes.scene_parameters(scenes.get_scene("spin_up_beam")) if p.name == "omega_s")
    with tempfile.TemporaryDirectory() as out:
        if args.quick:
            runs = {"default, 1 s": projeq_run(Path(out), "--t-end", "1")}
        else:
            former = ("--method", "DOP853", "--rtol", "1e-9", "--atol", "1e-11")
            runs = {"default": projeq_run(Path(out)), "--plots": projeq_run(Path(out), "--plots"),
                    "former DOP853 1e-9": projeq_run(Path(out), *former)}
    python_cpu, python_wall, _ = child(["-c", "pass"])
    import_cpu, import_wall, _ = child(["-c", IMPORT])
    latency = first_call(fill=not args.quick)
    if args.quick:
        print("quick: no converged reference (it costs ~25 s): the tip errors are nan")
        reference = np.full(len(TIMES), np.nan)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # DOP853 at rtol 1e-10 on the stiff modes: slow, known
            reference = tip_deflection(omega_s, **REFERENCE)[0]
    print(f"projeq run (spin_up_beam, Ωs = {omega_s:g} rad/s, 20 s), fresh processes: CPU s (wall s); "
          f"Python alone {python_cpu:.2f} ({python_wall:.2f}), importing what projeq run imports (CLI, scenes, "
          f"driver) {import_cpu:.2f} ({import_wall:.2f})")
    print(f"{'run':<20} {'method':>8} {'rtol':>7} {'process':>8} {'wall':>6} {'simulate':>9} {'rest':>9} "
          f"{'files':>6} {'nfev':>6} {'max |tip − ref| m':>18}")
    report = {"python_s": [python_cpu, python_wall], "import_s": [import_cpu, import_wall], "first_call": latency,
              "reference_tip_m": reference.tolist(), "runs": {}}
    for name, run in runs.items():
        rest = run["process_cpu_s"] - import_cpu - run["simulation_cpu_s"]  # writing, plus build and the record
        error = float(np.abs(run["tip_m"] - reference).max())
        report["runs"][name] = {**run, "tip_m": run["tip_m"].tolist(), "writing_s": rest, "max_tip_error_m": error}
        print(f"{name:<20} {run['method']:>8} {run['tolerances']['rtol']:>7} {run['process_cpu_s']:>8.2f} "
              f"{run['process_wall_s']:>6.1f} {run['simulation_cpu_s']:>9.2f} {rest:>9.2f} {run['files']:>6} "
              f"{run['nfev']:>6} {error:>18.1e}")
    if not args.quick:
        cpu = {name: run["process_cpu_s"] for name, run in runs.items()}
        print(f"default / --plots: {cpu['default'] / cpu['--plots']:.2f} of the CPU time; default / former: "
              f"{cpu['default'] / cpu['former DOP853 1e-9']:.2f} ('rest': the process's CPU time less the "
              "imports of projeq run and the simulation: NPZ, CSV, ParaView files, plots with matplotlib's "
              "import when asked, the build, the record, and Python's start)")
    print(f"\nfirst compiled s̈ in a fresh process, numba's cache filled (chain(5), evaluator {latency['evaluator']}): "
          "CPU s (wall s)")
    for phase, (cpu, wall) in latency["phases"].items():
        print(f"  {phase:<40} {cpu:7.3f} ({wall:.3f})")
    for name, counts in latency["kernels"].items():
        print(f"  kernel {name:<24} specialisations loaded {counts['loaded']}, in its cache index "
              f"{counts['in_cache_index']}, cache misses {counts['cache_misses']}")
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # also for the child processes: single-threaded CPU times
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # the children's modules from bytecode, as an installed package's
    main()
