"""Compare formulations of the equations of motion of one system.

``compare(name)`` derives the equations of the named system with each available
formulation, times the derivation, counts operations after common-subexpression
elimination, checks whether the equations are identical to the first (reference)
formulation, and optionally simulates each, reporting integration time, energy drift and
constraint drift. Every formulation that yields a Gauss form M s̈ = rhs in the same
coordinates is simulated through :func:`projeq.simulate` with a compiled evaluator, so all
rows share one integrator and one energy function.

Where a formulation's equations differ from the reference, ``difference`` holds the terms
(reference minus that formulation, one sympy expression per equation) and ``why`` the
reason; ``derivation`` says how each formulation follows from Bremer's Central Equation
B(2) (docs/theory.md). Effort is measured the same way for every row (``EFFORT``), and the
table states H. Bremer's effort claims ("Problems in Fast Moving Non-Holonomic Elastic
Systems") beside the measured numbers, agreeing or not.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
import sympy as sp

from projeq.studies.compare_barhorst import BARHORST_STUDIES, BARHORST_T_END
from projeq.studies.effort import (DERIVATION_REPEATS, EFFORT, as_symbols, cse_ops, derivation_repeats,
                                   derivation_timed, timed)
from projeq.studies.table import Table
from projeq.symbolic.algebra import trig_normal

COLUMNS = ("formulation", "derivation_s", "n_ops", "identical", "check", "difference", "why", "integration_s",
           "energy_drift", "constraint_drift", "derivation", "note")
#: the columns of the text table (header shown); the others are printed below it, wrapped
TEXT_COLUMNS = {"formulation": "formulation", "derivation_s": "deriv_s", "n_ops": "n_ops", "identical": "identical",
                "integration_s": "integ_s", "energy_drift": "E_drift", "constraint_drift": "c_drift"}
TEXT_WIDTH = 100


@dataclass
class ComparisonTable:
    """Rows of a comparison, one dict per formulation with the keys of ``COLUMNS``; ``effort``
    says how derivation_s and n_ops were measured, ``claims`` the documents' effort claims
    beside the measured numbers."""

    name: str
    rows: list = field(default_factory=list)
    effort: str = ""
    claims: list = field(default_factory=list)

    def format(self) -> str:
        """Plain text at most ``TEXT_WIDTH`` columns wide: the table of numbers (3 significant
        digits), then per row its check, difference (abbreviated), why and note, the derivations
        from B(2), the effort procedure and the claims."""
        grid = Table(tuple(TEXT_COLUMNS.values()), [[row.get(c) for c in TEXT_COLUMNS] for row in self.rows])
        width = max(len(line) for line in grid.to_text().splitlines())
        if width > TEXT_WIDTH:  # shorten the formulation names, the one column of free text
            fitted = max(len("formulation"), max(len(row["formulation"]) for row in self.rows) - (width - TEXT_WIDTH))
            grid = replace(grid, rows=[(_fit(row[0], fitted), *row[1:]) for row in grid.rows])
        lines = grid.to_text().splitlines()
        for row in self.rows:
            details = _details(row)
            if details:
                lines += [_fit(row["formulation"], TEXT_WIDTH), *details]
        derivations = list(dict.fromkeys(row["derivation"] for row in self.rows if row.get("derivation")))
        if derivations:
            lines.append("derivations from the Central Equation B(2), d/dt[(∂T/∂ṡ) δs] − δT − δW = 0 "
                         "(docs/theory.md):")
            lines += [line for text in derivations for line in _wrap(text, "- ", "  ")]
            lines += _wrap(CENTRAL_EQUATION_CODE, "in code: ", "  ")
        if self.effort:
            lines += _wrap(self.effort, "effort: ", "  ")
        lines += [line for claim in self.claims for line in _wrap(claim, "- ", "  ")]
        return f"compare {self.name}\n" + "\n".join(lines)

    def to_csv(self, path) -> None:
        """Write the rows to ``path`` as CSV with a header line (``difference`` in full): ``COLUMNS``,
        then any further keys the rows carry (Barhorst's study: his reported numbers)."""
        columns = COLUMNS + tuple(dict.fromkeys(k for row in self.rows for k in row if k not in COLUMNS))
        Table(columns, [[_csv_cell(row.get(c)) for c in columns] for row in self.rows]).to_csv(path)


def _csv_cell(value):
    return _difference_text(value) if isinstance(value, tuple) else value


def _fit(text: str, width: int) -> str:
    """``text`` cut to ``width`` characters, with … where it was cut."""
    return text if len(text) <= width else text[: width - 1] + "…"


def _wrap(text: str, first: str, rest: str) -> list[str]:
    return textwrap.wrap(text, TEXT_WIDTH, initial_indent=first, subsequent_indent=rest, break_on_hyphens=False)


def _difference_text(difference) -> str:
    """One string per equation, functions of time and space as plain symbols (α̈ → alpha_tt)."""
    return "[" + ", ".join(sp.sstr(as_symbols(d)) for d in difference) + "]"


def _details(row) -> list[str]:
    """The row's check, nonzero difference (one line, abbreviated), why and note, indented."""
    lines = []
    if row.get("check"):
        lines += _wrap(row["check"], "  check: ", "    ")
    if row.get("difference") and any(d != 0 for d in row["difference"]):
        lines.append(_fit("  difference (reference − this): " + _difference_text(row["difference"]), TEXT_WIDTH))
    for key in ("why", "note", "barhorst"):
        if row.get(key):
            lines += _wrap(row[key], f"  {key}: ", "    ")
    return lines


@dataclass
class Formulation:
    """One way to derive the equations: ``derive()`` returns a GaussForm, or ``evaluator``
    names a numeric method of the System ("dense", "recursive"); neither: not available."""

    name: str
    derive: Callable | None = None
    evaluator: str | None = None
    note: str = ""
    why: str = ""  # the reason, if its equations differ from the reference


def _residuals(gauss) -> sp.Matrix:
    """M s̈ − rhs of a Gauss form, s̈ as the symbols ``<s>_dot``."""
    return gauss.M * sp.Matrix([sp.Symbol(f"{x}_dot") for x in gauss.s]) - gauss.rhs


def _compare_equations(reference, other, evaluators, system) -> dict:
    """identical ("yes"/"no"), check (how) and difference (reference − other per equation, or None).

    Symbolic when both are Gauss forms in the same symbols: the residuals' difference in the
    normal form of :func:`~projeq.symbolic.algebra.trig_normal` (zero there is a proof). Otherwise at random states."""
    if reference is not None and other is not None and (reference.q, reference.s) == (other.q, other.s):
        difference = tuple(trig_normal(d, reference.q) for d in _residuals(reference) - _residuals(other))
        return {"identical": "yes" if all(d == 0 for d in difference) else "no", "difference": difference,
                "check": "symbolic: residuals subtracted, sin² + cos² = 1 normal form"}
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(5):
        q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
        a_ref, a = (e.accelerations(q, s_dot, 0.0) for e in evaluators)
        errors.append(np.max(np.abs(a - a_ref)) / max(1.0, np.max(np.abs(a_ref))))
    # 1e-9: round-off of two independently compiled evaluators, far below any modelling difference
    return {"identical": "yes" if max(errors) < 1e-9 else "no", "difference": None,
            "check": f"numeric, 5 random states, max rel err {max(errors):.1e}"}


def _simulate_row(system, evaluator, t_end: float) -> tuple[dict, np.ndarray]:
    """(integration time, energy and constraint drift of a run; the run's q at its output times)."""
    from projeq.simulation.driver import simulate

    result = simulate(system, t_end, evaluator=evaluator, rtol=1e-9, atol=1e-12)
    drift = float(np.abs(result.constraint_residual).max()) if result.constraint_residual.size else None
    return {"integration_s": result.wall_time, "energy_drift": result.energy_drift, "constraint_drift": drift}, result.q


def _gauss_form_rows(system, formulations, values, simulate: bool, t_end: float) -> list[dict]:
    """Rows for formulations sharing the coordinates of ``system`` (first one = reference);
    ``values``: numbers for the parameters of the symbolic forms."""
    rows, reference, reference_evaluator, reference_q = [], None, None, None
    for f in formulations:
        row = {"formulation": f.name, "note": f.note}
        if f.derive is None and f.evaluator is None:
            row["identical"] = "not available"
            rows.append(row)
            continue
        gauss = None
        if f.derive is not None:
            try:
                gauss, row["derivation_s"] = derivation_timed(f.derive)
            except ValueError as exc:  # refused (gauss_form of callable loads): a row saying why
                row.update(identical="not available", note=f"{f.note}; not derived: {exc}".lstrip("; "))
                rows.append(row)
                continue
            row["n_ops"] = cse_ops([*gauss.M, *gauss.rhs], values)
            evaluator = gauss.evaluator({k: v for k, v in values.items() if k in gauss.parameters})
        else:
            evaluator = f.evaluator
            row["note"] = row["note"] or "numeric evaluator: no symbolic expressions"
        numeric = system.evaluator(evaluator) if isinstance(evaluator, str) else evaluator
        if reference_evaluator is None:
            reference, reference_evaluator = gauss, numeric
            row["identical"], row["check"] = "reference", ""
        else:
            row.update(_compare_equations(reference, gauss, (reference_evaluator, numeric), system))
            if row["identical"] == "no":
                row["why"] = f.why
        if simulate:
            metrics, q = _simulate_row(system, evaluator, t_end)
            row.update(metrics)
            reference_q = q if reference_q is None else reference_q
            if row["identical"] == "no" and q.shape == reference_q.shape:
                row["note"] += f"; its motion leaves the reference's by max |Δq| = {np.abs(q - reference_q).max():.2g}"
        rows.append(row)
    return rows


# -- why formulations differ ----------------------------------------------------------------
TOO_EARLY = "hamel (constraint inserted too early)"
CAR_TOO_EARLY = ("constraint inserted before the derivation: with v_y = 0 in T, ∂T/∂v_y = m (v_y + c ω_z) is 0 "
                 "instead of m c ω_z, so Hamel's terms β₂^{3,1} ω_z ∂T/∂v_y and β₂^{1,3} v_x ∂T/∂v_y of B(8) are "
                 "lost (Bremer §2.1: \"not allowed to set v_y = 0 in advance\"). The lost terms do no work "
                 "(v_x Δ₁ + ω_z Δ₂ = 0): the energy is conserved, the motion is wrong.")
DISC_TOO_EARLY = ("constraint inserted before the derivation: with c₁ = c₂ = 0 in T, ∂T/∂c_ν (the horizontal "
                  "momentum m v_G) is 0, so Hamel's terms (∂T/∂c_ν) ṡ_μ β_ν^{μ,n} of B(3) are lost. They do no "
                  "work (β_ν^{μ,n} = −β_ν^{n,μ}, B(4)): the energy is conserved, the motion is wrong.")
BEAM_NON_ORTHOGONAL = ("non-orthogonal axes: Hamilton's principle differentiates T along the Cardan rates "
                       "(α̇, −ẇ′, v̇′), whose axes (x, y′, z″) are not orthogonal; its v equation picks up the "
                       "torsional balance ρI_x α̈ = 2ρI α̈ weighted by w′ (Bremer §4.1), so B(18)'s ρI α̈ coupling is "
                       "symmetric where B(23)'s, in the co-rotating frame, is skew.")
BEAM_TORSION_FREE = ("slice rotation: B(23) gives the slice no turn about x when the beam bends, B(18) the Cardan "
                     "angle −½v′w′; a beam without torsional strain turns by the geometric twist τ, which changes "
                     "the ρI α̈ terms under spin-up (equal at constant spin).")


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
        Formulation("projection (symbolic, recursive chain)",
                    lambda: _in_symbols(gauss_form(chain(n), chain_parameters(n)), q, s),
                    note="gauss_form(scenes.chain(2)): body frames, composite inertias"),
        Formulation("lagrange (2nd kind)", lambda: _lagrange(bodies, q, s, parameters),
                    note="d/dt ∂T/∂q̇ − ∂T/∂q = Q from the same bodies"),
        Formulation("kane (sympy.physics.mechanics)", lambda: _plain(*kane_pendulum(n), q, s, parameters),
                    note="KanesMethod, M u̇ = forcing"),
    ]
    return _gauss_form_rows(chain(n), _select(all_formulations, formulations), values, simulate, t_end)


