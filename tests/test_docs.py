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
