"""Barhorst's formulation study with compiled right-hand sides: times that compare formulations, not Python.

A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion", §3, reports the projective and canonical forms of his particle 94–95 %
faster than Hamilton's canonical DAE and his quick-return mechanism's 10 s in 0.056 s. The rows of
:mod:`projeq.studies.compare_barhorst` integrate lambdified sympy called from Python, so their times
measure Python. Here every formulation's right-hand side is generated from the same sympy derivation
into scalar code (:func:`projeq.symbolic.codegen.numeric_function`, with common subexpressions), its
pieces and their composition compiled by numba (float64, eager), and integrated by the same Radau IIA
(:func:`projeq.simulation.integrators.radau_dae`, forward-difference Jacobian, rtol 1e-8, atol 1e-10) and,
the ODE forms, also by the same explicit DOP853 (``scipy.integrate.solve_ivp``, same tolerances; Barhorst
used each form's default integrator of Mathematica's NDSolve):

* Hamilton's canonical equations with multipliers (his eq. 7 with 3), the index-2 DAE in (q, p, λ):
  q̇ = M⁻¹(p − ∂L/∂q̇|₀), ṗ = ∂L/∂q + Q + Aᵀλ, 0 = A q̇ − b;
* the projective (Kane) form, Bremer's Projection Equation B(10): q̇ = K u, M u̇ = rhs;
* the projective and Lagrangian canonical forms (eqs. 28–37, 45–52): u = (∂p/∂u)⁻¹(p − p|ᵤ₌₀),
  q̇ = K u + J, ṗ = ṗ(q, u).

Each :class:`CompiledRun` reports the time to generate the code (``generate_s``), to compile it
(``compile_s``) and to integrate, warm (``radau_s``, ``dop853_s``: process time, the least of ``repeat``
runs), beside the number of steps.  projeq's Radau IIA is Python around the compiled right-hand side:
its steps cost ~0.5 ms each whatever the formulation, so its ratios stay near 1; DOP853 in scipy costs
~0.15 ms a step. ``compile=False`` runs the same generated code in
numpy (no numba: the quick mode of ``benchmarks/barhorst_compiled.py``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import sympy as sp

from projeq.studies.compare_barhorst import RTOL, ATOL, study_formulations
from projeq.symbolic.codegen import numeric_function

__all__ = ["CompiledRun", "compiled_study"]


@dataclass(frozen=True)
class CompiledRun:
    """One formulation integrated from generated code: times in s (``dop853_*`` None for the DAE), ``q`` of
    the Radau IIA run at ``t`` (columns are instants)."""

    formulation: str
    generate_s: float
    compile_s: float
    radau_s: float
    radau_steps: int
    dop853_s: float | None
    dop853_steps: int | None
    t: np.ndarray
    q: np.ndarray


def _printed(name: str, symbols, expressions, values: dict):
    """The scalar code of ``expressions`` in (t, q, z) with the parameters' ``values`` as numbers."""
    t, q, z = symbols
    numbers = {k: sp.Float(v) for k, v in values.items()}
    expressions = sp.Matrix(expressions).xreplace(numbers)
    return numeric_function(name, [("t", t), ("q", list(q)), ("z", list(z))], expressions)()


def _pieces(derived, values):
    """(kind, sizes, printed pieces) of a derived formulation (a MultiplierSystem, a CanonicalForm or the
    Projection Equation's (evaluator, K, GaussForm)), all functions of (t, q, z)."""
    from projeq.symbolic.canonical import CanonicalForm
    from projeq.symbolic.lagrange import MultiplierSystem

    if isinstance(derived, MultiplierSystem):
        q_dot, L, dL_dq_dot, Q, A, b = derived._plain
        symbols = (derived.t, derived.q_symbols, q_dot)
        M, p0 = dL_dq_dot.jacobian(q_dot), dL_dq_dot.subs({v: 0 for v in q_dot})
        force = sp.Matrix([L]).jacobian(derived.q_symbols).T + Q
        pieces = {"M": M, "p0": p0, "force": force, "A": A, "b": b}
        printed = {k: _printed(k, symbols, X, values) for k, X in pieces.items()}
        return "hamilton", (len(q_dot), A.rows), printed
    if isinstance(derived, CanonicalForm):
        u = sp.Matrix(derived.u)
        J = sp.zeros(len(derived.q), 1) if derived.J is None else derived.J
        pieces = {"dp_du": derived.p.jacobian(u), "p0": derived.p.subs({ui: 0 for ui in u}), "K": derived.K,
                  "J": J, "p_dot": derived.p_dot}
        symbols = (derived.t, derived.q, derived.u)
        return "canonical", (len(derived.q), len(u)), {k: _printed(k, symbols, X, values)
                                                       for k, X in pieces.items()}
    gauss = derived[2]
    pieces = {"K": gauss.K, "M": gauss.M, "rhs": gauss.rhs}
    symbols = (gauss.t, gauss.q, gauss.s)
    printed = {k: _printed(k, symbols, X, values) for k, X in pieces.items()}
    return "kane", (len(gauss.q), len(gauss.s)), printed