def _lagrange(bodies, q, s, parameters):
    """Lagrange's equations of the 2nd kind as a Gauss form
    (:func:`projeq.studies.effort_growth.lagrange_steps`)."""
    from projeq.studies.effort_growth import lagrange_steps
    from projeq.symbolic import GaussForm

    steps = lagrange_steps(bodies, q, s)
    return GaussForm(steps["M"], steps["rhs"], tuple(q), tuple(s), sp.eye(len(q)), parameters=parameters)


def _plain(q_t, u_t, M, forcing, q, s, parameters):
    """A Gauss form from sympy.physics.mechanics output: q(t), u(t) replaced by q, s (u = q̇)."""
    from projeq.symbolic import GaussForm

    symbols = dict(zip(q_t, q)) | dict(zip(u_t, s))
    return GaussForm(M.xreplace(symbols), forcing.xreplace(symbols), tuple(q), tuple(s), sp.eye(len(q)),
                     parameters=parameters)


def _in_symbols(gauss, q, s):
    """``gauss`` with its coordinates and velocities renamed (in order) to the symbols ``q``, ``s``
    of another formulation of the same coordinates: their residuals can then be subtracted."""
    from projeq.symbolic.projection import GaussForm

    names = dict(zip((*gauss.q, *gauss.s), (*q, *s)))
    return GaussForm(gauss.M.xreplace(names), gauss.rhs.xreplace(names), tuple(q), tuple(s),
                     gauss.K.xreplace(names), gauss.t, gauss.parameters)


