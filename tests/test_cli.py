"""The projeq command: list, run (short), exit codes."""

import numpy as np

import projeq as pq
from projeq.cli import main


def test_list_names_every_scene(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in pq.scenes.SCENES)


def test_run_writes_results_that_load_back(tmp_path, capsys):
    """A short run of the default scene: exit 0, summary printed, NPZ equal to CSV."""
    assert main(["run", "--t-end", "0.5", "--out", str(tmp_path)]) == 0
    assert "tip displacement" in capsys.readouterr().out
    result = pq.Result.load(tmp_path / "spin_up_beam.npz")
    table = np.loadtxt(tmp_path / "spin_up_beam.csv", delimiter=",", skiprows=1)
    assert np.allclose(table[:, 0], result.t) and (tmp_path / "paraview" / "spin_up_beam.pvd").exists()


def test_unknown_scene_is_a_usage_error(capsys):
    assert main(["run", "no_such_scene"]) == 2
    assert "known scenes" in capsys.readouterr().err
