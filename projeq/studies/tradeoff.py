"""Work-precision studies: the error against a converged reference versus the CPU time,
for every integrator, tolerance and model knob of a scene (``projeq tradeoff SCENE``).

Each setting (integrator, rtol, knob) is one :func:`projeq.simulate` run from 0 to t_end in
one ``solve_ivp`` call (``n_segments=1``: the step-size controller is never restarted);
atol = ``study.atol_scale`` · rtol. The reference is the study's finest model integrated by
``study.reference_method`` at ``study.reference_rtol`` (DOP853 at 1e-13; the beam: LSODA,
the bicycle: 1e-11, see :data:`projeq.studies.tradeoff_studies.STUDIES`), computed once and cached
in the output directory. The error of a run is
max |m − m_ref| of the study's measured quantity m at t_end (see
:mod:`projeq.studies.tradeoff_studies`); its CPU time is ``time.process_time`` of the run alone
(building the model and deriving or compiling an evaluator is ``setup_cpu``, once per knob).

A setting that fails is a row with ``failure`` set — ``timeout`` (more than ``timeout`` s of
CPU), ``diverged`` (a non-finite or singular state), ``integrator failed: ...``,
``skipped: ...`` (the knob cannot be built, e.g. a symbolic derivation too large),
``interrupted`` (Ctrl-C) — and NaN error; nothing is dropped. Warnings of a run (e.g. the
stiffness warning of an explicit method) go to the ``warning`` column.

>>> table = tradeoff("chain", methods=["DOP853"], tolerances=[1e-4, 1e-8], knobs=["recursive"],
...                  overrides={"n": 1}, t_end=0.5)
>>> list(table["failure"]), bool(np.all(table["error"] < 100 * table["rtol"]))
(['', ''], True)
"""

from __future__ import annotations

import hashlib
import json
import time
import warnings
from pathlib import Path

import numpy as np

from projeq.checks import finite_array, positive
from projeq.simulation.integrators import PROJECTED
from projeq.simulation.driver import INTEGRATORS, SimulationError, simulate
from projeq.studies.tradeoff_studies import STUDIES, Knob, Study, evaluator_for
from projeq.studies.tradeoff_table import (
    COLUMNS,
    ERROR_LEVELS,
    cheapest,
    columns,
    format_table,
    plot,
    read_csv,
    save_csv,
)

__all__ = [
    "COLUMNS",
    "ERROR_LEVELS",
    "METHODS",
    "QUICK_TOLERANCES",
    "TOLERANCES",
    "RunTimeout",
    "build",
    "cheapest",
    "format_table",
    "get_study",
    "plot",
    "read_csv",
    "reference",
    "run_setting",
    "save_csv",
    "tradeoff",
]

#: solve_ivp's methods and projeq's own (energy-projecting RK45/DOP853, :mod:`projeq.simulation.integrators`)
METHODS = (*INTEGRATORS, *PROJECTED)
TOLERANCES = tuple(10.0**-k for k in range(3, 13))  # rtol 1e-3 ... 1e-12
QUICK_TOLERANCES = (1e-3, 1e-6, 1e-9)


class RunTimeout(RuntimeError):
    """A run used more CPU time than the study allows."""


class _Counted:
    """An evaluator that counts its calls, keeps the time ``t`` of the latest, and stops the
    run at a CPU-time deadline (from the second call on: the first is simulate's check of
    the initial state, outside the run)."""

    def __init__(self, evaluator, timeout: float):
        self.evaluator, self.n_calls, self.t = evaluator, 0, 0.0
        self.deadline = time.process_time() + timeout

    def accelerations(self, q, s_dot, t):
        self.n_calls, self.t = self.n_calls + 1, t
        if self.n_calls > 1 and time.process_time() > self.deadline:
            raise RunTimeout(f"more than the allowed CPU time, at t = {t:.6g} s")
        return self.evaluator.accelerations(q, s_dot, t)


def _failure(exc: SimulationError) -> str:
    """The failure column of a run the integrator or the model stopped."""
    cause = exc.__cause__
    if isinstance(cause, RunTimeout):
        return "timeout"
    if isinstance(cause, (FloatingPointError, np.linalg.LinAlgError)):
        return "diverged"
    return "integrator failed: " + str(exc).split(": ", 1)[-1].split("; the trajectory")[0]


