"""Compare formulations of the equations of motion of one system (issue 5, THEORY §8, §9, §11).

``compare(name)`` derives the equations of the named system with each available
formulation, times the derivation, counts operations after common-subexpression
elimination, checks whether the equations are identical to the first (reference)
formulation, and optionally simulates each, reporting integration time, energy drift and
constraint drift. Every formulation that yields a Gauss form M s̈ = rhs in the same
coordinates is simulated through :func:`projeq.simulate` with a compiled evaluator, so all
rows share one integrator and one energy function.
"""

from __future__ import annotations

import argparse
import csv
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy as sp

COLUMNS = ("formulation", "derivation_s", "n_ops", "identical", "check", "integration_s", "energy_drift",
           "constraint_drift", "note")


@dataclass
class ComparisonTable:
    """Rows of a comparison, one dict per formulation with the keys of ``COLUMNS``."""

    name: str
    rows: list = field(default_factory=list)

    def format(self) -> str:
        """Plain-text table (numbers to 3 significant digits)."""
        cells = [list(COLUMNS)] + [[_cell(row.get(c)) for c in COLUMNS] for row in self.rows]
        widths = [max(len(r[i]) for r in cells) for i in range(len(COLUMNS))]
        lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in cells]
        lines.insert(1, "  ".join("-" * w for w in widths))
        return f"compare {self.name}\n" + "\n".join(lines)

    def to_csv(self, path) -> None:
        """Write the rows to ``path`` as CSV with a header line."""
        with open(path, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=COLUMNS)
            writer.writeheader()
            writer.writerows({c: row.get(c, "") for c in COLUMNS} for row in self.rows)


def _cell(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)


@dataclass
class Formulation:
    """One way to derive the equations: ``derive()`` returns a GaussForm, or ``evaluator``
    names a numeric method of the System ("dense", "recursive"); neither: not available."""

    name: str
    derive: Callable | None = None
    evaluator: str | None = None
    note: str = ""


def _cse_ops(expressions) -> int:
    """sympy.count_ops over the output of sympy.cse (replacements and reduced expressions)."""
    replacements, reduced = sp.cse(list(expressions))
    return sum(sp.count_ops(e) for _, e in replacements) + sum(sp.count_ops(e) for e in reduced)


def _timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def _equal(reference, other, evaluators, system) -> tuple[str, str]:
    """("yes"/"no", how): symbolic difference when both are small, else random states."""
    if reference is not None and other is not None and sp.count_ops(other.rhs) < 400:
        diff_M = (reference.M - other.M).applyfunc(sp.simplify)
        diff_rhs = (reference.rhs - other.rhs).applyfunc(sp.simplify)
        same = diff_M.is_zero_matrix and diff_rhs.is_zero_matrix
        return ("yes" if same else "no"), "symbolic"
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(5):
        q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
        a_ref, a = (e.accelerations(q, s_dot, 0.0) for e in evaluators)
        errors.append(np.max(np.abs(a - a_ref)) / max(1.0, np.max(np.abs(a_ref))))
    # 1e-9: round-off of two independently compiled evaluators, far below any modelling difference
    return ("yes" if max(errors) < 1e-9 else "no"), f"numeric, 5 random states, max rel err {max(errors):.1e}"


def _simulate_row(system, evaluator, t_end: float) -> dict:
    from projeq.simulation import simulate

    result = simulate(system, t_end, evaluator=evaluator, rtol=1e-9, atol=1e-12)
    drift = float(np.abs(result.constraint_residual).max()) if result.constraint_residual.size else None
    return {"integration_s": result.wall_time, "energy_drift": result.energy_drift, "constraint_drift": drift}


def _gauss_form_rows(system, formulations, values, simulate: bool, t_end: float) -> list[dict]:
    """Rows for formulations sharing the coordinates of ``system`` (first one = reference)."""
    rows, reference, reference_evaluator = [], None, None
    for f in formulations:
        row = {"formulation": f.name, "note": f.note}
        if f.derive is None and f.evaluator is None:
            row["identical"] = "not available"
            rows.append(row)
            continue
        if f.derive is not None:
            gauss, row["derivation_s"] = _timed(f.derive)
            evaluator = gauss.evaluator(values)
            row["n_ops"] = evaluator.n_ops
        else:
            gauss, row["derivation_s"] = _timed(lambda: system.evaluator(f.evaluator))
            evaluator = f.evaluator
            row["note"] = row["note"] or "numeric evaluator: no symbolic expressions"
        numeric = system.evaluator(evaluator) if isinstance(evaluator, str) else evaluator
        if reference_evaluator is None:
            reference, reference_evaluator = (gauss if f.derive else None), numeric
            row["identical"], row["check"] = "reference", ""
        else:
            row["identical"], row["check"] = _equal(reference, gauss if f.derive else None,
                                                    (reference_evaluator, numeric), system)
        if simulate:
            row.update(_simulate_row(system, evaluator, t_end))
        rows.append(row)
    return rows


