"""Work-precision studies (projeq.studies.tradeoff): the table, its reference, the cheapest setting, CSV, CLI."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ellipj, ellipk

from projeq.studies import tradeoff as tr
from projeq.cli.commands import main as projeq_main
from projeq.studies.tradeoff_studies import STUDIES, SYMBOLIC_MAX_BODIES, Knob, Study, final_q

PENDULUM = {"n": 1}  # chain(1): a compound pendulum released from rest at 0.5 rad


def pendulum_angle(t: float, theta0: float = 0.5) -> float:
    """Exact angle of the compound pendulum chain(1), released from rest at theta0:
    theta(t) = 2 arcsin(k sn(K(k) - omega t, k)), k = sin(theta0/2), omega^2 = m g d / I_O
    (Landau & Lifshitz, Mechanics, §11, problem 1 with the elliptic integral inverted;
    Whittaker, Analytical Dynamics, §44). The link of scenes.chain: m = 1 kg, d = 0.5 m,
    a solid cylinder of radius 0.01 m and length 1 m: I_O = m L²/3 + m r²/4."""
    I_O = 1.0 / 3.0 + 0.01**2 / 4.0
    omega = np.sqrt(9.81 * 0.5 / I_O)
    k = np.sin(theta0 / 2.0)
    sn = ellipj(ellipk(k**2) - omega * t, k**2)[0]
    return 2.0 * np.arcsin(k * sn)


def test_tiny_study_is_complete_and_its_reference_is_the_exact_pendulum(tmp_path):
    """Every (knob, method, rtol) has a row with all columns; the cached reference (DOP853,
    rtol 1e-13) is the closed-form pendulum angle to 1e-11 rad, so the error column is the
    error against the exact solution."""
    table = tr.tradeoff("chain", methods=["DOP853", "RK45"], tolerances=[1e-4, 1e-7],
                        knobs=["recursive", "dense"], overrides=PENDULUM, t_end=1.0, out=tmp_path)
    assert len(table["method"]) == 2 * 2 * 2
    assert set(tr.COLUMNS) <= set(table)
    assert list(table["failure"]) == [""] * 8
    assert np.all(table["n_evaluations"] > 0) and np.all(table["cpu"] >= 0) and np.all(table["t_reached"] == 1.0)
    (cached,) = tmp_path.glob("reference_chain_*.npz")
    reference = np.load(cached)["measured"]
    # DOP853 at rtol = atol = 1e-13 over 1 s: measured 1.9e-15 rad (the bound was 1e-11)
    assert abs(reference[0] - pendulum_angle(1.0)) < 2e-14
    # second call: the reference is read from the cache (same file, same numbers)
    again = tr.tradeoff("chain", methods=["RK45"], tolerances=[1e-4], knobs=["recursive"],
                        overrides=PENDULUM, t_end=1.0, out=tmp_path)
    assert len(list(tmp_path.glob("reference_chain_*.npz"))) == 1
    assert again["error"][0] == table["error"][table["method"] == "RK45"][0]
    # the recursive and the dense evaluator are the same model: same errors to round-off
    recursive, dense = (table["error"][table["knob"] == k] for k in ("recursive", "dense"))
    np.testing.assert_allclose(recursive, dense, rtol=1e-3, atol=1e-13)  # step sequences may differ by round-off


def test_error_decreases_with_the_tolerance_of_a_convergent_method():
    """Tolerance proportionality (Hairer, Nørsett & Wanner, Solving ODEs I, §II.4): DOP853's
    global error against the exact pendulum falls with rtol; over three decades of rtol by
    at least one decade of error, and it stays within 100 rtol (rtol = atol, |q| < 1)."""
    table = tr.tradeoff("chain", methods=["DOP853"], tolerances=[1e-3, 1e-6, 1e-9], knobs=["recursive"],
                        overrides=PENDULUM, t_end=2.0)
    error = table["error"]
    assert np.all(error[1:] < 0.1 * error[:-1])
    assert np.all(error < 100 * table["rtol"])


def _constructed_table():
    rows = [  # (method, error, cpu, failure)
        ("A", 1e-3, 1.0, ""), ("B", 5e-3, 0.5, ""), ("C", 1e-5, 3.0, ""), ("D", 1e-7, 2.0, ""),
        ("E", 1e-9, 0.1, "timeout"), ("F", np.nan, 0.01, "diverged"), ("G", 1e-7, 2.5, ""),
        ("H", 1e-3, 0.2, ""),  # H at rtol 1e-6; H at rtol 1e-3 below: 1e-9 by a lucky cancellation
    ]
    table = [{"scene": "s", "method": m, "rtol": 1e-6, "atol": 1e-6, "knob": "k", "error": e, "cpu": c,
              "setup_cpu": 0.0, "n_evaluations": 10, "t_reached": 1.0, "failure": f, "warning": ""}
             for m, e, c, f in rows]
    table.append({**table[-1], "rtol": 1e-3, "atol": 1e-3, "error": 1e-9, "cpu": 0.05})
    return tr.columns(table)


def test_cheapest_setting_for_each_error_level():
    """1e-2: H at rtol 1e-3 (0.05 s; H at 1e-6 stays below 1e-2 as well); 1e-4 and 1e-6: D
    (2.0 s beats C's 3.0 and G's 2.5; H at 1e-3 is not reliable: H at 1e-6 has 1e-3);
    1e-8: none — E reaches it but failed, F is cheaper but diverged, H at 1e-3 by luck."""
    table = _constructed_table()
    choice = tr.cheapest(table)
    assert {level: None if i is None else (table["method"][i], table["rtol"][i]) for level, i in choice.items()} == {
        1e-2: ("H", 1e-3), 1e-4: ("D", 1e-6), 1e-6: ("D", 1e-6), 1e-8: None}
    text = tr.format_table(table)
    assert "cheapest for error <= 1e-02: H rtol=1e-03 [k]" in text
    assert "cheapest for error <= 1e-08: no setting reaches it" in text


def test_csv_round_trip(tmp_path):
    table = _constructed_table()
    back = tr.read_csv(tr.save_csv(table, tmp_path / "t.csv"))
    for name in tr.COLUMNS:
        np.testing.assert_array_equal(back[name], table[name], err_msg=name)  # NaN == NaN here
    assert back["n_evaluations"].dtype.kind == "i"


def test_timeout_and_skipped_knobs_are_rows_not_crashes():
    """A run over its CPU budget is a 'timeout' row; a symbolic evaluator for more than
    SYMBOLIC_MAX_BODIES bodies is a 'skipped' row for every setting; errors are NaN."""
    table = tr.tradeoff("chain", methods=["RK23"], tolerances=[1e-6], knobs=["recursive"],
                        overrides=PENDULUM, t_end=1.0, timeout=1e-9)
    assert list(table["failure"]) == ["timeout"] and np.isnan(table["error"][0])
    assert table["t_reached"][0] < 1.0
    table = tr.tradeoff("chain", methods=["RK45", "DOP853"], tolerances=[1e-3], knobs=["symbolic"],
                        overrides={"n": 7}, t_end=0.1)
    assert len(table["failure"]) == 2
    assert all(f.startswith("skipped: evaluator: symbolic derivation skipped for 7 bodies") for f in table["failure"])


def test_symbolic_knob_agrees_with_the_recursive_evaluator():
    """The compiled sympy Gauss form and the recursive evaluator integrate the same model:
    with the same integrator their errors agree to round-off (a second formulation)."""
    table = tr.tradeoff("chain", methods=["DOP853"], tolerances=[1e-6], knobs=["recursive", "symbolic"],
                        overrides={"n": 2}, t_end=0.5)
    assert list(table["failure"]) == ["", ""]
    np.testing.assert_allclose(table["error"][0], table["error"][1], rtol=1e-3)  # step sequences differ by round-off


def test_ctrl_c_keeps_the_finished_rows(tmp_path, monkeypatch):
    calls = []
    real = tr.run_setting

    def interrupted_on_second(*args):  # the first call is the reference run
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(tr, "run_setting", interrupted_on_second)
    code = projeq_main(["tradeoff", "chain", "--set", "n=1", "--methods", "RK45", "--tolerances", "1e-3", "1e-4",
                        "--knobs", "recursive", "--t-end", "0.5", "--out", str(tmp_path), "--quiet"])
    assert code == 1
    table = tr.read_csv(tmp_path / "tradeoff_chain.csv")
    assert list(table["rtol"]) == [1e-3]


def test_cli_runs_a_study_and_writes_csv_and_plot(tmp_path, capsys):
    code = projeq_main(["tradeoff", "chain", "--set", "n=1", "--methods", "RK45", "DOP853", "--tolerances", "1e-3",
                        "1e-6", "--knobs", "recursive", "--t-end", "0.5", "--out", str(tmp_path)])
    assert code == 0
    out = capsys.readouterr().out
    assert "cheapest for error <= 1e-04:" in out and "error = max |q - q_ref|" in out
    assert len(tr.read_csv(tmp_path / "tradeoff_chain.csv")["method"]) == 4
    assert (tmp_path / "tradeoff_chain.png").stat().st_size > 0


@pytest.mark.parametrize("argv, name", [
    (["no_such_scene"], "scene"),
    (["chain", "--methods", "RK99"], "methods"),
    (["chain", "--tolerances", "abc"], "--tolerances"),
    (["chain", "--tolerances", "2"], "tolerances"),
    (["chain", "--t-end", "-1"], "t_end"),
    (["chain", "--knobs", "bogus"], "knobs"),
    (["chain", "--set", "n=x"], "n"),
    (["chain", "--set", "nn=3"], "nn"),
    (["chain", "--timeout", "0"], "--timeout"),
    (["spin_up_beam", "--set", "n_shapes=3"], "overrides"),
    (["chain", "--out", "/proc/no-such-dir"], "--out"),
])
def test_cli_bad_arguments_exit_2_naming_the_argument(argv, name, capsys, tmp_path):
    out = [] if "--out" in argv else ["--out", str(tmp_path)]  # nothing written into the working directory
    assert projeq_main(["tradeoff", *argv, *out]) == 2
    assert f"projeq tradeoff: {name}" in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["--methods", "RK45", "DOP853", "RK45"], "methods: ['RK45'] given more than once"),
    (["--tolerances", "1e-3", "1e-6", "1e-3"], "tolerances: [0.001] given more than once"),
    (["--knobs", "recursive", "recursive"], "knobs: ['recursive'] given more than once"),
], ids=["methods", "tolerances", "knobs"])
def test_cli_refuses_a_setting_given_twice(argv, message, capsys, tmp_path):
    """Passes if a method, tolerance or knob given twice is exit 2 naming it, before any run.
    Before, each such setting ran twice and its rows appeared twice in the table and the figure
    (as a repeated --grid value of projeq sweep, which is refused)."""
    assert projeq_main(["tradeoff", "chain", "--quick", "--set", "n=1", "--t-end", "0.1", *argv, "--out", str(tmp_path)]) == 2
    assert f"projeq tradeoff: {message}; each setting would run more than once" in capsys.readouterr().err


def test_cli_help_and_missing_scene(capsys):
    assert projeq_main(["tradeoff", "--help"]) == 0
    assert "--tolerances" in capsys.readouterr().out
    assert projeq_main(["tradeoff"]) == 2  # argparse names the missing SCENE
    assert "scene" in capsys.readouterr().err


def test_plot_returns_a_figure_with_one_line_per_method_and_knob():
    """Passes if the six successful settings are drawn and the two failed ones are counted by
    reason under the axis label (before, they were left out without a word; then named in a
    note over the lines); no text over the axes."""
    table = _constructed_table()
    fig = tr.plot(table)
    assert len(fig.axes[0].lines) == 6  # A, B, C, D, G, H succeeded; E, F failed and are not drawn
    label = "error\nnot drawn: 1 timeout, 1 diverged (of 9 settings; see the table)"
    assert fig.axes[0].get_xlabel() == label
    assert len(fig.axes[0].texts) == 0


def test_every_study_names_existing_knobs_and_scene_parameters():
    """The built-in studies are consistent with the scene registry: every quick knob is a
    knob and every fixed or varied parameter is accepted by the scene's build function."""
    import inspect

    from projeq.scenes import get_scene

    for name, study in STUDIES.items():
        assert study.scene == name and set(study.quick_knobs) <= {k.label for k in study.knobs}
        if name == "chain":  # a quick study runs no knob that is sure to be skipped
            assert "symbolic" not in study.quick_knobs or study.overrides["n"] <= SYMBOLIC_MAX_BODIES
        for knob in (*study.knobs, study.reference):
            inspect.signature(get_scene(name).build).bind(**study.overrides, **knob.overrides)


