"""A joint and a force law projeq does not ship, each stated once in this file, run compiled by default.

A helical (screw) joint of pitch p — rotation θ about the unit axis e with the advance p θ along
it — written as the one ``statement(q, t, m)`` that docs/architecture.md describes. On a chain of
N bodies (each on a helical joint about a tilted axis, 1 m below its parent) this script checks
that the default evaluator takes it compiled with no warning, that its s̈ equals the recursive
evaluator's (the statement on numpy), that ``gauss_form`` (the statement traced with sympy) and
the exact Jacobian work on it, and times one s̈ against the same chain built from built-in joints
(per link a Revolute about e on a massless Frame, then a Prismatic along e: the same placements
with the advance a freedom of its own), both through the evaluator and through the public
``System.accelerations``, in alternating rounds (ratio = helical / built-in, per round). Likewise a
quadratic air drag −c |v| v stated once as a ``projeq.BodyLoad``, on every body of ``chain(N)``,
against a built-in ``SpringDamper`` per body (from a point of the body to the ground).

    python benchmarks/statements.py            # N = 20, 1 s of timing per round, 5 rounds
    python benchmarks/statements.py --quick    # N = 3, a few ms per round (what the test runs)
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.joints import Stated
from projeq.studies.timing import per_call


class Helical(pq.Joint):
    """Rotation θ about the unit axis e with the advance p θ along it (pitch p in m/rad)."""

    n_q = n_s = 1

    def __init__(self, parent=None, axis=(0.0, 0.0, 1.0), pitch=0.01, r_pn=(0.0, 0.0, 0.0)):
        super().__init__(parent, r_pn)
        self.e, self.pitch = np.asarray(axis, float) / np.linalg.norm(axis), float(pitch)

    def statement(self, q, t, m):
        return Stated(A=m.rotation(self.e, q[0]), r=self.pitch * q[0] * m.vector(self.e),
                      F=m.columns(m.vector([*(self.pitch * self.e), *self.e])))


class QuadraticDrag(pq.BodyLoad):
    """Air drag −c |v| v on the origin of a body (v its velocity, body coordinates)."""

    def __init__(self, body, c):
        super().__init__(body)
        self.c = float(c)

    def statement(self, R, r, v, omega, t, m):
        speed = m.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
        return m.vector([*(-self.c * speed * v), 0.0, 0.0, 0.0])


def loaded_chains(n: int) -> tuple[pq.System, pq.System]:
    """``chain(n)`` with a QuadraticDrag on every body, and with a SpringDamper on every body."""
    chain = pq.scenes.chain(n)
    parts = (dict(zip(chain.names, chain.subsystems)), dict(zip(chain.names, chain.joints)))
    drag = pq.System(*parts, gravity=chain.gravity, forces=[QuadraticDrag(name, 0.3) for name in chain.names])
    springs = pq.System(*parts, gravity=chain.gravity,
                        forces=[pq.SpringDamper(name, (0.0, 0.0, -0.5), None, (0.0, 0.0, 0.0), 50.0, 0.5, 0.2)
                                for name in chain.names])
    return drag, springs


AXIS, PITCH = np.array([0.2, 1.0, 0.1]) / np.linalg.norm([0.2, 1.0, 0.1]), 0.02


def _link() -> pq.RigidBody:
    return pq.RigidBody(1.0, r_c=(0.1, 0.0, -0.5), I_c=np.diag([0.1, 0.12, 0.05]))


def helical_chain(n: int) -> pq.System:
    """N bodies, each on a Helical joint about AXIS, 1 m below the previous one."""
    joints = {f"b{i}": Helical(None if i == 0 else f"b{i - 1}", AXIS, PITCH, (0.0, 0.0, -1.0 if i else 0.0))
              for i in range(n)}
    return pq.System({name: _link() for name in joints}, joints, gravity=(0.0, 0.0, -9.81))


def built_in_chain(n: int) -> pq.System:
    """The same links, each on a Revolute about AXIS (a massless Frame) and a Prismatic along it."""
    bodies, joints = {}, {}
    for i in range(n):
        bodies[f"f{i}"], bodies[f"b{i}"] = pq.Frame(), _link()
        joints[f"f{i}"] = pq.Revolute(None if i == 0 else f"b{i - 1}", AXIS, (0.0, 0.0, -1.0 if i else 0.0))
        joints[f"b{i}"] = pq.Prismatic(f"f{i}", AXIS)
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -9.81))


def checks(system: pq.System, q: np.ndarray, s_dot: np.ndarray) -> dict:
    """The default evaluator (compiled, no warning), its s̈ against the recursive evaluator's, the
    symbolic Gauss form and the exact Jacobian (on a chain of two, the sympy derivation's cost)."""
    from projeq.analysis.jacobians import state_jacobian

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        default = system.evaluator()
    reference = system.accelerations(q, s_dot, method="recursive")
    error = np.abs(default.accelerations(q, s_dot, 0.0) - reference).max() / (1 + np.abs(reference).max())
    small = helical_chain(2)
    q2, s2 = q[:2], s_dot[:2]
    symbolic = pq.symbolic.gauss_form(small).evaluator().accelerations(q2, s2)
    symbolic_error = np.abs(symbolic - small.accelerations(q2, s2, method="recursive")).max()
    _, how = state_jacobian(system, np.concatenate((q, s_dot)), 0.0)
    return {"evaluator": default.name, "in Python": default.evaluator.interpreted, "compiled vs recursive": error,
            "gauss_form vs recursive (N = 2)": symbolic_error, "Jacobian": how}



def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, default=20, help="bodies in the chain (default 20)")
    parser.add_argument("--seconds", type=float, default=1.0, help="timing per model and round (default 1)")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    parser.add_argument("--quick", action="store_true", help="N = 3, 0.02 s per round, 2 rounds")
    args = parser.parse_args(argv)
    n, seconds, rounds = (3, 0.02, 2) if args.quick else (args.n, args.seconds, args.rounds)
    helical, built_in = helical_chain(n), built_in_chain(n)
    rng = np.random.default_rng(0)
    q, s_dot = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    q_b, s_b = np.zeros(2 * n), np.zeros(2 * n)  # the built-in chain at the same angles and advances
    q_b[0::2], q_b[1::2], s_b[0::2], s_b[1::2] = q, PITCH * q, s_dot, PITCH * s_dot
    start = time.process_time()
    found = checks(helical, q, s_dot)
    for key, value in found.items():
        print(f"{key:32} {value}")
    print(f"{'checks (CPU s)':32} {time.process_time() - start:.2f}")
    drag, springs = loaded_chains(n)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found["drag in Python"] = drag.evaluator().evaluator.interpreted
    q_c, s_c = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    reference = drag.accelerations(q_c, s_c, method="recursive")
    found["drag compiled vs recursive"] = float(np.abs(drag.accelerations(q_c, s_c) - reference).max()
                                                / (1 + np.abs(reference).max()))
    print(f"{'drag in Python':32} {found['drag in Python']}")
    print(f"{'drag compiled vs recursive':32} {found['drag compiled vs recursive']:.2g}")
    pairs = {
        "helical, evaluator": (lambda ev=helical.evaluator(): ev.accelerations(q, s_dot, 0.0),
                               lambda ev=built_in.evaluator(): ev.accelerations(q_b, s_b, 0.0)),
        "helical, public call": (lambda: helical.accelerations(q, s_dot), lambda: built_in.accelerations(q_b, s_b)),
        "drag, evaluator": (lambda ev=drag.evaluator(): ev.accelerations(q_c, s_c, 0.0),
                            lambda ev=springs.evaluator(): ev.accelerations(q_c, s_c, 0.0)),
        "drag, public call": (lambda: drag.accelerations(q_c, s_c), lambda: springs.accelerations(q_c, s_c)),
    }
    print(f"\nchain of {n}: s̈ in µs, stated / built-in (helical vs Revolute + Frame + Prismatic; drag vs "
          "SpringDamper per body), alternating rounds")
    print(f"{'round':>5} " + " ".join(f"{name:>22}" for name in pairs))
    ratios = []
    for k in range(rounds):
        row = []
        for stated, built in pairs.values():
            a, b = per_call(stated, seconds), per_call(built, seconds)
            row.append(a / b)
        ratios.append(row)
        print(f"{k:5d} " + " ".join(f"{r:22.2f}" for r in row))
    median = np.median(np.array(ratios), axis=0)
    print("median ratio: " + ", ".join(f"{name} {m:.2f}" for name, m in zip(pairs, median)) + " (target ≤ 1.3)")
    return found | {"ratios": ratios}


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
