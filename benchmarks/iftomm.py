"""IFToMM multibody benchmark problems: effort and accuracy per problem, as the library asks.

Library of computational benchmark problems of the IFToMM Technical Committee for Multibody
Dynamics (M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS
simulation software", Multibody System Dynamics 16 (2006) 179–190): A01 simple pendulum,
A02 N-four-bar mechanism (through singular positions; N = 2 and the benchmark's N = 40), A03
Andrews' squeezing mechanism, A04 Bricard's mechanism (a redundant constraint), from
:mod:`projeq.scenes.iftomm`, each run to its horizon with
:class:`projeq.constraints.partitioned.TangentSystem`. Per problem: CPU time, right-hand-side
evaluations, the largest loop-closure residual |Φ| and velocity-constraint residual
|A_s ṡ_tree − b_s| at the outputs, the largest change of the energy (A03: of the energy balance
T + V − E₀ − mom (β − β₀)), and the largest error against a reference: A01 Jacobi's closed form
(angle, rad), A02 the parallelogram motion (B0's position and velocity, along the run), A03 the
published reference solution at 0.03 s (Hairer & Wanner 1996, §VII.7; relative, angles and rates),
A04 none but energy. The benchmark library's reference files are not read (no network here).

A05, the stiff flyball governor (a tree with two stiff spring-dampers, no constraint equations),
has a table of its own: each integrator (simulate's default pick, BDF, and DOP853 — the pick
before the default looked at whether the fastest mode oscillates — over ``--dop853-t-end``)
over ``--flyball-t-end`` (the benchmark's 10 s) at ``--rtol``: CPU time, evaluations,
Jacobians, s at the end, the energy balance T + V − E₀ + W_d (W_d the dampers' dissipated work,
flyball_balance), the drift of the angular momentum about the free shaft, and the distance of s
from the relative equilibrium when started there (flyball_steady_state, the amended potential).

A second table measures the choice of formulation on the double four-bar (N = 2): the partitioned
ConstrainedSystem (re-pivoting), the augmented Lagrangian AugmentedSystem (Bayo & Ledesma 1996),
TangentSystem without the continuation of the branch (``separation=0``) and TangentSystem, each to
``--compare-t-end`` at each of ``--compare-rtol``.

    python benchmarks/iftomm.py [--rtol 1e-9] [--n 2 40] [--compare-t-end 10] [--compare-rtol 1e-8 1e-9 1e-10]
                                [--flyball-t-end 10] [--dop853-t-end 1] [--only flyball]

(about 3 CPU minutes with the defaults, two of them for N = 40; set OMP_NUM_THREADS=1 on a
shared machine: the 80 × 81 SVDs of N = 40 slow down 40-fold when BLAS threads compete)
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import projeq as pq
from projeq.constraints.augmented import AugmentedSystem
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.constraints.partitioned import TangentSystem
from projeq.scenes.iftomm import (
    ANDREWS_REFERENCE, _flyball_geometry, andrews_balance, andrews_error, andrews_squeezer, bricard, flyball_balance,
    flyball_governor, flyball_steady_state, n_four_bar, parallelogram_motion, pendulum_angle, point_b0,
    simple_pendulum,
)


def velocity_residual(system, r) -> float:
    """max |A_s ṡ_tree − b_s| over the outputs."""
    return max(float(np.abs(A_s @ system.tree_velocities(q, s_dot, t) - b_s).max(initial=0.0))
               for t, q, s_dot in zip(r.t, r.q, r.s_dot) for A_s, b_s in [system.constraint_matrix(q, t)])


def energy_change(system, r) -> np.ndarray:
    energy = r.kinetic + r.potential
    return energy - energy[0]


def measure(system, t_end: float, rtol: float, error, balance=energy_change, t_eval=None) -> dict:
    """One run: effort, drift, the energy balance's largest value and the error function's value."""
    started = time.process_time()
    r = pq.simulate(system, t_end, t_eval=t_eval, n_points=401, rtol=rtol, atol=rtol * 1e-2)
    cpu = time.process_time() - started
    return {"t": r.t[-1], "cpu": cpu, "nfev": r.nfev, "phi": np.abs(r.constraint_residual).max(),
            "velocity": velocity_residual(system, r), "energy": np.abs(balance(system, r)).max(),
            "error": error(system, r)}


def pendulum_error(system, r) -> float:
    return float(np.abs(np.arctan2(r.q[:, 0], -r.q[:, 1]) - pendulum_angle(r.t)).max())


def b0_error(n: int):
    return lambda system, r: float(np.abs(point_b0(system, r.q, r.s_dot) - parallelogram_motion(r.t, n)).max())


def andrews_reference_error(system, r) -> float:
    at = int(np.argmin(np.abs(r.t - ANDREWS_REFERENCE[0])))
    return andrews_error(system, r.q[at], r.s_dot[at])


def problems(args) -> None:
    print(f"IFToMM problems, TangentSystem, rtol {args.rtol:g}")
    print(f"{'problem':<24}{'t_end':>6}{'CPU s':>8}{'nfev':>7}{'max|Φ|':>10}{'max|Aṡ-b|':>11}"
          f"{'max|ΔE| J':>11}{'error':>10}")
    cases = [("A01 simple pendulum", simple_pendulum(), 10.0, pendulum_error, {})]
    cases += [(f"A02 {n}-four-bar", n_four_bar(n), 10.0, b0_error(n), {}) for n in args.n]
    cases += [("A03 Andrews' squeezer", andrews_squeezer(), 0.05, andrews_reference_error,
               {"balance": andrews_balance, "t_eval": np.linspace(0.0, 0.05, 51)}),
              ("A04 Bricard", bricard(), 10.0, lambda system, r: float("nan"), {})]
    for label, system, t_end, error, options in cases:
        try:
            row = measure(system, t_end, args.rtol, error, **options)
        except pq.SimulationError as failure:
            print(f"{label:<24}stopped at t = {failure.result.t[-1]:.3f} s: {str(failure)[:80]}")
            continue
        print(f"{label:<24}{row['t']:>6.2f}{row['cpu']:>8.1f}{row['nfev']:>7d}{row['phi']:>10.1e}"
              f"{row['velocity']:>11.1e}{row['energy']:>11.1e}{row['error']:>10.1e}")


def formulations(args) -> None:
    print(f"\ndouble four-bar (N = 2) to {args.compare_t_end} s: the formulations (B0 error along the run)")
    print(f"{'formulation':<36}{'rtol':>7}{'reached s':>10}{'CPU s':>8}{'nfev':>7}{'B0 error':>10}{'max|ΔE| J':>11}")
    for rtol in args.compare_rtol:
        tangent = n_four_bar(2)
        cases = [("ConstrainedSystem, repivot", ConstrainedSystem(tangent.tree, phi=tangent.phi, q0=tangent.q0,
                                                                  independent=[0], s_dot0=[-1.0], repivot=True)),
                 ("AugmentedSystem", AugmentedSystem(tangent.tree, phi=tangent.phi, q0=tangent.q0,
                                                     s_dot0=tangent.tree_velocities(tangent.q0, tangent.s_dot0))),
                 ("TangentSystem, separation=0", TangentSystem(tangent.tree, phi=tangent.phi, q0=tangent.q0,
                                                               independent=[0], s_dot0=[-1.0], separation=0.0)),
                 ("TangentSystem (continued branch)", tangent)]
        for label, system in cases:
            try:
                row = measure(system, args.compare_t_end, rtol, b0_error(2))
            except pq.SimulationError as failure:
                r = failure.result
                print(f"{label:<36}{rtol:>7.0e}{r.t[-1]:>10.3f}   stopped: {str(failure).split(': ', 1)[1][:60]}")
                continue
            print(f"{label:<36}{rtol:>7.0e}{row['t']:>10.3f}{row['cpu']:>8.1f}{row['nfev']:>7d}{row['error']:>10.1e}"
                  f"{row['energy']:>11.1e}")


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
        at_rest = pq.simulate(held, 1.0, method=r.method, rtol=args.rtol, atol=args.rtol * 1e-2, n_points=11)
        label = f"{r.method}" + (" (default)" if method is None else "")
        print(f"{label:<18}{t_end:>6.1f}{cpu:>8.1f}{r.nfev:>8d}{r.njev:>6d}{r.q[-1, 1]:>12.8f}"
              f"{np.abs(flyball_balance(r)).max():>16.1e}{np.abs(L_z / L_z[0] - 1).max():>11.1e}"
              f"{np.abs(at_rest.q[:, 1] - steady['s']).max():>15.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtol", type=float, default=1e-9)
    parser.add_argument("--n", type=int, nargs="+", default=[2, 40], help="four-bars of A02 (the benchmark's: 40)")
    parser.add_argument("--compare-t-end", type=float, default=10.0)
    parser.add_argument("--compare-rtol", type=float, nargs="+", default=[1e-8, 1e-9, 1e-10])
    parser.add_argument("--flyball-t-end", type=float, default=10.0, help="A05's horizon (the benchmark's: 10 s)")
    parser.add_argument("--dop853-t-end", type=float, default=1.0, help="A05 with DOP853 (about 4.5 CPU s per simulated s)")
    parser.add_argument("--only", choices=["problems", "formulations", "flyball"], help="run one table")
    args = parser.parse_args()
    for name, table in (("problems", problems), ("formulations", formulations), ("flyball", flyball)):
        if args.only in (None, name):
            table(args)


if __name__ == "__main__":
    main()