def _user_system(system, formulations, simulate: bool, t_end: float) -> list[dict]:
    """A user's System: its Projection Equation evaluated numerically, recursive (the reference)
    and dense, and derived in sympy (:func:`projeq.symbolic.gauss_form`; "not available", with the
    reason, where gauss_form refuses the System)."""
    from projeq.symbolic import gauss_form

    available = [Formulation("projection (numeric, recursive)", evaluator="recursive"),
                 Formulation("projection (numeric, dense)", evaluator="dense"),
                 Formulation("projection (symbolic)", lambda: gauss_form(system),
                             note="gauss_form(system): the System's own joints and bodies in sympy")]
    return _gauss_form_rows(system, _select(available, formulations), {}, simulate, t_end)


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

    def hamel(constraint_first=False):  # B(3)–(8) with v_y, then v_y = 0 inserted after the derivation
        H = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
        T = m * (vx**2 + (vy + c * wz) ** 2) / 2 + (C0 - m * c**2) * wz**2 / 2
        if constraint_first:  # the mistake of Bremer §2.1: v_y = 0 put into T before the derivation
            T = T.subs(vy, 0)
        s_ddot = sp.symbols("vx_dot vy_dot wz_dot")
        residual = hamel_equations(T, q, (vx, vy, wz), H, sp.zeros(3, 1), s_ddot, parameters=parameters)
        residual = residual.subs({vy: 0, s_ddot[1]: 0})
        M, rhs = sp.linear_eq_to_matrix([residual[0], residual[2]], [s_ddot[0], s_ddot[2]])
        return GaussForm(M, rhs, q, (vx, wz), K, parameters=parameters)

    values = {m: 1200.0, c: 1.2, C0: 3228.0}  # scenes.car defaults
    available = [
        Formulation("projection (symbolic)", projection, note="B(9) from B(11)–(12), v_y = 0 inserted up front"),
        Formulation("hamel", hamel, note="β of B(7); v_y = 0 after the derivation"),
        Formulation(TOO_EARLY, lambda: hamel(constraint_first=True), note="β of B(7); v_y = 0 put into T first",
                    why=CAR_TOO_EARLY),
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
    ]
    system = car()
    rows = _gauss_form_rows(system, _select(available, without_multiplier_rows(formulations, available)), values,
                            simulate, t_end)
    return rows + multiplier_rows(formulations, lambda: car_multiplier_system(values), system, CAR_COORDINATES,
                                  simulate, t_end)


