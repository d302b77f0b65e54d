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

import csv
import time
from dataclasses import dataclass, field, replace
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
    from projeq.symbolic.projection import operation_count

    return operation_count(*sp.cse(list(expressions)))


def _timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def _equal(reference, other, evaluators, system) -> tuple[str, str]:
    """("yes"/"no", how): symbolic difference when both are small, else random states."""
    if reference is not None and other is not None and sp.count_ops(other.rhs) < 400:
        differences = [*(reference.M - other.M), *(reference.rhs - other.rhs)]
        same = all(_vanishes(d, reference.q) for d in differences)
        return ("yes" if same else "no"), "symbolic"
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(5):
        q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
        a_ref, a = (e.accelerations(q, s_dot, 0.0) for e in evaluators)
        errors.append(np.max(np.abs(a - a_ref)) / max(1.0, np.max(np.abs(a_ref))))
    # 1e-9: round-off of two independently compiled evaluators, far below any modelling difference
    return ("yes" if max(errors) < 1e-9 else "no"), f"numeric, 5 random states, max rel err {max(errors):.1e}"


def _vanishes(expression, q) -> bool:
    """expression ≡ 0: by a cheap exact normal form (trigonometric sums expanded, sin² q =
    1 − cos² q, expanded) — zero there is a proof —, else by ``sympy.simplify``."""
    normal = sp.expand(sp.expand(sp.expand_trig(expression)).subs({sp.sin(x) ** 2: 1 - sp.cos(x) ** 2 for x in q}))
    return normal == 0 or sp.simplify(expression) == 0


