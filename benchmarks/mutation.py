"""Mutation test of projeq's core: a fixed, seeded sample of mutants of ``projeq/assembly``,
``projeq/constraints`` and ``projeq/subsystems/beam``, each run against the tests that run its lines.

A mutant is the source with one small change (``+`` for ``-``, ``<`` for ``<=``, a number changed, a
loop that never runs, ...) that the tests should notice. The mutation tool is cosmic-ray (its
operators enumerate the mutants, it applies one to the file on disk and puts the file back, and its
session database records each result: ``cr-report OUT/session.sqlite`` reads it). From every mutant its
operators give (the replacements of arithmetic by bitwise and shift operators left out: on float code
they only raise a TypeError) the script draws ``--mutants`` with ``random.Random(--seed)``, in the
order of file, operator and occurrence, so the sample is the same for the same source and seed.

The mutants run on the interpreted path, with ``NUMBA_DISABLE_JIT=1``: numba's disk cache keys a
compiled function by the time stamp of its own file only, so a kernel that inlines a mutated helper of
another file would load unmutated from the cache (a false survivor), and compiling the kernels anew
for each mutant costs minutes. With the JIT off numba's kernels run as the Python they are written
in; the tests that need compiled code (numba's intrinsics), or that take longer than
``--test-seconds`` there, fail and are left out. Before the first mutant, the baseline runs each
package's tests (and its modules' doctests) on the unmutated source under coverage.py, one context per
test: a mutant's tests are the passing ones that run one of its lines (all of its package's where
only the import runs them), fastest first up to ``--budget`` seconds; a mutant on lines no passing
test runs survives unrun ("not run"). OUT/baseline.json lists each mutant's tests and their times.
Hypothesis draws the same examples in every run (``--hypothesis-seed=0``, its database cleared before
each), so a property test kills a mutant only where the mutant changes what it checks.

Each worker mutates its own copy of the source (``projeq``, ``tests``, ``benchmarks``, ``examples``,
``pyproject.toml`` in a temporary folder) and runs the mutant's tests with ``pytest -x`` (the first
failure kills the mutant; a run longer than ``--timeout-factor`` times the baseline's, plus 30 s, kills
it too). The results go to the session database as they arrive: Ctrl-C stops, and the same command
continues with the mutants still pending. The survivors are written to OUT/survivors.md with their
diffs; ``--again OUT`` runs a session's survivors again against the tests as they are now (the "after"
of a round of new tests); ``--compiled`` runs its not-run mutants with numba's JIT on against the test
files of :data:`COMPILED_TESTS`, an empty numba cache each (minutes per mutant).

    python benchmarks/mutation.py [--mutants 200] [--seed=37] [--workers 2] [--out DIR]
    python benchmarks/mutation.py --again OUT --out OUT2   # OUT's survivors against the tests of today
    python benchmarks/mutation.py --compiled --out OUT   # OUT's not-run mutants against the compiled tests
    python benchmarks/mutation.py --quick     # 3 mutants of assembly/linalg.py against its test file
"""

from __future__ import annotations