def _knife_edge_disc(formulations, simulate, t_end):
    """The knife-edge disc of the lecture on non-holonomic systems (slides 28–37): the Projection
    Equation with the lecture's frame E (reference) and from the scene, numerically, Hamel's
    equations with the constraints inserted after and before the derivation, and the lecture's
    multiplier and canonical forms in (x, y, z, ψ, ϕ, θ)."""
    from projeq.studies.compare_multipliers import FullCoordinates, multiplier_rows, without_multiplier_rows
    from projeq.scenes import knife_edge_disc
    from projeq.symbolic import gauss_form
    from projeq.symbolic.formulation_examples import (
        DISC_UNITS, hamel_disc, lecture_disc, lecture_disc_state, projection_disc,
    )

    system = knife_edge_disc()
    available = [
        Formulation("projection (symbolic)", projection_disc,
                    note="B(10) with R = E (turns with heading and tilt, not with the spin), rolling in the velocities"),
        Formulation("projection (numeric, dense)", evaluator="dense"),
        Formulation("projection (numeric, recursive)", evaluator="recursive"),
        Formulation("projection (symbolic, from the scene)", lambda: gauss_form(knife_edge_disc()),
                    note="gauss_form(scenes.knife_edge_disc()): R = the body frame, building the scene included"),
        Formulation("hamel", hamel_disc, note="β of ṡ = (ψ̇, ϕ̇, θ̇, c₁, c₂); c = 0 after the derivation"),
        Formulation(TOO_EARLY, lambda: hamel_disc(constraints_first=True),
                    note="β of ṡ = (ψ̇, ϕ̇, θ̇, c₁, c₂); c = 0 put into T first", why=DISC_TOO_EARLY),
    ]
    rows = _gauss_form_rows(system, _select(available, without_multiplier_rows(formulations, available)),
                            DISC_UNITS, simulate, t_end)
    disc_coordinates = FullCoordinates(
        initial=lecture_disc_state,
        to_scene=lambda q, q_dot: (q[[0, 1, 3, 4, 5]].T, q_dot[3:].T),  # drop z = −r cos ϕ; ṡ = (ψ̇, ϕ̇, θ̇)
        independent=("psi", "phi", "theta"),
    )
    return rows + multiplier_rows(formulations, lecture_disc.__wrapped__, system, disc_coordinates, simulate, t_end)