# -- the systems ---------------------------------------------------------------------------
def _pendulum(formulations, simulate, t_end):
    from projeq.inertia import cylinder
    from projeq.scenes import chain
    from projeq.symbolic import projection_equation
    from projeq.symbolic.examples import n_link_pendulum

    n = 2
    bodies, q, s, parameters = n_link_pendulum(n)
    m, l, J, J_a, g = parameters
    I_c = cylinder(m=1.0, radius=0.01, length=1.0, axis="z")  # chain(): the link's inertia
    values = {m: 1.0, l: 1.0, J: I_c[0, 0], J_a: I_c[2, 2], g: 9.81}
    all_formulations = [
        Formulation("projection (symbolic)", lambda: projection_equation(bodies, q, s, parameters=parameters)),
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
        Formulation("lagrange (2nd kind)", lambda: _lagrange(bodies, q, s, parameters),
                    note="d/dt ∂T/∂q̇ − ∂T/∂q = Q from the same bodies"),
    ]
    return _gauss_form_rows(chain(n), _select(all_formulations, formulations), values, simulate, t_end)


def _lagrange(bodies, q, s, parameters):
    """Lagrange's equations of the 2nd kind d/dt ∂T/∂q̇ − ∂T/∂q = Q with ṡ = q̇ (scleronomic,
    T quadratic in ṡ): M = ∂²T/∂ṡ², rhs = Q + ∂T/∂q − (∂²T/∂ṡ∂q) ṡ, Q = Σ (∂v_c/∂ṡ)ᵀ f."""
    from projeq.symbolic import GaussForm

    T, Q = 0, sp.zeros(len(s), 1)
    for b in bodies.values():
        v_c, omega = sp.Matrix(b.v_c), sp.Matrix(b.omega)
        T += b.m * v_c.dot(v_c) / 2 + (omega.T * sp.Matrix(b.I_c) * omega)[0] / 2
        Q += v_c.jacobian(s).T * sp.Matrix(b.f) + omega.jacobian(s).T * sp.Matrix(b.M)
    p = sp.Matrix([T]).jacobian(s).T
    rhs = Q + sp.Matrix([T]).jacobian(q).T - p.jacobian(q) * sp.Matrix(s)
    return GaussForm(p.jacobian(s), rhs, tuple(q), tuple(s), sp.eye(len(q)),
                     parameters=parameters)


def _select(available, wanted):
    if wanted is None:
        return available
    names = [f.name for f in available]
    unknown = [w for w in wanted if w not in names]
    if unknown:
        raise ValueError(f"formulations: unknown {unknown}; available: {names}")
    return [f for f in available if f.name in wanted]


def _car(formulations, simulate, t_end):
    from projeq.scenes import car
    from projeq.symbolic import Body, GaussForm, hamel_equations, projection_equation

    x, y, g = q = sp.symbols("x y gamma")
    vx, vy, wz = sp.symbols("v_x v_y omega_z")
    m, c, C0 = parameters = sp.symbols("m c C0")
    K = sp.Matrix([[sp.cos(g), 0], [sp.sin(g), 0], [0, 1]])

    def projection():  # B(10)–(12): R fixed to the car, v_y = 0 inserted up front
        body = Body(v_c=(vx, c * wz, 0), omega=(0, 0, wz), m=m, I_c=sp.diag(0, 0, C0 - m * c**2), omega_IR=(0, 0, wz))
        return projection_equation({"car": body}, q, (vx, wz), K, parameters)

    def hamel():  # B(3)–(8) with v_y, then v_y = 0 inserted after the derivation (THEORY §8)
        H = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
        T = m * (vx**2 + (vy + c * wz) ** 2) / 2 + (C0 - m * c**2) * wz**2 / 2
        s_ddot = sp.symbols("vx_dot vy_dot wz_dot")
        residual = hamel_equations(T, q, (vx, vy, wz), H, sp.zeros(3, 1), s_ddot, parameters=parameters)
        residual = residual.subs({vy: 0, s_ddot[1]: 0})
        M, rhs = sp.linear_eq_to_matrix([residual[0], residual[2]], [s_ddot[0], s_ddot[2]])
        return GaussForm(M, rhs, q, (vx, wz), K, parameters=parameters)

    values = {m: 1200.0, c: 1.2, C0: 3228.0}  # scenes.car defaults
    available = [
        Formulation("projection (symbolic)", projection, note="B(9)"),
        Formulation("hamel", hamel, note="β of B(7); v_y = 0 after the derivation"),
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
    ]
    multiplier = ("lagrange + multipliers", "hamilton canonical + multipliers", "barhorst lagrangian canonical")
    wanted = [f for f in (formulations or [f.name for f in available] + list(multiplier)) if f not in multiplier]
    system = car()
    rows = _gauss_form_rows(system, _select(available, wanted), values, simulate, t_end)
    for form, name in zip(("lagrange", "hamilton", "barhorst"), multiplier):
        if formulations is None or name in formulations:
            rows.append(_car_multiplier_row(form, name, system, values, simulate, t_end))
    return rows


