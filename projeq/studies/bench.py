"""Quick benchmarks (``projeq bench``): cost of s̈ for ``scenes.chain(n)`` against peers,
then the quick modes of the derivation-effort and beam-convergence studies
(:mod:`projeq.studies.bench_derivation`, :mod:`projeq.studies.bench_beam`; their full
runs are ``benchmarks/derivation.py`` and ``benchmarks/beam_convergence.py``).

Every evaluator is timed alternately with the others in one run and each entry is the
minimum CPU time over repetitions, so ratios are robust on a noisy machine; absolute times hold for
this machine only. The peers, when installed (``pip install 'projeq[bench]'``), are
Pinocchio's ABA (``pin.aba``) and MuJoCo's ``mj_forward`` on the same chain, built here
from the same parameters; their s̈ is compared with the dense evaluator, which checks
that the peer models are the same chain.

Every s̈ is also compared with the exact one, :func:`projeq.studies.bench_exact.chain_s_ddot`
(Lagrange's equations in absolute angles at 40 digits; up to n = 300, ``--exact-up-to``):
the deviation from the dense s̈ includes the dense evaluator's own error, up to κ(M) ε
(κ(M) ≈ 1.3e8 at n = 100 at the benchmark's state), the deviation from the exact s̈ is each
evaluator's own.

    projeq bench                 # chain n = 10, 30, 100, then the quick studies
    projeq bench --json          # one JSON document with every report
    projeq bench --chain-only --no-peers --sizes 10,30
"""

from __future__ import annotations

import json
import math
import time
import traceback

import numpy as np

from projeq import scenes
from projeq.assembly.kernels import has_numba
from projeq.subsystems import inertia
from projeq.studies.bench_beam import convergence
from projeq.studies.bench_derivation import derivation_effort
from projeq.studies.bench_exact import chain_s_ddot
from projeq.studies.bench_scenes import scene_costs
from projeq.studies.timing import time_per_call

QUICK_SIZES = (10, 30, 100)
OURS = ("recursive", "fast", "dense")
DENSE_UP_TO = 300  # the dense evaluator is O(N³): skipped above this n
EXACT_UP_TO = 300  # the exact s̈ costs O(n²) mpmath operations: 0.5 s at n = 100, 4 s at n = 300
PINOCCHIO_UP_TO = 300  # pin 4.1's Data needs 1.9 GB at n = 300, growing as n²: skipped above
_LINK_I_C = inertia.cylinder(m=1.0, radius=0.01, length=1.0, axis="z")  # the links of scenes.chain


def pinocchio_chain(n: int):
    """s̈ function of ``scenes.chain(n)`` by Pinocchio's ABA, or None without ``pin``."""
    try:
        import pinocchio as pin
    except ImportError:
        return None
    model = pin.Model()
    parent = 0
    for i in range(n):
        placement = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.0 if i == 0 else -1.0]))
        parent = model.addJoint(parent, pin.JointModelRY(), placement, f"j{i}")
        model.appendBodyToJoint(parent, pin.Inertia(1.0, np.array([0.0, 0.0, -0.5]), _LINK_I_C), pin.SE3.Identity())
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    data, tau = model.createData(), np.zeros(n)
    return lambda q, s_dot: pin.aba(model, data, q, s_dot, tau)


def mujoco_chain(n: int, smooth_only: bool = False):
    """s̈ function of ``scenes.chain(n)`` by MuJoCo's ``mj_forward`` (built with MjSpec —
    a nested MJCF string needs gigabytes to parse at n = 1000 —, no geoms, contacts off),
    or None without ``mujoco``. ``smooth_only``: instead of ``mj_forward``, only its smooth
    dynamics, M⁻¹(τ − b) (kinematics, composite inertia, factorisation, RNE bias, solve)."""
    try:
        import mujoco
    except ImportError:
        return None
    spec = mujoco.MjSpec()
    spec.option.gravity = [0.0, 0.0, -9.81]
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    body = spec.worldbody
    for i in range(n):
        body = body.add_body(pos=[0.0, 0.0, 0.0 if i == 0 else -1.0], mass=1.0, ipos=[0.0, 0.0, -0.5],
                             inertia=np.diagonal(_LINK_I_C), explicitinertial=True)
        body.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 1.0, 0.0])
    model = spec.compile()
    data = mujoco.MjData(model)

    def s_ddot(q, s_dot):
        data.qpos[:], data.qvel[:] = q, s_dot
        mujoco.mj_forward(model, data)
        return data.qacc.copy()

    bias, acceleration = np.zeros(n), np.zeros((1, n))

    def smooth_s_ddot(q, s_dot):
        data.qpos[:], data.qvel[:] = q, s_dot
        for stage in (mujoco.mj_kinematics, mujoco.mj_comPos, mujoco.mj_crb, mujoco.mj_factorM, mujoco.mj_comVel):
            stage(model, data)
        mujoco.mj_rne(model, data, 0, bias)  # b: Coriolis, centrifugal and gravity terms
        mujoco.mj_solveM(model, data, acceleration, -bias[None, :])
        return acceleration[0].copy()

    return smooth_s_ddot if smooth_only else s_ddot


