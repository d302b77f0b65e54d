"""The projeq command: list, run, sweep, compare, one exit-code convention, bad input."""

import gc
import io
import json
import os
import runpy
import signal
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

import projeq as pq
import projeq.cli.studies
import projeq.simulation.driver
from projeq.cli.commands import THRESHOLDS, command, imports_frozen, main


def atwood_angle(m1, t, m2=1.0, pulley_mass=0.5, a=0.1, g=9.81):
    """Pulley angle of ``atwood`` from rest: θ = −½ ẍ t²/a, ẍ = (m1 − m2) g / (m1 + m2 + I/a²),
    I = ½ M a² (Problem 1, eq. (4) of the Lagrange seminars)."""
    return -0.5 * (m1 - m2) * g / (m1 + m2 + 0.5 * pulley_mass) * t**2 / a


def test_list_names_every_scene(capsys):
    assert main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(pq.scenes.SCENES)


def test_list_scene_shows_parameters_with_units_and_defaults(capsys):
    assert main(["list", "atwood"]) == 0
    rows = [line.split()[:3] for line in capsys.readouterr().out.splitlines()[1:]]  # then its description
    assert ["m1", "2.0", "kg"] in rows and ["radius", "0.1", "m"] in rows and ["g", "9.81", "m/s²"] in rows


def test_list_a_constrained_scene(capsys):
    """The Whipple bicycle (a ConstrainedSystem) lists its initial speed and angles with units."""
    assert main(["list", "whipple_bicycle"]) == 0
    rows = [line.split()[:3] for line in capsys.readouterr().out.splitlines()[1:]]  # then its description
    assert ["speed", "4.0", "m/s"] in rows and ["roll", "0.0", "rad"] in rows and ["steer_rate", "0.0", "rad/s"] in rows


@pytest.mark.parametrize("name", list(pq.scenes.SCENES))
def test_every_real_valued_parameter_has_a_unit(name):
    """Scenes as data (issue 8, item 7): a parameter with a float or tuple default is a
    physical quantity, so its unit must be known (counts and switches are dimensionless)."""
    missing = [p.name for p in pq.scenes.scene_parameters(pq.scenes.SCENES[name])
               if isinstance(p.default, (float, tuple)) and p.unit == "-"]
    assert missing == []


def test_run_writes_results_that_load_back(tmp_path, capsys):
    """A short run of the default scene: exit 0, summary printed, NPZ equal to CSV, the
    ParaView series written, no plots unless --plots asks (then three PNG images that
    matplotlib reads back, of the size drawn); run.json lists every file written."""
    assert main(["run", "--t-end", "0.2", "--out", str(tmp_path / "plain"), "--quiet"]) == 0
    assert main(["run", "--t-end", "0.2", "--out", str(tmp_path / "plots"), "--quiet", "--plots"]) == 0
    assert capsys.readouterr().out == ""
    (plain,), (plots,) = (list((tmp_path / kind).iterdir()) for kind in ("plain", "plots"))  # each run's own folder
    for run in (plain, plots):
        result = pq.Result.load(run / "spin_up_beam.npz")
        table = np.loadtxt(run / "spin_up_beam.csv", delimiter=",", skiprows=1)
        assert np.allclose(table[:, 0], result.t) and (run / "paraview" / "spin_up_beam.pvd").exists()
        listed = json.loads((run / "run.json").read_text())["files"]
        assert all((run / f).is_file() for f in listed) and "paraview/spin_up_beam.pvd" in listed
        assert {f.name for f in run.glob("*.*")} == {f for f in listed if "/" not in f} | {"run.json"}
    assert list(plain.glob("*.png")) == []
    pngs = {p.name: matplotlib.image.imread(p) for p in plots.glob("*.png")}
    assert set(pngs) == {"spin_up_beam_history.png", "spin_up_beam_drift.png", "spin_up_beam_tip_beam.png"}
    assert all(image.shape[1] == 100 * 9.0 for name, image in pngs.items() if "history" in name)