def _spinning_beam(formulations, simulate, t_end):
    """Field equations B(18) vs B(23) and their Ritz models under spin-up."""
    from projeq.scenes.elastic import spin_up_motion
    from projeq.symbolic import spinning_beam as sb

    def torsion_free():
        """The torsion-free Ritz model (n = 2) is derived; it has no field equations, no steps are counted."""
        sb._torsion_free_ritz(2)
        return {}

    # (the field equations' steps, the Ritz model's steps at n = 2), each a dict of expressions
    derivations = {
        "projection (field equations, Ritz)": (sb.projection_field_steps,
                                               lambda: sb.projection_ritz_steps(2)[0]),
        "hamilton (field equations, Ritz)": (sb.hamilton_field_steps, lambda: sb.hamilton_ritz_steps(2)[0]),
        "torsion_free (Ritz, = RitzBeam)": (dict, torsion_free),
    }
    wanted = list(derivations) if formulations is None else formulations
    unknown = [w for w in wanted if w not in derivations]
    if unknown:
        raise ValueError(f"formulations: unknown {unknown}; available: {list(derivations)}")
    notes = {"projection": "B(23): slice balance in the co-rotating frame R projected on R's y, z: "
                           "ρI α̈ coupling skew (circulatory)",
             "hamilton": "B(18): the same balance projected on the Cardan axes (x, y′, z″): ρI α̈ coupling "
                         "symmetric (a time-dependent potential)",
             "torsion_free": "the beam without torsional strain (κ_x = 0): each slice turns about x by the "
                             "geometric twist τ = ½∫(v′w″ − w′v″)dξ, ρI α̈ terms ρI_x α̈ δ∫τ dx; projeq's "
                             "RitzBeam and a converged chain of rigid slices agree with it (docs/theory.md, "
                             "'The spinning beam's rotary inertia'); no field equations derived"}
    rows, motions = [], {}
    for name in wanted:
        fields, ritz = derivations[name]
        steps, seconds = derivation_timed(lambda: {**fields(), **ritz()})
        kind = name.split()[0]
        row = {"formulation": name, "derivation_s": seconds,
               "n_ops": sum(cse_ops(e) for e in steps.values()) if steps else None, "note": notes[kind]}
        if kind == "projection":
            row.update(identical="reference", check="")
        elif kind == "hamilton":
            difference = tuple(-d for d in sb.field_difference())  # B(23) − B(18), per equation (v, w)
            row.update(identical="no" if any(d != 0 for d in difference) else "yes", difference=difference,
                       check="symbolic: the field equations subtracted", why=BEAM_NON_ORTHOGONAL)
        else:
            row.update(identical="no", check="numeric: the Ritz motions under spin-up", why=BEAM_TORSION_FREE)
        if simulate:
            model = sb.ritz_models(2, rho_I_value=0.05, kinds=(kind,))[kind]
            a0 = np.array([0.01, 0.0, 0.0, 0.0])
            (times, a, _, E, W), row["integration_s"] = timed(
                lambda: sb.simulate_ritz(model, spin_up_motion(3.0, 2.0), a0, np.zeros(4), t_end))
            motions[kind] = a
            row["energy_drift"] = float(np.max(np.abs(E - E[0] - W)) / E[0])
            row["note"] += "; energy_drift = work-balance residual |E − E0 − W|/E0 under spin-up"
            if kind != "projection" and "projection" in motions:
                gap = float(np.max(np.abs(a - motions["projection"])))
                row["note"] += f"; Ritz motion under spin-up differs from B(23)'s by max |Δa| = {gap:.2e} m"
        rows.append(row)
    return rows