def _car_multiplier_row(form: str, name: str, system, values: dict, simulate: bool, t_end: float) -> dict:
    """The car in (x, y, γ) with the Pfaffian constraint −sin γ ẋ + cos γ ẏ = 0 and a
    multiplier (seed 001, K(7) and K(23)–(26)); compared by its motion with the reference."""
    from sympy.physics.mechanics import dynamicsymbols

    from projeq.simulation import simulate as run
    from projeq.symbolic import t as time_symbol
    from projeq.symbolic.canonical import lagrangian_canonical
    from projeq.symbolic.lagrange import multiplier_system

    def derive():
        x, y, g = q = dynamicsymbols("x y gamma")
        xd, yd, gd = (qi.diff(time_symbol) for qi in q)
        m, c, C0 = values
        v_c = (xd - c * sp.sin(g) * gd, yd + c * sp.cos(g) * gd)  # mass centre O + c e_x
        L = m * (v_c[0] ** 2 + v_c[1] ** 2) / 2 + (C0 - m * c**2) * gd**2 / 2
        ms = multiplier_system(L, q, time_symbol, A=[[-sp.sin(g), sp.cos(g), 0]], parameters=values)
        if form == "barhorst":  # seed 000, eqs. 45–52: ODE in (q, p), no multiplier
            canonical = lagrangian_canonical(ms, independent=[x, g])  # u = (ẋ, γ̇), ẏ = tan γ ẋ
            return (ms, canonical), canonical.p_dot
        return (ms, None), (ms.lagrange_equations() if form == "lagrange" else sp.Matrix([*ms.canonical_equations()]))

    ((ms, canonical), equations), seconds = _timed(derive)
    row = {"formulation": name, "derivation_s": seconds, "n_ops": _cse_ops(equations),
           "note": "q̇ = K u, ṗ = Kᵀ(∂L/∂q + Q) + K̇ᵀ∂L/∂q̇: no multiplier" if canonical else
           "index-1 by differentiating the constraint once (λ solved), no Baumgarte"}
    if not simulate:
        row.update(identical="not compared", check="equations in (x, y, γ, λ): compared by motion only")
        return row
    reference = run(system, t_end, rtol=1e-9, atol=1e-12)
    q0, s0 = reference.q[0], reference.s_dot[0]
    q_dot0 = system.q_dot(q0, s0)
    if canonical is None:
        sol, row["integration_s"] = _timed(lambda: ms.simulate(
            q0, q_dot0, (0.0, t_end), form=form, t_eval=reference.t, rtol=1e-9, atol=1e-12))
    else:
        independent = [ms.q_symbols.index(sp.Symbol(str(u)[: -len("_dot")])) for u in canonical.u]
        sol, row["integration_s"] = _timed(lambda: canonical.simulate(
            q0, q_dot0[independent], (0.0, t_end), t_eval=reference.t, rtol=1e-9, atol=1e-12))
        K = sp.lambdify([canonical.q], canonical.K.subs(canonical.parameters), modules="numpy")
        sol.q_dot = np.column_stack([np.asarray(K(qi), float) @ ui for qi, ui in zip(sol.q.T, sol.u.T)])
    gap = float(np.max(np.abs(sol.q.T - reference.q)))
    # 1e-6 m: both integrations at rtol 1e-9 over metres of travel; a modelling error is O(1)
    row.update(identical="yes" if gap < 1e-6 else "no", check=f"numeric, same motion, max |Δq| {gap:.1e}")
    s_dot = np.column_stack([np.cos(sol.q[2]) * sol.q_dot[0] + np.sin(sol.q[2]) * sol.q_dot[1], sol.q_dot[2]])
    kinetic = np.array([system.energy(qi, si)[0] for qi, si in zip(sol.q.T, s_dot)])
    row["energy_drift"] = float(np.max(np.abs(kinetic - kinetic[0])) / kinetic[0])
    row["constraint_drift"] = float(max(abs(ms.velocity_residual(0.0, qi, ui)).max() for qi, ui in zip(sol.q.T, sol.q_dot.T)))
    return row


