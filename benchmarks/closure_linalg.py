"""The closure kernels' linear algebra by LAPACK (numba's ``np.linalg``) against the hand-written
routines it replaced, side by side in one run (issue 33, item 3).

:func:`projeq.constraints.compiled.tangent` takes the SVD of A_s (at q and at q moved onto the
constraint manifold, :func:`~projeq.constraints.compiled._on_manifold`) and N_ind⁻¹,
:func:`~projeq.constraints.compiled.partitioned` A_dep⁻¹. They are LAPACK's now
(:func:`~projeq.constraints.compiled._svd`: gesdd; :func:`~projeq.constraints.compiled._inverse`:
getrf, getri), as on the numpy path. Until then the kernels carried their own: a QR with column
pivoting of A_sᵀ as the preconditioner of one-sided Jacobi rotations (Drmač & Veselić, "New fast and
accurate Jacobi SVD algorithm I", SIAM J. Matrix Anal. Appl. 29, 2008; Demmel & Veselić, "Jacobi's
method is more accurate than QR", SIAM J. Matrix Anal. Appl. 13, 1992; de Rijk 1989) and
Gauss–Jordan elimination. They are kept below, in this file only, verbatim (the constant DRIFT
written as its value), and compiled into the kernels' own source under the names of LAPACK's
(:func:`projeq.assembly.kernels.jit` with them among the callees): both variants of each kernel in
one process.

Printed per model — the closed-loop scenes: the four-bar and the Whipple bicycle partitioned (A_dep
2 × 2 and 5 × 5); the simple pendulum, the double four-bar (IFToMM A02, N = 2), Bricard's mechanism,
Andrews' squeezer and the A02 N-four-bar with N = 10 and the benchmark's N = 40 in the null-space
form (A_s 1 × 2 … 80 × 81) —: the compiled s̈ per call of both variants
(:meth:`~projeq.constraints.compiled.CompiledClosure.minimal_accelerations`: the kernel and its
Python wrapper), timed alternately at moving states near q0
(:func:`projeq.studies.bench_scenes.moving_states`: off the manifold by round-off, so that the
tangent kernel takes both SVDs) by :func:`projeq.studies.timing.time_per_call` (the fastest batch,
CPU time), their ratio, and the largest difference of their s̈_tree (relative to max(1, |s̈_tree|)).
Then (``--compile``, the default outside ``--quick``) the cold compilation of each kernel: a fresh
process per variant and kernel with an empty ``NUMBA_CACHE_DIR`` compiles the tree's kernels through
its fast evaluator, then the closure kernel at its first call (CPU seconds of each step).

    python benchmarks/closure_linalg.py                 # all models, 2 s each, then the compile times
    python benchmarks/closure_linalg.py --no-compile    # the s̈ table only
    python benchmarks/closure_linalg.py --quick         # both variants interpreted, small models (the test)

OPENBLAS_NUM_THREADS=1 unless set (single-threaded CPU times: on a shared machine the 80 × 81 SVDs
slow down up to 100-fold when BLAS threads compete, as benchmarks/iftomm.py says). ``--quick`` runs
both variants' kernels interpreted (plain Python on numpy: nothing to compile) on the three smallest
models: it checks that the script runs and that both give the same s̈, not their speed.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402 — after the thread count, which OpenBLAS reads when numpy loads it
import copy  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import types  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

import projeq as pq  # noqa: E402
from projeq.assembly import kernels  # noqa: E402
from projeq.constraints import compiled  # noqa: E402
from projeq.constraints.partitioned import PARTITION_CONDITION, TangentSystem  # noqa: E402
from projeq.constraints.tangent import ACTING  # noqa: E402
from projeq.scenes.bicycle import whipple_bicycle  # noqa: E402
from projeq.scenes.iftomm import andrews_squeezer, bricard, n_four_bar, simple_pendulum  # noqa: E402
from projeq.studies.bench_scenes import moving_states  # noqa: E402
from projeq.studies.timing import time_per_call  # noqa: E402

#: (name, builder) per model, by the size of the matrix factorised; ``--quick`` takes the first QUICK
MODELS = (
    ("four_bar", pq.scenes.four_bar),
    ("simple_pendulum", simple_pendulum),
    ("A02 N=2", n_four_bar),
    ("whipple_bicycle", whipple_bicycle),
    ("bricard", bricard),
    ("andrews_squeezer", andrews_squeezer),
    ("A02 N=10", lambda: n_four_bar(10)),
    ("A02 N=40", lambda: n_four_bar(40)),
)
QUICK = 3
STATES = 4  # moving states per model, taken in turn
#: the model whose first s̈ compiles each kernel in the cold compilation
COMPILED_FIRST = {"partitioned": pq.scenes.four_bar, "tangent": n_four_bar}


# -- the hand-written routines the kernels carried until LAPACK replaced them (projeq/constraints/compiled.py
#    at 0e1eda0), verbatim but DRIFT; here only to be measured against --------------------------------------


def _svd(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """(U, σ, Vᵀ) of A (m × n) with all n singular values, descending (those beyond m zero to
    round-off), V n × n and U m × n (column j = A v_j / σ_j, zero where σ_j = 0), for the few rows
    and columns of a loop's A_s, without LAPACK's calls and workspace: the QR decomposition with
    column pivoting of Aᵀ (:func:`_transposed_qr`, A[order] Q = [L 0]) as the preconditioner of
    Drmač & Veselić ("New fast and accurate Jacobi SVD algorithm I", SIAM J. Matrix Anal. Appl. 29,
    2008, §3: the one-sided Jacobi method on Rᵀ = L converges in fewer sweeps than on A), then
    one-sided Jacobi rotations of the columns of L (:func:`_jacobi` of [L; E]ᵀ): L W = Ũ Σ, so that
    V = Q diag(W, E) and U[order] = Ũ."""
    m, n = A.shape
    X, Qt, order = _transposed_qr(A)  # X = [L; E]ᵀ
    p = X.shape[0]
    _jacobi(X, m)  # X = [Ũ Σ; W]ᵀ
    norms = np.zeros(p)
    for j in range(p):
        norms[j] = _row_square(X, m, j)
    ranked = np.argsort(-norms)
    sigma, U, Vt = np.zeros(n), np.zeros((m, n)), np.zeros((n, n))
    for c in range(p):
        j = ranked[c]
        for l in range(p):  # v_c = Q₁ w_j: Vt[c] = Σ_l W[l, j] Qᵀ[l]
            for i in range(n):
                Vt[c, i] += X[j, m + l] * Qt[l, i]
        if norms[j] > 0.0:
            sigma[c] = np.sqrt(norms[j])
            for i in range(m):
                U[order[i], c] = X[j, i] / sigma[c]
    for c in range(p, n):  # the columns of Q beyond the rows of A: in its null space
        for i in range(n):
            Vt[c, i] = Qt[c, i]
    return U, sigma, Vt


def _transposed_qr(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """([L; E]ᵀ, Qᵀ, order): Householder QR with column pivoting of Aᵀ (m × n A), Aᵀ[:, order] = Q R
    (Golub & Van Loan, "Matrix Computations", 4th ed., 2013, Algorithm 5.4.1; Q n × n orthogonal,
    the product H_0 ⋯ H_{p−1} of p = min(m, n) reflectors accumulated backwards, §5.1.6), so that
    A[order] Q = Rᵀ = [L 0] with L = R[:p]ᵀ, m × p lower trapezoidal, above the p × p identity.
    The columns of Aᵀ are the rows of A: the reflectors act on rows (:func:`_reflect`)."""
    m, n = A.shape
    p = min(m, n)
    C, order = A.copy(), np.arange(m)  # C = Aᵀᵀ: row j is column j of Aᵀ, reflected in place
    reflectors, scales = np.zeros((p, n)), np.zeros(p)  # H_c = E − scales[c] v_c v_cᵀ, v_c zero before entry c
    for c in range(p):
        size, chosen = -1.0, c  # the column of largest norm below row c first
        for j in range(c, m):
            column = 0.0
            for i in range(c, n):
                column += C[j, i] * C[j, i]
            if column > size:
                size, chosen = column, j
        for i in range(n):
            C[c, i], C[chosen, i] = C[chosen, i], C[c, i]
        order[c], order[chosen] = order[chosen], order[c]
        if size == 0.0:  # the rest is zero: H_c = E
            continue
        head = -np.sqrt(size) if C[c, c] >= 0.0 else np.sqrt(size)  # R[c, c], of the sign that avoids cancellation
        for i in range(c, n):
            reflectors[c, i] = C[c, i]
        reflectors[c, c] -= head
        scales[c] = 2.0 / (size - C[c, c] * C[c, c] + reflectors[c, c] * reflectors[c, c])  # 2 / v_cᵀ v_c
        _reflect(reflectors, scales[c], c, C, c + 1, m)
        C[c, c] = head
    Qt = np.eye(n)
    for c in range(p - 1, -1, -1):  # Q = H_0 (H_1 (⋯ H_{p−1})): H_c touches rows and columns c… only
        _reflect(reflectors, scales[c], c, Qt, c, n)
    X = np.zeros((p, m + p))  # [L; E]ᵀ = [R[:p] E]
    for c in range(p):
        for i in range(c, m):
            X[c, i] = C[i, c]
        X[c, m + c] = 1.0
    return X, Qt, order


def _reflect(reflectors: NDArray, scale: float, c: int, X: NDArray, first: int, last: int) -> None:
    """Rows first … last − 1 of X ← X H_c (each the transpose of H_c times a column), H_c = E − scale v vᵀ,
    v = reflectors[c] (zero before entry c)."""
    if scale == 0.0:
        return
    for j in range(first, last):
        dot = 0.0
        for i in range(c, X.shape[1]):
            dot += reflectors[c, i] * X[j, i]
        dot *= scale
        for i in range(c, X.shape[1]):
            X[j, i] -= dot * reflectors[c, i]


def _jacobi(X: NDArray, m: int) -> None:
    """Rotate the rows of X = [W; V]ᵀ (the columns of W their first ``m`` entries, those of V the
    others, rotated alike; rows, so that the loops run over contiguous entries) until the columns
    of W are orthogonal to round-off (one-sided Jacobi, Demmel & Veselić, "Jacobi's method is more
    accurate than QR", SIAM J. Matrix Anal. Appl. 13, 1992, Algorithm 4.1): a pair (a, r) whose
    cosine |γ| / √(α β) (α, β the squared norms of the columns of W, γ their dot product) is above
    1e-15 is rotated by the angle that makes it zero. The squared norms are taken at each sweep's
    start and updated by each rotation, α' = α − t γ, β' = β + t γ with t = tan of the angle (de
    Rijk, "A one-sided Jacobi algorithm for computing the singular value decomposition on a vector
    computer", SIAM J. Sci. Stat. Comput. 10, 1989), computed anew where one drops below DRIFT of
    its value; the last sweep rotates none, so that every pair's cosine is tested on norms taken
    afresh. A column below 1e-15 of ‖W‖_F is W v = 0 to round-off (in the null space): not rotated."""
    p = X.shape[0]
    squares, floor = np.zeros(p), 0.0
    for j in range(p):
        floor += 1e-30 * _row_square(X, m, j)
    for _ in range(100):  # sweeps; quadratic convergence takes a handful
        for j in range(p):
            squares[j] = 0.0
            for i in range(m):
                squares[j] += X[j, i] * X[j, i]
        rotated = False
        for a in range(p - 1):
            for r in range(a + 1, p):
                alpha, beta = squares[a], squares[r]
                if alpha <= floor or beta <= floor:
                    continue
                gamma = 0.0
                for i in range(m):
                    gamma += X[a, i] * X[r, i]
                if abs(gamma) <= 1e-15 * np.sqrt(alpha * beta):
                    continue  # orthogonal to round-off
                rotated = True
                if abs(beta - alpha) > 1e100 * abs(gamma):  # a tiny angle: tan = 1/(2ζ) to round-off
                    tan = gamma / (beta - alpha)
                else:
                    zeta = (beta - alpha) / (2.0 * gamma)
                    tan = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                cos = 1.0 / np.sqrt(1.0 + tan * tan)
                sin = cos * tan
                for i in range(X.shape[1]):
                    x_a, x_r = X[a, i], X[r, i]
                    X[a, i], X[r, i] = cos * x_a - sin * x_r, sin * x_a + cos * x_r
                squares[a], squares[r] = alpha - tan * gamma, beta + tan * gamma
                if squares[a] < 0.1 * alpha:  # DRIFT = 0.1
                    squares[a] = _row_square(X, m, a)
                if squares[r] < 0.1 * beta:
                    squares[r] = _row_square(X, m, r)
        if not rotated:
            break


def _row_square(X: NDArray, m: int, j: int) -> float:
    """|X[j, :m]|²."""
    total = 0.0
    for i in range(m):
        total += X[j, i] * X[j, i]
    return total


def _inverse(A: NDArray) -> NDArray:
    """A⁻¹ by Gauss–Jordan elimination with partial pivoting (∞ entries for a singular A)."""
    m = A.shape[0]
    work, inv = A.copy(), np.eye(m)
    for c in range(m):
        p = c + np.argmax(np.abs(work[c:, c]))
        if work[p, c] == 0.0:
            return np.full((m, m), np.inf)
        for row in (work, inv):
            for j in range(m):
                row[c, j], row[p, j] = row[p, j], row[c, j]
        d = work[c, c]
        for j in range(m):
            work[c, j] /= d
            inv[c, j] /= d
        for r in range(m):
            if r != c and work[r, c] != 0.0:
                e = work[r, c]
                for j in range(m):
                    work[r, j] -= e * work[c, j]
                    inv[r, j] -= e * inv[c, j]
    return inv


HANDWRITTEN = (_svd, _transposed_qr, _reflect, _jacobi, _row_square, _inverse)


# -- the two variants of a kernel ----------------------------------------------------------------------------


def handwritten_kernels() -> dict:
    """{"partitioned": …, "tangent": …}: the closure kernels of rigid trees with a Φ of their own (the
    models here) compiled as :func:`projeq.constraints.compiled._compiled` compiles them, the
    hand-written routines among the callees under the names of LAPACK's (cached on disk apart)."""
    rules = ("partitioned", "tangent")
    return dict(zip(rules, kernels.jit(*(getattr(compiled, rule) for rule in rules),
                                       callees=compiled._HELPERS + HANDWRITTEN,
                                       kernels=compiled._compiled_callees(False),
                                       names=tuple(f"handwritten_{rule}" for rule in rules))))


def interpreted_kernel(rule: str, handwritten: bool):
    """The kernel ``rule`` as plain Python, the callees of :mod:`projeq.constraints.compiled` bound in a
    namespace of their own that holds the hand-written routines where ``handwritten``."""
    namespace = dict(vars(compiled))
    own = [f for f in compiled._HELPERS if f.__module__ == compiled.__name__]
    for f in own + list(HANDWRITTEN if handwritten else ()):
        namespace[f.__name__] = types.FunctionType(f.__code__, namespace, f.__name__, f.__defaults__)
    return types.FunctionType(getattr(compiled, rule).__code__, namespace, rule)


def closures(build, interpreted: bool) -> tuple:
    """((model, closure) by LAPACK, (model, closure) hand-written): the model built twice (each keeps its
    own tangent along the branch), each with its CompiledClosure, the second's kernel the hand-written
    one; where ``interpreted``, both kernels interpreted (``CompiledClosure(compiled=False)``: Φ itself,
    nothing compiled)."""
    pair = []
    for handwritten in (False, True):
        model = build()
        assert compiled.unsupported(model) is None and model.tree.evaluator("fast")._width == 6  # rigid
        if interpreted:
            rule, constant = ("tangent", ACTING) if isinstance(model, TangentSystem) else \
                ("partitioned", PARTITION_CONDITION)
            closure = compiled.CompiledClosure(model.tree, model.n_c, model._phi, rule, (constant,), compiled=False,
                                               m_h=model.m_h, pfaffian=model._A if model.m_p else None)
            closure.kernel = interpreted_kernel(rule, handwritten)
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("error")  # the model's s̈ is one compiled call
                closure = copy.copy(model.compiled_kernel())
            assert not len(closure.pins)  # the kernels handwritten_kernels compiles
            if handwritten:
                closure.kernel = handwritten_kernels()[closure.rule]
        pair.append((model, closure))
    return tuple(pair)


def size(closure) -> str:
    """The matrix the variants factorise: A_dep (partitioned) or A_s (tangent)."""
    m, n = closure._A.shape
    return f"A_dep {m}×{m}" if closure.rule == "partitioned" else f"A_s {m}×{n}"


def compare(name: str, build, budget: float, interpreted: bool) -> dict:
    """One model: µs per s̈ of both variants, alternately, and the largest difference of their s̈_tree."""
    (lapack_model, lapack), (hand_model, hand) = closures(build, interpreted)
    states = moving_states(lapack_model, STATES, np.random.default_rng(7))
    difference = 0.0
    for q, s_dot in states:
        assert lapack._call(lapack_model, q, s_dot, 0.0) and hand._call(hand_model, q, s_dot, 0.0), name
        hand_s_ddot = hand._s_ddot_tree.copy()
        scale = max(1.0, np.abs(lapack._s_ddot_tree).max())
        difference = max(difference, float(np.abs(hand_s_ddot - lapack._s_ddot_tree).max() / scale))
    turns = {"lapack": itertools.cycle(states), "hand": itertools.cycle(states)}
    seconds = time_per_call({
        "lapack": lambda _q, _s: lapack.minimal_accelerations(lapack_model, *next(turns["lapack"]), 0.0),
        "hand": lambda _q, _s: hand.minimal_accelerations(hand_model, *next(turns["hand"]), 0.0),
    }, None, None, budget)
    return {"model": name, "rule": lapack.rule, "size": size(lapack), "lapack_us": seconds["lapack"] * 1e6,
            "hand_us": seconds["hand"] * 1e6, "ratio": seconds["lapack"] / seconds["hand"],
            "difference": difference}


# -- cold compilation ----------------------------------------------------------------------------------------


def first_call(variant: str, rule: str) -> dict:
    """In this process (a fresh one, its numba cache empty): CPU seconds to build the model of ``rule``
    (:data:`COMPILED_FIRST`) with its tree's kernels compiled by one s̈ of the tree, then of the first s̈
    of the closure kernel of ``variant`` ("lapack" or "hand"), which compiles it."""
    start = time.process_time()
    model = COMPILED_FIRST[rule]()
    model.tree.evaluator("fast").accelerations(model.q0, np.zeros(model.tree.n_s), 0.0)
    closure = copy.copy(model.compiled_kernel())
    if variant == "hand":
        closure.kernel = handwritten_kernels()[rule]
    tree = time.process_time()
    assert closure.minimal_accelerations(model, model.q0, model.s_dot0, 0.0) is not None
    return {"variant": variant, "rule": rule, "tree_s": tree - start, "kernel_s": time.process_time() - tree}


def cold_compile(variant: str, rule: str) -> dict:
    """:func:`first_call` in a fresh process with an empty ``NUMBA_CACHE_DIR``, and the process's CPU
    (user + system) and wall seconds."""
    with tempfile.TemporaryDirectory() as cache:
        started, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
        path = os.pathsep.join([str(Path(pq.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": path}
        done = subprocess.run([sys.executable, __file__, "--first-call", variant, rule], capture_output=True,
                              text=True, check=True, env=env)
        found = json.loads(done.stdout.strip().splitlines()[-1])
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return {**found, "process_cpu_s": cpu, "wall_s": time.perf_counter() - started}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=2.0, help="timing budget per model (default 2)")
    parser.add_argument("--compile", action=argparse.BooleanOptionalAction, default=None,
                        help="time the cold compilation of both variants (default: yes, but with --quick)")
    parser.add_argument("--quick", action="store_true",
                        help="both variants interpreted on the smallest models, 0.05 s each, no compilation")
    parser.add_argument("--first-call", nargs=2, metavar=("VARIANT", "RULE"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.first_call:
        found = first_call(*args.first_call)
        print(json.dumps(found))
        return found
    models, budget = (MODELS[:QUICK], 0.05) if args.quick else (MODELS, args.seconds)
    print("constrained s̈ per call, µs, LAPACK (numba's np.linalg) and the hand-written SVD / inverse alternately"
          f"{' — interpreted: the script checked, not the speeds' if args.quick else ''}")
    print(f"{'model':18} {'kernel':12} {'factorised':13} {'LAPACK':>10} {'hand':>10} {'LAPACK/hand':>12} "
          f"{'|Δs̈_tree|':>10}")
    rows = []
    for name, build in models:
        row = compare(name, build, budget, args.quick)
        rows.append(row)
        print(f"{name:18} {row['rule']:12} {row['size']:13} {row['lapack_us']:10.1f} {row['hand_us']:10.1f} "
              f"{row['ratio']:12.2f} {row['difference']:10.1e}")
    found = {"rows": rows, "compile": []}
    if args.compile if args.compile is not None else not args.quick:
        print("\ncold compilation (fresh process, empty NUMBA_CACHE_DIR), CPU s: the tree's kernels, then "
              "the closure kernel at its first call; CPU and wall s of the whole process")
        for rule in COMPILED_FIRST:
            for variant in ("lapack", "hand"):
                row = cold_compile(variant, rule)
                found["compile"].append(row)
                print(f"{rule:12} {variant:7} tree {row['tree_s']:6.1f}  kernel {row['kernel_s']:6.1f}  "
                      f"process {row['process_cpu_s']:6.1f} CPU, {row['wall_s']:6.1f} wall")
    return found


if __name__ == "__main__":
    main()
