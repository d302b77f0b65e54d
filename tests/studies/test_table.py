"""projeq.studies.table.Table: the one CSV/text writer of compare, tradeoff, sweep and run."""

import math

import numpy as np
import pytest

from projeq.studies.table import Table


def test_csv_round_trips_numbers_bit_for_bit(tmp_path):
    values = [0.1 + 0.2, 1e-300, -2.5e17, math.pi, float("nan"), float("inf")]
    path = Table(("x", "n"), [(v, i) for i, v in enumerate(values)]).to_csv(tmp_path / "t.csv")
    rows = Table.read_csv(path)
    assert [float(r["x"]) for r in rows][:4] == values[:4]
    assert math.isnan(float(rows[4]["x"])) and float(rows[5]["x"]) == math.inf
    assert [int(r["n"]) for r in rows] == list(range(6))
    np.testing.assert_array_equal(np.loadtxt(path, delimiter=",", skiprows=1)[:4, 0], values[:4])


def test_a_multi_line_message_stays_one_csv_row(tmp_path):
    path = Table(("status", "error"), [("failed", "line one\nline two, with a comma"), ("ok", None)]).to_csv(
        tmp_path / "t.csv")
    assert len(path.read_text().splitlines()) == 3
    assert Table.read_csv(path) == [{"status": "failed", "error": "line one line two, with a comma"},
                                    {"status": "ok", "error": ""}]


def test_text_shows_units_and_formats():
    text = Table(("knob", "cpu", "error"), [("a", 0.123456, 1.5e-7), ("bb", 12.0, None)],
                 units={"cpu": "s"}, formats={"error": ".2e"}, title="study").to_text()
    lines = text.splitlines()
    assert lines[0] == "study" and lines[1].split() == ["knob", "cpu", "(s)", "error"]
    assert "0.123" in lines[3] and "1.50e-07" in lines[3] and "—" in lines[4]


@pytest.mark.parametrize("build, words", [
    (lambda: Table(("a", "b"), [(1,)]), ["rows", "row 0", "1 cells", "expected 2"]),
    (lambda: Table(("a",), [], units={"z": "m"}), ["units", "unknown columns", "'z'"]),
    (lambda: Table.from_columns({"a": [1, 2], "b": [1]}), ["columns", "same length"]),
])
def test_bad_tables_are_refused(build, words):
    with pytest.raises(ValueError) as error:
        build()
    assert all(w in str(error.value) for w in words)
