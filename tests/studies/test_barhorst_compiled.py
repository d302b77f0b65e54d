"""Barhorst's formulation study with generated right-hand sides (A. A. Barhorst, "Generalized momenta in
constrained non-holonomic systems — another perspective on the canonical equations of motion", §3.1):
benchmarks/barhorst_compiled.py in its quick mode (the particle, 1 s, the generated code run by numpy,
no numba compilation). The reference: the four formulations — Hamilton's canonical DAE in (q, p, λ), the
projective (Kane) form in (q, u) and the two canonical forms in (q, p) — are different equations, each
printed from its own derivation, and must give the same motion."""

import runpy
from pathlib import Path

import pytest

from projeq.studies.barhorst_compiled import compiled_study


def test_quick_mode_the_four_generated_formulations_give_one_motion():
    """End positions within 3e-10 of Hamilton's DAE (both at rtol 1e-8; measured 2.9e-11 over 1 s, was
    1e-7); every ODE form also run by DOP853, the DAE not; Barhorst's ratio beside each row."""
    benchmark = runpy.run_path(str(Path(__file__).parents[2] / "benchmarks" / "barhorst_compiled.py"))
    (rows,) = benchmark["main"](["--quick"]).values()
    assert [r["formulation"] for r in rows] == list(benchmark["PAPER"]["barhorst_particle"])
    assert all(r["gap"] < 3e-10 for r in rows), [r["gap"] for r in rows]
    assert rows[0]["dop853_s"] is None and all(r["dop853_s"] > 0 for r in rows[1:])
    assert rows[0]["radau_ratio"] == 1.0 and all(r["paper"] for r in rows)


def test_bad_input():
    with pytest.raises(ValueError, match="study"):
        compiled_study("pendulum")
    with pytest.raises(ValueError, match="t_end"):
        compiled_study("barhorst_particle", t_end=0.0)
    with pytest.raises(ValueError, match="formulations"):
        compiled_study("barhorst_particle", formulations=["euler"], compile=False)
