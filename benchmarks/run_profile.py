"""Where the time of ``projeq run`` (no arguments: the spin-up beam) goes, in fresh processes.

Three views of the same command, ``python -m projeq run --quiet --out TMP``:

1. phases (``--repeat`` processes, the median of each phase): the run's own functions timed
   from inside the process (CPU and wall): Python's start (interpreter, site), the parser
   (importing the CLI, the scenes and what they import), the scene's build, ``simulate``
   (with, inside it, numba's import — done just before ``simulate`` by ``projeq run``, which forms
   the run's evaluator among its imports —, numba's target initialisation — its compiler's
   registries, which it loads on the first cached function —, the loads of projeq's
   kernels from numba's disk cache, the implicit methods' Jacobians, the output rows'
   energies and the validity checks), the files (NPZ + CSV, ParaView series, run.json) and the
   interpreter's exit (the process's CPU time less the child's own at the end of ``main``:
   atexit handlers, module teardown);
2. ``-X importtime``: the import self-times summed by package (``scipy.linalg``, ``numba``,
   ``projeq`` ...), and the slowest cumulative imports;
3. ``--cprofile``: the run under cProfile, the functions with the largest own time (the
   profiler's overhead inflates Python-heavy code such as imports: for orientation only).

Also, asked for: ``--alternatives`` times what the fixed costs' alternatives would save (numba
initialised in a background thread beside scipy's import; numba's cache load without its
target refresh, through numba's private API, not used by projeq; an integrator needing only
scipy.linalg instead of scipy.integrate); ``--compare TREE`` times the phases of this tree's
``projeq run`` and another checkout's alternately (before/after a change, in one run).

    PYTHONPATH=. python benchmarks/run_profile.py [--repeat 5] [--cprofile] [--alternatives] [SCENE ...]
    PYTHONPATH=. python benchmarks/run_profile.py --compare /path/to/other/checkout [--repeat 5]
    PYTHONPATH=. python benchmarks/run_profile.py --quick   # a process of projeq run --t-end 1 per view
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict

#: the child: times the run's phases by wrapping the functions that do them, runs ``main``
PHASES = r"""
import json, sys, time
clock = lambda: (time.process_time(), time.perf_counter())
start = clock()  # CPU since the process started: Python's own start
spent = {}

import gc
collector = [0.0, 0.0, 0, 0]  # the cyclic garbage collector: CPU s, wall s, collections, full collections

def on_collection(phase, info, mark=[]):
    if phase == "start":
        mark[:] = clock()
        return
    collector[:2] = [c + b - a for c, a, b in zip(collector, mark, clock())]
    collector[2] += 1
    collector[3] += info["generation"] == 2

gc.callbacks.append(on_collection)
stack = []  # the timed calls in progress: [label, time of the timed calls inside it]

def timed(function, label):
    # function, its own time (less that of the timed calls inside it) added to spent[label]
    def wrapper(*args, **kwargs):
        before = clock()
        stack.append([label, [0.0, 0.0]])
        try:
            return function(*args, **kwargs)
        finally:
            after = clock()
            _, inner = stack.pop()
            elapsed = [b - a for a, b in zip(before, after)]
            total = spent.setdefault(label, [0.0, 0.0])
            for i in (0, 1):
                total[i] += elapsed[i] - inner[i]
                if stack:
                    stack[-1][1][i] += elapsed[i]
    return wrapper

def patch(owner, name, label):
    wrapper = timed(getattr(owner, name), label)
    wrapper.__wrapped__ = getattr(owner, name)
    setattr(owner, name, wrapper)

import projeq.cli.commands as commands
projeq_import = [b - a for a, b in zip(start, clock())]
if hasattr(commands, "THRESHOLDS"):  # what command() sets first, before the imports below (the parser's)
    gc.set_threshold(*commands.THRESHOLDS)
patch(commands, "parser", "parser: CLI, scenes, their imports")
import projeq.assembly.kernels as kernels

def load_numba(load=kernels._numba):  # numba's import where the run does it, then its functions wrapped
    numba = load()
    if numba is not None:
        import numba.core.base, numba.core.caching
    if numba is not None and not hasattr(numba.core.caching.Cache.load_overload, "__wrapped__"):
        patch(numba.core.base.BaseContext, "refresh", "  numba's target initialisation")
        patch(numba.core.caching.Cache, "load_overload", "  kernels loaded from numba's cache")
    return numba