import argparse
import difflib
import json
import os
import queue
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: package → (its modules, relative to ROOT; the tests that may kill their mutants)
PACKAGES = {
    "assembly": ("projeq/assembly", ("tests/assembly", "tests/joints", "tests/subsystems")),
    "constraints": ("projeq/constraints", ("tests/constraints", "tests/nonholonomic")),
    "beam": ("projeq/subsystems/beam", ("tests/subsystems", "tests/assembly/test_fast_beams.py")),
}
#: the quick mode: one small module against one test file
QUICK = {"assembly": ("projeq/assembly/linalg.py", ("tests/assembly/test_linalg.py",))}
#: cosmic-ray's replacements by these operators are left out (on float code they only raise TypeError)
BITWISE = ("_RShift", "_LShift", "_BitOr", "_BitAnd", "_BitXor")
#: the outcome's note for a mutant on lines that no passing test runs (it survives, unrun)
NOT_RUN = "no test that passes interpreted runs these lines"
#: ``--compiled``: the test files that run a module's compiled-only code (numba's JIT on)
COMPILED_TESTS = {
    "projeq/assembly/fast.py": ("tests/assembly/test_fast.py",),
    "projeq/assembly/generated.py": ("tests/assembly/test_stated_loads.py", "tests/assembly/test_time_loads.py",
                                     "tests/assembly/test_given.py", "tests/assembly/test_motion_callables.py"),
    "projeq/assembly/given.py": ("tests/assembly/test_given.py", "tests/assembly/test_motion_callables.py"),
    "projeq/assembly/kernels.py": ("tests/assembly/test_fast_beams.py", "tests/assembly/test_fast_energy.py"),
    "projeq/constraints/compiled.py": ("tests/constraints/test_compiled_closures.py",
                                       "tests/constraints/test_compiled_pins.py",
                                       "tests/constraints/test_compiled_pfaffian.py",
                                       "tests/simulation/test_output_rows.py"),
    "projeq/subsystems/beam/beam.py": ("tests/subsystems/test_beam_bad_input.py",),
    "projeq/subsystems/beam/slice_chain.py": ("tests/subsystems/test_beam_slice_chain.py",),
}

#: the baseline's pytest plugin: each test's outcome and time to a log, the lines of projeq each test runs
#: to coverage's data (one context per test); a test running longer than the limit is stopped by an alarm
#: (SIGALRM in the test's process) and fails
PLUGIN = '''
import json, os, signal
import coverage
import pytest

_coverage = coverage.Coverage(data_file=os.environ["MUTATION_COVERAGE"], data_suffix=True,
                              source=[os.path.join(os.getcwd(), "projeq")])

def _expired(signum, frame):
    raise TimeoutError("slower than the baseline's limit")

def pytest_configure(config):
    _coverage.start()

def pytest_unconfigure(config):
    _coverage.stop()
    _coverage.save()

@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    _coverage.switch_context(item.nodeid)
    yield
    _coverage.switch_context("")

@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    signal.signal(signal.SIGALRM, _expired)
    signal.setitimer(signal.ITIMER_REAL, float(os.environ["MUTATION_TEST_SECONDS"]))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)

def pytest_runtest_logreport(report):
    if report.when == "call" or report.outcome != "passed":
        with open(os.environ["MUTATION_BASELINE_LOG"], "a") as log:
            log.write(json.dumps([report.nodeid, report.when, report.outcome, report.duration]) + "\\n")
'''


def cosmic_ray():
    """cosmic-ray's modules (an ImportError naming the extra where it is not installed)."""
    try:
        import cosmic_ray.commands
        import cosmic_ray.mutating
        import cosmic_ray.plugins
        import cosmic_ray.work_db
        import cosmic_ray.work_item
    except ImportError as error:
        raise ImportError("benchmarks/mutation.py needs cosmic-ray: pip install 'projeq[test]' "
                          "(or pip install cosmic-ray)") from error
    return cosmic_ray


def modules(packages: dict) -> list[str]:
    """The modules to mutate (relative to ROOT), package by package, ``__init__`` files left out."""
    found = []
    for source, _ in packages.values():
        path = ROOT / source
        files = [path] if path.suffix == ".py" else sorted(path.glob("*.py"))
        found += [str(f.relative_to(ROOT)) for f in files if f.name != "__init__.py"]
    return found


def package_of(module: str, packages: dict) -> str:
    return next(name for name, (source, _) in packages.items() if module.startswith(source))


def operators(cr) -> dict:
    """cosmic-ray's operators that take no arguments, the bitwise replacements left out."""
    return {name: {} for name in cr.plugins.operator_names()
            if not name.endswith(BITWISE) and not cr.plugins.get_operator(name).arguments()}


