"""projeq bench (issue 7, item 2): help, the quick chain part, the quick studies within the budget, one JSON document, bad input."""

import json
import time

import numpy as np

from projeq.assembly.kernels import has_numba
from projeq.cli.commands import main as projeq
from projeq.studies import bench
from projeq.studies.bench_derivation import derivation_effort

OURS = {"recursive", "dense"} | ({"fast"} if has_numba() else set())  # "fast" is the compiled kernel: numba


def test_help_describes_the_benchmarks(capsys):
    assert projeq(["bench", "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: projeq bench") and "--chain-only" in out and "--total" in out


def test_quick_chain_part_is_one_json_report_whose_evaluators_agree(capsys):
    """The chain part of ``projeq bench`` without peers, timed once (budget 0 s): its JSON
    report holds every evaluator at every size and their s̈ agree with the dense Gauss form
    (a second formulation of the same Projection Equation, docs/theory.md §5 vs §6). Tolerance
    6e-12 relative (was 1e-11): the two solutions differ by about cond(M)·ε (docs/theory.md, "Accuracy
    of the two evaluators"), measured 3.5e-13 at n = 10 (6e-13 on another machine: 10× the larger).
    Each row also holds every evaluator's
    deviation from the exact s̈ (projeq.studies.bench_exact); the order-n ones are within 10 n ε of
    it (the bound of tests/studies/test_chain_exact.py), the dense one within its 6e-12 above (measured
    3.4e-13)."""
    assert projeq(["bench", "--chain-only", "--no-peers", "--json", "--budget", "0", "--sizes", "2,10"]) == 0
    report = json.loads(capsys.readouterr().out)
    rows = report["chain_scaling"]["rows"]
    assert [r["n"] for r in rows] == [2, 10]
    for row in rows:
        assert set(row["seconds"]) == OURS and min(row["seconds"].values()) > 0
        assert max(row["deviation"].values()) < 6e-12, row["deviation"]
        exact = row["exact_deviation"]
        assert set(exact) == set(row["seconds"]) and row["exact_seconds"] > 0
        assert max(exact[k] for k in OURS - {"dense"}) < 10 * row["n"] * np.finfo(float).eps
        assert exact["dense"] < 6e-12, exact
    assert set(report["chain_scaling"]["slopes"]) == OURS
    assert [p["benchmark"] for p in report["parts"]] == ["chain_scaling"]
    assert report["total_seconds"] < report["budget_seconds"]


def test_table_ends_with_the_share_of_the_budget(capsys):
    assert projeq(["bench", "--chain-only", "--no-peers", "--budget", "0", "--sizes", "2"]) == 0
    out = capsys.readouterr().out
    assert "fast dev" in out and "fast vs exact" in out and "chain_scaling" in out and "of the 120 s budget" in out


def test_exact_comparison_is_skipped_above_its_limit(capsys):
    assert projeq(["bench", "--chain-only", "--no-peers", "--json", "--budget", "0", "--sizes", "2,3", "--exact-up-to", "2"]) == 0
    rows = json.loads(capsys.readouterr().out)["chain_scaling"]["rows"]
    assert ["exact_deviation" in r for r in rows] == [True, False]


def test_bad_sizes_exit_2_naming_the_option(capsys):
    assert projeq(["bench", "--sizes", "10,0"]) == 2
    assert "--sizes: expected chain lengths >= 1" in capsys.readouterr().err


def test_quick_studies_share_the_budget_and_report_their_status(monkeypatch, capsys):
    """Each quick study gets a deadline within the total budget; a study that stops at its
    deadline or fails makes the exit code 1 and its status says so, the others still run."""
    deadlines = []

    def finished(deadline, show):
        deadlines.append(deadline)
        show("a finished study")
        return {"rows": [1, 2]}, True

    def stopped(deadline, show):
        deadlines.append(deadline)
        return {"rows": [1]}, False

    def broken(deadline, show):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(bench, "QUICK_STUDIES", {"finished": finished, "stopped": stopped, "broken": broken})
    assert projeq(["bench", "--no-peers", "--json", "--budget", "0", "--sizes", "2", "--total", "60"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert [(p["benchmark"], p["status"].split(" ")[0]) for p in report["parts"]] == [
        ("chain_scaling", "ok"), ("finished", "ok"), ("stopped", "stopped"), ("broken", "failed:")]
    assert report["finished"] == {"rows": [1, 2]} and "ZeroDivisionError" in report["broken"]["traceback"]
    assert all(0 < d - time.perf_counter() < 60 for d in deadlines)


def test_derivation_study_agrees_with_kane_and_lagrange():
    """The derivation study of the package (no benchmarks/ needed): at N = 2 the Projection
    Equation's M and rhs equal those of sympy's KanesMethod and LagrangesMethod (independent
    derivations) at random states to round-off (measured 1.0e-15 relative)."""
    (row,) = derivation_effort((2,))
    assert row["N"] == 2 and row["max_rel_diff"] < 1e-14
    assert min(row[f"{m}_ops"] for m in ("projeq", "velocities", "kane", "lagrange")) > 0 and row["kane/projeq"] > 0


def test_quick_beam_study_stops_at_its_deadline():
    """A deadline already passed: the reference run and the evaluation costs, no setting."""
    report, complete = bench.quick_beam_convergence(deadline=0.0)
    assert not complete and report["rows"] == [] and report["cheapest_within_1e-4_m"] is None
    assert len(report["reference_tip_m"]) == 4 and set(report["evaluation_cpu_s"]) == {2, 4}
