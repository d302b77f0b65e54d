"""Citations a user can follow (issue 19, item 2): no reference to documents that projeq does
not ship (the source texts "seed 00x", "lecture 001", the design notes THEORY/VALIDATION/
ARCHITECTURE/STYLE.md, paths under ``shared/``). Publications are cited by the short keys of
the References section of docs/theory.md, the project's theory by its numbered sections.
"""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("projeq", "docs", "tests", "examples", "benchmarks")
UNSHIPPED = re.compile(
    r"seed 00\d|[Ss]eed [0-9]|seeds?/|seed's|the seeds\b|seed §|lecture 00\d|THEORY §|shared/"
    r"|\b(?:VALIDATION|ARCHITECTURE|STYLE|THEORY)\.md")
REFERENCES = ROOT / "docs" / "theory.md"


def scanned_files():
    """Every text file a user gets or reads: sources, docs, tests, examples, benchmarks."""
    yield ROOT / "README.md"
    for top in SCANNED:
        for path in sorted((ROOT / top).rglob("*")):
            if path.is_file() and path.suffix in (".py", ".md", ".txt", ".toml", ".yml") \
                    and path != Path(__file__).resolve():
                yield path


def test_the_pattern_catches_each_old_form():
    """The check can fail: each form that was in the tree before is caught."""
    for old in ("seed 003", "Seed 003, Seminar 5", "``seeds/001_…``", "../shared/seeds/003_1.txt",
                "lecture 001", "THEORY §6", "VALIDATION.md", "the seed's printed", "(seed §6.4)"):
        assert UNSHIPPED.search(old), old
    for fine in ("seed=3", "for seed in range(5)", "docs/theory.md §6", "Bremer (2009) eq. (23)"):
        assert not UNSHIPPED.search(fine), fine


def test_no_citation_of_unshipped_documents():
    hits = [f"{path.relative_to(ROOT)}:{number}: {line.strip()[:100]}"
            for path in scanned_files()
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
            if UNSHIPPED.search(line)]
    assert not hits, "cite publications or docs/theory.md sections instead:\n" + "\n".join(hits)


@pytest.mark.parametrize("section", range(1, 12))
def test_theory_sections_cited_in_the_code_exist(section):
    """"docs/theory.md §n" points at a numbered section with the anchor sn."""
    text = REFERENCES.read_text(encoding="utf-8")
    assert f'<a id="s{section}"></a>' in text
    assert re.search(rf"^## {section}\. ", text, re.MULTILINE)


def test_every_cited_key_is_in_the_references():
    """The short keys used in the code and docs each have an entry under References."""
    references = REFERENCES.read_text(encoding="utf-8").split("## References", 1)[1]
    for key in ("Bremer (2009)", "Bremer (2008)", "Barhorst", "Orsino (2020)",
                "Jarzębowska (2002)", "Lagrange seminars", "Blevins (1979)"):
        assert f"**{key}**" in references, key