def sample(cr, module_paths: list[str], count: int, seed: int) -> list:
    """``count`` of cosmic-ray's mutants of ``module_paths`` drawn with ``random.Random(seed)``,
    with job ids 000, 001, ... in the order of file, operator and occurrence."""
    with tempfile.TemporaryDirectory() as scratch, \
            cr.work_db.use_db(Path(scratch) / "all.sqlite", cr.work_db.WorkDB.Mode.create) as db:
        cr.commands.init([ROOT / m for m in module_paths], db, {})
        wanted = set(operators(cr))
        mutations = sorted((item.mutations[0] for item in db.work_items if item.mutations[0].operator_name in wanted),
                           key=lambda m: (str(m.module_path), m.operator_name, m.occurrence))
    chosen = sorted(random.Random(seed).sample(range(len(mutations)), min(count, len(mutations))))
    print(f"{len(mutations)} mutants of {len(module_paths)} modules; {len(chosen)} drawn (seed={seed})", flush=True)
    items = []
    for number, index in enumerate(chosen):
        m = mutations[index]
        spec = cr.work_item.MutationSpec(module_path=str(Path(m.module_path).relative_to(ROOT)),
                                         operator_name=m.operator_name, occurrence=m.occurrence,
                                         start_pos=m.start_pos, end_pos=m.end_pos, definition_name=m.definition_name)
        items.append(cr.work_item.WorkItem.single(job_id=f"{number:03d}", mutation=spec))
    return items


def copy_source(target: Path) -> Path:
    """A copy of the package, its tests, the scripts they run (benchmarks, examples) and pyproject.toml
    in ``target`` (made anew)."""
    shutil.rmtree(target, ignore_errors=True)
    target.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".hypothesis", "results")
    for name in ("projeq", "tests", "benchmarks", "examples"):
        shutil.copytree(ROOT / name, target / name, ignore=ignore)
    shutil.copy2(ROOT / "pyproject.toml", target / "pyproject.toml")
    return target


