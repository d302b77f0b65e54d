"""Run records and CLI conventions: a folder per run with run.json, named CSV columns, --json
on list, run, sweep and compare, the simulation options on run and sweep, user scenes from
a file, ParaView files of a saved run."""

import csv
import json
import re

import numpy as np
import pytest

import projeq as pq
import projeq.cli.studies
import projeq.simulation.driver
from projeq.cli.commands import main


def run_folder(out):
    folder, = out.iterdir()
    return folder


def test_each_run_gets_a_folder_with_its_record(tmp_path, capsys):
    """Two runs of the same scene into the same --out: two folders, nothing overwritten; the
    record names scene, parameters, tolerances, method, evaluator, version and command line;
    the NPZ carries the same record, and its last state is the record's."""
    argv = ["run", "double_pendulum", "--t-end", "0.2", "--rtol", "1e-8", "--atol", "1e-10", "--method", "RK45",
            "--evaluator", "dense", "--set", "l1=0.5", "--out", str(tmp_path), "--quiet"]
    assert main(argv) == 0 and main(argv) == 0
    folders = sorted(tmp_path.iterdir())
    assert len(folders) == 2 and all(f.name.startswith("double_pendulum-") for f in folders)
    record = json.loads((folders[0] / "run.json").read_text())
    assert record["scene"] == "double_pendulum" and record["parameters"]["l1"] == 0.5
    assert record["parameters"]["m2"] == 1.0  # defaults recorded too
    assert record["tolerances"] == {"rtol": 1e-8, "atol": 1e-10} and record["method"] == "RK45"
    assert record["evaluator"] == "dense" and record["projeq_version"] == pq.__version__
    assert record["command_line"] == ["projeq", *argv] and record["status"] == "finished"
    assert record["exit_code"] == 0 and record["cpu_time"] > 0 and record["wall_time"] > 0
    assert "double_pendulum.npz" in record["files"] and record["energy"]["conserved"] is True
    result = pq.Result.load(folders[0] / "double_pendulum.npz")
    assert result.metadata["scene"] == "double_pendulum" and result.metadata["tolerances"]["atol"] == 1e-10
    assert record["final_q"] == {"bob1.angle": result.q[-1, 0], "bob2.angle": result.q[-1, 1]}


def test_the_csv_names_its_columns_with_units(tmp_path):
    """``projeq run double_pendulum``: the CSV header is t, the joint angles and their rates by
    name with units, the energies; its columns are the NPZ's arrays."""
    assert main(["run", "double_pendulum", "--t-end", "0.1", "--out", str(tmp_path), "--quiet"]) == 0
    folder = run_folder(tmp_path)
    with (folder / "double_pendulum.csv").open() as stream:
        header = next(csv.reader(stream))
    assert header == ["t (s)", "bob1.angle (rad)", "bob2.angle (rad)", "bob1.angle_dot (rad/s)",
                      "bob2.angle_dot (rad/s)", "kinetic (J)", "potential (J)"]
    table = np.loadtxt(folder / "double_pendulum.csv", delimiter=",", skiprows=1)
    result = pq.Result.load(folder / "double_pendulum.npz")
    assert np.array_equal(table[:, 1:3], result.q) and np.array_equal(table[:, 3:5], result.s_dot)


def test_the_summary_names_the_state_and_says_why_energy_changes(tmp_path, capsys):
    """The spin-up beam (a prescribed hub motion): final q by name in m, the always-zero
    w amplitudes (the spin is about the beam's normal, it bends in v only) left out and
    counted, and the energy caveat; the double pendulum (conservative) has no caveat. run.json
    reports the spin-up's energy as not conserved (no drift figure: the hub's drive changes E by
    its work) with its change, the pendulum's drift as a number (over 0.05 s at rtol 1e-8: measured
    9.8e-12, bound 9.8e-11; 6.2e-14 while the steps were cut at the 20 segments' ends, 2.5 ms apart)."""
    assert main(["run", "spin_up_beam", "--t-end", "0.05", "--out", str(tmp_path / "beam")]) == 0
    out = capsys.readouterr().out
    assert "final q: beam.v[0] = " in out and "beam.w[0]" not in out and "(4 zero throughout: not shown)" in out
    assert "not conserved here: a prescribed motion" in out
    assert all(len(line) <= 100 for line in out.splitlines() if not line.startswith(("wrote", "energy")))
    energy = json.loads((run_folder(tmp_path / "beam") / "run.json").read_text())["energy"]
    assert energy["drift"] == "not conserved: a prescribed motion or non-conservative forces"
    assert energy["conserved"] is False and energy["change"] == energy["final"] - energy["initial"] != 0.0
    assert main(["run", "double_pendulum", "--t-end", "0.05", "--out", str(tmp_path / "dp")]) == 0
    assert "not conserved" not in capsys.readouterr().out
    energy = json.loads((run_folder(tmp_path / "dp") / "run.json").read_text())["energy"]
    assert energy["conserved"] is True and 0.0 <= energy["drift"] < 9.8e-11, energy