def test_set_overrides_a_parameter(tmp_path, capsys):
    """--set m1=3 reaches the model: the final pulley angle is the closed form's for m1 = 3 kg
    (constant acceleration, a quadratic in t that the integrator follows exactly: measured 9.2e-16
    relative, bound 100 ε; was 1e-8)."""
    assert main(["run", "atwood", "--set", "m1=3", "--t-end", "0.5", "--rtol", "1e-10", "--out", str(tmp_path)]) == 0
    assert "energy" in capsys.readouterr().out
    result = pq.Result.load(next(tmp_path.rglob("atwood.npz")))
    assert result.q[-1, 0] == pytest.approx(atwood_angle(3.0, 0.5), rel=100 * np.finfo(float).eps, abs=0)


def test_the_generalized_alpha_method_takes_its_step_from_the_command_line(tmp_path, capsys):
    """--method GeneralizedAlpha --step H reaches simulate (the record names the method; the double
    pendulum's 0.1 s in steps of 1e-3 s at ρ∞ 0.5, q within 5.4e-6 rad of DOP853 at rtol 1e-12: measured 5.4e-7);
    without --step the run is refused before it starts, naming the option."""
    assert main(["run", "double_pendulum", "--t-end", "0.1", "--method", "GeneralizedAlpha", "--step", "1e-3",
                 "--rho-inf", "0.5", "--out", str(tmp_path), "--quiet"]) == 0
    result = pq.Result.load(next(tmp_path.rglob("double_pendulum.npz")))
    reference = pq.simulate(pq.scenes.double_pendulum(), 0.1, method="DOP853", rtol=1e-12, atol=1e-14,
                            t_eval=result.t)
    assert result.method == "GeneralizedAlpha" and np.abs(result.q - reference.q).max() <= 5.4e-6
    assert main(["run", "double_pendulum", "--method", "GeneralizedAlpha", "--out", str(tmp_path)]) == 2
    assert "(projeq run: --step H)" in capsys.readouterr().err


def test_failed_run_exits_1_with_partial_results(tmp_path, capsys, monkeypatch):
    """A run that fails half way writes what it computed and says how far it got."""
    real = projeq.simulation.driver.simulate

    def failing(system, t_end, **options):
        partial = real(system, t_end / 2, **options)
        raise projeq.simulation.driver.SimulationError(f"integration failed at t = {t_end / 2} s", partial)

    monkeypatch.setattr(projeq.simulation.driver, "simulate", failing)
    assert main(["run", "chain", "--t-end", "0.2", "--out", str(tmp_path), "--quiet"]) == 1
    assert "failed at t = 0.1" in capsys.readouterr().err
    assert pq.Result.load(next(tmp_path.rglob("chain.npz"))).t[-1] == pytest.approx(0.1)


def test_ctrl_c_exits_1_and_keeps_the_trajectory(tmp_path, capsys, monkeypatch):
    """A KeyboardInterrupt during the run (raised from the progress callback after the
    simulated time passes 0.1 s): the finished segments are written (over 10 s: the compiled loop
    joins the chain's segments into calls of about driver.CHUNK_EVALUATIONS, over 1 s into two)."""
    real = projeq.simulation.driver.simulate

    def interrupted(system, t_end, progress=None, **options):
        def progress_then_ctrl_c(t):
            progress(t)
            if t > 0.1:
                raise KeyboardInterrupt

        return real(system, t_end, progress=progress_then_ctrl_c, **options)

    monkeypatch.setattr(projeq.simulation.driver, "simulate", interrupted)
    assert main(["run", "chain", "--t-end", "10", "--out", str(tmp_path), "--quiet"]) == 1
    assert "interrupted at t = " in capsys.readouterr().err
    saved = pq.Result.load(next(tmp_path.rglob("chain.npz")))
    assert saved.status == 2 and 0.1 < saved.t[-1] < 10.0


# Child processes for the Ctrl-C tests: Python's own SIGINT handler (a shell may start
# background jobs with SIGINT ignored), and a line on stdout once there is something to keep.
_CHILD = """
import signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import projeq.simulation.driver, projeq.simulation.sweep
from projeq.cli.commands import command, main
simulate, finished = projeq.simulation.driver.simulate, projeq.simulation.sweep._finished

def reporting_simulate(system, t_end, progress=None, **options):  # projeq run passes a progress bar
    def report(t):
        progress(t)
        print("segment done", flush=True)
    return simulate(system, t_end, progress=progress and report, **options)

def reporting_finished(running):  # sweep's wait for the next finished points
    done = finished(running)
    print("point done", flush=True)
    return done

projeq.simulation.driver.simulate, projeq.simulation.sweep._finished = reporting_simulate, reporting_finished
sys.exit(main(sys.argv[1:]))
"""