def environment(copy: Path, cache: Path | None = None) -> dict:
    """The tests' environment: the copy's projeq first on the path, no bytecode written (a mutant and
    the original may share a time stamp), numba's JIT off, or on with the empty numba ``cache``."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONDONTWRITEBYTECODE="1", PYTHONPATH=str(copy))
    env.pop("PYTEST_ADDOPTS", None)
    if cache is not None:
        env.update(NUMBA_DISABLE_JIT="0", NUMBA_CACHE_DIR=str(cache), PROJEQ_COMPILE="now")
    return env


def pytest_command(arguments) -> list[str]:
    """pytest with hypothesis's draws fixed (the baseline's examples are each mutant's: a property test
    whose random draws reach code that fails interpreted would kill mutants by chance)."""
    return [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-W", "ignore", "--hypothesis-seed=0",
            *arguments]


def check_copy_is_imported(copy: Path) -> None:
    """The tests in ``copy`` must import its projeq, not the installed one."""
    found = subprocess.run([sys.executable, "-c", "import projeq; print(projeq.__file__)"], cwd=copy,
                           env=environment(copy), capture_output=True, text=True, check=True).stdout.strip()
    if not Path(found).resolve().is_relative_to(copy.resolve()):
        raise RuntimeError(f"the tests in {copy} import projeq from {found}, not the copy being mutated")


def baseline(copy: Path, packages: dict, module_paths: list[str], test_seconds: float, processes: int) -> dict:
    """package → {"seconds": {node id: seconds} of the tests that pass on the unmutated source within
    ``test_seconds`` each, "lines": {module: {line: [node ids of those that run it]}}}; the tests run in
    ``processes`` pytest-xdist workers (0: in pytest's own)."""
    found = {}
    for name, (_, tests) in packages.items():
        log, data = copy / f"baseline-{name}.jsonl", copy / f"coverage-{name}"
        log.unlink(missing_ok=True)
        shutil.rmtree(data, ignore_errors=True)
        data.mkdir()
        (copy / "mutation_baseline.py").write_text(PLUGIN)
        modules_here = [m for m in module_paths if package_of(m, packages) == name]
        started = time.perf_counter()
        env = dict(environment(copy), MUTATION_BASELINE_LOG=str(log), MUTATION_TEST_SECONDS=str(test_seconds),
                   MUTATION_COVERAGE=str(data / ".coverage"))
        subprocess.run(pytest_command(["-p", "mutation_baseline", "-n", str(processes), *tests, *modules_here]),
                       cwd=copy, env=env, capture_output=True, check=False)  # its failures are the tests left out
        seconds = passing_tests(log, test_seconds)
        found[name] = {"seconds": seconds, "lines": covered_lines(copy, data, modules_here, set(seconds))}
        print(f"baseline {name}: {len(seconds)} tests pass interpreted within {test_seconds:g} s each "
              f"({sum(seconds.values()):.0f} s in all; {time.perf_counter() - started:.0f} s)", flush=True)
        if not seconds:
            raise RuntimeError(f"no test of {name} passes on the unmutated source: see {log}")
    return found


def passing_tests(log: Path, test_seconds: float) -> dict:
    """{node id: seconds} of the tests the baseline's log shows passing within ``test_seconds``."""
    phases: dict[str, dict] = {}  # node id → phase → (outcome, seconds); xdist logs each report twice
    for line in log.read_text().splitlines() if log.exists() else ():
        nodeid, when, outcome, duration = json.loads(line)
        phases.setdefault(nodeid, {})[when] = (outcome, duration)
    totals = {nodeid: (all(o == "passed" for o, _ in by.values()), sum(d for _, d in by.values()))
              for nodeid, by in phases.items()}
    return {nodeid: seconds for nodeid, (ok, seconds) in totals.items() if ok and seconds <= test_seconds}


def covered_lines(copy: Path, data: Path, modules_here: list[str], passing: set) -> dict:
    """{module: {line: [passing tests that run it]}} from the baseline's coverage data; the context
    "" (lines run at import, outside any test) as the node id ""."""
    import coverage

    combined = coverage.CoverageData(basename=str(data / "combined"))
    for part in data.glob(".coverage.*"):
        piece = coverage.CoverageData(basename=str(part))
        piece.read()
        combined.update(piece)
    lines = {}
    for module in modules_here:
        by_line = combined.contexts_by_lineno(str((copy / module).resolve()))
        lines[module] = {line: sorted(c for c in contexts if c in passing or c == "")
                         for line, contexts in by_line.items()}
    return lines


def tests_of(mutation, found: dict, budget: float) -> list[str]:
    """The passing tests that run a line of ``mutation`` (all of its package's where only import runs
    it), fastest first, as many as fit in ``budget`` seconds of the baseline; [] where none runs it."""
    seconds, lines = found["seconds"], found["lines"].get(str(mutation.module_path), {})
    running = set()
    for line in range(mutation.start_pos[0], mutation.end_pos[0] + 1):
        running.update(lines.get(line, ()))
    if running == {""}:
        running = set(seconds)
    chosen, total = [], 0.0
    for test in sorted(running - {""}, key=lambda t: (seconds[t], t)):
        if total + seconds[test] > budget and chosen:
            break
        chosen.append(test)
        total += seconds[test]
    return chosen


def run_mutant(cr, copy: Path, item, tests: list[str], timeout: float, cache: Path | None = None):
    """Apply ``item``'s mutation to ``copy``, run ``tests`` there (none: it survives unrun; numba's JIT on
    with the empty ``cache`` where given), put the file back: (WorkResult, why it ended)."""
    mutation = item.mutations[0]
    operator = cr.plugins.get_operator(mutation.operator_name)()
    with cr.mutating.use_mutation(copy / mutation.module_path, operator, mutation.occurrence) as (before, after):
        if after is None:
            return cr.work_item.WorkResult(worker_outcome=cr.work_item.WorkerOutcome.NO_TEST), ""
        diff = "".join(difflib.unified_diff(before.splitlines(True), after.splitlines(True),
                                            f"a/{mutation.module_path}", f"b/{mutation.module_path}"))
        outcome, output, reason = run_tests(cr, copy, tests, timeout, cache) if tests else \
            (cr.work_item.TestOutcome.SURVIVED, NOT_RUN, NOT_RUN)
    result = cr.work_item.WorkResult(worker_outcome=cr.work_item.WorkerOutcome.NORMAL, output=output,
                                     test_outcome=outcome, diff=diff)
    return result, reason


def run_tests(cr, copy: Path, tests: list[str], timeout: float, cache: Path | None = None):
    """(outcome, output, the first failing test or the timeout) of ``tests`` run in ``copy`` with ``-x``
    (numba's JIT on with the empty ``cache`` where given); hypothesis's database of earlier failures
    (another mutant's) cleared first."""
    shutil.rmtree(copy / ".hypothesis", ignore_errors=True)
    try:
        done = subprocess.run(pytest_command(["-x", *tests]), cwd=copy, env=environment(copy, cache),
                              capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return cr.work_item.TestOutcome.KILLED, "timeout", f"timeout ({timeout:.0f} s)"
    failed = re.search(r"^(?:FAILED|ERROR) (\S+)", done.stdout, re.MULTILINE)
    reason = failed.group(1) if failed else ("" if done.returncode == 0 else f"exit {done.returncode}")
    outcome = cr.work_item.TestOutcome.SURVIVED if done.returncode == 0 else cr.work_item.TestOutcome.KILLED
    return outcome, done.stdout[-1500:] + done.stderr[-500:], reason


def compiled(cr, out: Path, copy: Path, timeout: float) -> dict:
    """The session's "not run" mutants against :data:`COMPILED_TESTS` with numba's JIT on and an empty
    cache each (minutes per mutant: the kernels compile anew): job id → (outcome, why, seconds), kept in
    OUT/compiled.json as they arrive."""
    record_file = out / "compiled.json"
    found = json.loads(record_file.read_text()) if record_file.exists() else {}
    with cr.work_db.use_db(out / "session.sqlite", cr.work_db.WorkDB.Mode.open) as db:
        unrun = [item for item, result in by_job(db.completed_work_items)
                 if outcome_of(result) == "not run" and item.job_id not in found]
    for item in unrun:
        mutation = item.mutations[0]
        tests = COMPILED_TESTS.get(str(mutation.module_path))
        started = time.perf_counter()
        if tests is None:
            found[item.job_id] = ("no compiled tests named", "", 0.0)
        else:
            with tempfile.TemporaryDirectory() as cache:
                result, reason = run_mutant(cr, copy, item, list(tests), timeout, Path(cache))
            found[item.job_id] = (outcome_of(result), reason, time.perf_counter() - started)
        record_file.write_text(json.dumps(found, indent=1))
        print(f"compiled {item.job_id} {found[item.job_id][0]:<9} {mutation.module_path}:{mutation.start_pos[0]} "
              f"{found[item.job_id][1]} ({found[item.job_id][2]:.0f} s)", flush=True)
    return found


def by_job(completed) -> list:
    """cosmic-ray's (work item, result) pairs in the order of their job ids (the sample's order)."""
    return sorted(completed, key=lambda pair: pair[0].job_id)


def outcome_of(result) -> str:
    """killed, survived, not run (survived: no passing test runs its lines), or cosmic-ray's worker outcome."""
    if result.output == NOT_RUN:
        return "not run"
    return result.test_outcome.value if result.test_outcome else result.worker_outcome.value


def report(out: Path, completed) -> dict:
    """Counts per package and outcome; the survivors (run and not run) with their diffs in OUT/survivors.md."""
    counts: dict[str, dict[str, int]] = {}
    lines = {"survived": ["# Survivors", ""], "not run": ["# Not run (no passing test runs these lines)", ""]}
    for item, result in by_job(completed):
        mutation, outcome = item.mutations[0], outcome_of(result)
        package = package_of(str(mutation.module_path), PACKAGES)
        counts.setdefault(package, {}).setdefault(outcome, 0)
        counts[package][outcome] += 1
        if outcome in lines:
            title = (f"## {item.job_id}: {mutation.module_path}:{mutation.start_pos[0]} {mutation.operator_name} "
                     f"(in {mutation.definition_name})")
            lines[outcome] += [title, "", "```diff", (result.diff or "").rstrip(), "```", ""]
    (out / "survivors.md").write_text("\n".join(lines["survived"] + lines["not run"]))
    print(f"\n{'package':<12} {'killed':>7} {'survived':>9} {'not run':>8} {'other':>6}")
    for package, by in sorted(counts.items()):
        other = sum(v for k, v in by.items() if k not in ("killed", "survived", "not run"))
        print(f"{package:<12} {by.get('killed', 0):>7} {by.get('survived', 0):>9} {by.get('not run', 0):>8} {other:>6}")
    print(f"survivors: {out / 'survivors.md'}")
    return counts


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mutants", type=int, default=200, help="how many mutants to draw (default 200)")
    parser.add_argument("--seed", type=int, default=37, help="the draw's seed (default 37)")
    parser.add_argument("--workers", type=int, default=2, help="mutants run at once (default 2)")
    parser.add_argument("--test-seconds", type=float, default=5.0,
                        help="a test slower than this on the unmutated source (interpreted) is left out (default 5)")
    parser.add_argument("--budget", type=float, default=30.0,
                        help="a mutant's tests (those that run its lines), fastest first, up to this many seconds "
                             "on the baseline (default 30)")
    parser.add_argument("--timeout-factor", type=float, default=4.0,
                        help="a mutant's tests running this many times their baseline time kill it (default 4)")
    parser.add_argument("--out", type=Path, default=None, help="session folder (default: a new temporary one)")
    parser.add_argument("--again", type=Path, default=None,
                        help="run the survivors of the session in this folder again, against the tests as they are now")
    parser.add_argument("--compiled", action="store_true",
                        help="run the session's not-run mutants against the compiled tests (COMPILED_TESTS), "
                             "numba's JIT on, an empty cache each")
    parser.add_argument("--quick", action="store_true", help="3 mutants of assembly/linalg.py, one test file")
    args = parser.parse_args(argv)
    if args.mutants < 1 or args.workers < 1 or min(args.test_seconds, args.budget) <= 0 \
            or args.timeout_factor <= 1:
        parser.error("--mutants and --workers must be ≥ 1, --test-seconds and --budget > 0, --timeout-factor > 1")
    cr = cosmic_ray()
    packages = QUICK if args.quick else PACKAGES
    count, workers = (3, 1) if args.quick else (args.mutants, args.workers)
    out = args.out or Path(tempfile.mkdtemp(prefix="projeq-mutation-"))
    out.mkdir(parents=True, exist_ok=True)
    module_paths = modules(packages)
    settings = {"mutants": count, "seed": args.seed, "modules": module_paths, "test_seconds": args.test_seconds,
                "budget": args.budget, "again": str(args.again) if args.again else None}
    if (out / "settings.json").exists() and json.loads((out / "settings.json").read_text()) != settings:
        raise SystemExit(f"{out} holds a session with other settings ({out / 'settings.json'}): give another --out")
    scratch = Path(tempfile.mkdtemp(prefix="projeq-mutants-"))
    try:
        copies = [copy_source(scratch / f"worker-{k}") for k in range(1 if args.compiled else workers)]
        check_copy_is_imported(copies[0])
        if args.compiled:
            return compiled(cr, out, copies[0], 1800.0)
        return run(cr, args, packages, module_paths, count, out, copies, settings)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def survivors_of(cr, old: Path) -> list:
    """The mutants that survived in the session in ``old`` (the same job ids and mutations)."""
    with cr.work_db.use_db(old / "session.sqlite", cr.work_db.WorkDB.Mode.open) as db:
        return [item for item, result in by_job(db.completed_work_items)
                if result.test_outcome == cr.work_item.TestOutcome.SURVIVED]


def start(cr, args, packages, module_paths, count, out, copy, settings) -> None:
    """A new session in ``out``: the mutants (drawn, or the survivors of ``--again``), the baseline,
    each mutant's tests (OUT/baseline.json: job id → tests, test → seconds)."""
    items = survivors_of(cr, args.again) if args.again else sample(cr, module_paths, count, args.seed)
    found = baseline(copy, packages, module_paths, args.test_seconds, 0 if args.quick else 2)
    chosen = {}
    for item in items:
        mutation = item.mutations[0]
        chosen[item.job_id] = tests_of(mutation, found[package_of(str(mutation.module_path), packages)], args.budget)
    seconds = {test: s for package in found.values() for test, s in package["seconds"].items()}
    unrun = sum(not tests for tests in chosen.values())
    print(f"{len(items) - unrun} mutants are on lines that passing tests run (each runs those, fastest first, up to "
          f"{args.budget:g} s); {unrun} on lines none runs", flush=True)
    (out / "baseline.json").write_text(json.dumps({"tests": chosen, "seconds": seconds}, indent=0))
    with cr.work_db.use_db(out / "session.sqlite", cr.work_db.WorkDB.Mode.create) as db:
        db.add_work_items(items)
    (out / "settings.json").write_text(json.dumps(settings))


def run(cr, args, packages, module_paths, count, out, copies, settings) -> dict:
    """The session in ``out`` (started if new): its pending mutants on ``copies``, then the report."""
    if not (out / "session.sqlite").exists():
        start(cr, args, packages, module_paths, count, out, copies[0], settings)
    tests = json.loads((out / "baseline.json").read_text())
    with cr.work_db.use_db(out / "session.sqlite", cr.work_db.WorkDB.Mode.open) as db:
        pending = sorted(db.pending_work_items, key=lambda item: item.job_id)
        print(f"{db.num_results} of {db.num_work_items} mutants done, {len(pending)} to run with {len(copies)} "
              f"workers", flush=True)
        results: queue.Queue = queue.Queue()
        threads = [threading.Thread(target=work, args=(cr, copy, pending, tests, args.timeout_factor, results),
                                    daemon=True) for copy in copies]
        for thread in threads:
            thread.start()
        try:
            record(db, threads, results)
        except KeyboardInterrupt:
            pending.clear()
            print("interrupted: the results so far are in the session; the same command continues", flush=True)
            raise
        return report(out, db.completed_work_items)


def work(cr, copy: Path, pending: list, tests: dict, timeout_factor: float, results) -> None:
    """A worker: takes mutants from ``pending`` until none is left, runs each in ``copy`` against its tests."""
    while True:
        try:
            item = pending.pop(0)
        except IndexError:
            return
        started, chosen = time.perf_counter(), tests["tests"][item.job_id]
        timeout = timeout_factor * sum(tests["seconds"][test] for test in chosen) + 30
        results.put((item, *run_mutant(cr, copy, item, chosen, timeout), time.perf_counter() - started))


def record(db, threads, results) -> None:
    """Each result into the session as it arrives, with one line of progress."""
    done, total = db.num_results, db.num_work_items
    while any(t.is_alive() for t in threads) or not results.empty():
        try:
            item, result, reason, seconds = results.get(timeout=0.5)
        except queue.Empty:
            continue
        db.set_result(item.job_id, result)
        done += 1
        m = item.mutations[0]
        print(f"[{done}/{total}] {outcome_of(result):<9} {m.module_path}:{m.start_pos[0]} "
              f"{m.operator_name.removeprefix('core/')} {reason} ({seconds:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
