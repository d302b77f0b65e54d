"""Figures of simulation results (matplotlib, Agg backend: works without a display).

Every function returns a :class:`matplotlib.figure.Figure` (not shown; save it with
``fig.savefig(path)``). The plotted line data are the result's own arrays.
"""

from __future__ import annotations

import numpy as np


ROUND_OFF = 1e-16  # the lowest constraint residual shown: below it is round-off


def _figure(rows: int = 1, width: float = 7.0):
    from matplotlib.figure import Figure  # a Figure without pyplot: no GUI backend, no global state

    fig = Figure(figsize=(width, 2.6 * rows + 0.8), layout="constrained")
    return fig, fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]


def _legend_outside(ax) -> None:
    """The legend right of the axes, where it hides no data."""
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def _check_rows(result) -> None:
    """A result with at least one output row (a run stopped in its first segment has none)."""
    if not len(result.t):
        raise ValueError(f"result: has no output rows (status {result.status}: {result.message!r}); nothing to plot")


def time_history(result, names=None):
    """q(t) (top) and ṡ(t) (bottom), each line labelled by its name (``names`` for q, default
    the result's, :meth:`projeq.Result.column_names`); :func:`grouped_history` separates
    angles, translations and elastic coordinates."""
    q_names, s_names = result.column_names(units=True)
    if names is not None and len(names) != len(q_names):  # labels by position: fewer would drop columns
        raise ValueError(f"names: expected {len(q_names)} labels, one per column of q ({q_names}), got {list(names)}")
    fig, (ax_q, ax_s) = _figure(2, width=9.0)
    for i, name in enumerate(names or q_names):
        ax_q.plot(result.t, result.q[:, i], label=name)
    for i, name in enumerate(s_names):
        ax_s.plot(result.t, result.s_dot[:, i], label=name)
    ax_q.set_ylabel("q")
    ax_s.set_ylabel("ṡ")
    ax_s.set_xlabel("t (s)")
    for ax in (ax_q, ax_s):
        ax.grid(alpha=0.3)
        _legend_outside(ax)
    return fig


def _group(name: str, unit: str, elastic: bool, velocity: bool) -> tuple[str, str]:
    """(kind, unit) of one column: the axes it is drawn on."""
    if elastic:
        return ("elastic velocities" if velocity else "elastic coordinates"), unit or "unit unknown"
    kinds = {"rad": "joint angles", "m": "translations", "rad/s": "angular velocities", "m/s": "velocities"}
    return kinds.get(unit, "velocities" if velocity else "coordinates"), unit or "unit unknown"


def grouped_history(result):
    """q(t) and ṡ(t) on one axes per kind and unit: joint angles (rad), translations (m),
    elastic coordinates (a deforming subsystem's, from ``result.system``), others by unit,
    then their velocities; legends outside the data."""
    system = result.system.tree if result.system is not None else None
    elastic_q = set(i for sl in (system.e_q_slice if system else ()) for i in range(sl.start, sl.stop))
    elastic_s = set(i for sl in (system.e_s_slice if system else ()) for i in range(sl.start, sl.stop))
    if result.system is not None and result.system.partition is not None:
        elastic_s = {k for k, i in enumerate(result.system.partition) if i in elastic_s}
    q_names, s_names = result.column_names()
    groups: dict = {}
    for values, names, named, elastic, velocity in ((result.q, q_names, result.coordinates, elastic_q, False),
                                                    (result.s_dot, s_names, result.velocities, elastic_s, True)):
        for i, name in enumerate(names):
            unit = named[i][1] if i < len(named) else ""
            groups.setdefault(_group(name, unit, i in elastic, velocity), []).append((name, values[:, i]))
    fig, axes = _figure(max(1, len(groups)), width=9.0)
    for ax, ((kind, unit), lines) in zip(axes, groups.items()):
        for name, values in lines:
            ax.plot(result.t, values, label=name)
        ax.set_ylabel(f"{kind}\n({unit})")
        ax.grid(alpha=0.3)
        _legend_outside(ax)
    axes[-1].set_xlabel("t (s)")
    return fig


