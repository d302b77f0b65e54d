"""The spinning beam's ρI α̈ coupling under spin-up: B(18), B(23), the beam without
torsional strain, projeq's RitzBeam and an independent chain of rigid slices
(docs/theory.md, "The spinning beam's rotary inertia"; H. Bremer, "Problems in fast moving
non-holonomic elastic systems", B(16)–(23)).

Case: α from ``spin_up_motion(3, 2)``, L = ρA = EI = 1, ρI = 0.05, 2 polynomial functions
per plane, a0 = (0.01, 0, 0, 0), 3 s. Prints

1. the Ritz-constrained chain (``projeq.subsystems.beam.slice_chain``) against the
   torsion-free Ritz model, matrix by matrix, for three kinds of joints and growing N;
2. the motions: max |Δa| over 3 s between the extrapolated chains, RitzBeam and the three
   Ritz models;
3. with ``--free``: a chain of free rigid slices built with projeq's rigid-body API
   (``scenes.elastic.rigid_slice_chain``: RigidBody, a Cardan UserJoint, JointSpring; no
   Ritz field) against RitzBeam and the three Ritz models with 6 functions per plane — the
   tip deflection (v, w)(L) over 3 s (slow: ~10 min; 32 slices take most of it).
   Measured: the chain changes by 4.5e-4 from 8 to 16 slices and 1.1e-4 from 16 to 32 (as
   Δx²); at 32 slices it is 6.5e-5 from the torsion-free model (whose own truncation, 4 → 6
   functions, is 1.8e-4), 6.7e-4 from B(18) and 7.5e-4 from B(23).

    python benchmarks/spinning_beam_chain.py [--free]
    python benchmarks/spinning_beam_chain.py --quick   # N = 10 only, 0.3 s of motion (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time

import numpy as np

from projeq.joints import Prescribed, Revolute
from projeq.scenes.elastic import spin_up_motion
from projeq.simulation.driver import simulate
from projeq.subsystems.beam.beam import RitzBeam
from projeq.subsystems.beam.slice_chain import JOINTS, SliceChain, extrapolated_model
from projeq.symbolic import spinning_beam as sb
from projeq.system import System

L, RHO_A, EI, RHO_I, T_END = 1.0, 1.0, 1.0, 0.05, 3.0
MOTION = spin_up_motion(3.0, 2.0)


def ritz_motion(model, n: int = 2, times=None, t_end: float = T_END):
    """a(t) of a RitzModel under the spin-up from a0 = (0.01, 0, …)."""
    a0 = np.zeros(2 * n)
    a0[0] = 0.01
    t, a = sb.simulate_ritz(model, MOTION, a0, np.zeros(2 * n), t_end)[:2]
    return a if times is None else np.array([np.interp(times, t, column) for column in a.T]).T


def ritzbeam_motion(n: int, times):
    beam = RitzBeam(L, RHO_A, EI, n_v=n, n_w=n, family="polynomial", rho_I=(RHO_I, RHO_I))
    system = System({"beam": beam}, {"beam": Prescribed(Revolute(axis="x"), MOTION)})
    a0 = np.zeros(2 * n)
    a0[0] = 0.01
    return simulate(system, times[-1], q0=a0, t_eval=times, rtol=1e-9, atol=1e-12).q


def matrices_table(sizes=(10, 20, 40, 80)) -> None:
    reference = sb.ritz_models(2, rho_I_value=RHO_I, kinds=("torsion_free",))["torsion_free"]
    print("1. Ritz-constrained chain − torsion-free Ritz model, max |entry| (2 functions per plane)")
    print(f"{'joint':>9} {'N':>4} {'time_s':>7} " + " ".join(f"{name:>9}" for name in reference._fields))
    for joint in JOINTS:
        for n_slices in sizes:
            start = time.process_time()
            model = SliceChain(n_slices, rho_I=RHO_I, joint=joint).linear_model()
            seconds = time.process_time() - start
            errors = " ".join(f"{np.max(np.abs(m - r)):9.2e}" for m, r in zip(model, reference))
            print(f"{joint:>9} {n_slices:4d} {seconds:7.2f} {errors}")


def motions_table(sizes=(10, 20, 40), t_end: float = T_END) -> None:
    models = sb.ritz_models(2, rho_I_value=RHO_I)
    times = np.linspace(0.0, t_end, 201)
    runs = {name: ritz_motion(model, times=times, t_end=t_end) for name, model in models.items()}
    for n_slices in sizes:
        chain = extrapolated_model(n_slices, rho_I=RHO_I)
        runs[f"chain {n_slices}/{2 * n_slices}"] = ritz_motion(chain, times=times, t_end=t_end)
    runs["RitzBeam"] = ritzbeam_motion(2, times)
    names = list(runs)
    print(f"\n2. spin-up: max |Δa| over {t_end:g} s (a0 = 0.01); chain N/2N = extrapolated from N and 2N "
          "slices")
    print(" " * 16 + " ".join(f"{name:>14}" for name in names))
    for row in names:
        print(f"{row:>16}" + " ".join(f"{np.max(np.abs(runs[row] - runs[col])):14.2e}" for col in names))


def free_table(slices=(8, 16, 32)) -> None:
    from projeq.scenes.elastic import rigid_slice_chain, rigid_slice_chain_tip

    times = np.linspace(0.0, T_END, 31)
    n = 6
    tips = {}
    for kind, model in sb.ritz_models(n, rho_I_value=RHO_I).items():
        a = ritz_motion(model, n, times)
        tips[kind] = np.stack([a[:, :n].sum(1), a[:, n:].sum(1)], 1)  # φ_k(L) = 1
    a = ritzbeam_motion(n, times)
    tips["RitzBeam"] = np.stack([a[:, :n].sum(1), a[:, n:].sum(1)], 1)
    for n_slices in slices:
        start = time.process_time()
        system, q0 = rigid_slice_chain(n_slices, MOTION, rho_I=RHO_I, initial_deflection=lambda x: 0.01 * x**2)
        result = simulate(system, T_END, q0=q0, t_eval=times, rtol=1e-8, atol=1e-11)
        tips[f"free {n_slices}"] = np.array([rigid_slice_chain_tip(q)[1:] for q in result.q])
        print(f"(free chain of {n_slices} slices: {time.process_time() - start:.1f} s CPU)")
    names = list(tips)
    print("\n3. free rigid slices (projeq RigidBody + Cardan UserJoint + JointSpring) vs 6 functions per plane:")
    print("   max |Δ(v, w)(L)| over 3 s")
    print(" " * 14 + " ".join(f"{name:>13}" for name in names))
    for row in names:
        print(f"{row:>14}" + " ".join(f"{np.max(np.abs(tips[row] - tips[col])):13.2e}" for col in names))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--free", action="store_true", help="add the free rigid-slice chain (slow)")
    parser.add_argument("--quick", action="store_true", help="N = 10 only and 0.3 s of motion")
    args = parser.parse_args(argv)
    if args.quick:
        matrices_table((10,))
        motions_table((10,), 0.3)
    else:
        matrices_table()
        motions_table()
    if args.free:
        free_table()


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