kernels._numba = timed(load_numba, "  numba's import")
before = clock()
from contextlib import nullcontext
with getattr(commands, "imports_frozen", nullcontext)():  # as the parser and run_scene import them
    import projeq.scenes, projeq.simulation.driver, projeq.simulation.export, projeq.cli.run
preimport = [b - a for a, b in zip(before, clock())]  # the parser's imports, done here to wrap them

def resolve_scene(text, resolve=projeq.scenes.resolve_scene):
    scene = resolve(text)
    return scene._replace(build=timed(scene.build, "scene build"))

projeq.scenes.resolve_scene = resolve_scene
patch(projeq.simulation.driver, "simulate", "simulate")
for name, label in (("differentiate", "  Jacobians ∂ẋ/∂x (implicit methods)"),  # where the driver has them
                    ("_row_values", "  output rows' q, energies, residuals"),
                    ("warn_out_of_range", "  validity checks (each segment)")):
    if hasattr(projeq.simulation.driver, name):
        patch(projeq.simulation.driver, name, label)
patch(projeq.cli.run, "_write", "write NPZ + CSV")
patch(projeq.simulation.export, "write_vtu_series", "write ParaView series")
patch(projeq.cli.run, "write_json", "write run.json")
patch(projeq.cli.run, "_plots", "write PNG plots (--plots; matplotlib's import)")
before_main = clock()
code = commands.command() if hasattr(commands, "command") else commands.main(sys.argv[1:])  # as the installed command
end = clock()
print(json.dumps({"code": code, "python_start": start, "end": end, "projeq_import": projeq_import,
                  "preimport": preimport, "main": [end[0] - before_main[0], end[1] - before_main[1]],
                  "phases": spent, "collector": collector}))
"""


def child(argv: list, env: dict | None = None) -> tuple[float, float, subprocess.CompletedProcess]:
    """(CPU s, wall s, the completed process) of one fresh Python process, started in the
    root of the tree its PYTHONPATH names (``python -c`` puts the working directory first on
    sys.path)."""
    before, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    root = (env or os.environ).get("PYTHONPATH", "").split(os.pathsep)[0] or None
    done = subprocess.run([sys.executable, *argv], capture_output=True, text=True, env=env, cwd=root)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    if done.returncode:
        raise RuntimeError(f"{argv}: exit {done.returncode}\n{done.stderr[-2000:]}")
    return cpu, time.perf_counter() - wall, done


def phases(scene: list, out: str, env: dict | None = None) -> dict:
    """One fresh process of ``projeq run SCENE --quiet``: its phases, name → (CPU s, wall s).

    The child imports what the parser would import before ``main`` (to wrap its functions),
    timed there; numba's import is timed where the run does it (inside ``simulate``, on the
    first compiled evaluator; a scene that uses no compiled kernel does not pay it), and its
    functions are wrapped then (imported earlier, numba would change the order of the
    interpreter's teardown, and with it the exit's cost)."""
    cpu, wall, done = child(["-c", PHASES, "run", *scene, "--quiet", "--out", out], env)
    record = json.loads(done.stdout)
    spent, nan = record["phases"], float("nan")
    parser = spent.pop("parser: CLI, scenes, their imports")
    rows = {"Python's start (interpreter, site)": [record["python_start"][0], nan],
            "import projeq (numpy)": record["projeq_import"],
            "imports of the CLI, scenes, driver (scipy)": [a + b for a, b in zip(record["preimport"], parser)],
            "scene build": spent.get("scene build", [0.0, 0.0]),
            "simulate": spent["simulate"]}
    inside = [k for k in spent if k.startswith("  ")]  # self-times: simulate's is the integration's
    rows["simulate"] = [spent["simulate"][i] + sum(spent[k][i] for k in inside) for i in (0, 1)]
    rows |= {k: spent[k] for k in inside}
    rows["  integration (the rest of simulate)"] = spent["simulate"]
    rows |= {k: v for k, v in spent.items() if k.startswith("write")}
    rows["rest of main (record, summary, checks)"] = [record["main"][0] - sum(v[0] for v in spent.values())
                                                      - parser[0], nan]
    rows["Python's exit (atexit, teardown)"] = [cpu - record["end"][0], nan]
    rows["cyclic garbage collector (in the rows above)"] = record["collector"][:2]
    rows["  its collections (full collections)"] = record["collector"][2:]
    rows["process (all)"] = [cpu, wall]
    return rows


def import_times(scene: list, out: str, top: int = 25) -> tuple[dict, list]:
    """``python -X importtime -m projeq run SCENE``: self-time (s) by package, and the ``top``
    slowest cumulative imports (name, s, depth)."""
    _, _, done = child(["-X", "importtime", "-m", "projeq", "run", *scene, "--quiet", "--out", out])
    by_package, cumulative = defaultdict(float), []
    for line in done.stderr.splitlines():
        if not line.startswith("import time:") or "self [us]" in line:
            continue
        own, total, name = line[len("import time:"):].split("|")
        module = name.strip()
        depth = (len(name) - len(name.lstrip()) - 1) // 2
        parts = module.split(".")
        package = ".".join(parts[:2]) if parts[0] in ("scipy", "projeq", "numpy") and len(parts) > 1 else parts[0]
        by_package[package] += int(own) / 1e6
        cumulative.append((module, int(total) / 1e6, depth))
    cumulative.sort(key=lambda row: -row[1])
    return dict(sorted(by_package.items(), key=lambda kv: -kv[1])), cumulative[:top]


def cprofile(scene: list, out: str, top: int = 30) -> str:
    """The run under cProfile: the ``top`` functions by own time."""
    with tempfile.NamedTemporaryFile(suffix=".prof") as stats:
        child(["-m", "cProfile", "-o", stats.name, "-m", "projeq", "run", *scene, "--quiet", "--out", out])
        code = (f"import pstats; pstats.Stats({stats.name!r}).sort_stats('tottime').print_stats({top})")
        return child(["-c", code])[2].stdout


#: the alternatives for the fixed costs, each timed in fresh processes (``--alternatives``)
THREAD = """
import sys, time
wall = time.perf_counter()
import numpy
def numba_ready():  # numba's import and its target initialisation (what loading a cached kernel does first)
    import numba
    from numba.core.registry import cpu_target
    cpu_target.target_context.refresh()