def ctrl_c(argv):
    """Run ``projeq argv`` in a new process group, press Ctrl-C (SIGINT to the group, as a
    terminal does) once it reports progress; its exit code and stderr."""
    child = subprocess.Popen([sys.executable, "-c", _CHILD, *argv], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True)
    assert child.stdout.readline().endswith("done\n")
    os.killpg(child.pid, signal.SIGINT)
    _, err = child.communicate(timeout=120)
    return child.returncode, err


def test_a_real_ctrl_c_during_run_writes_the_trajectory_so_far(tmp_path):
    """SIGINT arrives anywhere in the integrator: exit 1, and the results up to the last
    finished segment (1 % of the run) are written and load back."""
    code, err = ctrl_c(["run", "chain", "--set", "n=1", "--t-end", "1000", "--out", str(tmp_path), "--quiet"])
    assert code == 1 and "interrupted at t = " in err and "Traceback" not in err
    saved = pq.Result.load(next(tmp_path.rglob("chain.npz")))
    assert saved.status == 2 and 10.0 <= saved.t[-1] < 1000.0


def test_a_real_ctrl_c_during_sweep_keeps_finished_and_partial_points(tmp_path):
    """Ctrl-C reaches the main process and the pool's workers: the finished point (n = 1) is
    kept, the running one (n = 60 by the interpreted recursive evaluator, seconds per simulated
    second: Python code that a signal interrupts, not a first compilation in a fresh environment)
    returns as interrupted (status 2), nothing dies with a traceback, and the table is written;
    exit 1."""
    code, err = ctrl_c(["sweep", "chain", "--set", "planar=true", "--grid", "n=1:60:2", "--t-end", "5", "--rtol", "1e-6",
                        "--evaluator", "recursive", "--workers", "2", "--outputs", "q0", "--out", str(tmp_path), "--quiet"])
    assert code == 1 and "Traceback" not in err
    table = np.load(tmp_path / "sweep_chain.npz", allow_pickle=True)
    assert table["n"].tolist() == [1, 60] and table["status"].tolist() == [0, 2]
    assert np.isfinite(table["q0"][0])


@pytest.mark.parametrize(
    "argv, message",
    [
        (["run", "chian"], "did you mean 'chain'"),
        (["run", "chain", "--set", "nn=3"], "nn: unknown parameter (did you mean 'n'?)"),
        (["run", "chain", "--set", "n=three"], "n: expected an integer, got 'three'"),
        (["run", "chain", "--set", "n"], "--set: expected name=value"),
        (["run", "atwood", "--set", "m1=heavy"], "m1: expected a number"),
        (["run", "chain", "--set", "planar=maybe"], "planar: expected a bool"),
        (["run", "chain", "--set", "n=0"], "n: number of links"),
        (["run", "atwood", "--set", "m1=3", "--set", " m1 =4"],
         "projeq run: --set: m1 is set twice ('m1=3' and ' m1 =4'); set it once"),
        (["sweep", "atwood", "--grid", "m2=1:2:2", "--set", "g=9", "--set", "g=10"],
         "projeq sweep: --set: g is set twice ('g=9' and 'g=10'); set it once"),
        (["list", "nope"], "unknown scene 'nope'"),
        (["sweep", "chain", "--grid", "n=1:3"], "--grid: expected NAME=A:B:N"),
        (["sweep", "chain", "--grid", "links=1:3:3"], "links: unknown parameter"),
        (["sweep", "chain", "--grid", "n=1:2:2", "--workers", "0"], "--workers: expected a positive count"),
    ],
    ids=["scene", "parameter", "int", "setting", "float", "bool", "scene-check", "set-twice-run", "set-twice-sweep",
         "list", "grid", "grid-name", "workers"],
)
def test_bad_arguments_exit_2_with_the_reason(argv, message, capsys, tmp_path):
    assert main(argv + (["--out", str(tmp_path)] if argv[0] in ("run", "sweep") else [])) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("t_end", ["nan", "inf", "-1", "0"])
