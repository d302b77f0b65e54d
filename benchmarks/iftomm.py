"""IFToMM multibody benchmark problems: effort and accuracy per problem, as the library asks.

Library of computational benchmark problems of the IFToMM Technical Committee for Multibody
Dynamics (M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS
simulation software", Multibody System Dynamics 16 (2006) 179–190): A01 simple pendulum,
A02 N-four-bar mechanism (through singular positions; N = 2 and the benchmark's N = 40), A03
Andrews' squeezing mechanism, A04 Bricard's mechanism (a redundant constraint), from
:mod:`projeq.scenes.iftomm`, each a ConstrainedSystem in its null-space form. The tables:

- problems: per problem to ``--t-end`` (A03 to 0.05 s) at ``--rtol``: CPU time (warm; "first": a run over
  t_end / 1000 before it, which compiles or loads the model's kernels and loops), right-hand-side
  evaluations, the largest |Φ| and |A_s ṡ_tree − b_s| at the outputs, the largest change of the
  energy (A03: of the balance T + V − E₀ − mom (β − β₀)), and the error against a reference: A01
  Jacobi's closed form (angle, rad), A02 the parallelogram motion (B0's position and velocity),
  A03 Hairer & Wanner's published solution at 0.03 s (1996, §VII.7; relative), A04 energy only;
- criterion: each problem (A02 with the largest ``--n`` over ``--a02-t-end``, A05 over ``--flyball-t-end``) at
  simulate's default method and the largest rtol by decades whose error is within the benchmark's 1e-3 (A04,
  A05: against the model's own run at rtol 1e-11): the benchmark's measure of effort;
- references: A01 over ``--a01-t-end`` (the benchmark's 2000 s) and A02 with N = 40 over
  ``--a02-t-end`` (its 20 s) against the library's published files (found through PROJEQ_DATA;
  skipped, saying so, without them) and the closed forms, per ``--reference-rtol``;
- formulations: the double four-bar (N = 2) to ``--compare-t-end`` in each form — partitioned
  (stops at the singular position), the default (partitioned, then null space from the first
  singular position), the augmented Lagrangian AugmentedSystem (Bayo & Ledesma 1996), the null
  space without and with the continuation of the branch — at each ``--compare-rtol``;
- tolerances: the double four-bar's B0 error for rtol 1e-6 … 1e-11 by decades (each decade lowers it);
- forms: µs per s̈ of the partitioned and the null-space form side by side, on the double four-bar
  and the Whipple bicycle (the measure behind ConstrainedSystem's choice);
- flyball: A05, the stiff flyball governor (no constraint equations), by integrator (simulate's
  pick, BDF, DOP853 over ``--dop853-t-end``) over ``--flyball-t-end``: CPU time, evaluations,
  Jacobians, s at the end (Exudyn's run of the full specification: s(10 s) = 0.6196234 m), the
  energy balance T + V − E₀ + W_d, the angular momentum's drift, the distance from the relative
  equilibrium when started there.

    python benchmarks/iftomm.py [--rtol 1e-9] [--n 2 40] [--only references] [--quick] ...

(about 6 CPU minutes with the defaults, most of them for N = 40 and A01's 2000 s; set
OMP_NUM_THREADS=1 on a shared machine: the 80 × 81 SVDs of N = 40 slow down 40-fold when BLAS
threads compete; ``--quick`` runs every table on short horizons, its slowest rows left out, as a test does)
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import projeq as pq
from projeq.constraints.augmented import AugmentedSystem
from projeq.scenes.bicycle import whipple_bicycle
from projeq.scenes.iftomm import (
    ANDREWS_REFERENCE, _flyball_geometry, andrews_balance, andrews_error, andrews_squeezer, bricard, flyball_balance,
    flyball_governor, flyball_steady_state, n_four_bar, parallelogram_motion, pendulum_angle, point_b0,
    reference_solution, simple_pendulum,
)

REFERENCE_FILES = {"A01": "iftomm_A01_simple_pendulum_solution.txt", "A02": "iftomm_A02_n_four_bar_N40_solution.txt"}


def velocity_residual(system, r) -> float:
    """max |A_s ṡ_tree − b_s| over the outputs."""
    return max(float(np.abs(A_s @ system.tree_velocities(q, s_dot, t) - b_s).max(initial=0.0))
               for t, q, s_dot in zip(r.t, r.q, r.s_dot) for A_s, b_s in [system.constraint_matrix(q, t)])


def energy_change(system, r) -> np.ndarray:
    energy = r.kinetic + r.potential
    return energy - energy[0]


def measure(system, t_end: float, rtol: float, error, balance=energy_change, t_eval=None) -> dict:
    """One run, warm: effort, drift, the energy balance's largest value and the error function's value; the
    CPU of a run over t_end / 1000 before it, which compiles (or loads) the model's kernels and loops,
    apart ("first")."""
    started = time.process_time()
    pq.simulate(system, t_end * 1e-3, n_points=2, rtol=rtol, atol=rtol * 1e-2)
    first = time.process_time() - started
    started = time.process_time()
    r = pq.simulate(system, t_end, t_eval=t_eval, n_points=None if t_eval is not None else 401, rtol=rtol,
                    atol=rtol * 1e-2)
    cpu = time.process_time() - started
    return {"t": r.t[-1], "cpu": cpu, "first": first, "nfev": r.nfev, "phi": np.abs(r.constraint_residual).max(),
            "velocity": velocity_residual(system, r), "energy": np.abs(balance(system, r)).max(),
            "error": error(system, r)}


def pendulum_error(system, r) -> float:
    return float(np.abs(np.arctan2(r.q[:, 0], -r.q[:, 1]) - pendulum_angle(r.t)).max())


def b0_error(n: int):
    return lambda system, r: float(np.abs(point_b0(system, r.q, r.s_dot) - parallelogram_motion(r.t, n)).max())


def b0_position_error(n: int):
    """The largest distance of B0 from the parallelogram motion's (the reference file's quantity)."""
    return lambda system, r: float(np.abs(point_b0(system, r.q, r.s_dot)[:, :2]
                                          - parallelogram_motion(r.t, n)[:, :2]).max())


def andrews_reference_error(system, r) -> float:
    at = int(np.argmin(np.abs(r.t - ANDREWS_REFERENCE[0])))
    return andrews_error(system, r.q[at], r.s_dot[at])


def problems(args) -> None:
    print(f"IFToMM problems, ConstrainedSystem (null-space form), rtol {args.rtol:g}")
    print(f"{'problem':<24}{'t_end':>6}{'CPU s':>8}{'first s':>8}{'nfev':>7}{'max|Φ|':>10}{'max|Aṡ-b|':>11}"
          f"{'max|ΔE| J':>11}{'error':>10}")
    cases = [] if args.quick else [("A01 simple pendulum", simple_pendulum(), args.t_end, pendulum_error, {})]
    cases += [(f"A02 {n}-four-bar", n_four_bar(n), args.t_end, b0_error(n), {}) for n in args.n]
    cases += [] if args.quick else [("A03 Andrews' squeezer", andrews_squeezer(), 0.05, andrews_reference_error,
                                     {"balance": andrews_balance, "t_eval": np.linspace(0.0, 0.05, 51)})]
    cases += [("A04 Bricard", bricard(), args.t_end, lambda system, r: float("nan"), {})]
    for label, system, t_end, error, options in cases:
        try:
            row = measure(system, t_end, args.rtol, error, **options)
        except pq.SimulationError as failure:
            print(f"{label:<24}stopped at t = {failure.result.t[-1]:.3f} s: {str(failure)[:80]}")
            continue
        print(f"{label:<24}{row['t']:>6.2f}{row['cpu']:>8.2f}{row['first']:>8.1f}{row['nfev']:>7d}{row['phi']:>10.1e}"
              f"{row['velocity']:>11.1e}{row['energy']:>11.1e}{row['error']:>10.1e}")


#: the benchmark's error criterion (González et al. 2006): 1e-3 in the reported quantity over the horizon
CRITERION = 1e-3


def criterion_cases(args) -> list:
    """(label, builder, t_end, error of a run) of each problem for :func:`criterion`: A01 (the angle), A02 (N =
    the largest ``--n``; B0's position) against their closed forms, A03 against Hairer & Wanner's solution at 0.03 s, A04 and A05
    (no closed form) against the same model's run at rtol 1e-11 (A05's ends 4.8e-7 m from Exudyn's s(10 s),
    tests/constraints/test_iftomm_references.py): the largest distance of q at the outputs."""
    def against_tight(build, t_end):
        tight = pq.simulate(build(), t_end, rtol=1e-11, atol=1e-13, n_points=201)
        return lambda system, r: float(np.abs(r.q - tight.q).max())

    n = max(args.n)
    horizon = {"A02": args.a02_t_end if not args.quick else args.t_end, "A05": args.flyball_t_end}
    return [("A01 simple pendulum", simple_pendulum, args.t_end, pendulum_error),
            (f"A02 {n}-four-bar", lambda: n_four_bar(n), horizon["A02"], b0_position_error(n)),
            ("A03 Andrews' squeezer", andrews_squeezer, 0.05, andrews_reference_error),
            ("A04 Bricard", bricard, args.t_end, against_tight(bricard, args.t_end)),
            ("A05 flyball governor", flyball_governor, horizon["A05"], against_tight(flyball_governor,
                                                                                     horizon["A05"]))]


def criterion(args) -> None:
    """Each problem at simulate's default method, rtol 1e-3, 1e-4, … by decades (atol rtol / 100) until its
    error is within the benchmark's criterion, a row per run: the CPU of the last, the cheapest (warm: a run over t_end / 1000
    compiles or loads the kernels first), its rtol, evaluations and error — the benchmark's measure of
    effort (issue 34: each ≤ 1 s, A02 with N = 40 over 20 s ≤ 3 s)."""
    print(f"\nIFToMM problems, the cheapest run by decades of rtol within the criterion {CRITERION:g}")
    print(f"{'problem':<24}{'t_end':>6}{'rtol':>7}{'method':>8}{'CPU s':>8}{'nfev':>7}{'error':>10}")
    for label, build, t_end, error in criterion_cases(args):
        pq.simulate(build(), t_end * 1e-3, n_points=2)
        for rtol in 10.0 ** -np.arange(3, 11):
            system = build()
            started = time.process_time()
            outputs = {"t_eval": np.linspace(0.0, t_end, 51)} if label[:3] == "A03" else \
                {"n_points": 201 if label[:3] in ("A04", "A05") else 401}
            try:
                r = pq.simulate(system, t_end, rtol=rtol, atol=rtol * 1e-2, **outputs)
            except pq.SimulationError as failure:  # too loose to hold the loop together: the next decade
                print(f"{label:<24}{t_end:>6.2f}{rtol:>7.0e}  stopped at t = {failure.result.t[-1]:.3g} s")
                continue
            cpu = time.process_time() - started
            found = error(system, r)
            within = found <= CRITERION
            print(f"{label:<24}{t_end:>6.2f}{rtol:>7.0e}{r.method:>8}{cpu:>8.2f}{r.nfev:>7d}{found:>10.1e}"
                  + ("  <- the cheapest within" if within else ""))
            if within:
                break
        else:
            print(f"{label:<24}{t_end:>6.2f}  not within {CRITERION:g} at rtol 1e-10 (error {found:.1e})")


def formulations(args) -> None:
    print(f"\ndouble four-bar (N = 2) to {args.compare_t_end} s: the formulations (B0 error along the run)")
    print(f"{'formulation':<36}{'rtol':>7}{'reached s':>10}{'CPU s':>8}{'nfev':>7}{'B0 error':>10}{'max|ΔE| J':>11}")
    for rtol in args.compare_rtol:
        tangent = n_four_bar(2)
        cases = [("partitioned, repivot", n_four_bar(2, formulation="partitioned", repivot=True)),
                 ("auto: partitioned, then null space", n_four_bar(2, formulation="auto")),
                 ("AugmentedSystem", AugmentedSystem(tangent.tree, phi=tangent.phi, q0=tangent.q0,
                                                     s_dot0=tangent.tree_velocities(tangent.q0, tangent.s_dot0))),
                 ("null space, separation=0", n_four_bar(2, separation=0.0)),
                 ("null space (continued branch)", tangent)]
        if args.quick:  # the numpy-path forms (several seconds even for 0.1 s) left to the full run
            cases = cases[:2] + cases[-1:]
        for label, system in cases:
            try:
                row = measure(system, args.compare_t_end, rtol, b0_error(2))
            except pq.SimulationError as failure:
                r = failure.result
                print(f"{label:<36}{rtol:>7.0e}{r.t[-1]:>10.3f}   stopped: {str(failure).split(': ', 1)[1][:60]}")
                continue
            print(f"{label:<36}{rtol:>7.0e}{row['t']:>10.3f}{row['cpu']:>8.1f}{row['nfev']:>7d}{row['error']:>10.1e}"
                  f"{row['energy']:>11.1e}")


def reference(name: str):
    """The rows (t, x, y) of the benchmark library's reference file of problem ``name`` from
    $PROJEQ_DATA/iftomm/, or None (said) where it is absent."""
    path = Path(os.environ.get("PROJEQ_DATA", ""), "iftomm", REFERENCE_FILES[name])
    if not os.environ.get("PROJEQ_DATA") or not path.is_file():
        print(f"{name}: {REFERENCE_FILES[name]} not found (set PROJEQ_DATA to the folder holding iftomm/): skipped")
        return None
    return reference_solution(path)


def references(args) -> None:
    """A01 over its 2000 s and A02 (N = 40) over its 20 s against the published files: the largest
    distance of the output point from the file's rows (A01's file mirrored, x → −x: it starts at
    x = −1, the specification's text at +1) and from the closed form, per rtol, with CPU time."""
    print("\nagainst the published reference files (benchmark criterion: 1e-3 over the whole horizon)")
    print(f"{'problem':<22}{'t_end':>7}{'rtol':>7}{'CPU s':>8}{'nfev':>8}{'file error m':>14}{'exact error m':>15}")
    a01 = reference("A01")
    if a01 is not None:
        rows = a01[a01[:, 0] <= args.a01_t_end]
        for rtol in args.reference_rtol:
            started = time.process_time()
            r = pq.simulate(simple_pendulum(), rows[-1, 0], t_eval=rows[:, 0], rtol=rtol, method="DOP853")
            cpu = time.process_time() - started
            theta = pendulum_angle(r.t)
            file_error = np.abs(r.q[:, :2] - np.column_stack((-rows[:, 1], rows[:, 2]))).max()
            exact_error = np.abs(r.q[:, :2] - np.column_stack((np.sin(theta), -np.cos(theta)))).max()
            print(f"{'A01 simple pendulum':<22}{rows[-1, 0]:>7.0f}{rtol:>7.0e}{cpu:>8.1f}{r.nfev:>8d}"
                  f"{file_error:>14.1e}{exact_error:>15.1e}")
    a02 = reference("A02")
    if a02 is not None:
        rows = a02[a02[:, 0] <= args.a02_t_end]
        for rtol in args.reference_rtol:
            system = n_four_bar(40)
            started = time.process_time()
            r = pq.simulate(system, rows[-1, 0], t_eval=rows[:, 0], rtol=rtol, method="RK45")
            cpu = time.process_time() - started
            B0 = point_b0(system, r.q, r.s_dot)[:, :2]
            file_error, exact_error = (np.abs(B0 - other).max()
                                       for other in (rows[:, 1:], parallelogram_motion(r.t, 40)[:, :2]))
            print(f"{'A02 40-four-bar':<22}{rows[-1, 0]:>7.1f}{rtol:>7.0e}{cpu:>8.1f}{r.nfev:>8d}"
                  f"{file_error:>14.1e}{exact_error:>15.1e}")


