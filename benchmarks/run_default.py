"""``projeq run`` with no arguments (the spin-up beam, Ωs = 6 rad/s, 20 s): where its time
goes, and the accuracy of its default integrator setting.

In fresh processes, as a user starts it: the CPU time of ``python -m projeq run`` (all of
it: imports, build, simulation, the NPZ, CSV, PNG plots and ParaView files), of importing
the CLI alone, and of the same run with the CLI's former defaults (DOP853, rtol 1e-9,
atol 1e-11); the simulation's own CPU time and evaluations from its run.json; the writing
is the rest. In this process: building the scene and the first s̈. The in-plane tip
deflection of the default run at 5, 10, 15, 20 s is compared with the converged reference
of ``benchmarks/beam_convergence.py`` (8 clamped–free functions, DOP853 at rtol 1e-10) at
the scene's Ωs; with the former defaults likewise (both carry the error of the scene's
4 polynomial functions).

    python benchmarks/run_default.py            # ~1 min: the reference costs ~25 s
"""

from __future__ import annotations

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

IMPORT = "import time; import projeq.cli.commands; print(time.process_time())"


def child_cpu(argv: list) -> tuple[float, float, str]:
    """(CPU s, wall s, standard output) of one fresh Python process."""
    before, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    done = subprocess.run([sys.executable, *argv], capture_output=True, text=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, time.perf_counter() - wall, done.stdout


def projeq_run(out: Path, *options: str) -> dict:
    """``python -m projeq run [options] --json`` in a fresh process: its run.json, the process's
    CPU and wall time, and the tip deflection at TIMES from its NPZ."""
    cpu, wall, stdout = child_cpu(["-m", "projeq", "run", *options, "--out", str(out), "--json"])
    record = json.loads(stdout)
    result = Result.load(Path(record["folder"]) / "spin_up_beam.npz")
    beam = scenes.spin_up_beam().subsystem("beam")
    rows = [int(np.argmin(np.abs(result.t - t))) for t in TIMES]
    tip = beam.deflection(result.q[rows], beam.length)[:, 1]
    return {"process_cpu_s": cpu, "process_wall_s": wall, "simulation_cpu_s": record["cpu_time"],
            "nfev": record["nfev"], "method": record["method"], "tolerances": record["tolerances"], "tip_m": tip}


def main() -> dict:
    omega_s = next(p.default for p in scenes.scene_parameters(scenes.get_scene("spin_up_beam")) if p.name == "omega_s")
    started = time.process_time()
    system = scenes.spin_up_beam()
    built = time.process_time()
    system.evaluator().accelerations(system.q0, system.s_dot0, 0.0)
    first = time.process_time()
    with tempfile.TemporaryDirectory() as out:
        runs = {"default": projeq_run(Path(out)), "former DOP853 1e-9": projeq_run(
            Path(out), "--method", "DOP853", "--rtol", "1e-9", "--atol", "1e-11")}
        import_cpu = float(child_cpu(["-c", IMPORT])[2])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # DOP853 at rtol 1e-10 on the stiff modes: slow, known
        reference = tip_deflection(omega_s, **REFERENCE)[0]
    print(f"projeq run (spin_up_beam, Ωs = {omega_s:g} rad/s, 20 s): CPU s of a fresh process; "
          f"build {built - started:.3f} s, first s̈ {first - built:.4f} s ({system.evaluator().name}), "
          f"import of the CLI {import_cpu:.2f} s")
    print(f"{'run':<20} {'method':>8} {'rtol':>7} {'process':>8} {'simulate':>9} {'writing+':>9} {'nfev':>7} "
          f"{'wall':>6} {'max |tip − ref| m':>18}")
    report = {"build_s": built - started, "first_call_s": first - built, "import_s": import_cpu,
              "reference_tip_m": reference.tolist(), "runs": {}}
    for name, run in runs.items():
        rest = run["process_cpu_s"] - import_cpu - run["simulation_cpu_s"]  # writing, plus build and the record
        error = float(np.abs(run["tip_m"] - reference).max())
        report["runs"][name] = {**run, "tip_m": run["tip_m"].tolist(), "writing_s": rest, "max_tip_error_m": error}
        print(f"{name:<20} {run['method']:>8} {run['tolerances']['rtol']:>7} {run['process_cpu_s']:>8.2f} "
              f"{run['simulation_cpu_s']:>9.2f} {rest:>9.2f} {run['nfev']:>7} {run['process_wall_s']:>6.1f} {error:>18.1e}")
    ratio = runs["default"]["process_cpu_s"] / runs["former DOP853 1e-9"]["process_cpu_s"]
    print(f"default / former: {ratio:.2f} of the CPU time ('writing+': the process's CPU time less the import and "
          "the simulation: NPZ, CSV, plots with matplotlib's import, ParaView files)")
    return report


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # also for the child processes: single-threaded CPU times
    main()
