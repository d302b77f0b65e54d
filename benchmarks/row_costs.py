"""CPU per output row (µs) of a scene's default run, by part: the states the integrator hands to
the rows (``driver._row_values``' x, all 501 of a default run), each part timed over all rows
(best of 3): q's normalisation (with a ConstrainedSystem's projection onto Φ = 0), and for a
ConstrainedSystem A_s, ṡ_tree = F ṡ + f, the tree's energy, the residual and the rank; the
energy and the residual for a System; and the whole row (normalisation and ``output_row``).
Run it with either checkout on PYTHONPATH to compare them.

    PYTHONPATH=. python benchmarks/row_costs.py [SCENE[:t_end] ...]
    PYTHONPATH=. python benchmarks/row_costs.py --quick   # chain:0.1 and four_bar:0.1 (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time

import projeq as pq
import projeq.simulation.driver as driver
from projeq import scenes

SCENES = ("chain", "double_pendulum", "andrews_squeezer", "four_bar", "whipple_bicycle:2", "elastic_arm",
          "car")


def row_states(name: str, t_end: float | None) -> tuple:
    """(model, x, t) of every output row of the scene's default run."""
    scene = scenes.SCENES[name]
    model = scene.build()
    t_end = t_end or scene.t_end
    pq.simulate(model, t_end / 50, **(scene.settings or {}))  # the kernels from numba's disk cache
    kept, row_values = {}, driver._row_values

    def keep(run, rows, x):
        kept["x"], kept["t"] = x.copy(), [t for _, t in rows]
        return row_values(run, rows, x)

    driver._row_values = keep
    try:
        pq.simulate(model, t_end, **(scene.settings or {}))
    finally:
        driver._row_values = row_values
    return model, kept["x"], kept["t"]


def per_row(f, n: int) -> float:
    """µs per call of f(i) over i < n, best of 3."""
    best = float("inf")
    for _ in range(3):
        started = time.process_time()
        for i in range(n):
            f(i)
        best = min(best, (time.process_time() - started) / n)
    return 1e6 * best


def parts(model, X, T) -> dict:
    """µs per row of each part at the rows' states X (q, ṡ) and times T."""
    n, N = model.n_q, len(X)
    constrained = hasattr(model, "project")

    def normalise(i):
        return model.normalized(X[i][:n], T[i])

    Q = [normalise(i) for i in range(N)]
    cost = {"normalise": per_row(normalise, N)}
    if constrained:
        cost["A_s"] = per_row(lambda i: model.constraint_matrix(Q[i], T[i]), N)
        A = [model.constraint_matrix(Q[i], T[i]) for i in range(N)]
        cost["s_tree"] = per_row(lambda i: model.tree_velocities(Q[i], X[i][n:], T[i], A[i]), N)
        S = [model.tree_velocities(Q[i], X[i][n:], T[i], A[i]) for i in range(N)]
        cost["energy"] = per_row(lambda i: model.tree.energy(Q[i], S[i], T[i]), N)
        cost["residual"] = per_row(
            lambda i: model.constraint_residual(Q[i], model._q_dot(Q[i], S[i], T[i]), T[i]), N)
        cost["rank"] = per_row(lambda i: model._rank_and_mobility(A[i][0]), N)
    else:
        cost["energy"] = per_row(lambda i: model.energy(Q[i], X[i][n:], T[i]), N)
        cost["residual"] = per_row(
            lambda i: model.constraint_residual(Q[i], model.q_dot(Q[i], X[i][n:], T[i]), T[i]), N)
    cost["row"] = per_row(lambda i: model.output_row(normalise(i), X[i][n:], T[i]), N)
    return cost


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=SCENES, help="scene names, optionally name:t_end")
    parser.add_argument("--quick", action="store_true", help="chain:0.1 and four_bar:0.1")
    args = parser.parse_args(argv)
    for spec in ("chain:0.1", "four_bar:0.1") if args.quick else args.scenes:
        name, _, t = spec.partition(":")
        cost = parts(*row_states(name, float(t) if t else None))
        print(f"{name:17s} " + " ".join(f"{k} {v:6.0f}" for k, v in cost.items()) + "  µs/row", flush=True)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
