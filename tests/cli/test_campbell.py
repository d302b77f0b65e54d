"""projeq campbell SCENE: files written, numbers equal to the library's, bad arguments."""

import csv

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.campbell import campbell
from projeq.cli.commands import main


def test_campbell_writes_the_diagram_and_its_csv(tmp_path, capsys):
    """The spinning beam at three speeds (two clamped–free functions per plane): exit 0, the
    table and the critical speeds printed, the CSV equal to campbell's numbers, the PNG drawn."""
    pytest.importorskip("matplotlib")
    argv = ["campbell", "spinning_beam", "--set", "n_shapes=2", "--speeds", "0:4:3", "--modes", "2", "--out", str(tmp_path)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "forward whirl 1" in out and "critical speed: forward whirl 1 crosses 1Ω" in out
    rows = list(csv.reader(open(tmp_path / "spinning_beam_campbell.csv", encoding="utf-8")))
    expected = campbell(lambda w: pq.scenes.spinning_beam(omega=w, n_shapes=2), [0.0, 2.0, 4.0], n_modes=2)
    assert rows[0][1] == f"{expected.labels[0]} frequency (rad/s)"
    columns = [i for i, name in enumerate(rows[0]) if name.endswith(" frequency (rad/s)") and "stationary" not in name]
    assert np.array_equal(np.array(rows[1:], dtype=float)[:, columns], expected.frequencies)
    stationary = [i for i, name in enumerate(rows[0]) if name.endswith("stationary frequency (rad/s)")]
    assert len(stationary) == 2  # a whirl's frequency seen from the inertial frame, per whirl branch
    assert (tmp_path / "spinning_beam_campbell.png").stat().st_size > 0
    critical = list(csv.reader(open(tmp_path / "spinning_beam_critical_speeds.csv", encoding="utf-8")))
    assert critical[0] == ["mode", "engine order", "speed (rad/s)", "frequency (rad/s)"] and len(critical) > 1


@pytest.mark.parametrize(
    "argv, match",
    [
        (["--speeds", "0:4"], "--speeds: expected START:STOP:COUNT"),
        (["--speeds", "0:4:1"], "--speeds: expected START:STOP:COUNT"),
        (["--speeds", "3,1"], "speeds: must increase"),
        (["--orders", "one"], "--orders: expected comma-separated numbers"),
        (["--parameter", "spin"], "spin: unknown parameter"),
        (["--set", "omega=2"], "--set: omega is the swept speed"),
    ],
    ids=["speeds-short", "speeds-count", "decreasing", "orders", "parameter", "set-speed"],
)
def test_bad_campbell_arguments_exit_2(argv, match, tmp_path, capsys):
    assert main(["campbell", "rotating_blade", "--set", "n_shapes=1", *argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("projeq campbell: ") and match in err, err
