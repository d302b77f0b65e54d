"""benchmarks/iftomm.py runs in its quick mode (so it cannot rot): every table prints."""

import importlib.util
from pathlib import Path


def test_the_quick_mode_prints_every_table(capsys):
    path = Path(__file__).parents[2] / "benchmarks" / "iftomm.py"
    spec = importlib.util.spec_from_file_location("iftomm_benchmark", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(["--quick"])
    out = capsys.readouterr().out
    for heading in ("IFToMM problems", "against the published reference files", "the formulations",
                    "B0 position error by rtol", "partitioned against null space", "A05 stiff flyball governor"):
        assert heading in out, heading
    assert "stopped" not in out.split("the formulations")[1].split("auto")[1].splitlines()[0]
