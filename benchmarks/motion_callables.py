"""A Prescribed joint moved by a callable t -> (θ, θ̇, θ̈), compiled (after) against stated in Python
between the compiled kernels (before).

Per evaluation of the default evaluator's s̈ (``accelerations``) and of simulate's right-hand side
ẋ = (q̇, s̈) — the evaluator's one compiled call (``state_derivative``) where it has one, else q̇ and
its s̈ —, on ``scenes.rotating_blade()`` (a massless hub turned at Ω t, a RitzBeam of 8 coordinates:
the fast evaluator), on a hub turned by θ = Ω t + a sin ωt carrying two links under gravity, and on
``scenes.spin_up_beam()`` (the hub-beam path, whose kernel takes a callable motion's θ, θ̇, θ̈ from
Python both times: printing its row would cost ``projeq run`` the import of sympy; the ratio there is
about 1). Before: the same joint with
no compiled values (what projeq did for every callable motion until the callable was compiled, its row
by its Python ``relative_values`` at every evaluation; ``PythonMotion`` below); after: the callable
compiled (:func:`projeq.assembly.given.motion_callbacks`). Timed in alternating rounds (ratio =
before / after, per round; the median printed); it also checks that the compiled model runs with
nothing in Python and that its ẋ equals the recursive evaluator's.

    python benchmarks/motion_callables.py            # 1 s per model and round, 5 rounds
    python benchmarks/motion_callables.py --quick    # a few ms per round, 2 rounds (what the test runs)
"""

from __future__ import annotations

import argparse
import os
import warnings

import numpy as np

import projeq as pq
from projeq.assembly import given
from projeq.studies.timing import per_call, right_hand_side

OMEGA, A, W = 2.0, 0.3, 5.0  # the chain's hub: θ = Ω t + a sin ωt


class PythonMotion(pq.Prescribed):
    """A Prescribed joint without compiled values: its motion stated in Python at every evaluation."""

    def compiled_values(self):
        return None


def _spin(omega, a, w):
    return lambda t: (omega * t + a * np.sin(w * t), omega + a * w * np.cos(w * t), -a * w**2 * np.sin(w * t))


def rebuilt(system: pq.System, joint_class) -> pq.System:
    """``system`` with its first joint, a Prescribed one, rebuilt as ``joint_class``."""
    joints = dict(zip(system.names, system.joints))
    hub = system.joints[0]
    joints[system.names[0]] = joint_class(hub.joint, hub.motion)
    return pq.System(dict(zip(system.names, system.subsystems)), joints, gravity=system.gravity,
                     forces=system.forces, q0=system.q0, s_dot0=system.s_dot0)


def hub_chain() -> pq.System:
    """A hub turned by θ = Ω t + a sin ωt about an oblique axis, two links below it under gravity."""
    link = {"r_c": (0.0, 0.0, -0.5), "I_c": np.diag([0.08, 0.09, 0.01])}
    hub = pq.Prescribed(pq.Revolute(axis=(0.0, 0.6, 0.8), r_pn=(0.2, 0.0, 0.1)), _spin(OMEGA, A, W))
    return pq.System({"hub": pq.RigidBody(1.5, r_c=(0.3, 0.0, 0.0), I_c=np.diag([0.1, 0.2, 0.3])),
                      "a": pq.RigidBody(1.0, **link), "b": pq.RigidBody(0.7, **link)},
                     {"hub": hub, "a": pq.Revolute("hub", axis="x", r_pn=(0.5, 0.0, 0.0)),
                      "b": pq.Revolute("a", axis="y", r_pn=(0.0, 0.0, -1.0))},
                     gravity=(0.0, 0.0, -9.81), q0=(0.4, -0.3))


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=1.0, help="timing per model and round (default 1)")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    parser.add_argument("--quick", action="store_true", help="0.01 s per model and round, 2 rounds")
    args = parser.parse_args(argv)
    seconds, rounds = (0.01, 2) if args.quick else (args.seconds, args.rounds)
    t = 0.7
    report = {}
    for scene, after in (("rotating_blade", pq.scenes.rotating_blade()), ("hub chain", hub_chain()),
                         ("spin_up_beam", pq.scenes.spin_up_beam())):
        print(f"\n{scene}: µs per evaluation (t = {t}); ratio = before / after, alternating rounds")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.assembly.PythonPieceWarning)  # before: the joint in Python, said
            cases = {"before": rebuilt(after, PythonMotion).evaluator(), "after": after.evaluator()}
        x = np.concatenate((after.q0, after.s_dot0)) + 0.01
        q, s_dot, n_q = x[:after.n_q], x[after.n_q:], after.n_q
        reference = np.concatenate((after.q_dot(q, s_dot, t), after.accelerations(q, s_dot, t, method="recursive")))
        calls, checks = {}, {}
        for case, ev in cases.items():
            x_dot = right_hand_side(after, ev)
            calls[f"s̈ {case}"] = lambda ev=ev, q=q, s_dot=s_dot: ev.accelerations(q, s_dot, t)
            calls[f"ẋ {case}"] = lambda x_dot=x_dot, x=x: x_dot(t, x)
            error = float(np.abs(x_dot(t, x) - reference).max() / (1 + np.abs(reference).max()))
            hub = ev.evaluator.system.joints[0]
            checks[case] = {"evaluator": ev.name, "hub compiled": given.python_reason(hub) is None,
                            "in Python": getattr(ev.evaluator, "interpreted", []),
                            "one call": ev.state_derivative(t, x) is not None, "vs recursive": error}
            print(f"  {case:6} evaluator {ev.name}, hub compiled {checks[case]['hub compiled']}, in Python "
                  f"{checks[case]['in Python']}, one-call ẋ {checks[case]['one call']}, ẋ vs recursive {error:.1e}")
        ratios = []
        for k in range(rounds):
            times = {name: per_call(call, seconds) for name, call in calls.items()}
            ratios.append([times["s̈ before"] / times["s̈ after"], times["ẋ before"] / times["ẋ after"]])
            print(f"  round {k}: " + ", ".join(f"{name} {us:.1f}" for name, us in times.items())
                  + f"; ratios s̈ {ratios[-1][0]:.2f}, ẋ {ratios[-1][1]:.2f}")
        median = np.median(np.array(ratios), axis=0)
        print(f"  median ratio before / after: s̈ {median[0]:.2f}, ẋ {median[1]:.2f}")
        report[scene] = {"checks": checks, "ratios": ratios, "median": median.tolist(), "n_q": n_q}
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