COMPARISONS = {
    "car": _car,
    "knife_edge_disc": _knife_edge_disc,
    "spinning_beam": _spinning_beam,
    "n_link_pendulum": _pendulum,
}
DEFAULT_T_END = {"car": 2.0, "knife_edge_disc": 2.0, "spinning_beam": 3.0, "n_link_pendulum": 2.0}
COMPARISONS.update(BARHORST_STUDIES)  # A. A. Barhorst's formulation study (projeq.studies.compare_barhorst)
DEFAULT_T_END.update(BARHORST_T_END)


#: Where the derivations from B(2) are code, not only text.
CENTRAL_EQUATION_CODE = ("projeq.symbolic.central_equation(bodies, q, s, H, constrained) takes T (from the bodies' "
                         "velocities), ṡ = H q̇ and δW once and derives Hamel's equations (.hamel()), the Projection "
                         "Equation (.projection()), Kane's (.kane()) and Lagrange's with multipliers (.lagrange()); "
                         "tests/symbolic/test_central.py checks them against B(8), B(9), B(12) and KanesMethod.")


#: How each formulation follows from the Central Equation B(2) (docs/theory.md), by the first
#: prefix of the formulation's name that matches.
DERIVATIONS = (
    ("projection (numeric", "Projection Equation, numeric: B(10) evaluated at each state, by the dense Gauss form "
                            "B(14) or the order-n elimination of B(15); nothing is derived symbolically."),
    ("projection (field", "Projection Equation for beam slices: B(2) as the virtual work B(20) with δy = D̄∘δs "
                          "(B(22)), integrated by parts with the adjoint operator D (B(21)) into B(23)."),
    ("projection", "Projection Equation: B(2) with the Cartesian positions of the mass elements, where "
                   "d/dt δr = δṙ, is B(1); δr = (∂ṙ/∂ṡ) δs with velocities that already satisfy the constraints "
                   "gives B(10) — no derivative of T, so the constraints may go in first."),
    ("hamel", "Hamel: B(2) with ṡ = H(q) q̇; d δs − δ ds = Σ β ṡ δs (B(4)) gives B(3). The β terms carry "
              "∂T/∂ṡ_ν of every speed, so T must keep the constrained speeds until the end."),
    ("lagrange +", "Lagrange with multipliers: B(2) in redundant q, δq restricted by A δq = 0 and adjoined with "
                   "λ: d/dt ∂L/∂q̇ − ∂L/∂q − Q = Aᵀλ with A q̇ = b."),
    ("lagrange", "Lagrange (2nd kind): B(2) with ṡ = q̇ (H = E): d δq = δ dq, so d/dt ∂T/∂q̇ − ∂T/∂q = Q."),
    ("hamilton canonical", "Hamilton's canonical equations with multipliers: the multiplier form with p = ∂L/∂q̇ "
                           "and H = pᵀq̇ − L: q̇ = ∂H/∂p, ṗ = −∂H/∂q + Q + Aᵀλ."),
    ("hamilton", "Hamilton's principle: B(2) integrated over [t₀, t₁] with δq(t₀) = δq(t₁) = 0, "
                 "∫(δT − δV + δW) dt = 0 (B(16)), with the Cardan rates (α̇, −ẇ′, v̇′) of B(17) as velocities."),
    ("barhorst lagrangian", "Barhorst's Lagrangian canonical form: the multiplier form with δq = K δu (Kᵀ Aᵀ = 0 "
                            "removes λ): p = Kᵀ ∂L/∂q̇, ṗ = Kᵀ(∂L/∂q + Q) + K̇ᵀ ∂L/∂q̇."),
    ("barhorst projective", "Barhorst's projective canonical form: B(10) projected with the partial velocities "
                            "V = ∂v/∂u, W = ∂ω/∂u, momenta p = Σ (Vᵀ m v + Wᵀ I ω) and ṗ = Q + P."),
    ("torsion_free", "Lagrange (2nd kind) for the Ritz coordinates of a beam without torsional strain: T from "
                     "the slices' exact angular velocity with the geometric twist τ (docs/theory.md, 'The "
                     "spinning beam's rotary inertia'), the same as projeq's numeric RitzBeam."),
    ("kane", "Kane: B(2) in Jourdain's form (δq = 0, δṡ free), Σ (∂v/∂u)ᵀ(m v̇ − f) + (∂ω/∂u)ᵀ(L̇ − M) = 0: "
             "B(10) with the inertial frame as R."),
)