def run_setting(system, evaluator, study: Study, method: str, rtol: float, t_end: float, timeout: float) -> dict:
    """One run: measured quantity, CPU time, evaluations, time reached (of a failed run: the
    time of its latest evaluation), failure, warnings.

    ``measured`` is None when the run failed; ``failure`` then says how (module docstring).
    """
    counted = _Counted(evaluator, timeout)
    measured, failure = None, ""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cpu = time.process_time()
        try:
            result = simulate(system, t_end, method=method, rtol=rtol, atol=study.atol_scale * rtol,
                              evaluator=counted, n_points=2, n_segments=1)
        except SimulationError as exc:
            result, failure = exc.result, _failure(exc)
        except ValueError as exc:  # refused before the run: an energy projection without invariant
            cpu = time.process_time() - cpu
            return {"measured": None, "cpu": cpu, "n_evaluations": counted.n_calls, "t_reached": 0.0,
                    "failure": f"skipped: {exc}", "warning": ""}
        cpu = time.process_time() - cpu
    if result.status == 2:
        failure = "interrupted"
    elif not failure:
        measured = np.asarray(study.measure(system, result), dtype=float)
        if not np.all(np.isfinite(measured)):
            measured, failure = None, "diverged"
    warning = "; ".join(sorted({f"{type(w.message).__name__}: {str(w.message)[:160]}" for w in caught}))
    t_reached = float(result.t[-1]) if measured is not None else float(counted.t)  # a failed run: its latest t
    return {"measured": measured, "cpu": cpu, "n_evaluations": counted.n_calls, "t_reached": t_reached,
            "failure": failure, "warning": warning}


def build(study: Study, knob: Knob, overrides: dict):
    """(system, evaluator, setup CPU time) of one knob. The evaluator is called once with
    contiguous and once with strided arrays (the columns of the finite-difference Jacobians
    of Radau, BDF and LSODA): a numba kernel compiles for both here, not in a timed run."""
    from projeq.scenes import check_names, get_scene

    scene = get_scene(study.scene)
    check_names(scene, overrides)  # the study's own settings may also be the build's **options
    cpu = time.process_time()
    system = scene.build(**{**study.overrides, **overrides, **knob.overrides})
    evaluator = evaluator_for(system, knob)
    strided = (np.repeat(system.q0, 2)[::2], np.repeat(system.s_dot0, 2)[::2])
    for q, s_dot in ((system.q0, system.s_dot0), strided):
        evaluator.accelerations(q, s_dot, 0.0)
    return system, evaluator, time.process_time() - cpu


def reference(study: Study, t_end: float, overrides: dict, out=None) -> np.ndarray:
    """The measured quantity of the converged reference run (cached as NPZ in ``out``)."""
    key = json.dumps([study.scene, study.overrides, overrides, study.reference.label, study.reference.overrides,
                      study.reference_method, study.reference_rtol, study.atol_scale, t_end], sort_keys=True, default=str)
    digest = hashlib.sha1(key.encode()).hexdigest()[:10]
    path = None if out is None else Path(out) / f"reference_{study.scene}_{digest}.npz"
    if path is not None and path.exists():
        with np.load(path) as data:
            return data["measured"]
    system, evaluator, _ = build(study, study.reference, overrides)
    run = run_setting(system, evaluator, study, study.reference_method, study.reference_rtol, t_end, np.inf)
    if run["measured"] is None:
        raise RuntimeError(f"reference: the {study.reference_method} run at rtol {study.reference_rtol:g} "
                           f"failed ({run['failure']}) at t = {run['t_reached']:.6g} s")
    if path is not None:
        np.savez(path, measured=run["measured"], key=key)
    return run["measured"]


def get_study(scene) -> Study:
    """The work-precision study of ``scene`` (a key of :data:`STUDIES` or a :class:`Study`);
    ValueError naming the closest study."""
    if isinstance(scene, Study):
        return scene
    if scene not in STUDIES:
        from projeq.scenes.parameters import closest

        raise ValueError(f"scene: no work-precision study for {scene!r}{closest(str(scene), STUDIES)}; "
                         f"studies: {', '.join(STUDIES)}")
    return STUDIES[scene]


def _check_settings(study: Study, methods, tolerances, knobs, t_end) -> tuple:
    """Validated (methods, tolerances, knobs, t_end); ValueError naming the bad argument."""
    methods, knobs = ([x] if isinstance(x, str) else list(x) for x in (methods, knobs))
    for method in methods:
        if method not in METHODS:
            raise ValueError(f"methods: unknown integrator {method!r}; use some of {', '.join(METHODS)}")
    tolerances = np.atleast_1d(finite_array("tolerances", tolerances))
    if tolerances.ndim != 1 or not tolerances.size or not np.all((tolerances > 0.0) & (tolerances < 1.0)):
        raise ValueError(f"tolerances: expected relative tolerances in (0, 1), got {tolerances.tolist()}")
    by_label = {k.label: k for k in study.knobs}
    for label in knobs:
        if label not in by_label:
            raise ValueError(f"knobs: unknown knob {label!r} of the {study.scene} study; knobs: {', '.join(by_label)}")
    if not methods or not knobs:
        raise ValueError("methods, knobs: give at least one of each")
    for name, values in (("methods", methods), ("tolerances", tolerances.tolist()), ("knobs", knobs)):
        _once(name, values)
    return methods, tolerances.tolist(), [by_label[k] for k in knobs], positive("t_end", t_end)


def _once(name: str, values: list) -> None:
    """ValueError naming ``name`` and the repeated entries: each setting would run, and be
    tabulated and drawn, more than once."""
    repeated = [v for i, v in enumerate(values) if v in values[:i]]
    if repeated:
        raise ValueError(f"{name}: {sorted(set(repeated), key=values.index)} given more than once; "
                         "each setting would run more than once")