def evaluators(n: int, peers: bool = True) -> dict:
    """Name → function (q, ṡ) ↦ s̈ for projeq's evaluators and the installed peers ("fast",
    the compiled kernel, needs numba as the peers need their packages)."""
    system = scenes.chain(n)
    names = [m for m in OURS if (m != "dense" or n <= DENSE_UP_TO) and (m != "fast" or has_numba())]
    funcs = {m: _s_ddot(system.evaluator(m)) for m in names}
    if peers:
        builders = [("pinocchio", pinocchio_chain)] * (n <= PINOCCHIO_UP_TO) + [("mujoco", mujoco_chain)]
        for name, build in builders:
            f = build(n)
            if f is not None:
                funcs[name] = f
    return funcs


def _s_ddot(evaluator):
    """(q, ṡ) ↦ s̈ of one of projeq's evaluators, at t = 0."""
    return lambda q, s_dot: evaluator.accelerations(q, s_dot, 0.0)


def measure(sizes, budget: float = 1.0, peers: bool = True, exact_up_to: int = EXACT_UP_TO) -> list[dict]:
    """One row per chain length: seconds per call of every evaluator (``"seconds"``), and
    each one's largest deviation, relative to max(1, |s̈|∞), from the reference s̈ (dense
    up to n = 300, else recursive; ``"deviation"``) and for n ≤ ``exact_up_to`` from the
    exact s̈ (:func:`projeq.studies.bench_exact.chain_s_ddot`; ``"exact_deviation"``, and the
    reference's CPU time ``"exact_seconds"``)."""
    rng = np.random.default_rng(0)
    rows = []
    for n in sizes:
        q, s_dot = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        funcs = evaluators(n, peers)
        seconds = time_per_call(funcs, q, s_dot, budget)
        s_ddot = {k: f(q, s_dot) for k, f in funcs.items()}
        reference = s_ddot["dense" if "dense" in funcs else "recursive"]
        row = {"n": n, "seconds": seconds, "deviation": deviations(s_ddot, reference)}
        if n <= exact_up_to:
            started = time.process_time()
            exact = chain_s_ddot(q, s_dot)
            row["exact_seconds"] = time.process_time() - started
            row["exact_deviation"] = deviations(s_ddot, exact)
        rows.append(row)
    return rows


def deviations(s_ddot: dict, reference) -> dict:
    """Name → |s̈ − reference|∞ / max(1, |reference|∞)."""
    scale = max(1.0, np.abs(reference).max())
    return {k: float(np.abs(x - reference).max() / scale) for k, x in s_ddot.items()}


def slopes(rows) -> dict:
    """Least-squares slope of log(time) against log(n) for every evaluator timed at
    every size (none for fewer than two sizes)."""
    if len({r["n"] for r in rows}) < 2:
        return {}
    names = set.intersection(*(set(r["seconds"]) for r in rows))
    n = np.log([r["n"] for r in rows])
    return {k: float(np.polyfit(n, np.log([r["seconds"][k] for r in rows]), 1)[0]) for k in sorted(names)}


def format_table(rows, slope: dict) -> str:
    """µs per call, fast/peer time ratios, the fast evaluator's and the largest deviation
    from the reference s̈, the fast and the dense evaluator's deviation from the exact s̈
    ("-" where not computed; see :func:`measure`), and the log-log slopes."""
    names = list(rows[-1]["seconds"]) + [k for k in rows[0]["seconds"] if k not in rows[-1]["seconds"]]
    lines = [f"{'n':>6} " + " ".join(f"{k + ' µs':>14}" for k in names) + f" {'fast/pin':>9} {'fast/mujoco':>12} "
             f"{'fast dev':>9} {'max dev':>9} {'fast vs exact':>14} {'dense vs exact':>15}"]
    for r in rows:
        s = r["seconds"]
        cells = " ".join(f"{s[k] * 1e6:>14.1f}" if k in s else f"{'-':>14}" for k in names)
        ratio = {p: f"{s['fast'] / s[p]:.2f}" if p in s and "fast" in s else "-" for p in ("pinocchio", "mujoco")}
        exact = {k: f"{r['exact_deviation'][k]:.1e}" if k in r.get("exact_deviation", {}) else "-" for k in ("fast", "dense")}
        lines.append(f"{r['n']:>6} {cells} {ratio['pinocchio']:>9} {ratio['mujoco']:>12} "
                     f"{r['deviation'].get('fast', np.nan):>9.1e} {max(r['deviation'].values()):>9.1e} {exact['fast']:>14} {exact['dense']:>15}")
    if slope:
        lines.append("log-log slope: " + ", ".join(f"{k} {v:.3f}" for k, v in slope.items()))
    return "\n".join(lines)


