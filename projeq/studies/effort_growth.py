"""The derivation effort of the analytical route and of the Projection Equation, and how it grows.

H. Bremer, "Problems in fast moving non-holonomic elastic systems", claims that the Projection Equation
gives the spinning beam's equations B(23) "along with much less effort in calculation" than Hamilton's
principle gives B(18) (§4.2), and "minimum effort when compared to the analytical procedures" for rigid
multibody systems (§3). The effort meant is that of deriving: every expression a method forms on the way,
not only the equations it ends with. Here each method's intermediate expressions are kept by name —

* Hamilton / Lagrange: T − V (per length), its integrations by parts (field equations) or L = ∫(T − V) dx,
  ∂L/∂q̇, d/dt ∂L/∂q̇, ∂L/∂q (Ritz model; rigid bodies: T, Q, ∂T/∂q̇, ∂T/∂q, d/dt ∂T/∂q̇, M, rhs);
* the Projection Equation: the Newton–Euler residuals of the slice or body (its momentum balances), their
  projections (D r, Ψᵀ r, J_v and J_ω), the equations —

and measured by the operation count after ``sympy.cse`` of each (:func:`projeq.studies.effort.cse_ops`,
summed over the steps) and the CPU time of the derivation from a cold start
(:func:`projeq.studies.effort.cold_start`), for the spinning beam's field equations, its Ritz model with
n = 1 … 4 functions per plane and the n-link pendulum with 1 … 3 links (``benchmarks/effort_growth.py``).
"""

from __future__ import annotations

import time

import sympy as sp

from projeq.studies.effort import cold_start, cse_ops

__all__ = ["effort", "effort_rows", "lagrange_steps", "pendulum_steps", "verdict"]


def lagrange_steps(bodies, q, s) -> dict:
    """Lagrange's equations of the 2nd kind d/dt ∂T/∂q̇ − ∂T/∂q = Q with ṡ = q̇ (scleronomic, T quadratic
    in ṡ) for ``bodies`` (name → :class:`projeq.symbolic.Body`), with the expressions formed on the way:
    ``T``, ``Q`` = Σ (∂v_c/∂ṡ)ᵀ f + (∂ω/∂ṡ)ᵀ M, ``∂T/∂q̇``, ``∂T/∂q``, ``d/dt ∂T/∂q̇`` (without q̈),
    ``M`` = ∂²T/∂ṡ² and ``rhs`` = Q + ∂T/∂q − (∂²T/∂ṡ∂q) ṡ."""
    T, Q = 0, sp.zeros(len(s), 1)
    for b in bodies.values():
        v_c, omega = sp.Matrix(b.v_c), sp.Matrix(b.omega)
        T += b.m * v_c.dot(v_c) / 2 + (omega.T * sp.Matrix(b.I_c) * omega)[0] / 2
        Q += v_c.jacobian(s).T * sp.Matrix(b.f) + omega.jacobian(s).T * sp.Matrix(b.M)
    p = sp.Matrix([T]).jacobian(s).T
    dT_dq = sp.Matrix([T]).jacobian(q).T
    p_rate = p.jacobian(q) * sp.Matrix(s)
    return {"T": [T], "Q": list(Q), "∂T/∂q̇": list(p), "∂T/∂q": list(dT_dq), "d/dt ∂T/∂q̇": list(p_rate),
            "M": p.jacobian(s), "rhs": Q + dT_dq - p_rate}


def _projection_steps(bodies, q, s, parameters) -> dict:
    """The Projection Equation B(10) for ``bodies``, each body's intermediate expressions merged by name."""
    from projeq.symbolic import projection_equation

    trace = []
    gauss = projection_equation(bodies, q, s, parameters=parameters, trace=trace)
    steps = {name: [e for body in trace for e in body[name]] for name in trace[0]}
    return {**steps, "M": gauss.M, "rhs": gauss.rhs}


def pendulum_steps(links: int, method: str) -> dict:
    """The intermediate expressions of the planar ``links``-link pendulum
    (:func:`projeq.symbolic.examples.n_link_pendulum`) by ``method`` "lagrange" or "projection"."""
    from projeq.symbolic.examples import n_link_pendulum

    bodies, q, s, parameters = n_link_pendulum(links)
    if method == "lagrange":
        return lagrange_steps(bodies, q, s)
    return _projection_steps(bodies, q, s, parameters)


def _derivations(case: str, size: int, method: str):
    """The steps function of one (case, size, method) of :func:`effort_rows`."""
    from projeq.symbolic import spinning_beam as sb

    if case == "beam field equations":
        return sb.hamilton_field_steps if method == "hamilton" else sb.projection_field_steps
    if case == "beam Ritz":
        steps = sb.hamilton_ritz_steps if method == "hamilton" else sb.projection_ritz_steps
        return lambda: steps(size)[0]
    return lambda: pendulum_steps(size, "lagrange" if method == "hamilton" else "projection")


def effort(derive) -> dict:
    """``{"ops": {step: cse operation count}, "total_ops", "cpu_s"}`` of ``derive()`` (a dict of named
    expression lists) after :func:`projeq.studies.effort.cold_start`; ``cpu_s`` is its process time."""
    cold_start()
    begin = time.process_time()
    steps = derive()
    cpu = time.process_time() - begin
    ops = {name: cse_ops(list(expressions)) for name, expressions in steps.items()}
    return {"ops": ops, "total_ops": sum(ops.values()), "cpu_s": cpu}


CASES = {"beam field equations": (0,), "beam Ritz": (1, 2, 3, 4), "pendulum": (1, 2, 3)}


def effort_rows(sizes=None) -> list[dict]:
    """One row per case, size and method ("hamilton": Hamilton's principle for the beam, Lagrange's
    equations for the pendulum; "projection"): the :func:`effort` measures. ``sizes``: {case: sizes},
    default ``CASES`` (Ritz functions per plane, links; 0 for the field equations)."""
    sizes = CASES if sizes is None else sizes
    unknown = [case for case in sizes if case not in CASES]
    if unknown:
        raise ValueError(f"sizes: unknown cases {unknown}; available: {list(CASES)}")
    rows = []
    for case, values in sizes.items():
        for size in values:
            for method in ("hamilton", "projection"):
                measured = effort(_derivations(case, size, method))
                rows.append({"case": case, "size": size, "method": method, **measured})
    return rows


def verdict(rows: list[dict]) -> str:
    """Bremer's claim against the measured rows: per case, the Projection Equation's operations and CPU
    as fractions of the analytical route's, by size, and whether the claim holds."""
    lines = []
    for case in dict.fromkeys(row["case"] for row in rows):
        pairs = {}
        for row in rows:
            if row["case"] == case:
                pairs.setdefault(row["size"], {})[row["method"]] = row
        ratios = [(size, pair["projection"]["total_ops"] / pair["hamilton"]["total_ops"],
                   pair["projection"]["cpu_s"] / pair["hamilton"]["cpu_s"]) for size, pair in pairs.items()]
        fewer = [size for size, ops, _ in ratios if ops < 1]
        outcome = ("fewer operations at every size: the claim holds" if len(fewer) == len(ratios) else
                   f"fewer operations only at sizes {fewer}: the claim holds there, not at the others")
        lines.append(f"{case}: Projection Equation / analytical route, operations (CPU) "
                     + ", ".join(f"size {size}: {ops:.2f} ({cpu:.2f})" for size, ops, cpu in ratios)
                     + f" — {outcome}")
    return "\n".join(lines)
