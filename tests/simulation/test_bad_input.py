"""Bad input to projeq.sweep refused by name before any point runs, and a sweep's points
written under their own columns (issue 20's standard: the parameter named, never a bare
traceback nor a silently wrong table)."""

import concurrent.futures as cf

import numpy as np
import pytest

import projeq as pq
from projeq.simulation.sweep import SweepTable


def _sweep(**kwargs):
    return pq.sweep("atwood", **{"outputs": ["t_reached"], "executor": cf.ThreadPoolExecutor(1), "t_end": 0.01,
                                 "progress": False, **kwargs})


@pytest.mark.parametrize("kwargs, message", [
    ({"grid": {"m1": 2.0}}, r"^grid: m1 must be a sequence of values, got 2.0 \(write \[2.0\]\)"),
    ({"grid": {"m1": "2.0"}}, r"^grid: m1 must be a sequence of values, got '2.0'"),
    ({"samples": {"m1": 2.0}}, r"^samples: m1 must be a sequence of values, got 2.0"),
    ({"samples": [{"m1": 1.0, "m2": 2.0}, {"m1": 3.0}]},
     r"^samples\[1\]: sets the parameters \['m1'\], the first point \['m1', 'm2'\]; every point must set the same"),
    ({"samples": [{"m1": 1.0}, {"m1": 3.0, "m2": 2.0}]},
     r"^samples\[1\]: sets the parameters \['m1', 'm2'\], the first point \['m1'\]"),
    ({"grid": {"m1": [1.0]}, "t_end": -1.0}, r"^t_end: must be after t_start = 0.0, got -1.0"),
    ({"grid": {"m1": [1.0]}, "t_end": 0.5, "t_start": 1.0}, r"^t_end: must be after t_start = 1.0, got 0.5"),
    ({"grid": {"m1": [1.0]}, "t_end": np.nan}, r"^t_end: non-finite entries"),
    ({"grid": {"m1": [1.0]}, "t_end": "1 s"}, r"^t_end: expected numbers, got '1 s'"),
], ids=["grid-scalar", "grid-string", "samples-scalar", "samples-missing-parameter", "samples-extra-parameter",
        "t_end-negative", "t_end-before-t_start", "t_end-nan", "t_end-text"])
def test_sweep_refuses_before_any_point_runs(kwargs, message):
    """Passes if each is a ValueError naming the parameter. Before: bare TypeErrors ("object of
    type 'float' has no len()"), a KeyError 'm2' after every point had run (a point without
    m2), a table silently without the m2 column that point 2 ran with, a bare "could not
    convert string to float", and a bad t_end failed every point alike, one by one."""
    with pytest.raises(ValueError, match=message):
        _sweep(**kwargs)


def test_samples_in_another_key_order_are_logged_under_their_columns(tmp_path, monkeypatch):
    """Passes if a sample that gives its parameters in another order ({m2, m1}) is appended to
    path.csv under the right columns: the file a crash leaves (here: the final save fails) holds
    m1 = 4, m2 = 3 for it, as given. Before, its line was written in the point's own order,
    m1 = 3, m2 = 4 under the header m1, m2: a crash or a resume read the wrong masses."""
    def crash(self, path):
        raise OSError("disk full")

    monkeypatch.setattr(SweepTable, "save", crash)
    with pytest.raises(OSError, match="disk full"):
        _sweep(samples=[{"m1": 1.0, "m2": 2.0}, {"m2": 3.0, "m1": 4.0}], path=tmp_path / "run")
    logged = SweepTable.load(tmp_path / "run")
    assert logged["m1"].tolist() == [1.0, 4.0] and logged["m2"].tolist() == [2.0, 3.0]


def test_a_misspelt_simulate_option_is_refused_before_any_point_runs():
    """sweep(..., rtoll=1e-6) raises the ValueError simulate raises for it ("options: unknown
    option ['rtoll'] ...") before running a point (every point failed with it, status −1, and the
    sweep itself returned normally)."""
    with pytest.raises(ValueError, match=r"^options: unknown option \['rtoll'\]"):
        _sweep(grid={"m1": [1.0, 2.0]}, rtoll=1e-6)


def _result(n_t=3):
    """A Result of n_t rows of a cart (x in m) carrying a pendulum (angle in rad)."""
    t = np.linspace(0.0, 1.0, n_t)
    return pq.Result(t=t, q=np.column_stack((t, 0.5 * t)), s_dot=np.ones((n_t, 2)), kinetic=np.ones(n_t),
                     potential=np.zeros(n_t), constraint_residual=np.zeros((n_t, 0)),
                     coordinates=(("cart.x", "m"), ("bob.angle", "rad")),
                     velocities=(("cart.x_dot", "m/s"), ("bob.angle_dot", "rad/s")))


