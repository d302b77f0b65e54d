"""Where the time of one compiled s̈ of a TangentSystem goes (Andrews' squeezer and Bricard's
mechanism by default): each piece of :func:`projeq.constraints.compiled.tangent` — Φ_q by the
complex step, the SVD of A_s, N and F = N N_ind⁻¹, γ, x₀ = A_s⁺(−γ) and f̄, the tree's terms and
FᵀMF (:func:`projeq.constraints.compiled._projected`) — repeated in a compiled loop over the
moving states of ``benchmarks/scene_costs.py`` (:func:`projeq.studies.bench_scenes.moving_states`),
next to a compiled call that only takes the kernel's arguments, the whole kernel called from
Python, the Python wrapper around it
(:meth:`~projeq.constraints.compiled.CompiledClosure.minimal_accelerations`), the evaluator's s̈
and the compiled chain(k)'s, all timed alternately in one run
(:func:`projeq.studies.timing.time_per_call`: ratios hold on a loaded machine; µs per call).

    python benchmarks/tangent_profile.py                       # Andrews' squeezer, Bricard
    python benchmarks/tangent_profile.py n_four_bar            # another TangentSystem scene
    python benchmarks/tangent_profile.py --quick               # Andrews' squeezer, 0.05 s of timing
"""

from __future__ import annotations

import os
import argparse
import itertools
import types

import numpy as np

from projeq import scenes
from projeq.assembly import kernels
from projeq.assembly.linalg import SINGULAR_PIVOT
from projeq.constraints import compiled
from projeq.constraints.compiled import (
    _constraint_gamma, _constraint_rows, _particular, _projected, _scaled, _svd,
)
from projeq.studies.bench_scenes import STATES, moving_states
from projeq.studies.timing import time_per_call

REPEATS = 50  # passes over the states per compiled loop


def jacobian_loop(phi, pins, fields, pfaffian, joints, tree, Q, t, m_h, A, repeats):
    for _ in range(repeats):
        for j in range(Q.shape[0]):
            _constraint_rows(phi, pins, fields, pfaffian, joints, tree, Q[j], t, m_h, A)


def svd_loop(As, repeats):
    for _ in range(repeats):
        for j in range(As.shape[0]):
            _svd(As[j])


def scaled_loop(Vts, independent, repeats):
    k = independent.shape[0]
    for _ in range(repeats):
        for j in range(Vts.shape[0]):
            Vt = Vts[j]
            _scaled(Vt[Vt.shape[0] - k:].T.copy(), independent)


def gamma_loop(phi, pins, fields, pfaffian, joints, tree, Q, Q_dot, t, m_h, m, repeats):
    for _ in range(repeats):
        for j in range(Q.shape[0]):
            _constraint_gamma(phi, pins, fields, pfaffian, joints, tree, Q[j], Q_dot[j], t, m_h, m)


def particular_loop(U, sigma, Vt, gamma, F, independent, count, repeats):
    for _ in range(repeats):
        _particular(U, sigma, Vt, gamma, count, F, independent)


def projected_loop(tree, Q, Q_dot, t, F, f_bar, pivot, M, b, s_ddot_tree, repeats):
    for _ in range(repeats):
        for j in range(Q.shape[0]):
            _projected(tree, Q[j], Q_dot[j], t, F, f_bar, pivot, M, b, s_ddot_tree)


def call_only(*args):
    return 0


LOOPS = (jacobian_loop, svd_loop, scaled_loop, gamma_loop, particular_loop, projected_loop)


