"""Figures (projeq.simulation.plots): each returns a Figure whose line data are the result's own arrays."""

import numpy as np
import pytest

import projeq as pq
from projeq import plots


@pytest.fixture(scope="module")
def car_run():
    """Bremer's car, 1 s: a planar path and a velocity constraint (rear axle)."""
    return pq.simulate(pq.scenes.car(), 1.0, n_points=21, rtol=1e-9, atol=1e-11)


def lines(ax):
    return [(line.get_xdata(), line.get_ydata()) for line in ax.get_lines()]


def test_time_history_plots_q_and_s_dot(car_run):
    fig = plots.time_history(car_run, names=["x", "y", "gamma"])
    top, bottom = fig.axes
    assert [t.get_text() for t in top.get_legend().get_texts()] == ["x", "y", "gamma"]
    for i, (x, y) in enumerate(lines(top)):
        assert np.array_equal(x, car_run.t) and np.array_equal(y, car_run.q[:, i])
    for i, (x, y) in enumerate(lines(bottom)):
        assert np.array_equal(y, car_run.s_dot[:, i])


def test_planar_trajectory_draws_the_path_with_start_and_end(car_run, tmp_path):
    fig = plots.planar_trajectory(car_run, 0, 1)
    (path_x, path_y), start, end = lines(fig.axes[0])
    assert np.array_equal(path_x, car_run.q[:, 0]) and np.array_equal(path_y, car_run.q[:, 1])
    assert np.array_equal(start[0], [car_run.q[0, 0]]) and np.array_equal(end[1], [car_run.q[-1, 1]])
    fig.savefig(tmp_path / "path.png")  # headless: the Agg canvas renders without a display
    assert (tmp_path / "path.png").stat().st_size > 0


def test_drift_plots_energy_change_and_constraint_residual(car_run):
    fig = plots.drift(car_run)
    (_, energy), = lines(fig.axes[0])
    (_, residual), = lines(fig.axes[1])
    assert np.array_equal(energy, car_run.energy - car_run.energy[0])
    assert np.array_equal(residual, np.maximum(np.abs(car_run.constraint_residual).max(axis=1), 1e-300))


def test_tip_deflection_is_the_beams():
    system = pq.scenes.spinning_beam()
    result = pq.simulate(system, 0.05, n_points=6)
    beam = system.subsystem(system.names[-1])
    fig = plots.tip_deflection(result, beam)
    assert np.array_equal(np.array([y for _, y in lines(fig.axes[0])]).T, beam.deflection(result, beam.length))


def test_work_precision_sorts_each_method_by_error():
    rows = [("RK45", 1e-6, 0.2), ("RK45", 1e-9, 0.5), ("DOP853", 1e-10, 0.3), ("RK45", 1e-3, 0.1)]
    fig = plots.work_precision(rows)
    (rk_error, rk_cpu), (dop_error, _) = lines(fig.axes[0])
    assert rk_error.tolist() == [1e-9, 1e-6, 1e-3] and rk_cpu.tolist() == [0.5, 0.2, 0.1]
    assert dop_error.tolist() == [1e-10] and fig.axes[0].get_xscale() == "log"


@pytest.mark.parametrize("smallest, floor", [(1e-9, 1e-16), (1e-17, 1e-18)], ids=["round-off", "below-round-off"])
def test_work_precision_draws_an_exact_error_at_a_stated_floor(smallest, floor):
    """Passes if an error of exactly 0 is drawn at the floor (1e-16, or a decade below a smaller
    positive error), circled, with a note naming the floor. Before, the log axis dropped the
    point without a word (matplotlib masks x ≤ 0)."""
    rows = [("RK45", 0.0, 0.4), ("RK45", smallest, 0.2), ("RK45", 1e-3, 0.1)]
    fig = plots.work_precision(rows)
    ((error, cpu),) = lines(fig.axes[0])
    assert error.tolist() == [floor, smallest, 1e-3] and cpu.tolist() == [0.4, 0.2, 0.1]
    assert fig.axes[0].collections[0].get_offsets().tolist() == [[floor, 0.4]]
    assert [t.get_text() for t in fig.axes[0].texts] == [f"circled: error exactly 0, drawn at {floor:.0e}"]


@pytest.mark.parametrize("row, message", [
    (("RK45", -1e-8, 0.2), r"^rows\[1\]: the error of 'RK45' must be finite and >= 0, got -1e-08"),
    (("RK45", np.nan, 0.2), r"^rows\[1\]: the error of 'RK45' must be finite and >= 0, got nan"),
    (("RK45", 1e-8, 0.0), r"^rows\[1\]: the CPU time of 'RK45' must be finite and > 0 s, got 0.0"),
], ids=["negative-error", "nan-error", "zero-cpu"])
def test_work_precision_refuses_a_point_a_log_axis_cannot_show(row, message):
    """Passes if a point the log axes would drop is a ValueError naming its row."""
    with pytest.raises(ValueError, match=message):
        plots.work_precision([("RK45", 1e-3, 0.1), row])
