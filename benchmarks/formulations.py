"""Integration cost, energy drift and constraint drift of the formulations side by side, as A. A. Barhorst
compares them ("Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion", §3): first the knife-edge disc of the lecture on non-holonomic systems and
Lagrange multipliers (slides 28–37), then Barhorst's own three examples over his 10 s.

Formulations, all from the same initial state (tilt ϕ = 0.2, θ̇ = −3, ψ̇ = 0.4, m = g = r = 1, μ = ¼, ν = ½):

* ``PE``: projeq's numeric Projection Equation (scene ``knife_edge_disc``, 5 coordinates, ṡ = (ψ̇, ϕ̇, θ̇));
* ``Lagrange+λ``: lecture K(7), 6 coordinates, constraint differentiated once (index 1), no stabilisation;
* ``Lagrange+λ, Baumgarte``: the same with A q̈ + Ȧq̇ = −α A q̇, α = 1 and 10 per time unit;
* ``Hamilton+λ``: lecture K(23)–(24), state (q, p), same index reduction;
* ``Barhorst Lagrangian`` and ``Barhorst projective``: canonical momentum forms (eqs. 45–52, 28–37).

Columns: setup (derivation + lambdify + first call, s, sympy's cache cleared before each),
integration wall time (s), right-hand-side evaluations, max |E − E₀| (energy), max |A q̇| (velocity constraints; for the PE and the canonical
forms zero by construction), max |z + r cos ϕ| (the integrable constraint, only position-level drift
for the 6-coordinate forms). DOP853 at the given rtol, atol = rtol/100. Times are this machine's only.

Barhorst's examples — the particle with a non-holonomic constraint, the rolling disk with an eccentric
mass, the quick-return mechanism — run through ``projeq.compare`` (``projeq.studies.compare_barhorst``):
Hamilton's canonical equations with multipliers integrated as an index-2 DAE, the projective (Kane) form
with dependent speeds, his projective and Lagrangian canonical momentum forms (the disk also in his general
speeds u = Y q̇ of eq. 93), all by the same Radau IIA code at rtol 1e-8; integration time normalised to his
baseline row, energy and constraint drift, and his reported numbers beside.

    python benchmarks/formulations.py            # disc: t_end = 100, rtol 1e-6 and 1e-10; Barhorst: 10 s
    python benchmarks/formulations.py --quick    # disc: t_end = 0.1, PE, Lagrange+λ, Barhorst projective;
                                                 # Barhorst: his particle over 0.1 s (a test runs it)
    python benchmarks/formulations.py --barhorst # Barhorst's three examples only (10 s)
"""

from __future__ import annotations

import os
import argparse
import time

import numpy as np
import sympy as sp

import projeq as pq
from projeq.scenes.nonholonomic import knife_edge_disc
from projeq.symbolic.canonical import lagrangian_canonical
from projeq.symbolic.formulation_examples import lecture_disc, lecture_disc_state, projective_disc

# fresh (uncached) builds, so that the setup column measures derivation and compilation
build_lecture_disc, build_projective_disc = lecture_disc.__wrapped__, projective_disc.__wrapped__


def _row(name, setup, wall, nfev, q, q_dot, disc):
    """Drifts of one run: energy H = ½ pᵀq̇ − m g z (T homogeneous quadratic), |A q̇|, |z + r cos ϕ|."""
    energy = [0.5 * disc.momenta(0.0, qi, ui) @ ui - qi[2] for qi, ui in zip(q.T, q_dot.T)]
    residual = max(np.abs(disc.velocity_residual(0.0, qi, ui)).max() for qi, ui in zip(q.T, q_dot.T))
    return (name, setup, wall, nfev, np.abs(np.array(energy) - energy[0]).max(),
            residual, np.abs(q[2] + np.cos(q[4])).max())


