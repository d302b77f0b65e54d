"""Loads that depend on time stay compiled: ẋ with a time-dependent load against the constant one.

Per evaluation of simulate's right-hand side ẋ = (q̇, s̈) — the default evaluator's one compiled
call where it has one (``state_derivative``), else q̇ and its s̈ —, on ``scenes.flexible_arm()`` (a
RitzBeam as its last link) and on the rigid ``scenes.chain(10)``:

- a ``JointForce`` on the first joint, τ = 1.5 N m constant against τ(t) = a sin ωt given as a
  callable ``lambda t, q, s_dot: A * np.sin(OMEGA * t)`` (numba compiles it, its numbers as data);
- a ``projeq.BodyLoad`` on the last rigid link, a force 2 sin(3 · 0.3) N constant against
  2 sin 3t N (its statement uses t).

Timed in alternating rounds (ratio = time-dependent / constant, per round; the median printed).
Before time entered the compiled loop (projeq 0e1eda0), the time-dependent JointForce on the
flexible arm ran on the interpreted recursive evaluator (46–85× the constant-force run) and on
the rigid chain with the force law in Python between the kernels (3–4×); the BodyLoad of t
2× on the chain and the recursive evaluator on the arm. It also checks that every model runs
compiled with no warning and that its ẋ equals the recursive evaluator's.

    python benchmarks/time_loads.py            # 1 s per model and round, 5 rounds
    python benchmarks/time_loads.py --quick    # a few ms per round, 2 rounds (what the test runs)
"""

from __future__ import annotations

import os
import argparse
import warnings

import numpy as np

import projeq as pq
from projeq.studies.timing import per_call, right_hand_side

A, OMEGA = 1.5, 3.0  # τ(t) = A sin(OMEGA t)


class Push(pq.BodyLoad):
    """A force (0, a sin ωt, 0) at the body's origin, body coordinates; at t = 0.3 when not ``of_t``."""

    def __init__(self, body, a, omega, of_t=True):
        super().__init__(body)
        self.a, self.omega, self.of_t = float(a), float(omega), bool(of_t)

    def statement(self, R, r, v, omega, t, m):
        return m.vector([0.0, self.a * m.sin(self.omega * (t if self.of_t else 0.3)), 0.0, 0.0, 0.0, 0.0])


def with_forces(system: pq.System, forces: list) -> pq.System:
    """``system`` rebuilt with ``forces``."""
    return pq.System(dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
                     gravity=system.gravity, forces=forces, q0=system.q0, s_dot0=system.s_dot0)


def models() -> dict:
    """{scene: {case: System}}: each scene with a constant and a time-dependent JointForce and BodyLoad."""
    found = {}
    for scene, base, body in (("flexible_arm", pq.scenes.flexible_arm(), "fore"),
                              ("chain(10)", pq.scenes.chain(10), "link10")):
        joint = base.names[0]
        found[scene] = {
            "JointForce constant": with_forces(base, [pq.JointForce(joint, A * np.sin(OMEGA * 0.3))]),
            "JointForce of t": with_forces(base, [pq.JointForce(joint, lambda t, q, s_dot: A * np.sin(OMEGA * t))]),
            "BodyLoad constant": with_forces(base, [Push(body, 2.0, 3.0, of_t=False)]),
            "BodyLoad of t": with_forces(base, [Push(body, 2.0, 3.0)]),
        }
    return found


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=1.0, help="timing per model and round (default 1)")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    parser.add_argument("--quick", action="store_true", help="0.01 s per model and round, 2 rounds")
    args = parser.parse_args(argv)
    seconds, rounds = (0.01, 2) if args.quick else (args.seconds, args.rounds)
    t = 0.7
    report = {}
    for scene, cases in models().items():
        print(f"\n{scene}: per ẋ evaluation in µs (t = {t}); ratio = of t / constant, alternating rounds")
        calls, checks = {}, {}
        for case, system in cases.items():
            with warnings.catch_warnings():
                warnings.simplefilter("error")  # compiled by default: no warning that a piece runs in Python
                ev = system.evaluator()
            x = np.concatenate((system.q0, system.s_dot0)) + 0.1
            calls[case] = (lambda f=right_hand_side(system), x=x: f(t, x))
            n_q = system.n_q
            reference = np.concatenate((system.q_dot(x[:n_q], x[n_q:], t),
                                        system.accelerations(x[:n_q], x[n_q:], t, method="recursive")))
            error = float(np.abs(calls[case]() - reference).max() / (1 + np.abs(reference).max()))
            one_call = getattr(ev, "state_derivative", None) is not None and ev.state_derivative(t, x) is not None
            checks[case] = {"evaluator": ev.name, "in Python": ev.evaluator.interpreted, "one call": one_call,
                            "vs recursive": error}
            print(f"  {case:20} evaluator {ev.name}, in Python {ev.evaluator.interpreted}, one-call ẋ {one_call}, "
                  f"ẋ vs recursive {error:.1e}")
        ratios = []
        for k in range(rounds):
            times = {case: per_call(call, seconds) for case, call in calls.items()}
            ratios.append([times["JointForce of t"] / times["JointForce constant"],
                           times["BodyLoad of t"] / times["BodyLoad constant"]])
            print(f"  round {k}: " + ", ".join(f"{case} {us:.1f}" for case, us in times.items())
                  + f"; ratios {ratios[-1][0]:.2f}, {ratios[-1][1]:.2f}")
        median = np.median(np.array(ratios), axis=0)
        print(f"  median ratio: JointForce {median[0]:.2f} (target ≤ 1.2), BodyLoad {median[1]:.2f}")
        report[scene] = {"checks": checks, "ratios": ratios, "median": median.tolist()}
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