if sys.argv[1] == "thread":
    import threading
    worker = threading.Thread(target=numba_ready)
    worker.start()
    import scipy.integrate
    worker.join()
else:
    import scipy.integrate
    numba_ready()
print(time.perf_counter() - wall)
"""

NO_REFRESH = """
import sys, time
import numba.core.caching as caching
from numba.core.runtime import rtsys
if sys.argv[1] == "skip":  # NOT what projeq does: numba's private API, to measure what the refresh costs
    def load_overload(self, sig, target_context):
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)
    caching.Cache.load_overload = load_overload
from projeq import scenes
system = scenes.spin_up_beam()
evaluator = system.evaluator()
cpu = time.process_time()
s_ddot = evaluator.accelerations(system.q0, system.s_dot0 + 0.3, 0.1)
print(time.process_time() - cpu, evaluator.name, repr(s_ddot.tolist()))
"""

IMPORTS = """
import importlib, sys, time
cpu = time.process_time()
for module in sys.argv[1:]:
    importlib.import_module(module)
print(time.process_time() - cpu)
"""


def alternatives(repeat: int) -> None:
    """The fixed costs' alternatives, measured (medians of ``repeat`` interleaved fresh processes)."""
    def median(argvs):
        runs = [[child(argv) for argv in argvs] for _ in range(repeat)]
        return [[statistics.median(r[i][k] for r in runs) for k in (0, 1)] for i in range(len(argvs))], runs

    (seq, thread), _ = median([["-c", THREAD, "sequential"], ["-c", THREAD, "thread"]])
    print(f"numba's import + target initialisation beside scipy.integrate's import: sequential {seq[0]:.3f} "
          f"CPU s ({seq[1]:.3f} wall), numba in a background thread {thread[0]:.3f} ({thread[1]:.3f}): "
          f"wall ratio thread / sequential {thread[1] / seq[1]:.2f}")
    runs = [[float(child(["-c", NO_REFRESH, mode])[2].stdout.split()[0]) for mode in ("normal", "skip")]
            for _ in range(repeat)]
    same = len({child(["-c", NO_REFRESH, mode])[2].stdout.split(maxsplit=2)[2] for mode in ("normal", "skip")}) == 1
    normal, skip = (statistics.median(r[i] for r in runs) for i in (0, 1))
    print(f"first s̈ of the spin-up beam in a fresh process (numba imported before): {normal:.3f} CPU s; with numba's "
          f"cache load skipping the target refresh (private API, not used) {skip:.3f}; s̈ identical: {same}")
    chains = {"numpy": ["numpy"], "numpy, scipy.linalg": ["numpy", "scipy.linalg"],
              "numpy, scipy.integrate": ["numpy", "scipy.integrate"], "numpy, numba": ["numpy", "numba"]}
    costs = {name: statistics.median(float(child(["-c", IMPORTS, *modules])[2].stdout) for _ in range(repeat))
             for name, modules in chains.items()}
    print("imports, CPU s: " + ", ".join(f"{name} {cost:.3f}" for name, cost in costs.items()) +
          f"; an integrator needing only scipy.linalg would save {costs['numpy, scipy.integrate'] - costs['numpy, scipy.linalg']:.3f}")