def run(t_end: float, rtol: float, quick: bool = False):
    """The rows of the disc's table (module docstring); ``quick``: PE, Lagrange+λ and Barhorst projective."""
    system = knife_edge_disc(s_dot0=(0.4, 0.0, -3.0))
    q0, q_dot0 = lecture_disc_state(system)
    t_eval, rows = np.linspace(0, t_end, 201), []
    disc = build_lecture_disc()
    disc._compiled  # noqa: B018  (compile once for the drift evaluation)

    pe = pq.simulate(system, t_end, t_eval=t_eval, rtol=rtol, atol=rtol / 100, method="DOP853")
    z = -np.cos(pe.q[:, 3])
    q6 = np.vstack([pe.q[:, 0], pe.q[:, 1], z, pe.q[:, 2], pe.q[:, 3], pe.q[:, 4]])
    q_dot6 = np.array([system.q_dot(qi, si) for qi, si in zip(pe.q, pe.s_dot)]).T
    q_dot6 = np.vstack([q_dot6[:2], np.sin(pe.q[:, 3]) * q_dot6[3], q_dot6[2:]])
    rows.append(_row("PE (numeric, projeq)", 0.0, pe.wall_time, pe.nfev, q6, q_dot6, disc))

    multiplier_runs = (("Lagrange+λ", 0.0, "lagrange"), ("Lagrange+λ, Baumgarte α=1", 1.0, "lagrange"),
                       ("Lagrange+λ, Baumgarte α=10", 10.0, "lagrange"), ("Hamilton+λ", 0.0, "hamilton"))
    for name, alpha, form in multiplier_runs[:1] if quick else multiplier_runs:
        sp.core.cache.clear_cache()
        start = time.perf_counter()
        candidate = build_lecture_disc()
        candidate.simulate(q0, q_dot0, (0, 1e-3))
        setup = time.perf_counter() - start
        start = time.perf_counter()
        sol = candidate.simulate(q0, q_dot0, (0, t_end), form=form, alpha=alpha, t_eval=t_eval, rtol=rtol,
                                 atol=rtol / 100)
        rows.append(_row(name, setup, time.perf_counter() - start, sol.nfev, sol.q, sol.q_dot, disc))

    canonical_runs = (("Barhorst Lagrangian", lambda: lagrangian_canonical(build_lecture_disc())),
                      ("Barhorst projective", build_projective_disc))
    for name, build in canonical_runs[1:] if quick else canonical_runs:
        sp.core.cache.clear_cache()
        start = time.perf_counter()
        canonical = build()
        canonical.simulate(q0, q_dot0[3:], (0, 1e-3))
        setup = time.perf_counter() - start
        start = time.perf_counter()
        sol = canonical.simulate(q0, q_dot0[3:], (0, t_end), t_eval=t_eval, rtol=rtol, atol=rtol / 100)
        wall = time.perf_counter() - start
        rows.append(_row(name, setup, wall, sol.nfev, sol.q, _q_dot(canonical, sol), disc))
    return rows


def _q_dot(canonical, sol):
    """q̇ = K u along a canonical-form run."""
    K = sp.lambdify([canonical.q], canonical.K.subs(canonical.parameters), modules="numpy")
    return np.array([np.asarray(K(qi), float) @ ui for qi, ui in zip(sol.q.T, sol.u.T)]).T


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--barhorst", action="store_true", help="only Barhorst's three examples")
    args = parser.parse_args(argv)
    cases = [] if args.barhorst else [(0.1, 1e-8)] if args.quick else [(100.0, 1e-6), (100.0, 1e-10)]
    for t_end, rtol in cases:
        print(f"\nknife-edge disc, t_end = {t_end}, rtol = {rtol:g}, atol = {rtol / 100:g}")
        print(f"{'formulation':28s} {'setup s':>8s} {'run s':>7s} {'nfev':>6s} {'|ΔE|':>9s} {'|Aq̇|':>9s} "
              f"{'|z+rcϕ|':>9s} {'run/PE':>7s}")
        rows = run(t_end, rtol, args.quick)
        for name, setup, wall, nfev, dE, dA, dz in rows:
            print(f"{name:28s} {setup:8.2f} {wall:7.2f} {nfev:6d} {dE:9.2e} {dA:9.2e} {dz:9.2e} "
                  f"{wall / rows[0][2]:7.2f}")
    barhorst(*((0.1, ("barhorst_particle",)) if args.quick else (10.0,)))


def barhorst(t_end: float, names=("barhorst_particle", "rolling_disk", "quick_return")):
    """Barhorst's examples over ``t_end`` seconds (his runs: 10 s), each formulation's row with his
    reported numbers beside."""
    for name in names:
        table = pq.compare(name, t_end=t_end, repeats=1)
        print()
        print(table.format())
        print(f"{'formulation':48s} {'time/base':>9s} {'nfev':>6s} {'E drift':>9s} {'c drift':>9s}")
        for row in table.rows:
            if "integration_s" in row:
                print(f"{row['formulation']:48s} {row.get('time / baseline', float('nan')):9.3f} {row['nfev']:6d} "
                      f"{row['energy_drift']:9.2e} {row['constraint_drift']:9.2e}")


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
