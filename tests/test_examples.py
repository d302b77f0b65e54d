"""Every script in examples/ runs (quickly, PROJEQ_QUICK=1) and checks a physical fact.

Each example asserts its own fact with its provenance in its docstring (a closed form from
the literature or tables, a second formulation, or a conservation law); an example that leaves
a ``result`` of a conservative scene is also checked for energy conservation here, to 10 × the largest
drift measured in quick mode at the example's tolerance and at twice and half of it (or 100 ε).
"""

import runpy
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))
# relative energy drift of each example's ``result`` (quick mode): measured at its rtol, 2 rtol, rtol / 2
ENERGY_DRIFT = {
    "chain": 1.6e-12,  # 1.4e-13 (1.6e-13, 6.5e-14); DOP853 at rtol 1e-10
    "constraints": 8.4e-10,  # the four-bar: 4.1e-11 (8.4e-11, 2.5e-11); rtol 1e-10
    "flexible_arm": 100 * np.finfo(float).eps,  # 1.8e-15 (1.2e-15, 1.1e-15); DOP853 at rtol 1e-8 over 0.1 s
    "vehicle": 1.2e-12,  # 5.7e-14 (1.2e-13, 2.9e-14); DOP853 at rtol 1e-10
}


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PROJEQ_QUICK", "1")
    namespace = runpy.run_path(str(path), run_name="__main__")
    result = namespace.get("result")
    if result is not None:
        # a conservative scene: its drift at most 10× the measured (all were below 1e-6 before)
        assert path.stem in ENERGY_DRIFT, f"{path.stem}: state its measured energy drift in ENERGY_DRIFT"
        assert result.energy_drift < ENERGY_DRIFT[path.stem], result.energy_drift
