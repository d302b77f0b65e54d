"""The multiplier and canonical forms in a comparison table (:mod:`projeq.studies.compare`).

Lagrange's and Hamilton's equations with multipliers (the lecture on non-holonomic systems,
K(7), K(23)–(26)) and Barhorst's Lagrangian canonical form (A. A. Barhorst, "Generalized
momenta in constrained non-holonomic systems", eqs. 45–52) live in the full coordinates of
a Pfaffian model, not in the scene's minimal velocities; each row is derived, counted, and
compared with the scene's Projection Equation by the motion both produce from the same
initial state (:class:`FullCoordinates` maps one onto the other).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import sympy as sp

from projeq.studies.effort import cse_ops, derivation_timed, timed

__all__ = ["MULTIPLIER_FORMS", "FullCoordinates", "CAR_COORDINATES", "car_multiplier_system", "multiplier_rows",
           "without_multiplier_rows"]


MULTIPLIER_FORMS = {"lagrange + multipliers": "lagrange", "hamilton canonical + multipliers": "hamilton",
                    "barhorst lagrangian canonical": "barhorst"}


def without_multiplier_rows(formulations, available):
    """The wanted rows that share the scene's coordinates (all of ``available`` by default)."""
    wanted = formulations or [f.name for f in available] + list(MULTIPLIER_FORMS)
    return [f for f in wanted if f not in MULTIPLIER_FORMS]


@dataclass(frozen=True)
class FullCoordinates:
    """A multiplier model in full coordinates q (with A q̇ = 0) against the scene's (q, ṡ):
    ``initial(system)`` → (q, q̇) of the scene's initial state, ``to_scene(q, q̇)`` (columns
    are instants) → (q, ṡ) of the scene (rows are instants), ``independent``: the names of
    the coordinates whose rates are Barhorst's independent speeds u."""

    initial: Callable
    to_scene: Callable
    independent: tuple


def car_multiplier_system(values):
    """The car in (x, y, γ) with −sin γ ẋ + cos γ ẏ = 0 (Orsino (2020), K(7); B(6))."""
    from sympy.physics.mechanics import dynamicsymbols

    from projeq.symbolic import t as time_symbol
    from projeq.symbolic.lagrange import multiplier_system

    x, y, g = q = dynamicsymbols("x y gamma")
    xd, yd, gd = (qi.diff(time_symbol) for qi in q)
    m, c, C0 = values
    v_c = (xd - c * sp.sin(g) * gd, yd + c * sp.cos(g) * gd)  # mass centre O + c e_x
    L = m * (v_c[0] ** 2 + v_c[1] ** 2) / 2 + (C0 - m * c**2) * gd**2 / 2
    return multiplier_system(L, q, time_symbol, A=[[-sp.sin(g), sp.cos(g), 0]], parameters=values)


CAR_COORDINATES = FullCoordinates(
    initial=lambda system: (system.q0, system.q_dot(system.q0, system.s_dot0)),
    to_scene=lambda q, q_dot: (q.T, np.column_stack([np.cos(q[2]) * q_dot[0] + np.sin(q[2]) * q_dot[1], q_dot[2]])),
    independent=("x", "gamma"),
)


def multiplier_rows(formulations, build, system, coordinates: FullCoordinates, simulate, t_end) -> list:
    """Rows of the multiplier and canonical forms that ``formulations`` asks for (all by default),
    each compared with one reference run of the scene (rtol 1e-9, atol 1e-12)."""
    from projeq.simulation.driver import simulate as run

    names = [name for name in MULTIPLIER_FORMS if formulations is None or name in formulations]
    # 101 instants suffice to compare motions and energies; the integrator's steps are its own
    reference = run(system, t_end, rtol=1e-9, atol=1e-12, n_points=101) if simulate and names else None
    return [multiplier_row(MULTIPLIER_FORMS[name], name, build, system, coordinates, reference) for name in names]


def multiplier_row(form: str, name: str, build, system, coordinates: FullCoordinates, reference) -> dict:
    """Lagrange or Hamilton canonical equations with multipliers (Orsino (2020), K(7) and K(23)–(26)),
    or Barhorst's Lagrangian canonical form (Barhorst, eqs. 45–52), in full coordinates;
    compared by their motion with the ``reference`` run of the scene (None: not simulated)."""
    from projeq.symbolic.canonical import lagrangian_canonical

    def derive():
        ms = build()
        if form == "barhorst":  # an ODE in (q, p) with q̇ = K u, no multiplier
            independent = [qi for qi in ms.q if qi.func.__name__ in coordinates.independent]
            canonical = lagrangian_canonical(ms, independent=independent)
            return (ms, canonical), [*canonical.p, *canonical.p_dot]
        return (ms, None), (ms.lagrange_equations() if form == "lagrange" else sp.Matrix([*ms.canonical_equations()]))

    ((ms, canonical), equations), seconds = derivation_timed(derive)
    row = {"formulation": name, "derivation_s": seconds, "n_ops": cse_ops(equations, ms.parameters),
           "note": "q̇ = K u, ṗ = Kᵀ(∂L/∂q + Q) + K̇ᵀ∂L/∂q̇: no multiplier" if canonical else
           "index-1 by differentiating the constraint once (λ solved), no Baumgarte"}
    if reference is None:
        row.update(identical="not compared", check="equations in full coordinates and λ: compared by motion only")
        return row
    t_end = reference.t[-1]
    q0, q_dot0 = coordinates.initial(system)
    if canonical is None:
        sol, row["integration_s"] = timed(lambda: ms.simulate(
            q0, q_dot0, (0.0, t_end), form=form, t_eval=reference.t, rtol=1e-9, atol=1e-12))
    else:
        independent = [ms.q_symbols.index(sp.Symbol(str(u)[: -len("_dot")])) for u in canonical.u]
        sol, row["integration_s"] = timed(lambda: canonical.simulate(
            q0, q_dot0[independent], (0.0, t_end), t_eval=reference.t, rtol=1e-9, atol=1e-12))
        K = sp.lambdify([canonical.q], canonical.K.subs(canonical.parameters), modules="numpy")
        sol.q_dot = np.column_stack([np.asarray(K(qi), float) @ ui for qi, ui in zip(sol.q.T, sol.u.T)])
    q, s_dot = coordinates.to_scene(sol.q, sol.q_dot)
    gap = float(np.max(np.abs(q - reference.q)))
    # 1e-6: both integrations at rtol 1e-9 over O(1) motions; a modelling error is O(1)
    row.update(identical="yes" if gap < 1e-6 else "no", check=f"numeric, same motion, max |Δq| {gap:.1e}")
    energies = np.array([system.energy(qi, si) for qi, si in zip(q, s_dot)])
    total = energies.sum(axis=1)
    row["energy_drift"] = float(np.abs(total - total[0]).max() / max(np.abs(energies).max(), 1e-300))
    row["constraint_drift"] = float(max(abs(ms.velocity_residual(0.0, qi, ui)).max() for qi, ui in zip(sol.q.T, sol.q_dot.T)))
    return row