def derivation_of(name: str) -> str:
    """How the formulation ``name`` follows from B(2) (``DERIVATIONS``; empty if none matches)."""
    return next((text for prefix, text in DERIVATIONS if name.startswith(prefix)), "")


_ANALYTICAL = ("hamel", "lagrange + multipliers", "hamilton canonical + multipliers", "barhorst lagrangian canonical")
#: H. Bremer's effort claims, "Problems in Fast Moving Non-Holonomic Elastic Systems":
#: (where and what, the Projection Equation's row, the rows it is claimed to beat)
EFFORT_CLAIMS = {
    "car": ("§2.2, the car: the Projection Equation is \"preferable to the use of any of the analytical methods\"; "
            "\"The required effort is minimal.\"", "projection (symbolic)", _ANALYTICAL),
    "knife_edge_disc": ("§6: with the Projection Equation the non-holonomic constraints may be inserted in advance; "
                        "\"This goes along with a considerable reduction of calculation effort.\"",
                        "projection (symbolic)", _ANALYTICAL),
    "spinning_beam": ("§4.2: the Projection Equation gives B(23) \"along with much less effort in calculation\" "
                      "than Hamilton's principle gives B(18). n_ops here: every expression each derivation "
                      "forms (Hamilton: T − V, its integrations by parts, L, ∂L/∂ȧ, d/dt ∂L/∂ȧ, ∂L/∂a; "
                      "Projection Equation: the slice residuals, their projections), field equations and Ritz "
                      "model n = 2; "
                      "its growth with 1…4 Ritz functions and 1…3 bodies: projeq.studies.effort_growth "
                      "(benchmarks/effort_growth.py).", "projection (field equations, Ritz)",
                      ("hamilton (field equations, Ritz)",)),
    "n_link_pendulum": ("§3, rigid multibody systems: \"the use of the Projection Equation once more leads to minimum "
                        "effort when compared to the analytical procedures\".", "projection (symbolic)",
                        ("lagrange (2nd kind)",)),
}


