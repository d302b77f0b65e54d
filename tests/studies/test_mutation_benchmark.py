"""benchmarks/mutation.py's quick mode (issue 37, item 8): three mutants of projeq/assembly/linalg.py
drawn, run against tests/assembly/test_linalg.py in a copy of the source, recorded in cosmic-ray's
session database; the package itself is never touched.

The 200-mutant sample's survivors, and the tests that kill them, are in CHANGELOG.md (issue 37).
"""

import hashlib
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("cosmic_ray", reason="cosmic-ray (in projeq[test]) runs the mutants")


def load():
    spec = importlib.util.spec_from_file_location("benchmark_mutation", ROOT / "benchmarks" / "mutation.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_quick_mode_runs_three_mutants_in_a_copy(tmp_path, capsys):
    mutation = load()
    target = ROOT / "projeq" / "assembly" / "linalg.py"
    before = digest(target)
    counts = mutation.main(["--quick", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert digest(target) == before, "the package's own source was mutated"
    assert sum(counts["assembly"].values()) == 3 and set(counts["assembly"]) <= {"killed", "survived", "not run"}, counts
    # the tests ran against the mutated copy, not the installed package: some mutant dies (3 of 3 measured:
    # a pivot threshold and two comparisons of solve_spd, each caught by tests/assembly/test_linalg.py)
    assert counts["assembly"].get("killed", 0) >= 1, counts
    assert "3 drawn (seed=37)" in out and "[3/3]" in out and (tmp_path / "survivors.md").exists()
    from cosmic_ray.work_db import WorkDB, use_db

    with use_db(tmp_path / "session.sqlite", WorkDB.Mode.open) as db:
        assert db.num_results == 3 and not db.pending_work_items
    again = mutation.main(["--quick", "--out", str(tmp_path)])
    assert again == counts and "3 of 3 mutants done, 0 to run" in capsys.readouterr().out


def test_a_session_with_other_settings_is_refused(tmp_path):
    (tmp_path / "settings.json").write_text('{"mutants": 9}')
    with pytest.raises(SystemExit, match="other settings"):
        load().main(["--quick", "--out", str(tmp_path)])
