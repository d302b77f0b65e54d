"""projeq bench (issue 7, item 2): help, the quick chain part, one JSON document, bad input."""

import json

import numpy as np
import pytest

from projeq.assembly.kernels import has_numba
from projeq.studies.bench import main
from projeq.cli.commands import main as projeq

OURS = {"recursive", "dense"} | ({"fast"} if has_numba() else set())  # "fast" is the compiled kernel: numba


def test_help_describes_the_benchmarks(capsys):
    with pytest.raises(SystemExit) as exit_:
        projeq(["bench", "--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: projeq bench") and "--chain-only" in out and "--total" in out


def test_quick_chain_part_is_one_json_report_whose_evaluators_agree(capsys):
    """The chain part of ``projeq bench`` without peers, timed once (budget 0 s): its JSON
    report holds every evaluator at every size and their s̈ agree with the dense Gauss form
    (a second formulation of the same Projection Equation, THEORY §5 vs §6). Tolerance
    1e-11 relative: the two solutions differ by about cond(M)·ε (docs/theory.md, "Accuracy
    of the two evaluators"), measured 6e-13 at n = 10. Each row also holds every evaluator's
    deviation from the exact s̈ (projeq.studies.bench_exact); the order-n ones are within 10 n ε of
    it (the bound of tests/studies/test_chain_exact.py), the dense one within its 1e-11 above."""
    assert main(["--chain-only", "--no-peers", "--json", "--budget", "0", "--sizes", "2,10"]) == 0
    report = json.loads(capsys.readouterr().out)
    rows = report["chain_scaling"]["rows"]
    assert [r["n"] for r in rows] == [2, 10]
    for row in rows:
        assert set(row["seconds"]) == OURS and min(row["seconds"].values()) > 0
        assert max(row["deviation"].values()) < 1e-11
        exact = row["exact_deviation"]
        assert set(exact) == set(row["seconds"]) and row["exact_seconds"] > 0
        assert max(exact[k] for k in OURS - {"dense"}) < 10 * row["n"] * np.finfo(float).eps and exact["dense"] < 1e-11
    assert set(report["chain_scaling"]["slopes"]) == OURS
    assert [p["benchmark"] for p in report["parts"]] == ["chain_scaling"]
    assert report["total_seconds"] < report["budget_seconds"]


def test_table_ends_with_the_share_of_the_budget(capsys):
    assert main(["--chain-only", "--no-peers", "--budget", "0", "--sizes", "2"]) == 0
    out = capsys.readouterr().out
    assert "fast dev" in out and "fast vs exact" in out and "chain_scaling" in out and "of the 120 s budget" in out


def test_exact_comparison_is_skipped_above_its_limit(capsys):
    assert main(["--chain-only", "--no-peers", "--json", "--budget", "0", "--sizes", "2,3", "--exact-up-to", "2"]) == 0
    rows = json.loads(capsys.readouterr().out)["chain_scaling"]["rows"]
    assert ["exact_deviation" in r for r in rows] == [True, False]


def test_bad_sizes_exit_2_naming_the_option(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--sizes", "10,0"])
    assert exit_.value.code == 2 and "--sizes: expected chain lengths >= 1" in capsys.readouterr().err
