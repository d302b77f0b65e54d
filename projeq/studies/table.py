"""One table type for every table projeq writes: columns, rows and units, as CSV and as text.

``projeq compare`` (:class:`~projeq.studies.compare.ComparisonTable`), ``projeq tradeoff``
(:mod:`~projeq.studies.tradeoff_table`), ``projeq sweep``
(:meth:`~projeq.simulation.sweep.SweepTable.save`) and ``projeq run`` (the time history)
all write through :class:`Table`, so their files follow one convention:

- CSV: a header line of the column names, then one line per row. Numbers are written
  unquoted and exactly (floats as their shortest round-trip repr, so ``float(cell)`` gives
  the number back bit for bit; ``nan`` and ``inf`` as such), an empty cell is ``None``;
  text is quoted by the rules of :mod:`csv` where it holds a comma or a quote, and line
  breaks inside a cell become spaces, so every row is one line (``np.loadtxt``,
  ``np.genfromtxt`` and spreadsheets read it).
- Text: an optional title, a header of the column names with their units in parentheses,
  a rule, then the rows; every column as wide as its widest cell, numbers right-aligned
  with the column's format (default 3 significant digits), text left-aligned, ``—`` for
  an empty cell.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

_NUMBER = (int, float, np.integer, np.floating)


def _is_number(value) -> bool:
    return isinstance(value, _NUMBER) and not isinstance(value, (bool, np.bool_))


def _one_line(text: str) -> str:
    return " ".join(str(text).splitlines())


def _csv_cell(value) -> str:
    """A cell as CSV text: numbers exactly, ``None`` empty, anything else as one line of text."""
    if value is None:
        return ""
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if _is_number(value):
        return str(int(value))
    return _one_line(value)


def csv_cells(row) -> list[str]:
    """The cells of one row as :meth:`Table.to_csv` writes them (before CSV quoting)."""
    return [_csv_cell(value) for value in row]


def csv_line(row) -> str:
    """One row as the newline-terminated CSV line :meth:`Table.to_csv` writes, for a file
    appended to row by row (:func:`projeq.simulation.sweep.sweep` with ``path``)."""
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerow(csv_cells(row))
    return stream.getvalue()


@dataclass(frozen=True)
class Table:
    """Rows of cells under named columns (see the module docstring for the two formats).

    Parameters
    ----------
    columns : sequence of str
        Column names (the CSV header).
    rows : sequence of sequences
        One sequence of cells per row, in the order of ``columns``: numbers, text or ``None``.
    units : dict, optional
        Unit of a column (``{"cpu": "s"}``), shown in the text header as ``cpu (s)``.
    formats : dict, optional
        Format spec of a numeric column in the text (``{"error": ".2e"}``; default ``.3g``
        for floats, integers as they are).
    title : str, optional
        First line of the text.
    """

    columns: tuple
    rows: list
    units: dict = field(default_factory=dict)
    formats: dict = field(default_factory=dict)
    title: str = ""

    def __post_init__(self):
        object.__setattr__(self, "columns", tuple(self.columns))
        object.__setattr__(self, "rows", [tuple(row) for row in self.rows])
        for i, row in enumerate(self.rows):
            if len(row) != len(self.columns):
                raise ValueError(f"rows: row {i} has {len(row)} cells, expected {len(self.columns)} "
                                 f"(columns {list(self.columns)})")
        for what, mapping in (("units", self.units), ("formats", self.formats)):
            unknown = sorted(set(mapping) - set(self.columns))
            if unknown:
                raise ValueError(f"{what}: unknown columns {unknown}; the columns are {list(self.columns)}")

    @classmethod
    def from_columns(cls, columns: dict, **options) -> Table:
        """A table from ``{name: sequence of cells}`` (all of the same length)."""
        lengths = {name: len(cells) for name, cells in columns.items()}
        if len(set(lengths.values())) > 1:
            raise ValueError(f"columns: all columns must have the same length, got {lengths}")
        return cls(tuple(columns), list(zip(*columns.values())), **options)

    def to_csv(self, path) -> Path:
        """Write the table as CSV to ``path``; returns the path."""
        path = Path(path)
        with path.open("w", newline="") as stream:
            writer = csv.writer(stream, lineterminator="\n")
            writer.writerow(self.columns)
            writer.writerows([_csv_cell(value) for value in row] for row in self.rows)
        return path

    @staticmethod
    def read_csv(path) -> list[dict]:
        """The rows of a CSV file written by :meth:`to_csv`, as dicts of text cells by column name."""
        with Path(path).open(newline="") as stream:
            return list(csv.DictReader(stream))

    def to_text(self, max_width: int | None = None) -> str:
        """The table as aligned plain text; with ``max_width`` the last column of text (not
        numbers) is cut, with …, so that the lines fit ``max_width`` characters."""
        header = [f"{name} ({self.units[name]})" if self.units.get(name) else name for name in self.columns]
        cells = [[self._text_cell(name, value) for name, value in zip(self.columns, row)] for row in self.rows]
        numeric = [all(_is_number(row[k]) for row in self.rows if row[k] is not None) and
                   any(row[k] is not None for row in self.rows) for k in range(len(self.columns))]
        widths = [max([len(header[k])] + [len(row[k]) for row in cells]) for k in range(len(self.columns))]
        text_columns = [k for k in range(len(self.columns)) if not numeric[k]]
        excess = sum(widths) + 2 * (len(widths) - 1) - (max_width or 0)
        if max_width and excess > 0 and text_columns:
            k = text_columns[-1]
            widths[k] = max(len(header[k]), widths[k] - excess)
            for row in cells:
                row[k] = row[k] if len(row[k]) <= widths[k] else row[k][: widths[k] - 1] + "…"

        def line(texts):
            return "  ".join(t.rjust(w) if right else t.ljust(w) for t, w, right in zip(texts, widths, numeric)).rstrip()

        lines = [line(header), "  ".join("-" * w for w in widths)] + [line(row) for row in cells]
        return "\n".join(([self.title] if self.title else []) + lines)

    def _text_cell(self, name: str, value) -> str:
        if value is None:
            return "—"
        if _is_number(value):
            spec = self.formats.get(name, ".3g" if isinstance(value, (float, np.floating)) else "")
            return format(value, spec)
        return _one_line(value)