def test_a_sweep_refuses_its_end_time_before_it_announces_or_writes(t_end, capsys, tmp_path):
    """Exit 2 naming t_end, with nothing printed on stdout and no output directory made (before, the
    sweep printed its "N points on ..." line and created --out, then every point failed the same way)."""
    out = tmp_path / "out"
    assert main(["sweep", "atwood", "--grid", "m1=1:2:2", "--workers", "1", "--t-end", t_end, "--out", str(out)]) == 2
    said = capsys.readouterr()
    assert "projeq sweep: t_end:" in said.err and said.out == ""
    assert not out.exists()


@pytest.mark.parametrize("command", [["run", "chain"], ["sweep", "atwood", "--grid", "m1=1:2:2", "--workers", "1"]])
def test_an_output_directory_that_cannot_be_written(command, tmp_path, capsys):
    (tmp_path / "file").write_text("")
    assert main(command + ["--out", str(tmp_path / "file" / "out")]) == 2
    assert "--out: cannot write to directory" in capsys.readouterr().err


def test_compare_hands_its_options_to_the_library(monkeypatch, capsys):
    seen = []

    def compare(*args, **options):
        seen.append((args, options))
        return pq.ComparisonTable("car")

    monkeypatch.setattr(projeq.cli.studies, "compare", compare)
    assert main(["compare", "car", "--no-simulate", "--t-end", "1.5", "--formulation", "hamel", "--repeats", "3"]) == 0
    assert seen == [(("car", ["hamel"]), {"simulate": False, "t_end": 1.5, "repeats": 3})]
    assert capsys.readouterr().out.startswith("compare car")


@pytest.mark.parametrize("where, message", [
    ("file/table.csv", "cannot write to directory"), ("", "is a directory, not a file")], ids=["under-a-file", "a-directory"])
