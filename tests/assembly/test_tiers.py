"""The default evaluator's first tier (projeq/assembly/auto.py, projeq/assembly/compilation.py):
while the compiled kernels are not in numba's cache, the reference evaluators run, until a
budget of interpreted CPU is spent (counted over the runs of one cache), then the kernels compile.

tests/conftest.py sets ``PROJEQ_COMPILE=now`` for the rest of the suite; these tests unset it."""

import json
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import compilation
from projeq.assembly.auto import Tier

pytest.importorskip("numba")

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def budget(monkeypatch, tmp_path):
    """A fresh budget of 0.05 s whose ledger is a file of tmp_path; the tier policy on."""
    monkeypatch.delenv("PROJEQ_COMPILE", raising=False)
    monkeypatch.setattr(compilation, "BUDGET", 0.05)
    monkeypatch.setattr(compilation, "_BUDGET", compilation._Budget())
    monkeypatch.setattr(compilation, "_ledger", lambda: tmp_path / "projeq-interpreted-seconds")
    return tmp_path / "projeq-interpreted-seconds"


class _Kernel:
    """A compiled method whose kernel numba has not compiled until it is called outside cached_only."""

    def __init__(self):
        self.compiled, self.calls = False, 0

    def __call__(self, x):
        if not self.compiled and compilation._ANNOUNCER.deferring.on:
            raise compilation.NotCompiled("kernel")
        self.compiled, self.calls = True, self.calls + 1
        return 2.0 * x


def _interpreted(x):
    """The same result, slowly: 10 ms of CPU."""
    started = time.process_time()
    while time.process_time() - started < 0.01:
        pass
    return 2.0 * x


def test_a_tier_is_interpreted_until_the_budget_is_spent_then_compiled(budget, capsys):
    kernel = _Kernel()
    tier = Tier(kernel, _interpreted, "the model", 0)
    values = [tier(np.array([1.5])) for _ in range(4)]  # 40 ms of the 50 ms budget
    assert kernel.calls == 0 and tier.deferred == {"f"} and compilation._BUDGET.spent >= 0.04
    while kernel.calls == 0:  # the call after the budget is spent compiles
        values.append(tier(np.array([1.5])))
    assert 5 <= len(values) <= 8 and all(v[0] == 3.0 for v in values)  # 5 or 6 at 10 ms a call
    assert tier.ready == {"f"} and not tier.deferred
    tier(np.array([1.5]))
    assert kernel.calls == 2  # called directly from now on
    assert tier(np.array([1j]))[0] == 2j  # complex: numba's other specialization, compiled too (budget spent)
    said = capsys.readouterr().err
    assert said.count("projeq: the model's compiled kernels are not in numba's cache") == 1
    compilation._BUDGET.save()
    assert float(budget.read_text()) == pytest.approx(compilation._BUDGET.spent, abs=1e-3)


def test_the_budget_counts_over_the_runs_of_one_cache(budget):
    budget.write_text("0.06\n")  # earlier runs of this cache spent the budget
    kernel = _Kernel()
    tier = Tier(kernel, _interpreted, "the model", 0)
    assert tier(np.array([1.0]))[0] == 2.0 and kernel.calls == 1  # compiled at once
    budget.write_text("not a number")
    compilation._BUDGET.before = None
    assert compilation._BUDGET.total() == compilation._BUDGET.spent  # a damaged ledger: a new budget


def test_the_ledger_makes_its_folders_on_a_new_cache(budget, monkeypatch):
    """A first run on a new NUMBA_CACHE_DIR spends interpreted seconds before numba has made its cache
    folder (nothing compiled yet): saving them makes the folder, parents included, so that the next run
    of that cache counts them (a mutant that made the last folder alone survived every other test:
    issue 37, item 8)."""
    ledger = budget.parent / "new" / "numba cache" / budget.name
    monkeypatch.setattr(compilation, "_ledger", lambda: ledger)
    compilation.spend(0.02, "the model")
    compilation._BUDGET.save()
    assert float(ledger.read_text()) == 0.02


def test_a_kernel_in_numba_cache_runs_at_once(budget):
    kernel = _Kernel()
    kernel.compiled = True  # as if loaded from the disk cache
    tier = Tier(kernel, _interpreted, "the model", 0)
    assert tier(np.array([1.0]))[0] == 2.0 and kernel.calls == 1 and tier.ready == {"f"}
    assert compilation._BUDGET.spent == 0.0


