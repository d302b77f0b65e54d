"""Every documented command and code block runs (issue 19, item 2, "documented commands that
fail"): each ``projeq ...`` line of the bash blocks of README.md and the docs pages exits 0,
and the python blocks of each docs page run in order in one namespace.

Commands run in-process (``projeq.cli.commands.main``) in a temporary directory, shortened
where the command's own options allow it, so that the check costs seconds instead of the
documented runs' minutes: ``--t-end`` at most 0.1 s for run, sweep and tradeoff (the scene
is built and checked, the parameters validated, the outputs written as documented),
tradeoff on two tolerances of DOP853 with the recursive evaluator, compare without simulation
and one repeat, bench on the chain of 10 bodies only; a Dask scheduler address becomes a local
in-process cluster. A command that another test already runs in full as documented is named
in COVERED_ELSEWHERE with that test. Lines that install packages are not run.
The python blocks run as written except that ``projeq.simulate`` stops at 0.1 s of simulated
time (the tutorials' own scripts in examples/ run in full in tests/test_examples.py).
"""
import glob
import re
import shlex
from pathlib import Path

import pytest

import projeq
from projeq.cli.commands import main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "docs" / "tutorials").glob("*.md"))]
#: Pages whose python blocks are run elsewhere: the API reference (docstring examples, run as
#: doctests of the modules) and the architecture page (tests/test_docs.py); README.md's block
#: by tests/test_readme.py.
CODE_RUN_ELSEWHERE = ("README.md", "api.md", "architecture.md")
QUICK_T_END = 0.1
#: Commands run verbatim by another test (checked to exist): command -> (test file, test name).
COVERED_ELSEWHERE = {
    "run whipple_bicycle --set speed=3 --set roll=0.05":
        ("tests/cli/test_cli.py", "test_the_cli_pages_bicycle_falls_over_with_a_physical_message"),
}


def blocks(path, language):
    return re.findall(rf"^```{language}\n(.*?)^```", path.read_text(encoding="utf-8"), re.S | re.M)


def page_commands(path):
    """The ``projeq ...`` lines of a page's bash blocks, as argument lists."""
    return [shlex.split(line, comments=True)[1:] for block in blocks(path, "bash")
            for line in block.splitlines() if line.startswith("projeq ")]


def documented_commands():
    for path in PAGES:
        for argv in page_commands(path):
            yield pytest.param(argv, id=f"{path.relative_to(ROOT)}: {shlex.join(argv)}")


def expand(argv):
    """Shell globs in the arguments, as the shell would expand them (in the current folder)."""
    return [match for arg in argv for match in (sorted(glob.glob(arg)) or [arg] if "*" in arg else [arg])]


def option(argv, name, value):
    """argv with ``name value`` set (replacing a given value)."""
    if name in argv:
        i = argv.index(name)
        return argv[:i + 1] + [value] + argv[i + 2:]
    return argv + [name, value]


def quick(argv, tmp_path):
    command = argv[0]
    if command in ("run", "sweep", "tradeoff"):
        given = float(argv[argv.index("--t-end") + 1]) if "--t-end" in argv else QUICK_T_END
        argv = option(argv, "--t-end", str(min(given, QUICK_T_END)))
    if command in ("run", "sweep") and "--out" not in argv:
        argv = option(argv, "--out", str(tmp_path / "out"))
    if command == "tradeoff":
        argv = option(option(option(argv, "--methods", "DOP853"), "--knobs", "recursive"), "--out", str(tmp_path / "out"))
        argv = argv[:argv.index("--methods") + 2] + ["--tolerances", "1e-4", "1e-6"] + argv[argv.index("--methods") + 2:]
    if command == "compare":
        argv = option(argv, "--repeats", "1") + ([] if "--no-simulate" in argv else ["--no-simulate"])
    if command == "bench":
        argv = option(option(option(argv, "--sizes", "10"), "--budget", "0.05"), "--exact-up-to", "10")
        argv += [flag for flag in ("--chain-only", "--no-peers") if flag not in argv]
    return argv


def run_command(argv, tmp_path):
    if " ".join(argv) in COVERED_ELSEWHERE:
        path, name = COVERED_ELSEWHERE[" ".join(argv)]
        assert f"def {name}(" in (ROOT / path).read_text(encoding="utf-8")
        return 0
    argv = quick(expand(argv), tmp_path)
    if "--scheduler" in argv:
        distributed = pytest.importorskip("dask.distributed")
        with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
            return main(option(argv, "--scheduler", cluster.scheduler_address))
    return main(argv)


@pytest.mark.slow
@pytest.mark.parametrize("page", [pytest.param(p, id=str(p.relative_to(ROOT))) for p in PAGES if page_commands(p)])
def test_documented_commands_exit_0(page, tmp_path, monkeypatch):
    """A page's commands in order in one folder (a later one may read an earlier one's output,
    e.g. ``projeq export`` of a ``projeq run``)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    codes = {shlex.join(argv): run_command(argv, tmp_path) for argv in page_commands(page)}
    assert {command: code for command, code in codes.items() if code != 0} == {}


def test_the_commands_are_found():
    """The collection above sees the commands the issue names (README's sweep of the car,
    the CLI page's bicycle)."""
    found = [" ".join(p.values[0]) for p in documented_commands()]
    assert any(c.startswith("sweep car") for c in found)
    assert any(c.startswith("run whipple_bicycle") for c in found)
    assert len(found) >= 15


def code_pages():
    return [pytest.param(p, id=str(p.relative_to(ROOT))) for p in PAGES
            if p.name not in CODE_RUN_ELSEWHERE and blocks(p, "python")]


@pytest.mark.slow
@pytest.mark.parametrize("page", code_pages())
def test_documented_code_blocks_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    import matplotlib
    matplotlib.use("Agg")
    simulate = projeq.simulate

    def short_simulate(system, t_end, *args, **options):
        return simulate(system, min(t_end, QUICK_T_END), *args, **options)

    monkeypatch.setattr(projeq, "simulate", short_simulate)
    namespace = {"__name__": "__docs__"}
    for block in blocks(page, "python"):
        exec(compile(block, str(page.relative_to(ROOT)), "exec"), namespace)