def accuracy_by_tolerance(args) -> None:
    """The double four-bar's largest B0 position error over ``--compare-t-end`` for rtol 1e-6 … 1e-11
    by decades (simulate's atol): each decade should lower it by 2× or more until it is within 10× of
    the best (issue 35's measure)."""
    print(f"\ndouble four-bar (N = 2, ConstrainedSystem's null-space form) to {args.compare_t_end} s: "
          "B0 position error by rtol")
    print(f"{'rtol':>7}{'CPU s':>8}{'nfev':>7}{'B0 error m':>12}{'fall':>7}")
    previous = None
    for rtol in args.tolerance_sweep:
        system = n_four_bar(2)
        started = time.process_time()
        r = pq.simulate(system, args.compare_t_end, n_points=201, rtol=rtol)
        cpu = time.process_time() - started
        error = np.abs(point_b0(system, r.q, r.s_dot)[:, :2] - parallelogram_motion(r.t, 2)[:, :2]).max()
        fall = "" if previous is None else f"{previous / error:>7.1f}"
        print(f"{rtol:>7.0e}{cpu:>8.2f}{r.nfev:>7d}{error:>12.2e}{fall}")
        previous = error


def forms(args) -> None:
    """The cost of the two forms of a ConstrainedSystem per evaluation of s̈ (median of rounds over
    states along a run, the two forms alternating) and per run, on the double four-bar (its first
    0.6 s, before the singular position) and the Whipple bicycle (Pfaffian rolling constraints)."""
    print("\nthe forms of ConstrainedSystem: partitioned against null space (side by side in one process)")
    print(f"{'model':<18}{'form':<13}{'µs per s̈':>10}{'ratio':>7}{'run CPU s':>10}{'nfev':>7}")
    models = {
        "double four-bar": (lambda form: n_four_bar(2, formulation=form), 0.6),
        "Whipple bicycle": (lambda form: whipple_bicycle(formulation=form), args.bicycle_t_end),
    }
    if args.quick:  # the bicycle's null-space kernel is compiled here alone: a minute cold
        del models["Whipple bicycle"]
    for label, (build, t_end) in models.items():
        pair = [build(form) for form in ("partitioned", "null_space")]
        states = pq.simulate(pair[0], t_end, n_points=6)
        evaluators = [system.evaluator() for system in pair]
        for evaluator in evaluators:  # first calls (compilation) apart
            evaluator.accelerations(states.q[0], states.s_dot[0], 0.0)
        rounds = [[], []]
        for _ in range(args.rounds):
            for k, evaluator in enumerate(evaluators):
                started = time.perf_counter()
                for q, s_dot in zip(states.q, states.s_dot):
                    evaluator.accelerations(q, s_dot, 0.0)
                rounds[k].append((time.perf_counter() - started) / len(states.q) * 1e6)
        medians = [float(np.median(times)) for times in rounds]
        for k, system in enumerate(pair):
            started = time.process_time()
            r = pq.simulate(system, t_end, n_points=11)
            cpu = time.process_time() - started
            print(f"{label:<18}{system.formulation:<13}{medians[k]:>10.1f}{medians[k] / medians[0]:>7.2f}"
                  f"{cpu:>10.2f}{r.nfev:>7d}")


