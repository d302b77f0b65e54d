"""benchmarks/statements.py runs in its quick mode (so it cannot rot), and what it checks holds: a
joint stated once in a file outside the package runs compiled by default with no warning, equals
the recursive evaluator, and has its symbolic Gauss form and exact Jacobian."""

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "statements.py"


def test_the_quick_mode_runs_and_the_helical_joint_is_compiled(capsys):
    pytest.importorskip("numba")
    spec = importlib.util.spec_from_file_location("statements_benchmark", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    found = module.main(["--quick"])
    assert found["evaluator"] == "fast" and found["in Python"] == []
    assert found["compiled vs recursive"] <= 1e-12  # measured 1e-16 on a chain of three
    assert found["gauss_form vs recursive (N = 2)"] <= 1e-12  # measured 4e-16
    assert found["Jacobian"] == "exact"
    assert len(found["ratios"]) == 2 and "median ratio" in capsys.readouterr().out