def _effort_claims(name: str, rows: list) -> list[str]:
    """Bremer's claim for ``name`` with the measured ratios Projection Equation / other formulation
    (derivation time, n_ops) and whether they agree with it."""
    if name not in EFFORT_CLAIMS:
        return []
    claim, reference, others = EFFORT_CLAIMS[name]
    by_name = {row["formulation"]: row for row in rows}
    ref = by_name.get(reference, {})
    if ref.get("derivation_s") is None:
        return []
    measured = []
    for other in (by_name[o] for o in others if o in by_name and by_name[o].get("derivation_s") is not None):
        time_ratio = ref["derivation_s"] / other["derivation_s"]
        ops_ratio = ref["n_ops"] / other["n_ops"]
        verdict = {(True, True): "agrees", (True, False): "agrees in time, not in n_ops",
                   (False, True): "agrees in n_ops, not in time", (False, False): "disagrees"}[
            (time_ratio < 1, ops_ratio <= 1)]
        measured.append(f"vs {other['formulation']}: time ×{time_ratio:.2g}, n_ops ×{ops_ratio:.2g} → {verdict}")
    if not measured:
        return []
    return [f"H. Bremer {claim} Measured, {reference} ({ref['derivation_s']:.3g} s, {ref['n_ops']} ops) "
            + "; ".join(measured) + "."]


def compare(name, formulations=None, simulate: bool = True, t_end: float | None = None,
            repeats: int = DERIVATION_REPEATS) -> ComparisonTable:
    """Compare the formulations of the system ``name`` (a key of ``COMPARISONS``), or of a user's
    :class:`projeq.System` given as ``name``: its Projection Equation evaluated numerically,
    recursive (the reference) and dense, and derived in sympy (``projection (symbolic)``,
    :func:`projeq.symbolic.gauss_form`: "not available" with the reason where it refuses the
    System, e.g. callable loads). A ConstrainedSystem is refused (ValueError): its formulations
    (multipliers, partitions) are the built-in comparisons'.

    formulations : names of the rows to compute (default all); the first is the reference
    simulate : also integrate each formulation's equations (rtol 1e-9, atol 1e-12)
    t_end : simulated time in s (default ``DEFAULT_T_END[name]``; a user's System: 1 s)
    repeats : derivations per row; derivation_s is their median (``EFFORT``)

    Each row: derivation time (s), operation count after CSE (``sympy.count_ops``),
    whether the equations equal the reference (``check`` says how: symbolic difference or
    random states), the ``difference`` (reference − this, per equation) and ``why`` where they
    do not, integration time (s), relative energy drift, max constraint residual, and how the
    formulation follows from the Central Equation B(2) (``derivation``).
    """
    from projeq.system import Model

    system = name if isinstance(name, Model) else None
    if system is not None and system is not system.tree:
        raise ValueError(f"name: compare takes a System (a tree of joints) or one of {sorted(COMPARISONS)}; "
                         f"got a {type(system).__name__}, whose constraint forms only the built-in "
                         "comparisons have")
    if system is None and (not isinstance(name, str) or name not in COMPARISONS):
        raise ValueError(f"name: unknown comparison {name!r}; choose one of {sorted(COMPARISONS)} or pass a "
                         "System")
    t_end = (1.0 if system is not None else DEFAULT_T_END[name]) if t_end is None else t_end
    if not (isinstance(t_end, (int, float)) and 0 < t_end < np.inf):
        raise ValueError(f"t_end: must be a positive, finite number of seconds, got {t_end!r}")
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats: must be a positive integer (derivations per row), got {repeats!r}")
    if formulations is not None:
        formulations = [formulations] if isinstance(formulations, str) else list(formulations)
        if not formulations:
            raise ValueError("formulations: none given; name at least one (the first is the reference) or "
                             "pass None for all")
    token = derivation_repeats.set(repeats)
    try:
        rows = (_user_system(system, formulations, simulate, float(t_end)) if system is not None
                else COMPARISONS[name](formulations, simulate, float(t_end)))
    finally:
        derivation_repeats.reset(token)
    for row in rows:
        row.setdefault("derivation", derivation_of(row["formulation"]))
    label = name if system is None else f"System({', '.join(system.names)})"
    return ComparisonTable(label, rows, EFFORT.format(repeats=repeats), _effort_claims(label, rows))