def chain_report(sizes, budget: float, peers: bool = True, exact_up_to: int = EXACT_UP_TO) -> dict:
    """The chain-scaling report: :func:`measure` rows and their :func:`slopes`."""
    rows = measure(sizes, budget, peers, exact_up_to)
    return {"benchmark": "chain_scaling", "rows": rows, "slopes": slopes(rows)}


def chain_scaling(sizes, budget: float, as_json: bool, peers: bool = True, exact_up_to: int = EXACT_UP_TO) -> dict:
    """Measure, print (table or JSON) and return the chain-scaling report."""
    report = chain_report(sizes, budget, peers, exact_up_to)
    if as_json:
        print(json.dumps(report, indent=2))
    else:
        print(format_table(report["rows"], report["slopes"]))
    return report


TOTAL_BUDGET = 120.0  # s of wall time for all of projeq bench (issue 7, item 2: "under two minutes")


def quick_derivation(deadline: float = math.inf, show=None) -> tuple[list, bool]:
    """The derivation effort at N = 2 and 4 (:func:`projeq.studies.bench_derivation.derivation_effort`):
    (rows, complete)."""
    rows = derivation_effort((2, 4), deadline=deadline, show=show)
    return rows, len(rows) == 2


def quick_beam_convergence(deadline: float = math.inf, show=None) -> tuple[dict, bool]:
    """The quick beam study (:func:`projeq.studies.bench_beam.convergence`): (report, complete)."""
    report = convergence(quick=True, deadline=deadline, show=show)
    return report, report["complete"]


def quick_scene_costs(deadline: float = math.inf, show=None) -> tuple[list, bool]:
    """Every scene's s̈ with the default evaluator against chain(k)
    (:func:`projeq.studies.bench_scenes.scene_costs`): (rows, complete)."""
    return scene_costs(0.2, deadline, show)


#: the quick studies after the chain part, cheapest first: name → function (deadline, show) ↦ (report, complete)
QUICK_STUDIES = {"scenes": quick_scene_costs, "derivation": quick_derivation, "beam_convergence": quick_beam_convergence}


def quick_suite(sizes=QUICK_SIZES, budget: float = 0.5, total: float = TOTAL_BUDGET, peers: bool = True,
                exact_up_to: int = EXACT_UP_TO, chain_only: bool = False, show=None) -> dict:
    """``projeq bench``: the chain part (:func:`chain_report`), then each of
    :data:`QUICK_STUDIES` with an equal share of what is left of ``total`` seconds of wall
    time (a study stops before its next row once its share is spent); a summary of the wall
    times. ``show``, e.g. ``print``, receives the tables as they are computed.

    Returns one document: the chain report, each study's report, ``"parts"`` (benchmark,
    status — "ok", "stopped after T s" or "failed: ..." —, seconds), ``"total_seconds"`` and
    ``"budget_seconds"``.
    """
    show = show or (lambda text: None)
    started = time.perf_counter()
    chain = chain_report(sizes, budget, peers, exact_up_to)
    show(format_table(chain["rows"], chain["slopes"]))
    parts = [{"benchmark": "chain_scaling", "status": "ok", "seconds": time.perf_counter() - started}]
    reports = {}
    studies = {} if chain_only else QUICK_STUDIES
    for i, (name, study) in enumerate(studies.items()):
        share = (total - (time.perf_counter() - started)) / (len(studies) - i)
        show(f"\n{name} (quick):")
        reports[name], part = _timed_part(name, study, max(share, 1.0), show)
        parts.append(part)
    seconds = time.perf_counter() - started
    show(f"\n{'benchmark':>18} {'wall s':>8}  status")
    for p in parts:
        show(f"{p['benchmark']:>18} {p['seconds']:>8.1f}  {p['status']}")
    show(f"{'total':>18} {seconds:>8.1f}  = {seconds / total:.2f} of the {total:g} s budget")
    return {"chain_scaling": chain, **reports, "parts": parts, "total_seconds": seconds, "budget_seconds": total}


def _timed_part(name: str, study, share: float, show) -> tuple:
    """(report, part) of one quick study given ``share`` seconds of wall time."""
    started = time.perf_counter()
    try:
        report, complete = study(started + share, show)
        status = "ok" if complete else f"stopped after {time.perf_counter() - started:.0f} s"
    except Exception as exc:  # noqa: BLE001 -- one broken study is reported with its traceback; the others run
        report, status = {"traceback": traceback.format_exc()}, f"failed: {type(exc).__name__}: {exc}"
    return report, {"benchmark": name, "status": status, "seconds": time.perf_counter() - started}
