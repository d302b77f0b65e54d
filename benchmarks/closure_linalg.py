"""The closure kernels' linear algebra: LAPACK (numba's ``np.linalg``) against the hand-written
routines, side by side in one run (issue 33, item 3: LAPACK unless the hand-written one is faster at
the sizes used).

:func:`projeq.constraints.compiled.tangent` takes the SVD of A_s (at q and at q moved onto the
constraint manifold, :func:`~projeq.constraints.compiled._on_manifold`) and N_ind⁻¹,
:func:`~projeq.constraints.compiled.partitioned` A_dep⁻¹. The library's SVD
(:func:`~projeq.constraints.compiled._svd`) is LAPACK's gesdd (:func:`~projeq.constraints.compiled._lapack_svd`,
numba's ``np.linalg.svd``, as the numpy path) from ``LAPACK_SVD_SIZE`` entries of A_s on and below that the
hand-written one-sided Jacobi rotations preconditioned by a QR with column pivoting
(:func:`~projeq.constraints.compiled._jacobi_svd`; Drmač & Veselić, "New fast and accurate Jacobi SVD
algorithm I", SIAM J. Matrix Anal. Appl. 29, 2008); its inverse is Gauss–Jordan elimination
(:func:`~projeq.constraints.compiled._inverse`). Here the kernels are compiled twice, once with LAPACK's
routines at every size (:func:`lapack_inverse`: getrf/getri, numba's ``np.linalg.inv``) and once with the
hand-written ones, under the names the kernels call (the replacements of :func:`projeq.assembly.kernels.jit`),
and both run in one process.

Printed per model — the closed-loop scenes: the four-bar and the Whipple bicycle partitioned (A_dep
2 × 2 and 5 × 5); the simple pendulum, the double four-bar (IFToMM A02, N = 2), Bricard's mechanism,
Andrews' squeezer and the A02 N-four-bar with N = 10 and the benchmark's N = 40 in the null-space
form (A_s 1 × 2 … 80 × 81) —: the compiled s̈ per call of both variants
(:meth:`~projeq.constraints.compiled.CompiledClosure.minimal_accelerations`: the kernel and its
Python wrapper), timed alternately at moving states near q0
(:func:`projeq.studies.bench_scenes.moving_states`: off the manifold by round-off, so that the
tangent kernel takes both SVDs) by :func:`projeq.studies.timing.time_per_call` (the fastest batch,
CPU time), their ratio, and the largest difference of their s̈_tree (relative to max(1, |s̈_tree|)).
Then (``--compile``, the default outside ``--quick``) the cold compilation of each kernel of each
variant: a fresh process per kernel with an empty
``NUMBA_CACHE_DIR`` compiles the tree's kernels through its fast evaluator, then the closure kernel at
its first call (CPU seconds of each step).

    python benchmarks/closure_linalg.py                 # all models, 2 s each, then the compile times
    python benchmarks/closure_linalg.py --no-compile    # the s̈ table only
    python benchmarks/closure_linalg.py --quick         # both variants interpreted, small models (the test)

OPENBLAS_NUM_THREADS=1 unless set (single-threaded CPU times): with BLAS threads on a loaded machine
(``OPENBLAS_NUM_THREADS=2 … --models "A02 N=40"``) the 80 × 81 SVDs slow down up to 10-fold: the library
holds BLAS to one thread around the kernels that call LAPACK (:func:`projeq.assembly.linalg.one_blas_thread`). ``--quick`` runs
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


def lapack_inverse(A):
    """A⁻¹ by LAPACK (numba's ``np.linalg.inv``: getrf, getri), ∞ entries where A is singular or not
    finite, as :func:`~projeq.constraints.compiled._inverse` gives them (the kernel flags them)."""
    try:
        return np.linalg.inv(A)
    except Exception:  # noqa: BLE001 — numba raises LinAlgError, catchable only as Exception
        return np.full(A.shape, np.inf)


#: the two variants of the kernels' linear algebra: the routines under the names the kernels call (the
#: library's _svd calls LAPACK's from LAPACK_SVD_SIZE entries on, the hand-written one below; its _inverse
#: is the hand-written one)
VARIANTS = {"lapack": {"_svd": compiled._lapack_svd, "_inverse": lapack_inverse},
            "hand": {"_svd": compiled._jacobi_svd}}


def variant_kernels(variant: str) -> dict:
    """{"partitioned": …, "tangent": …}: the closure kernels of rigid trees with a Φ of their own (the
    models here) compiled as :func:`projeq.constraints.compiled._compiled` compiles them with the routines
    of ``variant`` in their place (cached on disk under names of their own)."""
    rules = ("partitioned", "tangent")
    functions = [getattr(compiled, rule) for rule in rules]
    names = tuple(f"{variant}_{rule}" for rule in rules)
    callees = compiled._HELPERS + (lapack_inverse,)  # in the digest of the names
    return dict(zip(rules, kernels.jit(*functions, callees=callees, names=names,
                                       kernels=compiled._compiled_callees(False), **VARIANTS[variant])))


def interpreted_kernel(rule: str, variant: str):
    """The kernel ``rule`` as plain Python, the callees of :mod:`projeq.constraints.compiled` bound in a
    namespace of their own that holds the routines of ``variant`` under the names the kernels call."""
    namespace = dict(vars(compiled))
    for f in compiled._HELPERS:
        if f.__module__ == compiled.__name__:
            namespace[f.__name__] = types.FunctionType(f.__code__, namespace, f.__name__, f.__defaults__)
    for name, f in VARIANTS[variant].items():
        namespace[name] = types.FunctionType(f.__code__, namespace, name)
    return types.FunctionType(getattr(compiled, rule).__code__, namespace, rule)


def closures(build, interpreted: bool) -> tuple:
    """((model, closure) by LAPACK, (model, closure) hand-written): the model built twice (each keeps its
    own tangent along the branch), each with its CompiledClosure calling the kernel of one variant; where
    ``interpreted``, both kernels interpreted (``CompiledClosure(compiled=False)``: Φ itself, nothing
    compiled)."""
    pair = []
    for variant in VARIANTS:
        model = build()
        assert compiled.unsupported(model) is None and model.tree.evaluator("fast")._width == 6  # rigid
        if interpreted:
            rule, constant = ("tangent", ACTING) if isinstance(model, TangentSystem) else \
                ("partitioned", PARTITION_CONDITION)
            pfaffian = model._A if model.m_p else None
            closure = compiled.CompiledClosure(model.tree, model.n_c, model._phi, rule, (constant,),
                                               compiled=False, m_h=model.m_h, pfaffian=pfaffian)
            closure.kernel = interpreted_kernel(rule, variant)
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("error")  # the model's s̈ is one compiled call
                closure = copy.copy(model.compiled_kernel())
            assert not len(closure.pins)  # the kernels variant_kernels compiles
            closure.kernel = variant_kernels(variant)[closure.rule]
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
    closure.kernel = variant_kernels(variant)[rule]
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
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=2.0, help="timing budget per model (default 2)")
    parser.add_argument("--models", nargs="+", choices=[name for name, _ in MODELS], metavar="MODEL",
                        help=f"these models only (default: all; {', '.join(name for name, _ in MODELS)})")
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
    models = [(name, build) for name, build in models if args.models is None or name in args.models]
    print("constrained s̈ per call, µs, LAPACK (numba's np.linalg) and the hand-written SVD / inverse "
          "alternately"
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
            for variant in VARIANTS:
                row = cold_compile(variant, rule)
                found["compile"].append(row)
                print(f"{rule:12} {variant:7} tree {row['tree_s']:6.1f}  kernel {row['kernel_s']:6.1f}  "
                      f"process {row['process_cpu_s']:6.1f} CPU, {row['wall_s']:6.1f} wall")
    return found


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