def test_compare_refuses_a_csv_it_cannot_write_before_comparing(where, message, monkeypatch, tmp_path, capsys):
    """Passes if ``projeq compare --csv PATH`` with a PATH that cannot be written exits 2 naming
    --csv before the comparison runs (the library's compare is never called). Before, the whole
    comparison ran (derivations and simulations) and then failed to write, exit 1."""
    (tmp_path / "file").write_text("")
    monkeypatch.setattr(projeq.cli.studies, "compare", lambda *args, **options: pytest.fail("compare ran"))
    assert main(["compare", "car", "--csv", str(tmp_path / where)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("projeq compare: --csv: ") and message in err


@pytest.mark.parametrize("error, code", [(ValueError("t_end: must be positive"), 2),
                                         (RuntimeError("reference: the run failed"), 1),
                                         (KeyboardInterrupt(), 1)])
def test_one_exit_code_convention_for_every_subcommand(error, code, monkeypatch, capsys):
    """A ValueError (a refused input) is exit code 2, a RuntimeError (a failed run) or Ctrl-C
    exit code 1, each with a one-line message naming the subcommand and no traceback."""
    def failing(*args, **options):
        raise error

    monkeypatch.setattr(projeq.cli.studies, "compare", failing)
    assert main(["compare", "car"]) == code
    err = capsys.readouterr().err
    assert err.startswith("projeq compare: ") and (str(error) or "interrupted") in err and "Traceback" not in err


@pytest.mark.parametrize("command", [[], ["list"], ["run"], ["sweep"], ["compare"], ["bench"], ["tradeoff"]])
def test_help_everywhere(command, capsys):
    assert main(command + ["--help"]) == 0
    assert "usage: projeq" in capsys.readouterr().out


def test_usage_errors_exit_2_without_raising(capsys):
    assert main(["no-such-command"]) == 2 and main(["run", "--rtol", "tight"]) == 2
    assert "invalid choice: 'no-such-command'" in capsys.readouterr().err


@pytest.mark.parametrize("option, value", [("--total", "-5"), ("--total", "0"), ("--budget", "nan"), ("--budget", "-1"),
                                           ("--budget", "inf")])
def test_bench_budgets_must_be_positive_seconds(option, value, capsys):
    """Passes if a negative, NaN or infinite time budget of projeq bench (or a zero --total) is a
    usage error (exit 2) naming the option and the value, before anything is timed (issue 20:
    --total -5 ran); --budget 0 times each evaluator once (tests/studies/test_bench_cli.py)."""
    assert main(["bench", option, value, "--chain-only", "--sizes", "2"]) == 2
    expected = "a positive number of seconds" if option == "--total" else "a number of seconds >= 0"
    assert f"argument {option}: expected {expected}, got '{value}'" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["-1", "2.5", "many"])
def test_bench_exact_up_to_must_be_a_chain_length(value, capsys):
    """Passes if --exact-up-to below 0 or not an integer is a usage error (exit 2) naming the option
    and the value, before anything is timed; before, -1 ran the benchmark (as 0 would) without a word."""
    assert main(["bench", "--exact-up-to", value, "--chain-only", "--sizes", "2"]) == 2
    assert f"argument --exact-up-to: expected a chain length >= 0, got '{value}'" in capsys.readouterr().err


def test_sweep_writes_one_table(tmp_path, capsys):
    """projeq sweep: a 3-point grid of the Atwood machine, final angles = closed form (a quadratic in t,
    exact for the integrator: 100 ε, measured 9.2e-16 relative; was 1e-8)."""
    argv = ["sweep", "atwood", "--grid", "m1=1:3:3", "--t-end", "0.5", "--rtol", "1e-10", "--outputs", "q0",
            "--workers", "2", "--out", str(tmp_path), "--quiet"]
    assert main(argv) == 0
    table = np.genfromtxt(tmp_path / "sweep_atwood.csv", delimiter=",", names=True, usecols=(0, 1, 2))
    assert np.allclose(table["q0"], [atwood_angle(m, 0.5) for m in (1.0, 2.0, 3.0)],
                       rtol=100 * np.finfo(float).eps, atol=0)


def test_unreachable_scheduler_writes_nothing(tmp_path, capsys):
    pytest.importorskip("dask.distributed")
    argv = ["sweep", "atwood", "--grid", "m1=1:3:3", "--scheduler", "tcp://127.0.0.1:9",
            "--scheduler-timeout", "0.5", "--out", str(tmp_path)]
    assert main(argv) == 2
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err and not list(tmp_path.iterdir())


def test_python_dash_m_is_the_same_command(capsys, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["projeq", "list"])
    monkeypatch.delitem(sys.modules, "projeq.__main__", raising=False)
    try:
        with pytest.raises(SystemExit) as exit_:
            runpy.run_module("projeq", run_name="__main__")
    finally:
        gc.unfreeze()  # the command froze this test process's objects, as at the end of a command
    assert exit_.value.code == 0 and capsys.readouterr().out.split()[0] == next(iter(pq.scenes.SCENES))


def test_the_command_freezes_what_is_alive_and_returns_main_s_code(monkeypatch):
    """``projeq`` (:func:`projeq.cli.command`) collects rarely (a young generation of 10,000
    objects: no full collection over the imports' objects) and exits without the interpreter's
    collection of numba's and scipy's objects (gc.freeze); the exit code is main's, a usage
    error's too."""
    monkeypatch.setattr(sys, "argv", ["projeq", "run", "no_such_scene"])
    thresholds = gc.get_threshold()
    try:
        assert command() == main(["run", "no_such_scene"]) == 2
        assert gc.get_freeze_count() > 0 and gc.get_threshold() == THRESHOLDS
    finally:
        gc.unfreeze()
        gc.set_threshold(*thresholds)


def test_imports_are_not_collected_and_frozen_when_new(tmp_path, monkeypatch):
    """imports_frozen: no collection while its block runs, however many tracked objects it makes
    (here 30,000 lists, three young generations of THRESHOLDS); what is alive frozen (gc.freeze)
    when the block imported a module, nothing when it did not; the collector enabled again only
    if it was."""
    (tmp_path / "freshly_imported.py").write_text("LISTS = [[] for _ in range(30_000)]\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    collections, thresholds = [], gc.get_threshold()
    gc.callbacks.append(on_start := lambda phase, info: collections.append(phase) if phase == "start" else None)
    gc.set_threshold(*THRESHOLDS)
    try:
        frozen = gc.get_freeze_count()
        with imports_frozen():
            import freshly_imported  # noqa: F401
        assert collections == [] and gc.isenabled() and gc.get_freeze_count() >= frozen + 30_000
        frozen = gc.get_freeze_count()
        with imports_frozen():
            import freshly_imported  # noqa: F401, F811 - imported before: nothing new
            made = [[] for _ in range(30_000)]
            during = len(collections)
        assert during == 0 and gc.get_freeze_count() == frozen and len(made) == 30_000
        gc.disable()
        with imports_frozen():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()
        gc.callbacks.remove(on_start)
        gc.unfreeze()
        gc.set_threshold(*thresholds)


def test_run_freezes_scipy_s_and_numba_s_modules_as_it_imports_them(tmp_path):
    """A fresh process's ``projeq run``: the modules of scipy.integrate (the driver's import) and
    numba (the compiled evaluator's) are frozen, left out of every later collection (gc.get_objects
    lists the collected generations only)."""
    code = ("import gc, sys; from projeq.cli import main; code = main(sys.argv[1:]); "
            "walked = {id(o) for o in gc.get_objects()}; "
            "print(code, [id(vars(sys.modules[m])) in walked for m in ('scipy.integrate', 'numba', 'projeq.scenes')])")
    done = subprocess.run([sys.executable, "-c", code, "run", "atwood", "--t-end", "0.2", "--quiet", "--out",
                           str(tmp_path)], capture_output=True, text=True, check=True)
    assert done.stdout.split(maxsplit=1) == ["0", "[False, False, False]\n"]


@pytest.mark.parametrize("option", ["--quiet", "--json", None])
def test_run_without_a_shown_bar_does_not_import_tqdm(option, tmp_path):
    """The progress bar is drawn on a terminal only: quiet, as JSON or into a pipe ``projeq run``
    does not import tqdm (nor start the monitor thread a disabled tqdm bar starts)."""
    code = "import sys; from projeq.cli import main; code = main(sys.argv[1:]); print(code, 'tqdm' in sys.modules)"
    argv = ["run", "atwood", "--t-end", "0.2", "--out", str(tmp_path)] + ([option] if option else [])
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, check=True)
    assert done.stdout.splitlines()[-1] == "0 False"


def test_files_are_complete_after_the_command_s_exit(tmp_path):
    """With the objects frozen at the end of ``python -m projeq run`` (no final collection), every
    file the record names is written, and the NPZ holds the run that the CSV holds."""
    done = subprocess.run([sys.executable, "-m", "projeq", "run", "atwood", "--t-end", "0.5", "--out", str(tmp_path),
                           "--json"], capture_output=True, text=True, check=True)
    record = json.loads(done.stdout)
    folder = Path(record["folder"])
    assert all((folder / name).is_file() for name in record["files"])
    result = pq.Result.load(folder / "atwood.npz")
    table = np.loadtxt(folder / "atwood.csv", delimiter=",", skiprows=1)
    assert np.array_equal(table[:, 0], result.t) and np.array_equal(table[:, 1], result.q[:, 0])


class Terminal(io.StringIO):
    """A stand-in for a terminal on stderr."""

    def isatty(self):
        return True


@pytest.mark.parametrize("quiet", [False, True])
def test_progress_bar_on_a_terminal_unless_quiet(quiet, tmp_path, monkeypatch):
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    argv = ["run", "atwood", "--t-end", "0.2", "--out", str(tmp_path)] + (["--quiet"] if quiet else [])
    assert main(argv) == 0
    assert ("100%|" in terminal.getvalue() and "t = 0.2/0.2 s" in terminal.getvalue()) is not quiet


def test_version(capsys):
    """``projeq --version`` prints the one version source, ``projeq.__version__``, and exits 0."""
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"projeq {pq.__version__}"


def test_the_cli_pages_bicycle_falls_over_with_a_physical_message(tmp_path, capsys):
    """``projeq run whipple_bicycle --set speed=3 --set roll=0.05`` (docs/cli.md): below the weave
    speed 4.29 m/s the benchmark bicycle is unstable (Meijaard, Papadopoulos, Ruina and Schwab,
    Proc. R. Soc. A 463 (2007), Table 2), so it falls. The run re-partitions where (φ̇, θ̇_R, δ̇)
    stop determining the other speeds, ends at the scene's fall event with exit 0, says so, and
    writes its results; the last row is the event's state, |roll| = 60°."""
    out = tmp_path / "bike"
    assert main(["run", "whipple_bicycle", "--set", "speed=3", "--set", "roll=0.05", "--quiet",
                 "--out", str(out)]) == 0
    assert "fell over" in capsys.readouterr().out
    result = pq.Result.load(next(out.rglob("whipple_bicycle.npz")))
    assert abs(abs(result.q[-1, 3]) - np.pi / 3) < 4e-9  # the event's root: measured 3.2e-10 (was 1e-8)
    assert len(result.partitions) >= 2
