"""The table of a work-precision study: columns, CSV, the cheapest setting per error level,
text and figure.

A table is a dict of numpy arrays, one entry per column of :data:`COLUMNS` (one row per
setting), as returned by :func:`projeq.studies.tradeoff.tradeoff`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from projeq.studies.table import Table

ERROR_LEVELS = (1e-2, 1e-4, 1e-6, 1e-8)
COLUMNS = ("scene", "method", "rtol", "atol", "knob", "error", "cpu", "setup_cpu", "n_evaluations",
           "t_reached", "failure", "warning")
_TEXT = {"scene", "method", "knob", "failure", "warning"}
_INTEGER = {"n_evaluations"}


def _kind(name: str) -> type:
    """str, int or float: the type of column ``name``."""
    return str if name in _TEXT else (int if name in _INTEGER else float)


def columns(rows) -> dict:
    """Rows (dicts) to columns (numpy arrays, text as object arrays) in the order of :data:`COLUMNS`."""
    table = {}
    for name in COLUMNS:
        dtype = object if _kind(name) is str else _kind(name)
        table[name] = np.array([row[name] for row in rows], dtype=dtype).reshape(len(rows))
    return table


def save_csv(table: dict, path) -> Path:
    """Write the columns :data:`COLUMNS` of ``table`` as CSV (a header row, then one row per setting)."""
    return Table.from_columns({name: table[name].tolist() for name in COLUMNS}).to_csv(path)


def read_csv(path) -> dict:
    """The table written by :func:`save_csv` (columns of :data:`COLUMNS`)."""
    rows = Table.read_csv(path)
    return columns([{name: _kind(name)(row[name]) for name in COLUMNS} for row in rows])


def cheapest(table: dict, levels=ERROR_LEVELS) -> dict:
    """For each error level, the index of the cheapest (least CPU time) successful row that
    reaches the level reliably, or None when none does.

    Reliably: every successful row of the same integrator and knob at a tighter tolerance
    reaches the level too. A loose tolerance can land near the reference by a cancellation of
    errors (a 2-function beam at rtol 1e-3 closer than at 1e-9, whose error is the model's);
    such a row is no setting to recommend.
    """
    ok = (table["failure"] == "") & np.isfinite(table["error"])
    choice = {}
    for level in levels:
        reached = ok & (table["error"] <= level)
        reliable = [i for i in np.flatnonzero(reached) if _stays_below(table, ok, i, level)]
        choice[level] = min(reliable, key=lambda i: table["cpu"][i]) if reliable else None
    return choice


def _stays_below(table: dict, ok, i: int, level: float) -> bool:
    """Whether the successful rows of row i's integrator and knob at tighter tolerances reach ``level``."""
    tighter = ok & (table["method"] == table["method"][i]) & (table["knob"] == table["knob"][i]) & (
        table["rtol"] < table["rtol"][i])
    return bool(np.all(table["error"][tighter] <= level))


def _setting(table: dict, i: int) -> str:
    return f"{table['method'][i]} rtol={table['rtol'][i]:.0e} [{table['knob'][i]}]"


def format_table(table: dict, levels=ERROR_LEVELS, width: int | None = None) -> str:
    """The table as text (its free-text column cut to ``width`` characters per line, when
    given), followed by the cheapest setting for each error level."""
    notes = [failure or warning for failure, warning in zip(table["failure"], table["warning"])]
    text = Table.from_columns(
        {"knob": table["knob"], "method": table["method"], "rtol": table["rtol"], "error": table["error"],
         "cpu": table["cpu"], "evals": table["n_evaluations"], "failure / warning": notes},
        units={"cpu": "s"}, formats={"rtol": ".0e", "error": ".2e"},
    )
    lines = [text.to_text(width)]
    if "measure" in table:
        lines.append(f"error = {table['measure']}")
    for level, i in cheapest(table, levels).items():
        best = "no setting reaches it" if i is None else (
            f"{_setting(table, i)}: error {table['error'][i]:.2e}, {table['cpu'][i]:.3g} s CPU")
        lines.append(f"cheapest for error <= {level:.0e}: {best}")
    return "\n".join(lines)


def plot(table: dict):
    """Work-precision figure of the successful rows: CPU time over error, one line per
    (integrator, knob). An error of exactly 0 is drawn at a floor and circled
    (:func:`projeq.simulation.plots.work_precision`); the settings left out (failed, or no
    finite error) are counted by reason under the axis label (the table names each), not over
    the lines."""
    from projeq.simulation import plots

    drawn = (table["failure"] == "") & np.isfinite(table["error"])
    ok = np.flatnonzero(drawn)
    rows = [(f"{table['method'][i]} [{table['knob'][i]}]", table["error"][i], table["cpu"][i]) for i in ok]
    fig = plots.work_precision(rows, legend=False)
    ax = fig.axes[0]
    if not drawn.all():
        reasons = [(table["failure"][i] or "no finite error").split(":")[0] for i in np.flatnonzero(~drawn)]
        counted = ", ".join(f"{reasons.count(r)} {r}" for r in dict.fromkeys(reasons))
        ax.set_xlabel(f"{ax.get_xlabel()}\nnot drawn: {counted} (of {len(drawn)} settings; see the table)",
                      fontsize="small")
    methods, knobs = (list(dict.fromkeys(table[name][ok])) for name in ("method", "knob"))
    color = {method: f"C{i % 10}" for i, method in enumerate(methods)}
    style = {knob: dict(linestyle=("-", "--", ":", "-.")[k % 4], marker="os^vDP"[k % 6]) for k, knob in enumerate(knobs)}
    for line in ax.lines:  # colour by integrator, line style and marker by knob
        method, knob = line.get_label().split(" [", 1)
        line.set(color=color[method], **style[knob[:-1]])
    # two legends, integrators (colours) and knobs (styles): m + k entries instead of m · k
    from matplotlib.lines import Line2D

    fig.legend([Line2D([], [], color=c) for c in color.values()], list(color), fontsize="x-small",
               title="integrator", title_fontsize="x-small", loc="outside right upper")
    fig.legend([Line2D([], [], color="0.3", **s) for s in style.values()], list(style), fontsize="x-small",
               title="knob", title_fontsize="x-small", loc="outside right lower")
    ax.set_title(f"{table['scene'][0] if len(table['scene']) else ''}: {table.get('measure', 'error')}", fontsize="small")
    return fig

