"""Every script in examples/ runs (quickly, PROJEQ_QUICK=1) and checks a physical fact.

Each example asserts its own fact with its provenance in its docstring (a closed form from
the literature or tables, a second formulation, or a conservation law); an example that leaves
a ``result`` of a conservative scene is also checked for energy conservation here.
"""

import runpy
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PROJEQ_QUICK", "1")
    namespace = runpy.run_path(str(path), run_name="__main__")
    result = namespace.get("result")
    if result is not None:
        # a conservative scene integrated at rtol 1e-10: energy is conserved far below 1e-6
        assert result.energy_drift < 1e-6
