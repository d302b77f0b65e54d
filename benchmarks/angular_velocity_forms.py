"""ω̃ = RᵀṘ of a body given by its orientation R alone (``symbolic.barhorst_examples.PoseBody``
without ω), its entries simplified two ways: ``sympy.trigsimp(sympy.expand(·))`` (the former
code) and the sin² + cos² = 1 normal form :func:`projeq.symbolic.algebra.trig_normal` (now): the
seconds of each, their ratio, and whether the two give identical expressions — for one, two and
three Euler angles (the last is the rolling disk's C = R_z(q1) R_x(q2) R_y(q3), Barhorst §3.2).

    PYTHONPATH=. python benchmarks/angular_velocity_forms.py [--quick]   # --quick: R_z alone
"""

from __future__ import annotations

import os
import argparse
import time

import sympy as sp

from projeq.symbolic.algebra import rotation_x, rotation_y, rotation_z, trig_normal


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one Euler angle only (what a test runs)")
    args = parser.parse_args(argv)
    q = sp.symbols("q1:4")
    q_dot = sp.symbols("q1_dot q2_dot q3_dot")
    cases = {"R_z": rotation_z(q[0]), "R_z R_x": rotation_z(q[0]) * rotation_x(q[1]),
             "R_z R_x R_y": rotation_z(q[0]) * rotation_x(q[1]) * rotation_y(q[2])}
    if args.quick:
        cases = {"R_z": cases["R_z"]}
    print(f"{'R':12s} {'trigsimp s':>10s} {'trig_normal s':>13s} {'ratio':>6s} identical")
    for name, R in cases.items():
        W = R.T * sum((R.diff(qi) * rate for qi, rate in zip(q, q_dot)), sp.zeros(3, 3))
        started = time.perf_counter()
        before = W.applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
        middle = time.perf_counter()
        after = W.applyfunc(lambda e: trig_normal(e, q))
        done = time.perf_counter()
        print(f"{name:12s} {middle - started:10.3f} {done - middle:13.3f} {(middle - started) / (done - middle):6.1f} "
              f"{before == after}")


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