def compare(other: str, scene: list, repeat: int) -> None:
    """The phases of ``projeq run SCENE --quiet`` (:func:`phases`) of this tree and of the tree
    ``other`` (another checkout's root), alternately in fresh processes: medians, side by side."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = {"this tree": here, "other": os.path.abspath(other)}
    runs = {name: [] for name in trees}
    with tempfile.TemporaryDirectory() as out:
        for round_ in range(repeat + 1):  # the first round fills numba's caches and the bytecode
            for name, root in trees.items():
                rows = phases(scene, out, os.environ | {"PYTHONPATH": root})
                if round_:
                    runs[name].append(rows)
    print(f"projeq run {' '.join(scene)} --quiet: CPU s, median of {repeat} fresh processes per tree, alternately "
          f"(load average {os.getloadavg()[0]:.1f}); other = {other}")
    print(f"  {'':<45} {'this tree':>10} {'other':>10} {'ratio':>7}")
    for row in runs["this tree"][0]:
        here_, there = (statistics.median(r[row][0] for r in runs[name]) for name in trees)
        print(f"  {row:<45} {here_:10.3f} {there:10.3f} {here_ / there if there else float('nan'):7.2f}")
    walls = [statistics.median(r["process (all)"][1] for r in runs[name]) for name in trees]
    print(f"  {'process wall':<45} {walls[0]:10.3f} {walls[1]:10.3f} {walls[0] / walls[1]:7.2f}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="*", help="scene and options of projeq run (default: none, the spin-up beam)")
    parser.add_argument("--repeat", type=int, default=5, help="fresh processes for the phases (median)")
    parser.add_argument("--cprofile", action="store_true", help="also print the cProfile top 30 by own time")
    parser.add_argument("--alternatives", action="store_true",
                        help="also time the alternatives for the fixed costs (numba in a thread, numba's cache load "
                             "without its target refresh, scipy.linalg instead of scipy.integrate)")
    parser.add_argument("--compare", metavar="TREE", help="only: this tree's projeq run against another checkout's")
    parser.add_argument("--quick", action="store_true",
                        help="spin_up_beam --t-end 1, one process for the phases and one for the imports")
    args = parser.parse_args(argv)
    if args.quick:
        args.scene, args.repeat = ["spin_up_beam", "--t-end", "1"], 1
    if args.compare:
        return compare(args.compare, args.scene, args.repeat)
    with tempfile.TemporaryDirectory() as out:
        if not args.quick:
            child(["-m", "projeq", "run", *args.scene, "--quiet", "--out", out])  # numba's cache filled
        runs = [phases(args.scene, out) for _ in range(args.repeat)]
        packages, slowest = import_times(args.scene, out)
        profile = cprofile(args.scene, out) if args.cprofile else ""
    load = os.getloadavg()[0]
    print(f"projeq run {' '.join(args.scene)} --quiet: median of {args.repeat} fresh processes, CPU s (wall s); "
          f"load average {load:.1f}")
    for name in runs[0]:
        cpu = statistics.median(r[name][0] for r in runs)
        wall = statistics.median(r[name][1] for r in runs)
        if name.endswith("(full collections)"):
            print(f"  {name:<45} {cpu:6.0f} ({wall:.0f})")
            continue
        print(f"  {name:<45} {cpu:6.3f}" + ("" if wall != wall else f" ({wall:.3f})"))
    print("\nimport self-time by package (-X importtime, s; the instrumentation inflates it):")
    for package, seconds in list(packages.items())[:20]:
        print(f"  {package:<30} {seconds:6.3f}")
    print(f"  {'all':<30} {sum(packages.values()):6.3f}")
    print("\nslowest cumulative imports (s):")
    for module, seconds, depth in slowest:
        print(f"  {'  ' * depth}{module:<{50 - 2 * depth}} {seconds:6.3f}")
    if profile:
        print("\ncProfile, by own time:\n" + profile)
    if args.alternatives:
        print()
        alternatives(args.repeat)


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # the modules' bytecode cached, as an installed package's is
    main()
