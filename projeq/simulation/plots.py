"""Figures of simulation results (matplotlib, Agg backend: works without a display).

Every function returns a :class:`matplotlib.figure.Figure` (not shown; save it with
``fig.savefig(path)``). The plotted line data are the result's own arrays.
"""

from __future__ import annotations

import numpy as np


def _figure(rows: int = 1):
    from matplotlib.figure import Figure  # a Figure without pyplot: no GUI backend, no global state

    fig = Figure(figsize=(7.0, 2.6 * rows + 0.8), layout="constrained")
    return fig, fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]


def time_history(result, names=None):
    """q(t) (top) and ṡ(t) (bottom); ``names`` labels the coordinates (default q0, q1, ...)."""
    fig, (ax_q, ax_s) = _figure(2)
    names = names or [f"q{i}" for i in range(result.q.shape[1])]
    for i, name in enumerate(names):
        ax_q.plot(result.t, result.q[:, i], label=name)
    for i in range(result.s_dot.shape[1]):
        ax_s.plot(result.t, result.s_dot[:, i], label=f"ṡ{i}")
    ax_q.set_ylabel("q (rad or m)")
    ax_s.set_ylabel("ṡ (rad/s or m/s)")
    ax_s.set_xlabel("t (s)")
    for ax in (ax_q, ax_s):
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", ncol=min(6, max(1, len(ax.lines))), loc="upper right")
    return fig


def planar_trajectory(result, x: int = 0, y: int = 1):
    """The path (q[x], q[y]) in the plane, with start and end marked, equal axis scales."""
    fig, (ax,) = _figure(1)
    ax.plot(result.q[:, x], result.q[:, y], label="path")
    ax.plot(result.q[0, x], result.q[0, y], "o", label="start")
    ax.plot(result.q[-1, x], result.q[-1, y], "s", label="end")
    ax.set_xlabel(f"q{x} (m)")
    ax.set_ylabel(f"q{y} (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def drift(result):
    """Energy change E(t) − E(0) (top) and the largest velocity-constraint residual (bottom)."""
    fig, (ax_e, ax_c) = _figure(2)
    ax_e.plot(result.t, result.energy - result.energy[0])
    ax_e.set_ylabel("E(t) − E(0) (J)")
    residual = np.abs(result.constraint_residual).max(axis=1) if result.constraint_residual.size else 0 * result.t
    ax_c.semilogy(result.t, np.maximum(residual, 1e-300))
    ax_c.set_ylabel("max |constraint residual|")
    ax_c.set_xlabel("t (s)")
    for ax in (ax_e, ax_c):
        ax.grid(alpha=0.3)
    return fig


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
    ``legend=False`` leaves the legend to the caller.
    """
    fig, (ax,) = _figure(1)
    series = {}
    for label, error, cpu in rows:
        series.setdefault(label, []).append((float(error), float(cpu)))
    for label, points in series.items():
        error, cpu = np.array(sorted(points)).T
        ax.loglog(error, cpu, "o-", label=label)
    ax.set_xlabel("error")
    ax.set_ylabel("CPU time (s)")
    ax.grid(alpha=0.3, which="both")
    if legend:
        ax.legend(fontsize="small")
    return fig