def _knife_edge_disc(formulations, simulate, t_end):
    from projeq.scenes import knife_edge_disc

    available = [
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
        Formulation("projection (symbolic)", note="not available: gauss_form(system) not yet in projeq.symbolic"),
        Formulation("lagrange + multipliers", note="not available: no symbolic disc model to feed multiplier_system"),
        Formulation("hamilton canonical", note="not available: as for lagrange + multipliers"),
    ]
    return _gauss_form_rows(knife_edge_disc(), _select(available, formulations), {}, simulate, t_end)


def _spinning_beam(formulations, simulate, t_end):
    """Field equations B(18) vs B(23) and their Ritz models under spin-up (THEORY §9)."""
    from projeq.scenes.elastic import spin_up_motion
    from projeq.symbolic import spinning_beam as sb

    derivations = {
        "projection (field equations, Ritz)": (sb.projection_field_equations, sb._projection_ritz),
        "hamilton (field equations, Ritz)": (sb.hamilton_field_equations, sb._hamilton_ritz),
    }
    wanted = list(derivations) if formulations is None else formulations
    unknown = [w for w in wanted if w not in derivations]
    if unknown:
        raise ValueError(f"formulations: unknown {unknown}; available: {list(derivations)}")
    rows = []
    for name in wanted:
        fields, ritz = derivations[name]
        (equations, _), seconds = _timed(lambda: (fields(), ritz(2)))
        row = {"formulation": name, "derivation_s": seconds, "n_ops": _cse_ops(equations)}
        if name.startswith("projection"):
            row.update(identical="reference", check="", note="B(23): ρI α̈ coupling skew")
        else:
            d_v, d_w = sb.field_difference()  # after the timing: it reuses both derivations
            row.update(identical="no" if (d_v, d_w) != (0, 0) else "yes", check="symbolic",
                       note=f"B(18): v equation − B(23)'s = {d_v}, w equations equal: {d_w == 0}")
        if simulate:
            model = sb.ritz_models(2, rho_I_value=0.05)[name.split()[0]]
            a0 = np.array([0.01, 0.0, 0.0, 0.0])
            (times, a, _, E, W), row["integration_s"] = _timed(
                lambda: sb.simulate_ritz(model, spin_up_motion(3.0, 2.0), a0, np.zeros(4), t_end))
            row["energy_drift"] = float(np.max(np.abs(E - E[0] - W)) / E[0])
            row["note"] += "; energy_drift = work-balance residual |E − E0 − W|/E0 under spin-up"
        rows.append(row)
    return rows


COMPARISONS = {
    "car": _car,
    "knife_edge_disc": _knife_edge_disc,
    "spinning_beam": _spinning_beam,
    "n_link_pendulum": _pendulum,
}
DEFAULT_T_END = {"car": 2.0, "knife_edge_disc": 2.0, "spinning_beam": 3.0, "n_link_pendulum": 2.0}


def compare(name: str, formulations=None, simulate: bool = True, t_end: float | None = None) -> ComparisonTable:
    """Compare the formulations of the system ``name`` (a key of ``COMPARISONS``).

    formulations : names of the rows to compute (default all); the first is the reference
    simulate : also integrate each formulation's equations (rtol 1e-9, atol 1e-12)
    t_end : simulated time in s (default ``DEFAULT_T_END[name]``)

    Each row: derivation time (s), operation count after CSE (``sympy.count_ops``),
    whether the equations equal the reference (``check`` says how: symbolic difference or
    random states), integration time (s), relative energy drift, max constraint residual.
    """
    if name not in COMPARISONS:
        raise ValueError(f"name: unknown comparison {name!r}; choose one of {sorted(COMPARISONS)}")
    t_end = DEFAULT_T_END[name] if t_end is None else t_end
    if not (isinstance(t_end, (int, float)) and t_end > 0):
        raise ValueError(f"t_end: must be a positive number of seconds, got {t_end!r}")
    if formulations is not None:
        formulations = [formulations] if isinstance(formulations, str) else list(formulations)
    return ComparisonTable(name, COMPARISONS[name](formulations, simulate, float(t_end)))


def main(argv=None) -> int:
    """``projeq compare NAME [--csv PATH] [--no-simulate] [--t-end T]``: print the table."""
    parser = argparse.ArgumentParser(prog="projeq compare", description=compare.__doc__.splitlines()[0])
    parser.add_argument("name", choices=sorted(COMPARISONS))
    parser.add_argument("--csv", metavar="PATH", help="also write the table as CSV")
    parser.add_argument("--no-simulate", action="store_true", help="derive and check only")
    parser.add_argument("--t-end", type=float, default=None, help="simulated time (s)")
    parser.add_argument("--formulation", action="append", help="restrict to these rows (repeatable)")
    args = parser.parse_args(argv)
    try:
        table = compare(args.name, args.formulation, simulate=not args.no_simulate, t_end=args.t_end)
    except ValueError as error:
        print(f"error: {error}")
        return 2
    print(table.format())
    if args.csv:
        table.to_csv(args.csv)
    return 0
