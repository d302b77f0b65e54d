"""Joints of kind GIVEN (UserJoints from sympy, Planar, Free, Prescribed) in the fast evaluator:
the cost of one s̈ (``accelerations``) and of one ẋ by the one-call kernel (``state_derivative``;
"-" where the evaluator has none), and of ``simulate``'s CPU time, for the rolling disk, the car,
the knife-edge disc and a Free-jointed body with a chain of two revolute links below it, with
``chain(k)`` (no joint of kind GIVEN) beside them. Run it on two checkouts alternately to compare:

    PYTHONPATH=/path/to/checkout python benchmarks/given_joints.py [--simulate 3]
    PYTHONPATH=. python benchmarks/given_joints.py --quick   # 10 ms of timing, 50 ms runs (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time
import timeit

import numpy as np

import projeq as pq


def free_chain() -> pq.System:
    """A rigid body on a Free joint under gravity, two links hanging from it by revolute joints."""
    body = pq.RigidBody(2.0, r_c=(0.0, 0.0, 0.0), I_c=np.diag([0.3, 0.4, 0.5]))
    link = pq.RigidBody(1.0, r_c=(0.0, 0.0, -0.5), I_c=np.diag([0.08, 0.08, 0.01]))
    return pq.System({"body": body, "a": link, "b": link},
                     {"body": pq.Free(), "a": pq.Revolute("body", axis="y"),
                      "b": pq.Revolute("a", axis="x", r_pn=(0.0, 0.0, -1.0))})


def models() -> dict:
    free = free_chain()
    return {"rolling_disk": pq.scenes.rolling_disk(), "car": pq.scenes.car(), "knife_edge_disc": pq.scenes.knife_edge_disc(),
            "free_chain": free, "chain(3)": pq.scenes.chain(3), "chain(10)": pq.scenes.chain(10)}


def state(model) -> tuple[np.ndarray, np.ndarray]:
    q = np.array(model.q0, dtype=float)
    s_dot = np.array(getattr(model, "s_dot0", np.zeros(model.n_s)), dtype=float) + 0.1
    return q, s_dot


def per_call(f, budget: float) -> float:
    """µs per call, the best of five repeats of about ``budget``/5 s each."""
    f()
    number = max(1, int(budget / 5 / max(timeit.timeit(f, number=20) / 20, 1e-7)))
    return min(timeit.repeat(f, number=number, repeat=5)) / number * 1e6


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=float, default=1.0, help="seconds of timing per model and quantity")
    parser.add_argument("--simulate", type=float, default=0.0, help="also simulate the first three this many s")
    parser.add_argument("--quick", action="store_true", help="--budget 0.01 --simulate 0.05")
    args = parser.parse_args(argv)
    if args.quick:
        args.budget, args.simulate = 0.01, 0.05
    print(f"{'model':16} {'s̈ µs':>8} {'ẋ one-call µs':>14}")
    for name, model in models().items():
        ev = model.evaluator("fast")
        q, s_dot = state(model)
        x = np.concatenate((q, s_dot))
        s_ddot = per_call(lambda ev=ev, q=q, s_dot=s_dot: ev.accelerations(q, s_dot, 0.0), args.budget)
        one_call = ev.state_derivative(0.0, x) is not None
        x_dot = per_call(lambda ev=ev, x=x: ev.state_derivative(0.0, x), args.budget) if one_call else None
        print(f"{name:16} {s_ddot:8.2f} {'-' if x_dot is None else f'{x_dot:.2f}':>14}")
    if args.simulate:
        for name in ("rolling_disk", "car", "knife_edge_disc"):
            model = models()[name]
            q, s_dot = state(model)
            pq.simulate(model, 0.1, q, s_dot)  # compiled and warm
            start = time.process_time()
            result = pq.simulate(model, args.simulate, q, s_dot)
            print(f"simulate {name} {args.simulate:g} s: {time.process_time() - start:.3f} CPU s, "
                  f"{result.nfev} evaluations")


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