def profile(name: str, budget: float) -> dict:
    """µs per call of each piece of the tangent kernel of scene ``name`` over the moving states
    of ``benchmarks/scene_costs.py`` (module docstring)."""
    system = scenes.SCENES[name].build()
    ev, closure = system.evaluator(), system.compiled_kernel()
    assert closure is not None and closure.rule == "tangent", f"{name} does not take the tangent kernel"
    k = system.n_s
    rng = np.random.default_rng(k)
    states = moving_states(system, STATES, rng)
    chain = scenes.chain(k).evaluator("fast")
    chain_states = itertools.cycle(moving_states(scenes.chain(k), STATES, rng))
    t, n, m = 0.0, system.tree.n_s, closure._A.shape[0]
    Q, Q_dot, As = np.zeros((STATES, system.n_q)), np.zeros((STATES, n)), np.zeros((STATES, m, n))
    for j, (q, s_dot) in enumerate(states):
        ev.accelerations(q, s_dot, t)  # fills the workspace: A_s, q̇ = ṡ_tree
        Q[j], Q_dot[j], As[j] = q, closure._q_dot, closure._A
    q, s_dot = states[-1]
    U, sigma, Vt = _svd(As[-1])
    Vts = np.array([_svd(A)[2] for A in As])
    F = system.F(q, t)[0]
    s_ddot_tree = closure._s_ddot_tree.copy()
    f_bar = s_ddot_tree - F @ s_ddot_tree[system.independent]
    gamma = -As[-1] @ s_ddot_tree  # A_s s̈_tree = −γ: its size
    callees = compiled._compiled_callees(elastic=False)  # the TangentSystem scenes are rigid trees
    loops = dict(zip((f.__name__ for f in LOOPS), kernels.jit(*_in_compiled_module(LOOPS), callees=compiled._HELPERS,
                                                                kernels=callees)))
    jitted_call_only = kernels._numba().njit(call_only)
    ws, m_h, r = closure._workspace, closure.m_h, REPEATS
    head = (closure.phi, closure.pins, closure.fields, closure.pfaffian, closure.joints, closure.tree)
    kept = np.array(system._tangent, dtype=float)
    args = (*head, q, s_dot, t, m_h, system.independent, n - k, system.separation, closure.constants[0], kept,
            SINGULAR_PIVOT, closure._q_dot, closure._s_ddot_tree, closure._A, ws.M_all, ws.b_all, closure._kappa)
    cycled = itertools.cycle(states)
    pieces = {  # name: (a call, how many s̈ pieces it times)
        "Φ_q (complex step)": (lambda: loops["jacobian_loop"](*head, Q, t, m_h, As[0].copy(), r), r * STATES),
        "SVD of A_s": (lambda: loops["svd_loop"](As, r), r * STATES),
        "N, F = N N_ind⁻¹": (lambda: loops["scaled_loop"](Vts, system.independent, r), r * STATES),
        "γ (complex step)": (lambda: loops["gamma_loop"](*head, Q, Q_dot, t, m_h, m, r), r * STATES),
        "x₀ = A_s⁺(−γ), f̄": (lambda: loops["particular_loop"](U, sigma, Vt, gamma, F, system.independent, n - k,
                                                               r * STATES), r * STATES),
        "tree terms, FᵀMF (_projected)": (lambda: loops["projected_loop"](
            closure.tree, Q, Q_dot, t, F, f_bar, SINGULAR_PIVOT, ws.M_all.copy(), ws.b_all.copy(),
            s_ddot_tree.copy(), r), r * STATES),
        "a compiled call of the kernel's arguments": (lambda: jitted_call_only(*args), 1),
        "kernel called from Python": (lambda: closure.kernel(*args), 1),
        "CompiledClosure.minimal_accelerations": (lambda: closure.minimal_accelerations(system, *next(cycled), t), 1),
        "evaluator.accelerations": (lambda: ev.accelerations(*next(cycled), t), 1),
        f"chain({k}) evaluator.accelerations": (lambda: chain.accelerations(*next(chain_states), t), 1),
    }
    seconds = time_per_call({key: (lambda f: lambda _q, _s: f())(f) for key, (f, _) in pieces.items()},
                            None, None, budget)
    return {key: seconds[key] * 1e6 / count for key, (_, count) in pieces.items()}


def _in_compiled_module(functions) -> list:
    """The loops as functions of :mod:`projeq.constraints.compiled` (its names, such as the complex
    step's COMPLEX_STEP, resolve as in its kernels)."""
    namespace = {**vars(compiled), **globals()}
    return [types.FunctionType(f.__code__, namespace, f.__name__) for f in functions]


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", default=["andrews_squeezer", "bricard"])
    parser.add_argument("--budget", type=float, default=2.0, help="seconds of timing per scene (default 2)")
    parser.add_argument("--quick", action="store_true", help="Andrews' squeezer, 0.05 s of timing")
    args = parser.parse_args(argv)
    if args.quick:
        args.scenes, args.budget = ["andrews_squeezer"], 0.05
    report = {}
    for name in args.scenes:
        report[name] = rows = profile(name, args.budget)
        print(f"{name}: µs per call (one run, alternating)")
        for key, value in rows.items():
            print(f"  {key:42s} {value:8.2f}")
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