def _simulate_row(system, evaluator, t_end: float) -> dict:
    from projeq.simulation.driver import simulate

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
    from projeq.subsystems.inertia import cylinder
    from projeq.scenes import chain
    from projeq.symbolic import gauss_form, projection_equation
    from projeq.symbolic.examples import chain_parameters, kane_pendulum, n_link_pendulum

    n = 2
    bodies, q, s, parameters = n_link_pendulum(n)
    m, l, J, J_a, g = parameters
    I_c = cylinder(m=1.0, radius=0.01, length=1.0, axis="z")  # chain(): the link's inertia
    values = {m: 1.0, l: 1.0, J: I_c[0, 0], J_a: I_c[2, 2], g: 9.81}
    all_formulations = [
        Formulation("projection (symbolic)", lambda: projection_equation(bodies, q, s, parameters=parameters)),
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
        Formulation("projection (symbolic, recursive chain)", lambda: gauss_form(chain(n), chain_parameters(n)),
                    note="gauss_form(scenes.chain(2)): body frames, composite inertias"),
        Formulation("lagrange (2nd kind)", lambda: _lagrange(bodies, q, s, parameters),
                    note="d/dt ∂T/∂q̇ − ∂T/∂q = Q from the same bodies"),
        Formulation("kane (sympy.physics.mechanics)", lambda: _plain(*kane_pendulum(n), q, s, parameters),
                    note="KanesMethod, M u̇ = forcing"),
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


def _plain(q_t, u_t, M, forcing, q, s, parameters):
    """A Gauss form from sympy.physics.mechanics output: q(t), u(t) replaced by q, s (u = q̇)."""
    from projeq.symbolic import GaussForm

    symbols = dict(zip(q_t, q)) | dict(zip(u_t, s))
    return GaussForm(M.xreplace(symbols), forcing.xreplace(symbols), tuple(q), tuple(s), sp.eye(len(q)),
                     parameters=parameters)


def _numbers(gauss, values: dict):
    """``gauss`` with its parameters replaced by the numbers ``values`` (parameters left: none)."""
    values = {k: sp.Float(v) for k, v in values.items()}
    return replace(gauss, M=gauss.M.xreplace(values), rhs=gauss.rhs.xreplace(values), K=gauss.K.xreplace(values),
                   parameters=())


def _select(available, wanted):
    if wanted is None:
        return available
    names = [f.name for f in available]
    unknown = [w for w in wanted if w not in names]
    if unknown:
        raise ValueError(f"formulations: unknown {unknown}; available: {names}")
    return [f for f in available if f.name in wanted]


def _car(formulations, simulate, t_end):
    from projeq.studies.compare_multipliers import CAR_COORDINATES, car_multiplier_system, multiplier_rows, \
        without_multiplier_rows
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
    system = car()
    rows = _gauss_form_rows(system, _select(available, without_multiplier_rows(formulations, available)), values,
                            simulate, t_end)
    return rows + multiplier_rows(formulations, lambda: car_multiplier_system(values), system, CAR_COORDINATES,
                                  simulate, t_end)


def _knife_edge_disc(formulations, simulate, t_end):
    """The knife-edge disc of the lecture (seed 001, slides 28–37): the scene's Projection
    Equation numerically and symbolically (``gauss_form``), and the lecture's multiplier
    and canonical forms in (x, y, z, ψ, ϕ, θ)."""
    from projeq.studies.compare_multipliers import FullCoordinates, multiplier_rows, without_multiplier_rows
    from projeq.scenes import knife_edge_disc
    from projeq.symbolic import gauss_form
    from projeq.symbolic.formulation_examples import DISC_UNITS, hamel_disc, lecture_disc, lecture_disc_state

    system = knife_edge_disc()
    available = [
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
        Formulation("projection (symbolic)", lambda: gauss_form(system), note="gauss_form(scenes.knife_edge_disc())"),
        Formulation("hamel", lambda: _numbers(hamel_disc(), DISC_UNITS),
                    note="β of ṡ = (ψ̇, ϕ̇, θ̇, c₁, c₂); c = 0 after the derivation"),
    ]
    rows = _gauss_form_rows(system, _select(available, without_multiplier_rows(formulations, available)), {},
                            simulate, t_end)
    disc_coordinates = FullCoordinates(
        initial=lecture_disc_state,
        to_scene=lambda q, q_dot: (q[[0, 1, 3, 4, 5]].T, q_dot[3:].T),  # drop z = −r cos ϕ; ṡ = (ψ̇, ϕ̇, θ̇)
        independent=("psi", "phi", "theta"),
    )
    return rows + multiplier_rows(formulations, lecture_disc.__wrapped__, system, disc_coordinates, simulate, t_end)


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
    notes = {"projection": "B(23): slice balance in the co-rotating frame R projected on R's y, z: "
                           "ρI α̈ coupling skew (circulatory)",
             "hamilton": "B(18): the same balance projected on the Cardan axes (x, y′, z″): ρI α̈ coupling "
                         "symmetric (a time-dependent potential)"}
    rows, motions = [], {}
    for name in wanted:
        fields, ritz = derivations[name]
        (equations, _), seconds = _timed(lambda: (fields(), ritz(2)))
        kind = name.split()[0]
        row = {"formulation": name, "derivation_s": seconds, "n_ops": _cse_ops(equations), "note": notes[kind]}
        if kind == "projection":
            row.update(identical="reference", check="")
        else:
            d_v, d_w = sb.field_difference()  # after the timing: it reuses both derivations
            row.update(identical="no" if (d_v, d_w) != (0, 0) else "yes", check="symbolic",
                       note=f"{row['note']}; v equation − B(23)'s = {d_v}, w equations equal: {d_w == 0}")
        if simulate:
            model = sb.ritz_models(2, rho_I_value=0.05, kinds=(kind,))[kind]
            a0 = np.array([0.01, 0.0, 0.0, 0.0])
            (times, a, _, E, W), row["integration_s"] = _timed(
                lambda: sb.simulate_ritz(model, spin_up_motion(3.0, 2.0), a0, np.zeros(4), t_end))
            motions[kind] = a
            row["energy_drift"] = float(np.max(np.abs(E - E[0] - W)) / E[0])
            row["note"] += "; energy_drift = work-balance residual |E − E0 − W|/E0 under spin-up"
        rows.append(row)
    if len(motions) == 2:  # the Ritz models (n = 2, ρI = 0.05) under the same spin-up from a = (0.01, 0, 0, 0)
        gap = float(np.max(np.abs(motions["hamilton"] - motions["projection"])))
        rows[-1]["note"] += f"; Ritz motions under spin-up differ by max |Δa| = {gap:.2e} m (equal at constant spin)"
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
