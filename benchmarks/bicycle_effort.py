"""Effort for the Whipple bicycle (issue 4, item 6): projeq versus sympy's KanesMethod.

projeq (``projeq.scenes.whipple_bicycle``): the number of minimal velocities, the time to
build the model from scratch (sympy for the rear frame's joint, the tree, the constraint
partition), the CPU time of one evaluation of s̈ and of q̇, and of one eigenvalue
computation (``whipple_eigenvalues``). KanesMethod (``tests/bicycle/kane_whipple.py``, the
independent derivation the tests compare with): derivation time by stage (kinematics,
``kanes_equations``, lambdify), operation count (``sympy.count_ops`` of M, f and the
constraint rows), and the CPU time of one evaluation of u̇ from the lambdified model.
Both models' weave and capsize speeds (Brent's method on the eigenvalues' real parts)
close the table. Ratios are measured in one run; absolute times are this machine's only.

    python benchmarks/bicycle_effort.py           # table (~1–2 min)
    python benchmarks/bicycle_effort.py --json
    python benchmarks/bicycle_effort.py --quick   # projeq's part alone, 0.02 s of timing (a test runs it:
                                                  # KanesMethod's derivation takes ~16 s CPU)
"""

from __future__ import annotations

import os
import argparse
import json
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))  # for tests.bicycle

from projeq.studies.bench import time_per_call  # noqa: E402
from projeq.scenes import bicycle  # noqa: E402
from tests.bicycle import kane_whipple  # noqa: E402

SPEED = 5.0  # m/s, the state timed: a generic leaning, steering, rolling bicycle
ROLL, STEER, ROLL_RATE, STEER_RATE = 0.1, 0.05, 0.2, -0.3


def projeq_effort(budget: float) -> dict:
    bicycle._rear_frame_symbols.cache_clear()
    started = time.perf_counter()
    bike = bicycle.whipple_bicycle(speed=SPEED, roll=ROLL, steer=STEER, roll_rate=ROLL_RATE, steer_rate=STEER_RATE)
    build = time.perf_counter() - started
    seconds = time_per_call({"s_ddot": bike.accelerations, "q_dot": bike.q_dot}, bike.q0, bike.s_dot0, budget)
    started = time.process_time()
    bicycle.whipple_eigenvalues(SPEED)
    return {"n_q": bike.n_q, "n_s_tree": bike.tree.n_s, "n_constraints": bike.n_c, "n_s": bike.n_s,
            "build_s": build, "s_ddot_s": seconds["s_ddot"], "q_dot_s": seconds["q_dot"],
            "eigenvalues_s": time.process_time() - started}


def kane_effort(budget: float) -> tuple[dict, object]:
    stages = {}
    model = kane_whipple.derive(bicycle.BENCHMARK, stages, count=True)
    q = np.array([0.0, ROLL, kane_whipple.pitch(model, ROLL, STEER), 0.0, STEER, 0.0])
    u_ind = np.array([ROLL_RATE, -SPEED / bicycle.BENCHMARK["r_R"], STEER_RATE])
    seconds = time_per_call({"u_dot": lambda q_, u_: kane_whipple.accelerations(model, q_, u_)}, q, u_ind, budget)
    previous, steps = 0.0, {}
    for name, at in stages.items():  # cumulative → per stage
        steps[name + "_s"], previous = at - previous, at
    return {"n_u": 6, "n_u_independent": 3, **steps, "operations": model.operations,
            "u_dot_s": seconds["u_dot"]}, model


def stability_limits(model) -> dict:
    r_R = bicycle.BENCHMARK["r_R"]
    kane = kane_whipple.stability_limits(lambda v: kane_whipple.eigenvalues(model, v, r_R))
    projeq = kane_whipple.stability_limits(bicycle.whipple_eigenvalues)
    return {"weave_kane": kane[0], "capsize_kane": kane[1], "weave_projeq": projeq[0], "capsize_projeq": projeq[1]}


def print_table(p: dict, k: dict, limits: dict) -> None:
    print("Whipple bicycle (MJPR 2007 benchmark parameters)\n")
    print(f"{'':34}{'projeq':>14}{'KanesMethod':>14}")
    print(f"{'coordinates / speeds':34}{p['n_q']:>9} / {p['n_s_tree']:<2}{6:>9} / 6")
    print(f"{'constraints':34}{p['n_constraints']:>14}{'4 (1 + 3)':>14}")
    print(f"{'minimal velocities':34}{p['n_s']:>14}{k['n_u_independent']:>14}")
    derivation = sum(v for key, v in k.items() if key.endswith("_s") and key != "u_dot_s" and key != "count_ops_s")
    print(f"{'build / derive + lambdify (s)':34}{p['build_s']:>14.3f}{derivation:>14.3f}")
    for key in ("kinematics_s", "kanes_equations_s", "lambdify_s"):
        print(f"{'  Kane: ' + key[:-2]:34}{'':>14}{k[key]:>14.3f}")
    print(f"{'operation count (count_ops)':34}{'—':>14}{k['operations']:>14d}")
    print(f"{'one evaluation of the ODE (ms)':34}{1e3 * (p['s_ddot_s'] + p['q_dot_s']):>14.3f}{1e3 * k['u_dot_s']:>14.3f}")
    print(f"{'  ratio projeq / Kane':34}{(p['s_ddot_s'] + p['q_dot_s']) / k['u_dot_s']:>14.1f}")
    print(f"{'eigenvalues at one speed (s)':34}{p['eigenvalues_s']:>14.3f}")
    print(f"{'weave speed (m/s)':34}{limits['weave_projeq']:>14.8f}{limits['weave_kane']:>14.8f}")
    print(f"{'capsize speed (m/s)':34}{limits['capsize_projeq']:>14.8f}{limits['capsize_kane']:>14.8f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of the table")
    parser.add_argument("--budget", type=float, default=1.0, help="seconds of timing per evaluation")
    parser.add_argument("--quick", action="store_true",
                        help="projeq's part alone (no KanesMethod, no stability limits), 0.02 s of timing")
    args = parser.parse_args(argv)
    p = projeq_effort(0.02 if args.quick else args.budget)
    if args.quick:
        print("Whipple bicycle, quick: projeq's part alone (KanesMethod's derivation, ~16 s CPU, and the "
              "stability limits are the full run's)\n" + json.dumps({"projeq": p}))
        return 0
    k, model = kane_effort(args.budget)
    limits = stability_limits(model)
    if args.json:
        print(json.dumps({"projeq": p, "kane": k, "stability": limits}, indent=2))
    else:
        print_table(p, k, limits)
        print("\n" + json.dumps({"projeq": p, "kane": k, "stability": limits}))
    return 0


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    sys.exit(main())
