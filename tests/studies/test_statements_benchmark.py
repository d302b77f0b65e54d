"""benchmarks/statements.py runs in its quick mode (so it cannot rot), and what it checks holds: a
joint and a force law stated once in a file outside the package run compiled by default with no warning
and equal the recursive evaluator; the joint has its symbolic Gauss form and exact Jacobian."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "statements.py"


def test_the_quick_mode_runs_and_the_stated_plug_ins_are_compiled(capsys):
    pytest.importorskip("numba")
    spec = importlib.util.spec_from_file_location("statements_benchmark", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    found = module.main(["--quick"])
    assert found["evaluator"] == "fast" and found["in Python"] == []
    eps = np.finfo(float).eps  # bounds 100 ε (were 1e-12, 500-1400 times the errors)
    assert found["compiled vs recursive"] <= 100 * eps, found  # measured 6.9e-16 on a chain of three
    assert found["gauss_form vs recursive (N = 2)"] <= 100 * eps, found  # measured 1.8e-15
    assert found["Jacobian"] == "exact"
    assert found["drag in Python"] == [] and found["drag compiled vs recursive"] <= 100 * eps, found  # measured 1.9e-15
    assert len(found["ratios"]) == 2 and "median ratio" in capsys.readouterr().out


def test_code_size_counts_code_lines_only(tmp_path, capsys):
    """benchmarks/code_size.py counts the lines that hold code (a docstring, comments and blank lines
    left out) and prints both lists with their ratio."""
    spec = importlib.util.spec_from_file_location("code_size", SCRIPT.parent / "code_size.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sample = tmp_path / "sample.py"
    sample.write_text('"""A module\ndocstring."""\n\n# a comment\ndef f(x):\n    """Its docstring."""\n'
                      '    return (x +  # a trailing comment\n            1)\n')
    assert module.code_lines(sample) == 3
    report = module.main(["--json"])
    assert report["totals"]["compiled"] > 0 and report["ratio"] == report["totals"]["compiled"] / report["totals"]["interpreted"]