def test_planar_trajectory_labels_its_axes_by_the_columns_units():
    """Passes if the path of (cart.x, bob.angle) has the axes "cart.x (m)" and "bob.angle (rad)",
    the result's own names and units; before, every axis read "q<i> (m)": an angle in metres."""
    from projeq import plots

    ax = plots.planar_trajectory(_result(), 0, 1).axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("cart.x (m)", "bob.angle (rad)")


@pytest.mark.parametrize("draw, message", [
    (lambda plots, r: plots.time_history(r, names=["x"]),
     r"^names: expected 2 labels, one per column of q \(\['cart.x \(m\)', 'bob.angle \(rad\)'\]\), got \['x'\]"),
    (lambda plots, r: plots.planar_trajectory(r, 0, 2), r"^y: expected a column of q, 0 … 1 .*got 2"),
    (lambda plots, r: plots.drift(_result(0)), r"^result: has no output rows \(status 0"),
    (lambda plots, r: plots.planar_trajectory(_result(0)), r"^result: has no output rows"),
], ids=["time_history-too-few-names", "planar_trajectory-column", "drift-empty", "planar_trajectory-empty"])
def test_plots_refuse_by_name(draw, message):
    """Passes if each is a ValueError naming the parameter. Before: names=["x"] for two columns
    silently drew only q0 (labels are taken by position), a column beyond q an IndexError, and an
    empty run (one stopped in its first segment) "index 0 is out of bounds"."""
    from projeq import plots

    with pytest.raises(ValueError, match=message):
        draw(plots, _result())


def test_simulate_refuses_n_points_beside_t_eval():
    """simulate(t_eval=[0, 0.5, 1], n_points=50) is a ValueError naming both (the run returned the
    3 rows of t_eval and dropped the 50 asked for without a word)."""
    with pytest.raises(ValueError, match=r"^n_points, t_eval: "):
        pq.simulate(pq.scenes.chain(2), 1.0, t_eval=[0.0, 0.5, 1.0], n_points=50)


@pytest.mark.parametrize("kwargs, message", [
    ({"grid": {"n": [1], "q0": [(0.1,), (0.2,)]}, "outputs": ["q0"]},
     r"^outputs: \['q0'\] are parameters of the sweep too; the table has one column per name"),
    ({"grid": {"n": [1]}, "outputs": ["q0", "q0"]}, r"^outputs: \['q0'\] asked for more than once"),
    ({"grid": {"n": [1]}, "outputs": "q0"}, r"^outputs: expected a sequence of output names, got the string 'q0'"),
], ids=["output-named-like-a-parameter", "output-twice", "outputs-string"])
def test_sweep_outputs_have_columns_of_their_own(kwargs, message):
    """Passes if each is refused by name before any point runs. Before, chain's parameter q0
    (the initial angle, (0.1,) and (0.2,)) and the output q0 (the final q[0]) shared one column:
    the table held −0.034 and −0.067 under q0 and no longer said which initial angle each row
    had; a repeated output wrote the header q0 twice; outputs="q0" was read letter by letter."""
    with pytest.raises(ValueError, match=message):
        pq.sweep("chain", **{"executor": cf.ThreadPoolExecutor(1), "t_end": 0.01, "progress": False, **kwargs})


def test_the_energy_drift_of_a_run_without_rows_is_nan():
    """Passes if a Result without output rows (a run stopped in its first segment) has
    energy_drift NaN, as the sweep's output of it (output_value), so that a check
    ``energy_drift < 1e-8`` fails. Before it was 0.0: perfect conservation claimed for a run that
    computed nothing, and such checks passed."""
    from projeq.simulation.sweep import output_value

    empty = _result(0)
    assert np.isnan(output_value(empty, "energy_drift"))  # the reference: the sweep's own word
    assert np.isnan(empty.energy_drift) and not empty.energy_drift < 1e-8
    assert _result(3).energy_drift == 0.0  # kinetic 1, potential 0 throughout


def test_a_result_loads_under_the_name_it_was_saved_with(tmp_path):
    """Passes if Result.save("run") — which writes run.npz, as numpy does — and
    Result.load("run") round-trip (the arrays equal); before, load looked for "run" itself:
    FileNotFoundError for the name just given to save."""
    result = _result(3)
    result.save(tmp_path / "run")
    loaded = pq.Result.load(tmp_path / "run")
    assert np.array_equal(loaded.q, result.q) and loaded.coordinates == result.coordinates