def _hamilton_rhs(n, c, M, p0, force, A, b):
    """q̇ = M⁻¹(p − p0), ṗ = force + Aᵀλ, 0 = A q̇ − b at y = (q, p, λ)."""
    def f(t, y):
        q, p, lam = y[:n], y[n:2 * n], y[2 * n:]
        q_dot = np.linalg.solve(M(t, q, p).reshape(n, n), p - p0(t, q, p))
        A_ = A(t, q, q_dot).reshape(c, n)
        out = np.empty_like(y)
        out[:n] = q_dot
        out[n:2 * n] = force(t, q, q_dot) + A_.T @ lam
        out[2 * n:] = A_ @ q_dot - b(t, q, q_dot)
        return out
    return f


def _canonical_rhs(n, k, dp_du, p0, K, J, p_dot):
    """u = (∂p/∂u)⁻¹(p − p0), q̇ = K u + J, ṗ(q, u) at y = (q, p)."""
    def f(t, y):
        q, p = y[:n], y[n:]
        u = np.linalg.solve(dp_du(t, q, p).reshape(k, k), p - p0(t, q, p))
        out = np.empty_like(y)
        out[:n] = K(t, q, u).reshape(n, k) @ u + J(t, q, u)
        out[n:] = p_dot(t, q, u)
        return out
    return f


def _kane_rhs(n, k, K, M, rhs):
    """q̇ = K u, u̇ = M⁻¹ rhs at y = (q, u)."""
    def f(t, y):
        q, u = y[:n], y[n:]
        out = np.empty_like(y)
        out[:n] = K(t, q, u).reshape(n, k) @ u
        out[n:] = np.linalg.solve(M(t, q, u).reshape(k, k), rhs(t, q, u))
        return out
    return f


_COMPOSE = {"hamilton": _hamilton_rhs, "canonical": _canonical_rhs, "kane": _kane_rhs}


def _start(kind, derived, start, sizes):
    """y₀ of a formulation from its ``start`` (q₀ and q̇₀ or u₀), with its DAE mass and index."""
    q0, velocities0 = (np.asarray(v, dtype=float) for v in start)
    if kind == "hamilton":
        n, c = sizes
        return (derived.dae_start(0.0, q0, velocities0), np.r_[np.ones(2 * n), np.zeros(c)],
                np.r_[np.ones(2 * n), np.full(c, 2)])
    if kind == "canonical":
        return np.r_[q0, derived.momenta(0.0, q0, velocities0)], None, None
    return np.r_[q0, velocities0], None, None


def _compiled(kind, sizes, pieces, compile: bool):
    """The right-hand side f(t, y), numba-compiled (pieces and composition, float64, eager) or numpy."""
    if not compile:
        return _COMPOSE[kind](*sizes, **pieces)
    from projeq.assembly.kernels import numba_module

    numba = numba_module()
    jitted = {name: numba.njit(f) for name, f in pieces.items()}
    return numba.njit("float64[:](float64, float64[:])")(_COMPOSE[kind](*sizes, **jitted))


def compiled_study(study: str, t_end: float = 10.0, formulations=None, compile: bool = True,
                   repeat: int = 2, n_points: int = 51) -> list[CompiledRun]:
    """Generate, compile and integrate each formulation of Barhorst's ``study`` (``barhorst_particle``,
    ``rolling_disk``, ``quick_return``; :func:`projeq.studies.compare_barhorst.study_formulations`) over
    ``t_end``; ``formulations``: the names to run (default all that exist for the example)."""
    from scipy.integrate import solve_ivp

    from projeq.simulation.integrators import radau_dae

    if not t_end > 0:
        raise ValueError(f"t_end: must be positive, got {t_end!r}")
    if int(repeat) != repeat or repeat < 1:
        raise ValueError(f"repeat: must be a positive integer, got {repeat!r}")
    example, available = study_formulations(study)
    available = [f for f in available if f.run is not None]
    names = [f.name for f in available]
    unknown = [name for name in (formulations or ()) if name not in names]
    if unknown:
        raise ValueError(f"formulations: unknown {unknown}; available: {names}")
    t_eval, runs = np.linspace(0.0, t_end, n_points), []
    for formulation in available:
        if formulations is not None and formulation.name not in formulations:
            continue
        derived = formulation.derive()
        start = time.perf_counter()
        kind, sizes, pieces = _pieces(derived, example.values)
        generated = time.perf_counter()
        f = _compiled(kind, sizes, pieces, compile)
        y0, mass, index = _start(kind, derived, formulation.start, sizes)
        f(0.0, y0)
        compiled = time.perf_counter()
        radau = _least_cpu(repeat, lambda: radau_dae(f, (0.0, t_end), y0, mass=mass, index=index, rtol=RTOL,
                                                     atol=ATOL, t_eval=t_eval))
        dop853 = None if mass is not None else _least_cpu(repeat, lambda: solve_ivp(
            f, (0.0, t_end), y0, method="DOP853", rtol=RTOL, atol=ATOL))
        runs.append(CompiledRun(formulation.name, generated - start, compiled - generated, radau[0],
                                radau[1].n_steps, None if dop853 is None else dop853[0],
                                None if dop853 is None else dop853[1].t.size - 1, radau[1].t,
                                radau[1].y[:len(formulation.start[0])]))
    return runs


def _least_cpu(repeat: int, integrate):
    """(the least process time of ``repeat`` calls of ``integrate``, its last result); raises if it failed."""
    cpu = np.inf
    for _ in range(repeat):
        begin = time.process_time()
        sol = integrate()
        cpu = min(cpu, time.process_time() - begin)
    if not sol.success:
        raise RuntimeError(f"integration failed: {sol.message}")
    return cpu, sol