def test_cached_only_refuses_a_projeq_kernel_numba_would_compile(tmp_path, monkeypatch):
    name = f"projeq_generated_tier_probe_{os.getpid()}"
    (tmp_path / f"{name}.py").write_text("import numba\n\n@numba.njit\ndef twice(x):\n    return 2.0 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    probe = __import__(name)
    with pytest.raises(compilation.NotCompiled, match="twice"), compilation.cached_only():
        probe.twice(1.5)
    assert not probe.twice.signatures  # nothing compiled
    assert probe.twice(1.5) == 3.0  # compiles
    with compilation.cached_only():
        assert probe.twice(2.5) == 5.0  # compiled: runs
    assert compilation._ANNOUNCER.depth == 0


RUN = textwrap.dedent("""
    import json
    import projeq as pq
    system = pq.scenes.double_pendulum()
    result = pq.simulate(system, t_end=2.0, method="DOP853", rtol=1e-10, atol=1e-12)
    print(json.dumps({"q": list(result.q[-1]), "s_dot": list(result.s_dot[-1]),
                      "interpreting": system.evaluator(None).interpreting, "reason": system.evaluator(None).reason}))
""")


def test_a_new_cache_runs_the_default_evaluator_interpreted(tmp_path):
    """README's case: a short run on an empty numba cache compiles nothing and gives the compiled
    evaluator's result (measured in-process, recursive against fast: 7.3e-13 in q, 9.0e-12 in ṡ after
    2 s, DOP853 at rtol 1e-10, the same 1190 evaluations: the two evaluators' round-off, grown by the
    double pendulum's chaos; bounds 10×)."""
    env = {k: v for k, v in os.environ.items() if k != "PROJEQ_COMPILE"}
    env.update(NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(ROOT))
    run = subprocess.run([sys.executable, "-c", RUN], env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "evaluating it interpreted" in run.stderr and "projeq: compiling" not in run.stderr, run.stderr
    ledger, = tmp_path.rglob("projeq-interpreted-seconds")  # beside the cache's entries of compilation.py's folder
    spent = float(ledger.read_text())
    assert 0.0 < spent < compilation.BUDGET
    child = json.loads(run.stdout)
    assert child["interpreting"] and child["reason"].endswith("interpreted by the reference evaluator until its "
                                                              "kernels are compiled")
    system = pq.scenes.double_pendulum()
    compiled = pq.simulate(system, t_end=2.0, method="DOP853", rtol=1e-10, atol=1e-12, evaluator="fast")
    assert np.abs(np.array(child["q"]) - compiled.q[-1]).max() < 7.3e-12
    assert np.abs(np.array(child["s_dot"]) - compiled.s_dot[-1]).max() < 9e-11


LOOP_RUN = textwrap.dedent("""
    import json, time
    import projeq as pq
    system = pq.scenes.four_bar()
    result = pq.simulate(system, t_end=2.0)
    print(json.dumps({"q": list(result.q[-1]), "s_dot": list(result.s_dot[-1]), "nfev": int(result.nfev),
                      "cpu": time.process_time()}))
""")


def test_a_new_cache_runs_a_closed_loop_by_its_numpy_path(tmp_path):
    """A closed loop's first run on an empty numba cache compiles none of projeq's kernels (the
    closure's, the tree's Gauss form, the loop: :class:`projeq.constraints.compiled.Deferred`, the
    tree's ``gauss_form`` tier), only the user's Φ for its callback, and gives the compiled kernel's
    result: measured 4.6–5.8 s of process CPU for the four-bar over 2 s at the defaults (95 s when the
    closure kernels compiled at first use), the same 1245 evaluations. (At rtol 1e-10 the run spends the
    10 s budget and compiles, as it should.)"""
    env = {k: v for k, v in os.environ.items() if k != "PROJEQ_COMPILE"}
    env.update(NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(ROOT))
    run = subprocess.run([sys.executable, "-c", LOOP_RUN], env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "the closed loop's compiled kernels are not in numba's cache" in run.stderr, run.stderr
    assert "compiled partitioned" not in run.stderr and "compiled chain_terms" not in run.stderr, run.stderr
    child = json.loads(run.stdout)
    assert child["cpu"] < 10.0, child["cpu"]  # the cold-start bound of README's commands
    compiled = pq.simulate(pq.scenes.four_bar(), t_end=2.0)
    assert child["nfev"] == compiled.nfev
    # the numpy path's round-off against the kernel's, through 1311 RK45 evaluations: measured 1.1e-12 in q
    # (|q| ≤ 1.9), 1.7e-12 in ṡ (|ṡ| = 5.3); bounds 10×
    assert np.abs(np.array(child["q"]) - compiled.q[-1]).max() < 1.1e-11, np.array(child["q"]) - compiled.q[-1]
    assert np.abs(np.array(child["s_dot"]) - compiled.s_dot[-1]).max() < 1.7e-11


def test_a_closed_loops_stand_in_spends_the_cpu_between_its_calls_less_compiling(budget, monkeypatch):
    """:class:`projeq.constraints.compiled.Deferred` flags NOT_COMPILED and spends the CPU since its last
    call from the budget, less the CPU that compiling other kernels took meanwhile (which would
    otherwise spend the budget at once: the cut joints' rows compile at first use)."""
    from projeq.constraints.compiled import NOT_COMPILED, Deferred

    compiling = [0.0]
    monkeypatch.setattr(compilation, "compiling_seconds", lambda: compiling[0])
    stand_in = Deferred()
    assert stand_in() == NOT_COMPILED and compilation._BUDGET.spent == 0.0  # the clock starts
    _interpreted(1.0), _interpreted(1.0), _interpreted(1.0)  # 30 ms of CPU
    compiling[0] += 0.02  # 20 ms of it "compiling"
    assert stand_in() == NOT_COMPILED
    assert 0.005 < compilation._BUDGET.spent < 0.02, compilation._BUDGET.spent