def test_a_custom_study_object_is_accepted():
    study = Study("chain", {"n": 1}, (Knob("recursive", evaluator="recursive"),), ("recursive",),
                  Knob("recursive", evaluator="recursive"), final_q, "q at t_end (rad)", t_end=0.3, quick_t_end=0.1,
                  reference_rtol=1e-12)
    table = tr.tradeoff(study, methods=["RK45"], quick=True)
    assert len(table["method"]) == len(tr.QUICK_TOLERANCES) and table["measure"] == "q at t_end (rad)"


@pytest.mark.parametrize("kwargs, name", [
    ({"methods": ["Euler"]}, "methods"),
    ({"tolerances": ["a"]}, "tolerances"),
    ({"tolerances": [0.0]}, "tolerances"),
    ({"knobs": []}, "methods, knobs"),
    ({"t_end": -1.0}, "t_end"),
    ({"timeout": 0.0}, "timeout"),
    ({"overrides": {"n_links": 3}}, "n_links"),
])
def test_bad_arguments_of_tradeoff_name_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        tr.tradeoff("chain", **{"methods": ["RK45"], "tolerances": [1e-3], "knobs": ["recursive"], "t_end": 0.1,
                                "overrides": {"n": 1}, **kwargs})


def test_projeq_integrators_are_studied_and_refused_where_they_do_not_apply():
    """The energy-projecting DOP853 (projeq.simulation.integrators) converges on the conservative
    pendulum like DOP853 (error within 100 rtol, as above); on Bremer's car pushed by a
    force f_x (energy not invariant) it is refused before the run: a 'skipped' row, while
    the other method still runs."""
    table = tr.tradeoff("chain", methods=["DOP853-projected"], tolerances=[1e-4, 1e-8], knobs=["recursive"],
                        overrides=PENDULUM, t_end=1.0)
    assert list(table["failure"]) == ["", ""] and np.all(table["error"] < 100 * table["rtol"])
    pushed_car = Study("car", {"f_x": 100.0}, (Knob("default"),), ("default",), Knob("default"), final_q,
                       "q at t_end (m, rad)", t_end=0.1, quick_t_end=0.1)
    table = tr.tradeoff(pushed_car, methods=["RK45-projected", "RK45"], tolerances=[1e-4])
    assert table["failure"][0].startswith("skipped: method: the projected integrators keep the energy constant")
    assert table["failure"][1] == ""