def planar_trajectory(result, x: int = 0, y: int = 1):
    """The path (q[x], q[y]) in the plane, with start and end marked, equal axis scales; the
    axes labelled by the columns' names and units (:meth:`projeq.Result.column_names`)."""
    _check_rows(result)
    labels = result.column_names(units=True)[0]
    for name, i in (("x", x), ("y", y)):
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < len(labels):
            raise ValueError(f"{name}: expected a column of q, 0 … {len(labels) - 1} ({labels}), got {i!r}")
    fig, (ax,) = _figure(1)
    ax.plot(result.q[:, x], result.q[:, y], label="path")
    ax.plot(result.q[0, x], result.q[0, y], "o", label="start")
    ax.plot(result.q[-1, x], result.q[-1, y], "s", label="end")
    ax.set_xlabel(labels[x])
    ax.set_ylabel(labels[y])
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def drift(result, energy_conserved: bool | None = None):
    """Energy change E(t) − E(0) (top) and, for a model with constraints, the largest
    velocity-constraint residual (bottom, its axis floored at round-off, :data:`ROUND_OFF`).
    ``energy_conserved=False`` titles the energy panel with why it need not be constant
    (:func:`projeq.simulation.integrators.conserves_energy`)."""
    _check_rows(result)
    constrained = result.constraint_residual.size > 0
    fig, axes = _figure(2 if constrained else 1)
    axes[0].plot(result.t, result.energy - result.energy[0])
    axes[0].set_ylabel("E(t) − E(0) (J)")
    if energy_conserved is False:
        axes[0].set_title("energy not conserved: a prescribed motion or non-conservative forces", fontsize="small")
    if constrained:
        residual = np.abs(result.constraint_residual).max(axis=1)
        axes[1].semilogy(result.t, np.maximum(residual, 1e-300))
        axes[1].set_ylim(bottom=ROUND_OFF, top=max(10 * ROUND_OFF, 2 * residual.max()))
        axes[1].set_ylabel("max |constraint residual|")
    axes[-1].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig


def _work_precision_row(i: int, row) -> tuple[str, float, float]:
    """(label, error, cpu) of ``rows[i]``: error finite and ≥ 0, cpu finite and > 0."""
    label, error, cpu = row
    error, cpu = float(error), float(cpu)
    if not (np.isfinite(error) and error >= 0.0):
        raise ValueError(f"rows[{i}]: the error of {label!r} must be finite and >= 0, got {error}")
    if not (np.isfinite(cpu) and cpu > 0.0):
        raise ValueError(f"rows[{i}]: the CPU time of {label!r} must be finite and > 0 s, got {cpu}")
    return label, error, cpu


def tip_deflection(result, beam, x=None):
    """The deflection (u, v, w) of ``beam`` (a RitzBeam) at station x (default its tip)."""
    fig, (ax,) = _figure(1)
    x = beam.length if x is None else x
    for label, values in zip("uvw", beam.deflection(result, x).T):
        ax.plot(result.t, values, label=label)
    ax.set_title(f"deflection at x = {x:g} m")
    ax.set_ylabel("m")
    ax.set_xlabel("t (s)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def work_precision(rows, legend: bool = True):
    """Work-precision diagram: CPU time over error, one line per label.

    ``rows``: iterable of ``(label, error, cpu_seconds)``, e.g. one per tolerance and method;
    ``legend=False`` leaves the legend to the caller. A log axis has no 0: an error of exactly
    0 (a setting that reproduces the reference) is drawn at a floor, 1e-16 or a decade below the
    smallest positive error, circled, and a note on the axes says so. A negative or non-finite
    error, or a CPU time that is not positive and finite, is a ValueError naming the row (the
    axis would drop the point without a word).
    """
    fig, (ax,) = _figure(1)
    rows = [_work_precision_row(i, row) for i, row in enumerate(rows)]
    floor = min([ROUND_OFF] + [0.1 * error for _, error, _ in rows if error > 0])
    series = {}
    for label, error, cpu in rows:
        series.setdefault(label, []).append((error if error > 0 else floor, cpu))
    for label, points in series.items():
        error, cpu = np.array(sorted(points)).T
        ax.loglog(error, cpu, "o-", label=label)
    exact = [cpu for _, error, cpu in rows if error == 0]
    if exact:
        ax.scatter([floor] * len(exact), exact, s=120, facecolors="none", edgecolors="k", label="_exact")
        ax.text(0.01, 0.02, f"circled: error exactly 0, drawn at {floor:.0e}", transform=ax.transAxes,
                fontsize="x-small")
    ax.set_xlabel("error")
    ax.set_ylabel("CPU time (s)")
    ax.grid(alpha=0.3, which="both")
    if legend:
        ax.legend(fontsize="small")
    return fig