def flyball(args) -> None:
    steady = flyball_steady_state()
    print(f"\nA05 stiff flyball governor, rtol {args.rtol:g}; relative equilibrium of the start's angular momentum: "
          f"s = {steady['s']:.6f} m, α = {np.degrees(steady['alpha']):.4f}°, ω = {steady['omega']:.6f} rad/s")
    print(f"{'method':<18}{'t_end':>6}{'CPU s':>8}{'nfev':>8}{'njev':>6}{'s(t_end) m':>12}{'max|balance| J':>16}"
          f"{'max|ΔL/L|':>11}{'steady |Δs| m':>15}")
    for method, t_end in ((None, args.flyball_t_end), ("BDF", args.flyball_t_end), ("DOP853", args.dop853_t_end)):
        system = flyball_governor()
        started = time.process_time()
        r = pq.simulate(system, t_end, method=method, rtol=args.rtol, atol=args.rtol * 1e-2, n_points=201,
                        dense_output=True)
        cpu = time.process_time() - started
        I_zz = np.array([_flyball_geometry(alpha, s)[0] for s, alpha in r.q[:, 1:3]])
        L_z = I_zz * r.s_dot[:, 0]
        held = flyball_governor(s0=steady["s"], alpha0=steady["alpha"], omega0=steady["omega"])
        at_rest = pq.simulate(held, 1.0, method="Radau" if "Radau" in r.method else r.method, rtol=args.rtol,
                              atol=args.rtol * 1e-2, n_points=11)
        label = f"{r.method}" + (" (default)" if method is None else "")
        print(f"{label:<18}{t_end:>6.1f}{cpu:>8.1f}{r.nfev:>8d}{r.njev:>6d}{r.q[-1, 1]:>12.8f}"
              f"{np.abs(flyball_balance(r)).max():>16.1e}{np.abs(L_z / L_z[0] - 1).max():>11.1e}"
              f"{np.abs(at_rest.q[:, 1] - steady['s']).max():>15.1e}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtol", type=float, default=1e-9)
    parser.add_argument("--t-end", type=float, default=10.0, help="A01, A02, A04's horizon in the problems table")
    parser.add_argument("--n", type=int, nargs="+", default=[2, 40], help="four-bars of A02 (the benchmark's: 40)")
    parser.add_argument("--compare-t-end", type=float, default=10.0, help="the double four-bar's horizon")
    parser.add_argument("--compare-rtol", type=float, nargs="+", default=[1e-8, 1e-9, 1e-10])
    parser.add_argument("--flyball-t-end", type=float, default=10.0, help="A05's horizon (the benchmark's: 10 s)")
    parser.add_argument("--dop853-t-end", type=float, default=1.0, help="A05 with DOP853 (about 4.5 CPU s per simulated s)")
    parser.add_argument("--a01-t-end", type=float, default=2000.0, help="A01 against its file (the benchmark's: 2000 s)")
    parser.add_argument("--a02-t-end", type=float, default=20.0, help="A02 (N = 40) against its file (the benchmark's: 20 s)")
    parser.add_argument("--reference-rtol", type=float, nargs="+", default=[1e-8, 1e-9])
    parser.add_argument("--tolerance-sweep", type=float, nargs="+", default=[1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11])
    parser.add_argument("--bicycle-t-end", type=float, default=2.0)
    parser.add_argument("--rounds", type=int, default=7, help="alternating rounds of the forms' s̈ timing")
    parser.add_argument("--quick", action="store_true", help="every table on short horizons (a test runs it)")
    parser.add_argument("--only", choices=list(TABLES), help="run one table")
    args = parser.parse_args(argv)
    if args.quick:
        args.n, args.compare_t_end, args.compare_rtol, args.flyball_t_end, args.dop853_t_end = [2], 0.1, [1e-8], 0.05, 0.01
        args.a01_t_end, args.a02_t_end, args.reference_rtol, args.tolerance_sweep = 1.0, 0.1, [1e-8], [1e-7, 1e-8]
        args.rounds, args.t_end = 1, 0.1
    for name, table in TABLES.items():
        if args.only in (None, name):
            table(args)


TABLES = {"problems": problems, "criterion": criterion, "formulations": formulations, "forms": forms, "tolerances": accuracy_by_tolerance,
          "references": references, "flyball": flyball}

os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