def tradeoff(scene, methods=METHODS, tolerances=None, knobs=None, *, quick: bool = False, t_end=None,
             overrides=None, out=None, timeout: float = 120.0, progress: bool = False) -> dict:
    """Work-precision table of ``scene``: one row per (knob, integrator, rtol).

    Parameters
    ----------
    scene : str or Study
        A key of :data:`projeq.studies.tradeoff_studies.STUDIES` or a :class:`Study`.
    methods : sequence of str
        Integrators (default all of :data:`METHODS`; a projected method on a model without an
        energy invariant — a prescribed motion, a non-conservative force — is a skipped row).
    tolerances : sequence of float, optional
        rtol values (default :data:`TOLERANCES`, 1e-3 … 1e-12; quick: :data:`QUICK_TOLERANCES`).
    knobs : sequence of str, optional
        Knob labels of the study (default all; quick: ``study.quick_knobs``).
    quick : bool
        The quick study: fewer tolerances and knobs, ``study.quick_t_end``.
    t_end : float, optional
        Simulated time (s); default the study's.
    overrides : dict, optional
        Scene parameters on top of the study's (not those a knob varies).
    out : path, optional
        Directory for the cached reference and ``tradeoff_<scene>.csv``, rewritten after
        every row so that Ctrl-C keeps the rows finished so far.
    timeout : float
        CPU seconds allowed per run (longer runs: failure ``timeout``).
    progress : bool
        A tqdm bar over the settings (shown on a terminal only).

    Returns
    -------
    dict
        Columns :data:`COLUMNS` as numpy arrays, plus ``"measure"`` (the error's definition) and
        ``"complete"`` (False when Ctrl-C stopped the study).
    """
    study = get_study(scene)
    positive("timeout", timeout)
    methods, tolerances, knobs, t_end = _check_settings(
        study, methods, (QUICK_TOLERANCES if quick else TOLERANCES) if tolerances is None else tolerances,
        (study.quick_knobs if quick else [k.label for k in study.knobs]) if knobs is None else knobs,
        (study.quick_t_end if quick else study.t_end) if t_end is None else t_end)
    overrides = dict(overrides or {})
    varied = {name for knob in knobs for name in knob.overrides} & set(overrides)
    if varied:
        raise ValueError(f"overrides: {', '.join(sorted(varied))} is varied by the study's knobs")
    if out is not None:
        Path(out).mkdir(parents=True, exist_ok=True)
    from tqdm import tqdm

    rows, complete = [], True
    n_runs = len(knobs) * len(methods) * len(tolerances)
    with tqdm(total=n_runs, unit="run", disable=None if progress else True) as bar:

        def record(row):
            rows.append(row)
            bar.update()
            if out is not None:
                save_csv(columns(rows), Path(out) / f"tradeoff_{study.scene}.csv")

        try:
            ref = reference(study, t_end, overrides, out)
            for knob in knobs:
                _knob_rows(study, knob, overrides, ref, methods, tolerances, t_end, timeout, record)
        except KeyboardInterrupt:
            complete = False
    table = columns(rows)
    table.update(measure=study.measure_doc, complete=complete)
    return table


def _warm_up(system, evaluator, methods, t_end: float) -> None:
    """One short untimed run per method: the first call of a method (imports, LU set-up)
    costs up to 30 ms more than the next, which would distort the cheapest runs."""
    for method in methods:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                result = simulate(system, 1e-3 * t_end, method=method, rtol=1e-3, atol=1e-3, evaluator=evaluator,
                                  n_points=2, n_segments=1)
        except (SimulationError, ValueError):
            continue  # the timed run reports it
        if result.status == 2:  # simulate turned Ctrl-C into a partial result
            raise KeyboardInterrupt


def _knob_rows(study, knob, overrides, ref, methods, tolerances, t_end, timeout, record) -> None:
    """``record(row)`` for each (method, rtol) of one knob; KeyboardInterrupt after an
    interrupted run (which is recorded)."""
    try:
        system, evaluator, setup_cpu = build(study, knob, overrides)
        skipped = ""
    except (ValueError, NotImplementedError) as exc:
        system = evaluator = None
        setup_cpu, skipped = np.nan, f"skipped: {exc}"
    else:
        _warm_up(system, evaluator, methods, t_end)
    for method in methods:
        for rtol in tolerances:
            row = {"scene": study.scene, "method": method, "rtol": rtol, "atol": study.atol_scale * rtol,
                   "knob": knob.label, "setup_cpu": setup_cpu}
            if skipped:
                row.update(measured=None, cpu=np.nan, n_evaluations=0, t_reached=0.0, failure=skipped, warning="")
            else:
                row.update(run_setting(system, evaluator, study, method, rtol, t_end, timeout))
            measured = row.pop("measured")
            row["error"] = np.nan if measured is None else float(np.max(np.abs(measured - ref)))
            record(row)
            if row["failure"] == "interrupted":
                raise KeyboardInterrupt
