"""projeq.studies.compare (projeq.compare): the comparison table of formulations (issue 5 item 6).

References: equal equations are checked symbolically (Hamel vs Projection Equation for the
car, B(8)–(9) of seed 004) or at random states; the simulations' energy is conserved for
these conservative systems (a conservation law) and the rolling constraints hold."""

import csv

import pytest

from projeq.cli import main as projeq
from projeq.studies.compare import COMPARISONS, ComparisonTable, compare


def _row(table, name):
    return next(r for r in table.rows if r["formulation"] == name)


@pytest.fixture(scope="module")
def car_table():
    return compare("car", t_end=0.2)


def test_registry_has_the_four_systems():
    assert {"car", "knife_edge_disc", "spinning_beam", "n_link_pendulum"} <= set(COMPARISONS)


def test_car_hamel_equals_projection_symbolically(car_table):
    """Hamel with v_y = 0 inserted after the derivation = B(9) (seed 004, THEORY §8)."""
    hamel = _row(car_table, "hamel")
    assert (hamel["identical"], hamel["check"]) == ("yes", "symbolic")
    assert hamel["n_ops"] > 0 and hamel["derivation_s"] > 0
    for name in ("projection (numeric, dense)", "projection (numeric, recursive)"):
        assert _row(car_table, name)["identical"] == "yes"


def test_car_simulations_conserve_energy_and_constraint(car_table):
    """No loads: kinetic energy constant; v_y = 0 exactly since it is built into K (B(6))."""
    for row in car_table.rows:
        assert row["energy_drift"] < 1e-7  # rtol 1e-9 per step over 0.2 s: ≪ 1e-7
        if "multipliers" in row["formulation"]:
            # constraint differentiated once (index 1): its drift is integration error, rtol 1e-9
            assert row["constraint_drift"] < 1e-9
        else:
            assert row["constraint_drift"] < 1e-12  # constraint in K: round-off only


def test_car_multiplier_forms_give_the_same_motion(car_table):
    """Lagrange and Hamilton canonical equations with a multiplier for −sin γ ẋ + cos γ ẏ = 0
    (seed 001, K(7), K(23)–(26)) and Barhorst's Lagrangian canonical form (seed 000, eqs.
    45–52, no multiplier) move the car as the Projection Equation's B(9) does."""
    for name in ("lagrange + multipliers", "hamilton canonical + multipliers", "barhorst lagrangian canonical"):
        row = _row(car_table, name)
        assert row["identical"] == "yes" and row["check"].startswith("numeric, same motion")


def test_pendulum_lagrange_equals_projection():
    """Lagrange's equations of the 2nd kind (an independent formulation) = the symbolic
    Projection Equation = projeq's numeric evaluators; energy conserved in the simulation."""
    table = compare("n_link_pendulum", t_end=0.1)
    for row in table.rows[1:]:
        assert row["identical"] == "yes", row
    for row in table.rows:
        assert row["energy_drift"] < 1e-7  # rtol 1e-9 over 0.1 s


def test_knife_edge_disc_formulations_agree(tmp_path):
    """The knife-edge disc (seed 001, slides 28–37): the symbolic Gauss form of the scene
    (``gauss_form``) and Hamel's equations B(3) with the rolling constraints as speeds inserted
    after the derivation (THEORY §8) equal the numeric evaluators at random states; the
    lecture's Lagrange equations with multipliers (K(7)), in (x, y, z, ψ, ϕ, θ), move the
    disc as the Projection Equation does; energy is conserved and the constraints hold."""
    # one multiplier form (all three share one code path; the car's table runs all three, the
    # disc's Hamilton and canonical forms are tested in tests/symbolic/test_lagrange.py, test_canonical.py)
    wanted = ["projection (numeric, dense)", "projection (symbolic)", "hamel", "lagrange + multipliers"]
    table = compare("knife_edge_disc", wanted, t_end=0.1)
    assert [r["formulation"] for r in table.rows] == wanted
    assert all(r["n_ops"] > 0 for r in table.rows[1:])
    for row in table.rows[1:]:
        assert row["identical"] == "yes", row
    for row in table.rows:
        assert row["energy_drift"] < 1e-7  # rtol 1e-9 per step over 0.1 s: ≪ 1e-7
        # rolling constraints in K: round-off; differentiated once (index 1): integration error at rtol 1e-9
        assert row["constraint_drift"] < (1e-9 if "multipliers" in row["formulation"] else 1e-12)
    path = tmp_path / "disc.csv"
    table.to_csv(path)
    with open(path) as handle:
        rows = list(csv.DictReader(handle))
    assert [r["identical"] for r in rows] == ["reference", "yes", "yes", "yes"]
    assert rows[2]["check"].startswith("numeric, 5 random states")


def test_spinning_beam_reports_the_difference():
    """Hamilton's B(18) ≠ the Projection Equation's B(23): only the ρI α̈ w″ term (THEORY §9)."""
    table = compare("spinning_beam", simulate=False)
    hamilton = _row(table, "hamilton (field equations, Ritz)")
    assert (hamilton["identical"], hamilton["check"]) == ("no", "symbolic")
    assert "rho_I" in hamilton["note"] and "w equations equal: True" in hamilton["note"]


def test_format_and_csv(car_table, tmp_path):
    text = car_table.format()
    assert "hamel" in text and "derivation_s" in text
    path = tmp_path / "car.csv"
    car_table.to_csv(path)
    with open(path) as handle:
        rows = list(csv.DictReader(handle))
    assert [r["formulation"] for r in rows] == [r["formulation"] for r in car_table.rows]


def test_main_writes_csv(tmp_path, capsys):
    path = tmp_path / "out.csv"
    assert projeq(["compare", "car", "--no-simulate", "--csv", str(path), "--formulation", "projection (symbolic)",
                   "--formulation", "hamel"]) == 0
    assert "hamel" in capsys.readouterr().out and path.exists()


def test_main_bad_formulation(capsys):
    assert projeq(["compare", "car", "--no-simulate", "--formulation", "bogus"]) == 2
    assert "projeq compare: formulations" in capsys.readouterr().err


def test_bad_name():
    with pytest.raises(ValueError, match="name"):
        compare("no_such_system")


def test_bad_t_end():
    with pytest.raises(ValueError, match="t_end"):
        compare("car", t_end=-1.0)


def test_bad_formulation():
    with pytest.raises(ValueError, match="formulations"):
        compare("car", formulations=["bogus"])


def test_table_is_a_plain_object():
    table = ComparisonTable("x", [{"formulation": "a", "n_ops": 3}])
    assert "a" in table.format() and table.rows[0]["n_ops"] == 3