def test_list_describes_a_scenes_parameters(capsys):
    """``projeq list car``: each parameter with its description from the build function's
    numpydoc Parameters section (plain text, within 100 columns; in --json too); a parameter
    common to scenes (g) described where the docstring does not."""
    assert main(["list", "car"]) == 0
    out = capsys.readouterr().out
    assert "C°, the moment of inertia about the" in out and "``" not in out
    assert max(map(len, out.splitlines()[1:])) <= 100
    assert main(["list", "car", "--json"]) == 0
    described = {p["name"]: p["description"] for p in json.loads(capsys.readouterr().out)["parameters"]}
    assert all(described.values()) and described["m"] == "Mass of the car (kg)."
    assert main(["list", "double_pendulum"]) == 0
    assert "gravitational acceleration" in capsys.readouterr().out


def test_json_documents_of_list_run_sweep_and_compare(tmp_path, capsys, monkeypatch):
    assert main(["list", "--json"]) == 0
    assert set(json.loads(capsys.readouterr().out)) == set(pq.scenes.SCENES)
    assert main(["list", "atwood", "--json"]) == 0
    assert {p["name"] for p in json.loads(capsys.readouterr().out)["parameters"]} >= {"m1", "m2"}
    assert main(["run", "atwood", "--t-end", "0.1", "--out", str(tmp_path / "run"), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["status"] == "finished" and document["final_q"].keys() == {"pulley.angle"}
    assert json.loads((run_folder(tmp_path / "run") / "run.json").read_text())["final_q"] == document["final_q"]
    assert main(["sweep", "atwood", "--grid", "m1=1.5:2:2", "--t-end", "0.1", "--workers", "1", "--outputs", "q0",
                 "--atol", "1e-9", "--out", str(tmp_path / "sweep"), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["points"] == 2 and document["options"]["atol"] == 1e-9 and document["table"]["m1"] == [1.5, 2.0]
    record = json.loads((tmp_path / "sweep" / "sweep_atwood.json").read_text())  # the sweep's run.json
    assert record["grid"] == {"m1": [1.5, 2.0]}
    assert "m1" not in record["parameters"] and "m2" in record["parameters"]
    assert record["tolerances"]["atol"] == 1e-9 and record["outputs"] == ["q0"] and record["points"] == 2
    assert record["t_end"] == 0.1 and record["options"]["atol"] == 1e-9  # what --resume compares, kept
    assert record["failed"] == 0 and record["files"] == ["sweep_atwood.csv", "sweep_atwood.npz"]
    assert record["command_line"][:3] == ["projeq", "sweep", "atwood"]
    assert record["projeq_version"] == pq.__version__
    monkeypatch.setattr(projeq.cli.studies, "compare", lambda *a, **k: pq.ComparisonTable("car", rows=[{"x": 1.0}]))
    assert main(["compare", "car", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rows"] == [{"x": 1.0}]


def test_a_user_scene_from_a_file(tmp_path, capsys):
    """``projeq run my_model.py:build --set length=2``: the user's function with its keyword
    parameters, docstring and t_end; the trajectory is simulate()'s of the same function with
    the same options (a second path to the same numbers); an unknown function or parameter is
    a bad argument (exit 2) naming it."""
    model = tmp_path / "my_model.py"
    model.write_text(
        "import projeq as pq\n\n"
        "def build(length: float = 1.0):\n"
        "    '''A pendulum of the given length.'''\n"
        "    return pq.System({'bob': pq.PointMass(1.0, (0, 0, -length))}, {'bob': pq.Revolute(axis='y')},\n"
        "                     gravity=(0, 0, -9.81), q0=[0.4])\n"
        "build.t_end = 0.3\n")
    assert main(["list", f"{model}:build"]) == 0
    assert "A pendulum of the given length" in capsys.readouterr().out
    assert main(["run", f"{model}:build", "--set", "length=2", "--out", str(tmp_path / "out"), "--quiet"]) == 0
    folder = run_folder(tmp_path / "out")
    assert folder.name.startswith("my_model-build-")
    result = pq.Result.load(folder / "my_model-build.npz")
    from importlib import util

    spec = util.spec_from_file_location("check_model", model)
    module = util.module_from_spec(spec)
    spec.loader.exec_module(module)
    direct = pq.simulate(module.build(length=2.0), 0.3, n_points=201)  # projeq run: simulate's defaults
    # the same arithmetic: measured 0 (was 1e-9)
    assert result.t[-1] == 0.3 and np.allclose(result.q, direct.q, rtol=0, atol=100 * np.finfo(float).eps)
    assert main(["run", f"{model}:missing", "--out", str(tmp_path)]) == 2
    assert "has no function 'missing'" in capsys.readouterr().err
    assert main(["run", f"{model}:build", "--set", "lenght=2", "--out", str(tmp_path)]) == 2
    assert "did you mean 'length'" in capsys.readouterr().err


def test_a_user_function_returning_no_model_is_a_bad_argument(tmp_path, capsys):
    """``projeq run FILE.py:FUNCTION`` whose function returns something else than a System or a
    ConstrainedSystem: exit 2 with simulate's own refusal (projeq.system.check_model), nothing run
    or written — also now that the run's evaluator is formed before simulate."""
    model = tmp_path / "not_a_model.py"
    model.write_text("def build():\n    return None\n")
    assert main(["run", f"{model}:build", "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "system: expected a System or a ConstrainedSystem" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("source, message", [
    ("def build(:\n", "cannot be imported: SyntaxError at line 1: invalid syntax: 'def build(:'"),
    ("import no_such_module_of_projeq\n", "cannot be imported: ModuleNotFoundError: No module named "
                                          "'no_such_module_of_projeq'"),
], ids=["syntax", "import"])
def test_a_user_file_that_cannot_be_imported_is_a_bad_argument(source, message, tmp_path, capsys):
    """Passes if ``projeq run FILE.py:build`` of a file with a syntax error or a missing import
    exits 2 with one line naming the file and what is wrong, nothing written. Before: a bare
    traceback (main caught neither SyntaxError nor ImportError)."""
    model = tmp_path / "broken.py"
    model.write_text(source)
    assert main(["run", f"{model}:build", "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert capsys.readouterr().err == f"projeq run: scene: {model} {message}\n"
    assert not (tmp_path / "out").exists()


def test_export_of_a_file_that_is_no_result_writes_nothing(tmp_path, capsys):
    """Passes if ``projeq export`` of a .npz that is no Result exits 2 naming it and leaves no
    paraview/ directory behind (before, the directory was made first, empty)."""
    npz = tmp_path / "other.npz"
    np.savez(npz, x=np.arange(3.0))
    assert main(["export", str(npz)]) == 2
    assert "is not a projeq Result" in capsys.readouterr().err
    assert not (tmp_path / "paraview").exists()


def test_projeq_export_writes_paraview_files_of_a_saved_run(tmp_path, capsys):
    assert main(["run", "double_pendulum", "--t-end", "0.1", "--out", str(tmp_path), "--quiet"]) == 0
    npz = run_folder(tmp_path) / "double_pendulum.npz"
    assert main(["export", str(npz), "--out", str(tmp_path / "later")]) == 0
    assert (tmp_path / "later" / "double_pendulum.pvd").exists()
    assert (tmp_path / "later" / "double_pendulum_mechanism_0000.vtu").exists()
    assert main(["export", str(tmp_path / "none.npz")]) == 2


@pytest.mark.parametrize("command", [["run", "atwood"], ["sweep", "atwood", "--grid", "m1=1:2:2"]])
def test_every_simulating_command_takes_the_simulation_options(command, tmp_path):
    """The same options on run and sweep (one home: projeq.cli.options), refused alike."""
    assert main([*command, "--evaluator", "nonsense", "--out", str(tmp_path)]) == 2
    assert main([*command, "--method", "Euler", "--out", str(tmp_path)]) == 2


def test_text_fits_100_columns_and_help_has_no_markup(capsys):
    """``projeq list`` lines and a table with a long note fit 100 columns (the note cut with
    …, numbers untouched); ``projeq bench --help`` shows no reStructuredText roles."""
    from projeq.studies.table import Table

    assert main(["list"]) == 0
    assert max(len(line) for line in capsys.readouterr().out.splitlines()) <= 100
    table = Table(["rtol", "failure / warning"], [[1e-3, "x" * 300], [1e-6, "ok"]])
    lines = table.to_text(100).splitlines()
    assert max(map(len, lines)) == 100 and lines[2].endswith("…") and lines[2].startswith("0.001")
    assert table.to_text().splitlines()[2].endswith("x" * 300)
    assert main(["bench", "--help"]) == 0
    assert ":mod:" not in (help_text := capsys.readouterr().out) and "``" not in help_text


def test_run_uses_the_scenes_settings_then_simulates_defaults(tmp_path, capsys):
    """Without options ``projeq run`` takes the scene's integrator settings (the spin-up beam:
    Radau at rtol 1e-4, atol 1e-6, projeq.scenes.SPIN_UP_SETTINGS), a scene without settings
    simulate's own defaults (recorded as "default" and the integrator simulate used), and an
    option given on the command line wins over both."""
    assert main(["run", "--t-end", "0.5", "--out", str(tmp_path / "beam"), "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["scene"] == "spin_up_beam" and record["method"] == "Radau"
    assert record["tolerances"] == {"rtol": 1e-4, "atol": 1e-6}
    assert main(["run", "--t-end", "0.5", "--rtol", "1e-6", "--out", str(tmp_path / "beam"), "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["method"] == "Radau" and record["tolerances"] == {"rtol": 1e-6, "atol": 1e-6}
    assert main(["run", "double_pendulum", "--t-end", "0.1", "--out", str(tmp_path / "pendulum"), "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["tolerances"] == {"rtol": "default", "atol": "default"}
    assert record["method"] == pq.Result.load(next((tmp_path / "pendulum").rglob("*.npz"))).method != "default"


def test_a_run_out_of_range_exits_3_and_records_every_warning(tmp_path, capsys):
    """Passes if `projeq run spin_up_beam --set omega_s=200 --set t_s=2 --t-end 3 --json` (issue 37:
    exit 0, "finished", q ≈ 1e88 m, energy NaN) stops at the end of the step past t = 0.3 s (0.309 s),
    where the beam's tip has passed its moderate-deflection range, with exit code 3, status "out of range" in run.json and the NPZ,
    the ValidityWarning in run.json's warnings, and every warning on stderr as one line
    "projeq run: <Category>: <message>" (no Python source lines)."""
    argv = ["run", "spin_up_beam", "--set", "omega_s=200", "--set", "t_s=2", "--t-end", "3", "--json",
            "--out", str(tmp_path)]
    assert main(argv) == 3
    said = capsys.readouterr()
    record = json.loads((run_folder(tmp_path) / "run.json").read_text())
    assert json.loads(said.out)["status"] == record["status"] == "out of range" and record["exit_code"] == 3
    assert 0.3 <= record["t_reached"] < 0.31 and np.isfinite(record["energy"]["final"])
    validity = [w for w in record["warnings"] if w["category"] == "ValidityWarning"]
    assert len(validity) == 1 and re.match(r"'beam' by t = 0\.30\d* s: lateral deflection 0\.3\d* L", validity[0]["message"])
    lines = said.err.splitlines()
    assert [line for line in lines if line.startswith("projeq run: ")] == [f"projeq run: {w['category']}: {w['message']}"
                                                             for w in record["warnings"]]
    assert re.search(r"projeq: stopped at t = 0\.30\d* s: a subsystem left the range", said.err)
    assert "warnings.warn" not in said.err
    assert pq.Result.load(run_folder(tmp_path) / "spin_up_beam.npz").status == 3


def test_a_run_whose_state_overflows_exits_4(tmp_path, capsys, monkeypatch):
    """Passes if a run that simulate ends at a non-finite state (SimulationError, status 4: the
    spin-up beam at omega_s = 200 let go on past its range does, tests/simulation/test_physics_range;
    here a short chain run whose Result says so) exits with 4 and records "non-finite state",
    its results up to there written (before: a non-finite state was "failed", exit 1, like any
    failure)."""
    from dataclasses import replace

    real = projeq.simulation.driver.simulate

    def overflowing(system, t_end, **options):
        kept = replace(real(system, t_end / 2, **options), status=4)
        raise projeq.simulation.driver.SimulationError(f"integration failed at t = {t_end / 2} s: the energy (T, V) "
                                                       "= (nan, 1e+155) is not finite", kept)

    monkeypatch.setattr(projeq.simulation.driver, "simulate", overflowing)
    assert main(["run", "chain", "--t-end", "0.2", "--quiet", "--out", str(tmp_path)]) == 4
    record = json.loads((run_folder(tmp_path) / "run.json").read_text())
    assert record["status"] == "non-finite state" and record["exit_code"] == 4 and record["t_reached"] == 0.1
    assert "is not finite" in capsys.readouterr().err
    assert pq.Result.load(run_folder(tmp_path) / "chain.npz").status == 4
