"""The documentation builds (``mkdocs build --strict``: no broken link, nav entry or API
reference), every tutorial is backed by a script in examples/ that test_examples.py runs, and
the examples of docs/architecture.md run."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TUTORIALS = sorted((ROOT / "docs" / "tutorials").glob("*.md"))


def test_mkdocs_build_is_strictly_clean(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings")
    build = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                            str(ROOT / "mkdocs.yml"), "--site-dir", str(tmp_path / "site")],
                           cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stderr
    assert (tmp_path / "site" / "api" / "index.html").exists()


def test_every_tutorial_is_in_the_nav():
    nav = (ROOT / "mkdocs.yml").read_text()
    assert [p.name for p in TUTORIALS if f"tutorials/{p.name}" not in nav] == []


def test_every_example_belongs_to_a_tutorial():
    """One runnable script per tutorial: each example is named as a tutorial's script, and
    every script a tutorial names exists."""
    named = {m for p in TUTORIALS for m in re.findall(r"Script: `examples/(\w+\.py)`", p.read_text())}
    examples = {p.name for p in (ROOT / "examples").glob("*.py")}
    assert named == examples


def test_the_architecture_examples_run():
    """The python blocks of docs/architecture.md (a joint, a subsystem, a force law, each
    checked there against a closed form) run in order in one namespace."""
    blocks = re.findall(r"^```python\n(.*?)^```", (ROOT / "docs" / "architecture.md").read_text(), re.S | re.M)
    assert len(blocks) == 3
    namespace = {}
    for block in blocks:
        exec(compile(block, "docs/architecture.md", "exec"), namespace)


#: The numbered equations and worked examples of the five source documents (from the documents
#: themselves, not from docs/source_equations.py): each must be a row of docs/validation.md.
SOURCE_EQUATIONS = {
    'H. Bremer, "Problems in fast moving non-holonomic elastic systems"': [str(k) for k in range(1, 26)],
    "lecture on non-holonomic systems and Lagrange multipliers (Orsino 2020)": [str(k) for k in range(1, 27)],
    'A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems"': [
        str(k) for k in range(1, 117)],
    '"On derivation of motion equations for systems with non-holonomic high-order program constraints"': [
        "1", "1.1", "2", "2.1", "2.2a", "2.2", "3.1a", "3.1", "3.2", "4.1a", "4.1", "4.2", "4.3a", "4.3",
        *(f"5.{k}" for k in range(1, 10)), *(f"6.{k}" for k in range(1, 35)), "6.34a"],
    "problem seminars on Lagrange's equations (worked problems)": [
        *(f"Problem {k}"
          for k in (1, 2, 3, 4, 7, 8, 10, 11, 12, 14, 15, 16, 17, 19, 20, 23, 26, 27, 40, 41, 43, 44)),
        *(f"Seminar {k}" for k in (1, 2, 3, 4, 5, 6, 7, 10, 11)),
        *(f"Notes {k}" for k in ("I", "II", "III", "IV", "V", "VI", "VII"))],
}


def test_every_source_equation_has_a_validation_row():
    """docs/validation.md, "Source documents, equation by equation" (``python docs/gen_validation.py
    --equations``): one row per equation of SOURCE_EQUATIONS, with a test or a stated reason (never "no
    test cites it")."""
    text = (ROOT / "docs" / "validation.md").read_text()
    section = text.split("## Source documents, equation by equation")[1]
    rows = {}
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) == 4 and cells[0] not in ("document", "---"):
            rows[(cells[0], cells[1])] = cells[3]
    missing = [(d, n) for d, numbers in SOURCE_EQUATIONS.items() for n in numbers if (d, n) not in rows]
    assert missing == []
    assert [key for key, why in rows.items() if why.startswith("no test cites it")] == []
