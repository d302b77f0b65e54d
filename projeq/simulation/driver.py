"""Simulation: integrate q̇ = K(q) ṡ + k, s̈ from the Projection Equation.

The state is x = (q, ṡ) of a model (:class:`projeq.system.Model`: a System or a
ConstrainedSystem). The run is split into segments (``n_segments``) so that a failure, a
non-finite state or Ctrl-C keeps everything computed up to the last finished segment;
each segment is one ``scipy.integrate.solve_ivp`` call with the user's method, tolerances
and events, plus the model's own events (a ConstrainedSystem's degenerating partition),
after which the run goes on with the model's :meth:`~projeq.system.Model.after_event` — for
scipy's RK23, RK45, DOP853 and Radau without events of the user's, solve_ivp's loop written out
(``_Run._stepped_segment``: one solver stepped over the whole run) — or, for those four methods on a
model whose evaluator has a compiled one-call ẋ, no events of the user's and no dense output, one
call of the compiled loop (:mod:`projeq.simulation.loop`:
scipy's algorithm, the same steps to round-off, without Python between the steps; a
ConstrainedSystem's ẋ fails where its partition's event nears, and solve_ivp goes on from the loop's
last step and locates it). Neither cuts a step short at a segment's end: each pauses after the
first step that reaches it and the next segment goes on from there with the same steps, so a run
takes the steps of one segment (bit for bit on a tree; a closed loop's state is projected onto
Φ = 0 where a segment ends) — on short runs up to 40 % fewer evaluations (the double pendulum over
0.5 s: 203 instead of 351) — and a step that passes several ends finishes those segments together
(``progress`` is called once, with the time reached). On a tree of rigid bodies whose segment ends change
nothing (no quaternion to normalise) one call of the compiled loop takes as many segments as it reaches within
``CHUNK_EVALUATIONS`` at the last call's pace (``_Run.chunk_end``: fewer returns to Python; the checks,
``progress`` and Ctrl-C then act at the end of such a chunk). With events of the user's each segment is a
solve_ivp call that ends at the segment's end.
Quaternions are normalised where the pose is evaluated and in the output.

The steps: :class:`_Run` checks the arguments and holds the run's state, ``_Run.solve``
integrates one segment, ``_Run.after_model_event`` re-partitions, ``_Run.stopping``
turns Ctrl-C and failures into a status, :func:`_assemble` builds the :class:`Result`
and :func:`_failure` the :class:`SimulationError`.
"""

from __future__ import annotations

import inspect
import os
import time as _time
import traceback
import warnings
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import OdeSolution, OdeSolver, solve_ivp
from scipy.optimize import brentq

from projeq.analysis.jacobians import state_derivative, state_jacobian
from projeq.assembly import EVALUATORS, compilation
from projeq.checks import callable_name, closest, count, finite_array, flag, non_negative, positive, state_vector
from projeq.simulation import loop
from projeq.simulation.alpha import RHO_INF, GeneralizedAlpha
from projeq.simulation.integrators import (
    EXPLICIT, PROJECTED, fastest_mode, projected_solver, stability_limit, stiff_steps, warn_stiff, with_direct_lu,
)
from projeq.simulation.result import FAILED, NON_FINITE, OUT_OF_RANGE, Result, SimulationError
from projeq.constraints.nonholonomic import may_be_singular, near_singularity
from projeq.system import CLOSED, Model, check_model

__all__ = ["INTEGRATORS", "Result", "SimulationError", "ValidityWarning", "default_method", "simulate"]


INTEGRATORS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")  # the methods of solve_ivp
#: projeq's own OdeSolvers by name: fixed steps, not chosen by a tolerance (not in the studies of rtol)
OWN_SOLVERS = {"GeneralizedAlpha": GeneralizedAlpha}
#: the solvers :meth:`_Run._stepped_segment` steps over segment ends (their state y and ẋ f are all
#: that a step starts from, besides what the next step may reuse)
STEPPED = ("RK23", "RK45", "DOP853", "Radau", "GeneralizedAlpha")
EPS = np.finfo(float).eps
#: they solve with ∂ẋ/∂x: given exactly (jac="exact") unless told otherwise
IMPLICIT = ("Radau", "BDF", "LSODA", "GeneralizedAlpha")
MONITOR_EVERY = 200  # right-hand sides between checks of the state's distance to a coordinate singularity


def _check_method(method) -> None:
    if isinstance(method, str) and (method in INTEGRATORS or method in OWN_SOLVERS or method in PROJECTED):
        return
    if isinstance(method, type) and issubclass(method, OdeSolver):
        return
    raise ValueError(f"method: unknown integrator {method!r}; use one of "
                     f"{[*INTEGRATORS, *OWN_SOLVERS, *PROJECTED]} or an OdeSolver class")


# the keyword options of scipy's own solvers (solve_ivp passes them on; unknown ones only warn)
SOLVER_OPTIONS = {
    "RK45": ("first_step", "max_step"), "RK23": ("first_step", "max_step"), "DOP853": ("first_step", "max_step"),
    "Radau": ("first_step", "max_step", "jac_sparsity"), "BDF": ("first_step", "max_step", "jac_sparsity"),
    "LSODA": ("first_step", "max_step", "min_step", "lband", "uband"),
    "GeneralizedAlpha": ("step", "rho_inf"),
}


_SOLVE_IVP_OWN = ("fun", "t0", "y0", "t_bound", "rtol", "atol", "vectorized")  # set by solve_ivp itself


def check_options(options: dict) -> None:
    """ValueError naming a keyword of ``options`` that :func:`simulate` would refuse, before any run
    (a sweep's points): simulate's own parameters pass, the others are the integrator's options —
    of ``options["method"]`` if given, else of any built-in method (simulate chooses per model)."""
    method = options.get("method")
    if method is not None:
        _check_method(method)
    _check_options(method, {name: value for name, value in options.items() if name not in SIMULATE_KEYWORDS})


def _check_options(method, options: dict) -> None:
    """ValueError naming an option the integrator ``method`` does not know (solve_ivp would ignore
    it); ``method`` None: an option no built-in method knows."""
    if method is None:
        known = tuple(sorted(set().union(*SOLVER_OPTIONS.values())))
    elif isinstance(method, str):
        known = SOLVER_OPTIONS[PROJECTED[method].__name__ if method in PROJECTED else method]
    else:
        parameters = inspect.signature(method).parameters.values()
        known = tuple(p.name for p in parameters if p.kind is not p.VAR_KEYWORD and p.name not in _SOLVE_IVP_OWN)
    unknown = sorted(set(options) - set(known))
    if unknown:
        hint = "".join(closest(name, known) for name in unknown[:1])
        which = "any method" if method is None else f"method {method!r}"
        raise ValueError(f"options: unknown option{'s' * (len(unknown) > 1)} {unknown} for {which}{hint}; "
                         f"it takes {list(known)} (simulate's own: t_start, t_eval, n_points, dense_output, "
                         "evaluator, n_segments, progress, jac)")
    _check_step_sizes(options)
    if isinstance(method, str) and method in OWN_SOLVERS:
        OWN_SOLVERS[method].check_options(options)


def _check_step_sizes(options: dict) -> None:
    """ValueError naming a step size that is not a positive number (max_step may be inf, solve_ivp's
    default; min_step 0): scipy refuses one at t = 0 as a failed run, and ignores a NaN."""
    for name in ("first_step", "max_step", "min_step"):
        value = options.get(name)
        if value is None or (name == "max_step" and isinstance(value, (int, float, np.number)) and value == np.inf):
            continue
        (non_negative if name == "min_step" else positive)(name, value)


def _event_wrapper(event, n_q, label):
    def wrapped(t, x):
        value = event(t, x[:n_q], x[n_q:])
        if not np.isfinite(value):
            raise FloatingPointError(f"{label}: returned {value} at t = {t:.6g}; an event function must be finite")
        return value

    for attr in ("terminal", "direction"):
        if hasattr(event, attr):
            setattr(wrapped, attr, getattr(event, attr))
    return wrapped




def simulate(
    system: Model,
    t_end: float,
    q0=None,
    s_dot0=None,
    method=None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    events=None,
    *,
    t_start: float = 0.0,
    t_eval=None,
    n_points: int | None = None,
    dense_output: bool = False,
    evaluator: str | object | None = None,
    n_segments: int = 20,
    progress=None,
    jac="exact",
    out_of_range: str = "warn",
    **options,
) -> Result:
    """Integrate the equations of motion of ``system`` from ``t_start`` to ``t_end``.

    Parameters
    ----------
    system : System or ConstrainedSystem
        The model (:class:`projeq.system.Model`).
    t_end : float
        End time (s), > t_start.
    q0, s_dot0 : arrays, optional
        Initial coordinates and minimal velocities (default: the system's q0, ṡ0).
    method : str or scipy OdeSolver class, optional
        None (default): chosen by :func:`default_method` from ``rtol`` and the model's
        fastest mode measured at the initial state (DOP853 at rtol ≤ 1e-7, the default
        tolerance included, or for fast elastic modes; RK45 at looser tolerances; Radau with
        the exact Jacobian for very stiff models); a default run whose explicit steps are found
        to crawl at their stability limit goes on with Radau (``Result.method`` "DOP853, Radau
        from t = …", the evidence in ``Result.message``); ``Result.method`` names the choice. Or any method of
        ``scipy.integrate.solve_ivp`` (RK45, DOP853, Radau, BDF, LSODA, ...): by name, RK23, RK45
        and DOP853 step in the compiled loop where the model has a compiled ẋ (a tree, or a closed
        loop's one compiled call) and no ``events`` (:mod:`projeq.simulation.loop`; scipy's
        steps to round-off), and so does Radau (scipy's algorithm, its Jacobian by forward differences
        of the compiled ẋ: n_x evaluations each, counted in ``Result.nfev`` and ``Result.njev``; with
        ``jac`` "differences" or the user's own, solve_ivp steps), and ``method=`` the scipy class
        (``scipy.integrate.DOP853``) keeps solve_ivp stepping;
        or ``"RK45-projected"`` / ``"DOP853-projected"``: that method with each step projected
        onto the initial energy, so that a conservative scleronomic system's energy error
        stays at round-off over long runs (:mod:`projeq.simulation.integrators`; ValueError for a
        system whose energy is not conserved). An explicit method of the user's whose steps crawl
        at its stability limit (a stiff model) gets a :class:`projeq.simulation.integrators.StiffnessWarning`
        suggesting Radau or BDF. Or ``"GeneralizedAlpha"`` with the option ``step`` (and ``rho_inf``,
        default 0.9): the generalized-α method at fixed steps, damping the modes a step does not
        resolve, as Exudyn and Chrono integrate elastic models
        (:class:`projeq.simulation.alpha.GeneralizedAlpha`; in the compiled loop as Radau, its J by
        differences of the compiled ẋ; rtol and atol set only its Newton iteration): the flexible arm's
        tip within 3.2e-4 of the converged run over 0.5 s with ``step=1e-2``, where a step chosen by a
        tolerance resolves the bending modes.
    rtol, atol : float
        Tolerances passed to the integrator.
    events : callable or list of callables ``event(t, q, s_dot)``
        Zero crossings; ``terminal`` and ``direction`` attributes as in solve_ivp. Where
        each fired is in ``Result.t_events`` (times), ``q_events`` and ``s_dot_events``
        (states); a terminal event's exact state is also the Result's last row.
    t_eval : array, optional
        Output times (default ``n_points`` equally spaced, 501 if not given; not both).
    dense_output : bool
        Keep a continuous solution ``result.sol(t) -> (q, s_dot)``.
    evaluator : "recursive", "dense", "fast" or an object with ``accelerations(q, s_dot, t)``
        Right-hand side (default: the model's, :meth:`projeq.system.Model.evaluator`).
    progress : callable ``progress(t)``, optional
        Called after each segment with the time reached (the end of the integrator's first step past
        the segment's end; once for the segments one step passes, or one call of the compiled loop joins
        on a tree of rigid bodies; with events, the segment's end).
    jac : "exact", "differences", callable or matrix
        For Radau, BDF and LSODA: ∂ẋ/∂x by the complex step through the model ("exact",
        the default; exact to round-off, n complex evaluations per Jacobian, counted in
        ``Result.njev``), by scipy's finite differences ("differences"), or the user's. Radau in
        the compiled loop (``jac="exact"``) differentiates the compiled ẋ by forward differences
        instead (it takes real states only): n_x evaluations per Jacobian in ``Result.nfev``.
    out_of_range : "warn" or "stop"
        What a subsystem leaving the range its model describes (a beam beyond moderate
        deflections, :meth:`projeq.subsystems.base.Subsystem.out_of_range`, checked on the output
        rows of each segment) does besides its :class:`ValidityWarning`: "warn" (default) goes
        on, for studies of the model beyond its physical range (a divergence rate, the
        conservation of its energy); "stop" ends the run there with ``Result.status`` 3
        (:data:`projeq.simulation.result.OUT_OF_RANGE`), the rows up to the end of that segment
        kept, as ``projeq run`` and ``projeq sweep`` do.
    **options
        Further options for the integrator (max_step, first_step, ...; see ``SOLVER_OPTIONS``): an option the method does not take is a ValueError naming the
        valid ones (solve_ivp would ignore it).

    Returns
    -------
    Result
        On failure of the integrator (``status`` −1) or a non-finite state (``status`` 4: q, ṡ or
        their derivative not finite, or an output row whose energy is not: a state beyond
        floating-point range), :class:`SimulationError` is raised with ``.result`` holding the
        trajectory computed so far and a message giving the time reached; a run stopped where it
        left its model's range returns with ``status = 3`` (``out_of_range="stop"``); Ctrl-C returns the partial
        trajectory with ``status = 2``. Bad
        arguments raise ``ValueError`` naming the argument before the run starts, and a
        model that cannot be evaluated at the initial state raises its own error there
        (:class:`projeq.SingularMassError`, a force law's ``ValueError``). During the run a
        NaN from a user function, an exception in one (named with its file and line) or a
        state approaching a coordinate singularity (K or F with condition number above 1e5,
        checked every ``MONITOR_EVERY`` right-hand sides) is such a failure; a subsystem
        leaving the range its model describes (a beam beyond moderate deflections) gets a
        :class:`ValidityWarning` (and with ``out_of_range="stop"`` ends the run).
    """
    run = _Run(system, t_end, q0, s_dot0, method, rtol, atol, events, t_start, t_eval, n_points,
               evaluator, n_segments, progress, jac, options, dense_output, out_of_range)
    started, stiff, checked = _time.perf_counter(), None, 0  # one stiffness verdict per run at most
    with run.stopping():
        segments = deque(zip(run.bounds[:-1], run.bounds[1:]))  # a model event splits one
        while segments:
            if run.pieces and not dense_output:  # the last segment's interpolants are no longer needed
                run.pieces[-1] = replace(run.pieces[-1], sol=SimpleNamespace(ts=run.pieces[-1].sol.ts[[0, -1]]))
            a, b = segments.popleft()
            if b <= run.t_x:  # the compiled loop's last step went past this segment's end: its rows are kept
                continue
            b = run.chunk_end(b, segments)
            segment = run.solve(run.t_x, b)
            if run.model_event_fired(segment):  # a ConstrainedSystem's partition degenerates
                a = run.after_model_event(segment)
                if a < b:
                    segments.appendleft((a, b))
            elif segment.status != 0:
                run.status, run.message = segment.status, segment.message
                if segment.status == 1:  # a terminal event of the user's: its rows are checked as a segment's
                    run.check_rows(run.pieces[-1].x, run.pieces[-1].t[-1] if len(run.pieces[-1].t) else a)
                break
            else:
                if stiff is None and run.steps >= 2 * checked:  # ρ at most log₂(steps) times per run
                    checked = run.steps
                    stiff = stiff_steps(run.model_rhs, run.steps, run.t_start, run.t_x_end, run.x_end, run.method,
                                        rtol)
                    if stiff is not None and run.chosen:
                        run.go_implicit(run.t_x_end, stiff)
                    elif stiff is not None:
                        warn_stiff(run.method, stiff)
                run.end_segment()
                if run.status == OUT_OF_RANGE:
                    break
    result = _assemble(run, _time.perf_counter() - started, dense_output)
    if not run.out_of_range and len(result.t) and result.q.shape[1] == system.tree.n_q:  # rows of a failed or
        warn_out_of_range(system.tree, result.q, result.t[-1])  # interrupted segment: warned, the run over anyway
    if run.status in (FAILED, NON_FINITE):
        raise _failure(run, result) from run.cause
    return result


#: simulate's own keyword parameters (the rest of its keywords are the integrator's options)
SIMULATE_KEYWORDS = frozenset(inspect.signature(simulate).parameters) - {"system", "t_end", "options"}


def check_arguments(system: Model, t_end: float, **options) -> None:
    """The ValueError naming an argument that :func:`simulate` would raise for these arguments
    before its run starts (a tolerance, a method, an option, the initial state, the evaluator),
    without running: a sweep checks its first point's run with it before any point runs."""
    arguments = inspect.signature(simulate).bind(system, t_end, **options)
    arguments.apply_defaults()
    a = arguments.arguments
    _Run(system, t_end, a["q0"], a["s_dot0"], a["method"], a["rtol"], a["atol"], a["events"], a["t_start"],
         a["t_eval"], a["n_points"], a["evaluator"], a["n_segments"], a["progress"], a["jac"], a["options"],
         a["dense_output"], a["out_of_range"])


@dataclass(frozen=True)
class _Piece:
    """What one segment gave: the model its ṡ rows are in, the output times t and states x
    (one row (q, ṡ) per time), and its dense solution."""

    model: Model
    t: NDArray
    x: NDArray
    sol: OdeSolution


class _Run:
    """One call of :func:`simulate`: the checked arguments, the model (a ConstrainedSystem
    changes its partition during a run), the state x = (q, ṡ) where the next segment starts,
    and what the finished segments gave (pieces, the user's events, nfev, status)."""

    def __init__(self, system, t_end, q0, s_dot0, method, rtol, atol, events, t_start, t_eval, n_points,
                 evaluator, n_segments, progress, jac, options, dense_output=False, out_of_range="warn"):
        check_model(system)
        if out_of_range not in ("stop", "warn"):
            raise ValueError(f"out_of_range: expected 'stop' or 'warn', got {out_of_range!r}")
        self.stop_out_of_range = out_of_range == "stop"
        self.t_start = t_start = float(finite_array("t_start", t_start, ()))
        q0 = system.check_q("q0", system.q0 if q0 is None else q0)
        system.check_closed("q0", q0, t_start, CLOSED)  # an open loop is a mistake, not a start to project
        q0 = system.normalized(q0, t_start)
        s_dot0 = state_vector("s_dot0", system.s_dot0 if s_dot0 is None else s_dot0, system.n_s)
        self.t_end = t_end = float(finite_array("t_end", t_end, ()))
        if not t_end > t_start:
            raise ValueError(f"t_end: must be after t_start = {t_start}, got {t_end}")
        self.rtol, self.atol = positive("rtol", rtol), positive("atol", atol)
        if self.rtol >= 1.0:
            raise ValueError(f"rtol: a relative tolerance must be below 1 (1 allows 100 % error), got {rtol}")
        if method is not None:
            _check_method(method)
            _check_options(method, options)
        self.t_eval = _output_times(t_start, t_end, t_eval, n_points)
        self.bounds = np.linspace(t_start, t_end, count("n_segments", n_segments) + 1)
        if progress is not None and not callable(progress):
            raise ValueError(f"progress: expected a callable progress(t), got {progress!r}")
        self.events = _checked_events(events, t_start, q0, s_dot0)
        self.model = self.user_model = system
        self.may_be_singular = may_be_singular(system.tree)  # one tree for every model of the run
        self.choice, self.ev = evaluator, _evaluator(system, evaluator)
        self.fused = getattr(self.ev, "state_derivative", None)
        system.check_configuration(q0, t_start)  # a coordinate singularity (or a degenerate partition) by name
        self.ev.accelerations(q0, s_dot0, t_start)  # a singular model or a failing force law raises here, by name
        self.chosen = method is None  # simulate's choice: it may go on with Radau (go_implicit)
        self.step_size = None  # the integrator's next step size where the last segment ended (_counted)
        if self.chosen:
            mode = measured_mode(self.ev, system, q0, s_dot0, t_start)
            method = default_method(self.ev, system, q0, s_dot0, t_start, t_end, self.rtol, mode=mode)
            _check_options(method, options)
            self.step_size = stable_first_step(method, mode, t_start, t_end)
        self.method, self.progress, self.options = method, progress, options
        self.solver = projected_solver(method, system, q0, s_dot0, t_start) if method in PROJECTED else method
        self.x, self.reached = np.concatenate((q0, s_dot0)), t_start  # reached: the latest right-hand side's t
        self.t_x, self.carried = t_start, None  # the time of x; the compiled loop's pause there (loop, Carried)
        self.jac, self.switched, self.note = _jac_option(method, jac, self.x.size), "", ""  # go_implicit's record
        self.pieces, self.nfev, self.njev, self.cause, self.steps, self.calls = [], 0, 0, None, 0, 0
        # x_end: the state where the last segment ended, at t_x_end (its end b, or the end of the compiled loop's
        # first step past b)
        self.dense_output, self.x_end, self.t_x_end = flag("dense_output", dense_output), None, t_start
        self.out_of_range = False  # warned that a subsystem left the range of its model
        self.status, self.message = 0, FINISHED_MESSAGE
        self.fired = [([], [], []) for _ in self.events]  # the user's events: times, q, ṡ
        self.loops, self.renting = {}, False  # (evaluator, its compiled loop or None) per evaluator and method
        self.chunk_rate = None  # evaluations per simulated second of the last compiled call that may join segments

    def rhs(self, t: float, x: NDArray) -> NDArray:
        """ẋ = (q̇, s̈) of the current model: by the evaluator's ``state_derivative`` where it
        has one (ẋ in one compiled call, None when x or ẋ is not finite), else (and then) by
        :meth:`checked_rhs`."""
        self.reached = t
        x_dot = None if self.fused is None else self.fused(t, x)
        if x_dot is None:
            return self.checked_rhs(t, x)
        self._monitor(x[: self.model.n_q], t)
        return x_dot

    def _monitor(self, q: NDArray, t: float) -> None:
        """Count a right-hand side; every ``MONITOR_EVERY`` calls the distance of q to a
        coordinate singularity (where a joint has minimal velocities of its own)."""
        self.calls += 1
        if self.calls % MONITOR_EVERY == 0 and self.may_be_singular:
            near_singularity(self.model.tree, q, t)

    def checked_rhs(self, t: float, x: NDArray) -> NDArray:
        """ẋ = (q̇, s̈) by the model's q̇ and the evaluator's s̈, FloatingPointError when x or ẋ
        is not finite; every ``MONITOR_EVERY`` calls the distance to a coordinate singularity."""
        n_q = self.model.n_q
        q, s_dot = x[:n_q], x[n_q:]
        if not np.isfinite(x).all():  # the ufunc and the array's own all(): half the cost of np.all
            raise NonFiniteState(f"the state is not finite at t = {t:.6g} (q = {q}, s_dot = {s_dot}): the "
                                     "solution blew up (or a tolerance too loose let it)")
        self._monitor(q, t)
        x_dot = np.concatenate((self.model.q_dot(q, s_dot, t), self.ev.accelerations(q, s_dot, t)))
        if not np.isfinite(x_dot).all():
            raise NonFiniteState(f"non-finite state derivative at t = {t:.6g} (q = {q}, s_dot = {s_dot})")
        return x_dot

    def model_rhs(self, t: float, x: NDArray) -> NDArray:
        """ẋ of the current model without the run's counters and monitor of :meth:`rhs`: the stiffness
        check differentiates it. By the evaluator's one-call ẋ where it has one (None: not finite), else
        :func:`projeq.analysis.jacobians.state_derivative`."""
        x_dot = None if self.fused is None else self.fused(t, x)
        return state_derivative(self.model, x, t) if x_dot is None else x_dot

    def jacobian(self, t: float, x: NDArray) -> NDArray:
        """∂ẋ/∂x of the current model by the complex step (:func:`projeq.analysis.jacobians.state_jacobian`:
        through the compiled kernels where they take the model; differences for user callables
        that take no complex arguments), for the implicit methods."""
        self.njev += 1
        return state_jacobian(self.model, x, t)[0]

    def solve(self, a: float, b: float):
        """One segment from the current state at a to b (solve_ivp's result), with the user's
        events and, last, the model's own; its output rows are kept as a :class:`_Piece`.

        A dense solution is formed only where it is needed — the user's ``dense_output``,
        events, the steps holding output times — because DOP853's costs three more
        evaluations per step: without one, the state at b is an extra output time, kept
        in ``x_end`` and not in the piece."""
        t_eval = self.t_eval
        inside = t_eval[(t_eval > a) & (t_eval <= b)] if self.pieces else t_eval[(t_eval >= a) & (t_eval <= b)]
        n_q = self.model.n_q
        jac = {"jac": self.jacobian if isinstance(self.jac, str) else self.jac} if self.method in IMPLICIT else {}
        labels = [f"events[{i}] ({callable_name(e)})" for i, e in enumerate(self.events)]
        labels += [f"the model's event {callable_name(e)}" for e in self.model.events()]
        events = [_event_wrapper(e, n_q, label) for e, label in zip(self.events + list(self.model.events()), labels)]
        dense = self.dense_output or bool(events)
        compiled = None if self.dense_output else self.compiled_loop()
        ahead = t_eval[t_eval > a] if self.pieces else t_eval[t_eval >= a]
        if compiled is not None:
            segment = self._compiled_segment(compiled, a, b, ahead)
            if not isinstance(segment, float):
                return segment
            # solve_ivp goes on where the compiled loop stopped
            a, inside, ahead = segment, inside[inside > segment], ahead[ahead > segment]
        if not self.events and _scipy_class(self.solver) in STEPPED:
            return self._stepped_segment(a, b, ahead, jac, events)
        extra = not dense and not (len(inside) and inside[-1] == b)  # b as an output time
        started = _time.process_time()
        segment = solve_ivp(self.rhs, (a, b), self.x, method=_counted(self.solver, self),
                            t_eval=np.append(inside, b) if extra else inside, rtol=self.rtol, atol=self.atol,
                            events=events or None, dense_output=dense, **jac, **self._continued(b - a))
        if self.renting:
            compilation.spend(_time.process_time() - started, "the integration loop")
        self.nfev += segment.nfev
        if segment.status == 0:
            self.x_end, self.t_x_end = segment.sol(b) if dense else segment.y[:, -1].copy(), b
        if extra and segment.status == 0:
            segment.t, segment.y = segment.t[:-1], segment.y[:, :-1]
        if not dense:
            segment.sol = SimpleNamespace(ts=np.array([a, self.reached if segment.status else b]))
        self._keep(segment)
        return segment

    def _stepped_segment(self, a: float, b: float, ahead: NDArray, jac: dict, events: list):
        """One segment from the current state at a by solve_ivp's loop written out (scipy's RK23, RK45,
        DOP853 or Radau stepping one solver over the rest of the run), as the compiled loop steps it: to
        the end of the first step that reaches b, the rows at the output times ``ahead`` up to there kept
        (also where a step fails: then the error raises), the solver kept for the next segment, which goes
        on with its steps (ẋ evaluated again where the state was normalised in between) — the steps of
        one segment, as the compiled loop and solve_ivp over the whole run take them; with ``dense_output``
        every step's interpolant kept (the same steps, the same rows). ``events``: the model's own (terminal:
        where one fires, located as solve_ivp locates it, the segment ends there, status 1)."""
        started, (solver, nfev) = _time.process_time(), self._resumed(a)  # (a new one's count: ẋ at a, the first step's)
        if solver is None:
            solver = _counted(self.solver, self)(self.rhs, a, self.x.copy(), self.t_end, rtol=self.rtol,
                                                 atol=self.atol, **jac, **self._continued(self.t_end - a))
        self.carried = None
        times, rows, first, steps, interpolants, fired = [], [], 0, [a], [], None
        g = [event(solver.t, solver.y) for event in events]
        try:
            while solver.status == "running" and fired is None and (solver.t < b or not times and solver.t == a):
                _step(solver)
                if solver.status == "failed":
                    break
                interpolant = _Interpolant(solver)  # formed once a step, where it is read (DOP853: 3 evaluations)
                fired, g = _fired(events, g, solver, interpolant)
                t = solver.t if fired is None else fired[1]
                last = np.searchsorted(ahead, t, side="right")  # solve_ivp's rows of a step
                if self.dense_output:
                    steps.append(solver.t)
                    interpolants.append(interpolant.formed())
                if last > first:
                    times.append(ahead[first:last])
                    rows.append(interpolant(ahead[first:last]).T)
                    first = last
        finally:
            self.nfev += solver.nfev - nfev
            if self.renting:
                compilation.spend(_time.process_time() - started, "the integration loop")
            segment = _segment(np.concatenate(times or [np.zeros(0)]), np.vstack(rows or [np.zeros((0, len(self.x)))]),
                               a, solver.t if fired is None else fired[1])
            if interpolants:
                segment.sol = OdeSolution(steps, interpolants)
            if fired is not None:  # the model's event: solve_ivp's terminal event, its time and state
                _terminated(segment, fired[0], len(events), *fired[1:])
            self._keep(segment)
        if fired is not None:
            return segment
        if solver.status == "failed":
            segment.status, segment.message = -1, solver.message
        else:
            self.x_end, self.t_x_end, self.reached = solver.y.copy(), solver.t, solver.t
            self.carried = None if solver.status == "finished" else (self.solver, solver)
            self._pace(solver.nfev - nfev, a, solver.t)
        return segment

    def _resumed(self, a: float) -> tuple:
        """(the solver the last segment paused at a (:meth:`_stepped_segment`), at the current state x (its
        ẋ evaluated again where x is not the state it paused at), and its evaluations before), or (None, 0)."""
        if self.carried is None or self.carried[0] is not self.solver or not isinstance(self.carried[1], OdeSolver):
            return None, 0
        solver = self.carried[1]
        if solver.t != a:
            return None, 0
        nfev = solver.nfev
        if not np.array_equal(solver.y, self.x):
            solver.y = self.x.copy()
            solver.f = solver.fun(solver.t, solver.y)
        return solver, nfev

    def compiled_loop(self):
        """The compiled integration loop of the run's method on the current model
        (:func:`projeq.simulation.loop.loop`), or None where solve_ivp steps: a method the loop does not
        step (BDF, LSODA, projected, an OdeSolver class: ``method=scipy.integrate.DOP853`` keeps scipy's),
        events, options besides max_step, a Radau run whose ``jac`` is not "exact" (the default: the loop
        differentiates the compiled ẋ itself), an evaluator without a compiled one-call ẋ, or an empty state
        (n_q = n_s = 0, only prescribed motion: nothing to integrate, whose error norm the loop would divide
        by zero entries)."""
        key = (id(self.ev), self.method)
        if self.loops.get(key, (None,))[0] is not self.ev:  # (kept with its evaluator: an id is reused once freed)
            taken = {"max_step", *(SOLVER_OPTIONS[self.method] if self.method in OWN_SOLVERS else ())}
            ready = len(self.x) and not (self.events or set(self.options) - taken) and (
                self.method not in IMPLICIT or isinstance(self.jac, str))  # Radau: jac "exact", the default
            provider = getattr(self.ev, "loop_model", None) if ready else None
            if provider is not None and self.fused is not None:
                self.fused(self.reached, self.x)  # ẋ's kernel compiled or found (the default evaluator's tier)
            model = None if provider is None else provider()
            if model is not None and self.model.events() and not model.checks_events:
                model = None  # the model's events located by solve_ivp
            try:
                self.loops[key] = self.ev, loop.loop(model, self.method)
            except compilation.NotCompiled:  # rented: solve_ivp steps, its CPU spent from the budget
                self.loops[key], self.renting = (self.ev, None), True
        return self.loops[key][1]

    def _compiled_segment(self, compiled, a: float, b: float, ahead: NDArray):
        """One segment from the current state at a by the compiled loop, as solve_ivp's result (its output
        rows, status and message; where the model's own event fired, its time and state as solve_ivp
        gives a terminal event's). The loop steps towards the run's end and pauses after the first step
        that reaches b (the rows at the output times ``ahead`` up to that step's end kept, and the state
        there: ``x_end`` at ``t_x_end``), so that the next segment goes on with the same steps (no step cut
        short at b, no restart: the steps of one segment); where an evaluation failed for a reason the
        checked evaluation does not raise (a closed loop's partition flagged by its kernel), the time of the
        last accepted step, from where solve_ivp goes on to b; where an evaluation failed, the rows up to
        that step are kept."""
        first = self._continued(self.t_end - a).get("first_step") or 0.0
        carried = self.carried[1] if self.carried is not None and self.carried[0] is compiled else None
        self.reached, self.carried = a, None
        alpha = (float(self.options.get("rho_inf", RHO_INF)), float(self.options.get("step", 0.0)), self.bounds[0])
        stepped = compiled.run(
            self.model.n_q, a, self.x, self.t_end, first, float(self.options.get("max_step", np.inf)), self.rtol,
            self.atol, np.ascontiguousarray(ahead, dtype=float), self._paused,
            MONITOR_EVERY if self.may_be_singular else 0, b, carried, alpha)
        self._pace(stepped.nfev, a, stepped.t)
        self.nfev, self.njev, self.steps, self.calls, self.step_size, self.reached = (
            self.nfev + stepped.nfev, self.njev + stepped.njev, self.steps + stepped.steps, self.calls + stepped.nfev,
            stepped.h_abs, stepped.t_failed)
        rows = stepped.rows
        segment = _segment(ahead[:len(rows)], rows, a, stepped.t)
        if stepped.status == loop.EVALUATION_FAILED:
            self._keep(segment)  # the rows up to the last accepted step
            self.checked_rhs(stepped.t_failed, stepped.x_failed)  # raises, naming why
            self.check_rows(np.vstack((rows, stepped.state)), stepped.t)
            self.x, self.reached = stepped.state, stepped.t
            return float(stepped.t)
        if stepped.status == loop.TOO_SMALL_STEP:
            segment.status, segment.message = -1, "Required step size is less than spacing between numbers."
        elif stepped.status == loop.MODEL_EVENT:  # the model's own terminal event, located where it fired
            _terminated(segment, len(self.events), len(self.events) + 1, stepped.t, stepped.state.copy())
        elif stepped.status in (loop.FINISHED, loop.PAUSED):
            self.x_end, self.t_x_end = stepped.state, stepped.t
            self.carried = None if stepped.carried is None else (compiled, stepped.carried)
        self._keep(segment)
        if stepped.stopped_by is not None:  # the monitor's verdict, the rows before it kept
            raise stepped.stopped_by
        return segment

    def _pace(self, evaluations: int, a: float, t: float) -> None:
        """The evaluations per simulated second of a segment from a to t that :meth:`chunk_end` reads, where
        the run's model is a tree of rigid bodies whose segment ends change nothing (else None: no segments
        joined): no joint whose coordinates are normalised there, no subsystem of coordinates of its own,
        whose range each segment's rows are checked against (a beam found beyond moderate deflections at
        the end of a joined chunk would have gone far beyond)."""
        tree = self.model.tree
        joins = tree is self.model and not tree._normalizing and t > a and not any(sub.n_e for sub in tree.subsystems)
        self.chunk_rate = evaluations / (t - a) if joins else None

    def chunk_end(self, b: float, segments: deque) -> float:
        """The end of the next call of the compiled loop (or of scipy's solver stepped over the run,
        :meth:`_stepped_segment`): b, or the end of the last of the following ``segments`` (taken from it)
        that it reaches within ``CHUNK_EVALUATIONS`` at the last call's evaluations per simulated second
        (:meth:`_pace`), where that call stepped a tree of rigid bodies whose segment ends change nothing
        (the same steps, bit for bit): each return to Python costs about 0.1 ms,
        a tenth of a short run's CPU (the double pendulum over 0.5 s: 9 calls, 2 now).
        Counted in evaluations, not seconds, so that a run's calls, and where its checks of the rows fall
        (progress, a subsystem out of range), do not depend on the machine's load; such a chunk lasts a
        few milliseconds to a second (1 µs to 0.5 ms per evaluation), as a segment may."""
        while self.chunk_rate is not None and segments and \
                (segments[0][1] - self.t_x) * self.chunk_rate < CHUNK_EVALUATIONS:
            b = segments.popleft()[1]
        return b

    def _paused(self, t: float, x: NDArray) -> None:
        """The check of :meth:`_monitor` where a compiled segment pauses (every ``MONITOR_EVERY``
        evaluations, on a tree whose joints may lose rank): the distance of q to a coordinate singularity."""
        self.reached = t
        near_singularity(self.model.tree, x[:self.model.n_q], t)

    def _continued(self, span: float) -> dict:
        """The integrator's options for the next segment: the user's, and where they set no first
        step, the step size the last segment's integrator would have taken next. A restart would
        guess it from ẋ (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4), blind to stiffness: on
        a closed loop with stiff bending modes the guess was ~40× the stable step, and the trial
        stage left the loop's domain (its partition check raised where the step would have been
        rejected)."""
        if "first_step" in self.options or self.step_size is None:
            return self.options
        return {**self.options, "first_step": min(self.step_size, span)}

    def _keep(self, segment) -> None:
        """The segment's rows, ended by the state where a terminal event of the user's
        stopped it, and where the user's events fired."""
        n_q, n_x = self.model.n_q, self.model.n_q + self.model.n_s
        t, x = segment.t, np.reshape(segment.y, (n_x, len(segment.t))).T  # no output times: y = []
        for (times, q, s_dot), te, ye in zip(self.fired, segment.t_events or [], segment.y_events or []):
            times.extend(te)
            q.extend(self.model.normalized(y[:n_q], tau) for tau, y in zip(te, ye))
            s_dot.extend(y[n_q:] for y in ye)
        if segment.status == 1 and not self.model_event_fired(segment):
            t_stop = segment.sol.ts[-1]  # the terminal event, where the dense solution ends
            if not len(t) or t_stop > t[-1]:
                t, x = np.append(t, t_stop), np.vstack((x, segment.sol(t_stop)))
        self.pieces.append(_Piece(self.model, t, x, segment.sol))

    def model_event_fired(self, segment) -> bool:
        """Whether one of the model's own (terminal) events stopped the segment."""
        return segment.status == 1 and any(len(te) for te in segment.t_events[len(self.events):])

    def after_model_event(self, segment) -> float:
        """Go on from the model's event with :meth:`Model.after_event` (a ConstrainedSystem's
        new partition, or its ValueError); the time to go on from."""
        k = next(i for i, te in enumerate(segment.t_events) if i >= len(self.events) and len(te))
        t, x = segment.t_events[k][0], segment.y_events[k][0]
        n_q = self.model.n_q
        self.model, s_dot = self.model.after_event(x[:n_q], x[n_q:], t)
        self.x, self.ev = np.concatenate((x[:n_q], s_dot)), _evaluator(self.model, self.choice)
        self.t_x, self.carried = t, None
        self.fused = getattr(self.ev, "state_derivative", None)
        if self.method in PROJECTED:  # the same energy, now in the new partition's s_dot
            self.solver = projected_solver(self.method, self.model, x[:n_q], s_dot, t)
        return t

    def go_implicit(self, t: float, evidence: str) -> None:
        """The rest of a run whose explicit method simulate chose goes on with Radau and the
        exact Jacobian, from t, where its steps were found to crawl at their stability limit
        (``evidence``: :func:`~projeq.simulation.integrators.stiff_steps`): the choice a
        :class:`~projeq.simulation.integrators.StiffnessWarning` would advise, recorded in
        ``Result.method`` ("DOP853, Radau from t = …") and, with the evidence, ``Result.message``."""
        self.switched = f"{self.method}, Radau from t = {t:.6g} s"
        self.note = f"{self.method} crawled at its stability limit by t = {t:.6g} s ({evidence}): Radau went on. "
        self.method = self.solver = "Radau"

    def end_segment(self) -> None:
        """The next segment starts where this one ended (``t_x_end``: its end, or the end of the compiled
        loop's step past it), from the state there (not at the last output time), after the checks of the
        segment's output rows and end state (not of every right-hand side): a non-finite one ends the run
        (:class:`NonFiniteState`), and one where a subsystem leaves its model's range warns and, with
        ``out_of_range="stop"``, ends it (status 3)."""
        t = self.t_x_end
        self.check_rows(np.vstack((self.pieces[-1].x, self.x_end)), t)
        self.x, self.t_x = self.x_end.copy(), t
        n_q = self.model.n_q
        self.x[:n_q] = self.model.normalized(self.x[:n_q], t)
        if self.may_be_singular:
            near_singularity(self.model.tree, self.x[:n_q], t)
        if self.progress is not None:
            self.progress(t)

    def check_rows(self, rows: NDArray, t: float) -> None:
        """The states ``rows`` (q, ṡ) of a finished segment, up to time t: NonFiniteState if one is
        not finite; a ValidityWarning if a subsystem leaves its model's range in them (the first
        time in the run), which with ``out_of_range="stop"`` ends the run with status 3."""
        finite = np.isfinite(rows).all(axis=1)
        if not finite.all():  # the segment's rows are kept up to the first non-finite one
            piece, first = self.pieces[-1], int(np.argmin(finite))
            self.pieces[-1] = replace(piece, t=piece.t[:first], x=piece.x[:first])
            raise NonFiniteState(f"the state is not finite by t = {t:.6g}: the solution blew up (or a tolerance "
                                 "too loose let it)")
        if not self.out_of_range and warn_out_of_range(self.model.tree, rows[:, :self.model.n_q], t):
            self.out_of_range = True
            if self.stop_out_of_range:
                self.status, self.message = OUT_OF_RANGE, (
                    f"stopped at t = {t:.6g} s: a subsystem left the range its model describes (the "
                    "ValidityWarning says which, how far and what to do)")

    @contextmanager
    def stopping(self):
        """Ctrl-C or a failure ends the run with a status; the finished segments are kept."""
        try:
            yield
        except KeyboardInterrupt:
            self.status, self.message = 2, "interrupted (Ctrl-C): the trajectory up to the last finished segment is kept"
        except Exception as exc:  # noqa: BLE001 - a user's force law or event failed: keep the trajectory
            self.status = NON_FINITE if isinstance(exc, NonFiniteState) else FAILED
            self.message, self.cause = _described(exc), exc


CHUNK_EVALUATIONS = 2000  # evaluations of a compiled call that joins the segments of a tree (_Run.chunk_end)
FAST_MODE_STEPS = 500  # RK45 steps forced by stability alone beyond which DOP853 is the default
STIFF_STEPS = 100_000  # DOP853 steps forced by stability alone beyond which Radau is the default
HIGH_ORDER_RTOL = 1e-7  # at rtol this tight or tighter the eighth order of DOP853 pays on every model measured


def measured_mode(evaluator, model, q0: NDArray, s_dot0: NDArray, t0: float) -> tuple[float, bool]:
    """(ρ, decays) of the model's fastest mode at the initial state
    (:func:`~projeq.simulation.integrators.fastest_mode` of ẋ = (q̇, s̈) by ``evaluator``: its one-call ẋ
    where it has one, as the integration loop calls it)."""
    one_call = getattr(evaluator, "state_derivative", None)

    def rhs(t, x):
        x_dot = None if one_call is None else one_call(t, x)
        if x_dot is not None:
            return x_dot
        q, s_dot = x[: model.n_q], x[model.n_q :]
        return np.concatenate((model.q_dot(q, s_dot, t), evaluator.accelerations(q, s_dot, t)))

    return fastest_mode(rhs, t0, np.concatenate((q0, s_dot0)), derivatives="differences")


def stable_first_step(method: str, mode: tuple[float, bool], t0: float, t_end: float) -> float | None:
    """The first step of simulate's own explicit choice where fast modes chose it (more than
    FAST_MODE_STEPS RK45 steps for stability alone): the stability limit of ``method`` over ρ.
    scipy's first-step guess reads ẋ and not the modes (Hairer, Nørsett & Wanner, *Solving ODEs I*,
    §II.4): on a UR5 robot whose last link is a RitzBeam (ρ ≈ 2e3 1/s) it was far beyond the stable
    step and DOP853's error estimate let it pass, the beam's modes growing until D_n was indefinite at
    t = 5.6 ms (benchmarks/urdf_pinocchio.py). None (scipy's guess) for the other models."""
    rho = mode[0]
    if method not in ("RK45", "DOP853") or not rho * (t_end - t0) > FAST_MODE_STEPS * stability_limit("RK45"):
        return None
    return 0.5 * stability_limit(method) / rho  # half the limit: the error estimate then sees the modes


def default_method(evaluator, model, q0: NDArray, s_dot0: NDArray, t0: float, t_end: float,
                   rtol: float = 1e-8, mode: tuple[float, bool] | None = None) -> str:
    """simulate's integrator when none is given, from the tolerance and the model's fastest
    mode measured at the initial state: ρ = the spectral radius of ∂ẋ/∂x
    (:func:`projeq.simulation.integrators.fastest_mode` by differences at real states: the
    eigenvalues of Richardson's Jacobian for n_x ≤ 64, else power iteration; a compiled model
    is not compiled for complex states for it)
    gives the steps an explicit method needs for stability alone, n = ρ (t_end − t0) / |x_s|
    with |x_s| its stability interval (:func:`~projeq.simulation.integrators.stability_limit`:
    RK45 3.31, DOP853 6.39). ``mode``: (ρ, decays) measured already (:func:`measured_mode`).

    * "Radau" (the compiled loop's where the model has a compiled ẋ, else solve_ivp's with the exact
      Jacobian) when even DOP853 would need more than ``STIFF_STEPS`` steps
      for stability alone, or when the fastest mode decays without oscillating (a real
      eigenvalue −ρ: a stiff damper) and would force more than ``FAST_MODE_STEPS`` RK45 steps —
      such a mode dies out, so only stability limits an explicit step (IFToMM A05, the stiff
      flyball governor, ρ = 8117 1/s, over 10 s at rtol 1e-8, one run of benchmarks/iftomm.py:
      DOP853 155,470 evaluations, 44.7 s CPU, and a StiffnessWarning; Radau 17,655 evaluations
      and 1,250 Jacobians, 26.4 s; BDF would take 6.5 s but misses the energy balance by
      6.4e-5 J where Radau keeps it to 1.1e-7 J);
    * "DOP853" at ``rtol`` ≤ ``HIGH_ORDER_RTOL`` (simulate's default 1e-8 included), or when
      RK45 would need more than ``FAST_MODE_STEPS`` steps for stability alone (fast elastic
      modes, n = 1200–4750 for the elastic and the flexible arm and the spin-up beam over
      their runs). At rtol 1e-8, atol 1e-10 DOP853 needs fewer evaluations than RK45 on every
      model measured (benchmarks/default_integrator.py, 5 s: chain(5) 2788 vs 5434, the
      three-link arm 4948 vs 5230; the flexible arm over 0.3 s 28159 vs 53716) and ends
      13–25× closer to the converged state; its order 8 against 5 is why (Hairer, Nørsett &
      Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., §II.10: the work-precision
      diagrams, eighth order ahead at stringent tolerances);
    * "RK45" otherwise (at rtol 1e-4 it needed 9–41 % fewer evaluations than DOP853 on the
      rigid models above), and for models with constraint equations at any tolerance unless
      fast modes ask for DOP853: their right-hand side switches partitions or carries the branch
      of the null space from call to call, which the eighth order does not see as smooth
      (at rtol 1e-9, atol 1e-11: the double four-bar, IFToMM A02 with N = 2, over 10 s, B0 off
      the parallelogram motion by 3.5e-5 with DOP853 and 4.6e-5 at rtol 1e-10 — an error
      floor — against 7.6e-6 with RK45; the four-bar's final state after 5 s 1.0e-6 vs 4.5e-8;
      Barhorst's quick-return mechanism the other way, 3.8e-7 vs 2.4e-5).

    Whether an explicit method's steps will be bound by stability, ρ at t0 does not tell: that
    depends on whether the run excites the fast modes. The spinning beam scene (ρ = 122.9 1/s,
    192 DOP853 steps for stability over its 10 s) rests, q = 0 being its solution, and DOP853's
    steps outgrow the stability limit (ρh = 8.8), with Radau no faster (0.19 vs 0.14 s CPU);
    bent by 1 cm at the tip, DOP853 is bound by accuracy and 4.1× faster than Radau (0.32 vs
    1.35 s, 5,839 vs 11,140 evaluations, errors 5.1e-8 and 4.4e-9). So the rule stays explicit
    there, and :func:`simulate` watches the explicit steps
    (:func:`~projeq.simulation.integrators.stiff_steps`, at each doubling of their number): a
    default run whose steps crawl at the stability limit goes on with Radau, where a user's
    explicit method gets the StiffnessWarning — the axially stiff beam of tests/simulation
    (ρ = 1.7e3 1/s over 1 s) from t = 0.1 s, 0.31 s CPU and 2,472 evaluations against DOP853's
    0.44 s and 12,031 (Radau throughout 0.27 s), the resting spinning beam from t = 4 s (0.16 vs
    0.14 s). On the elastic models that excite their fast modes DOP853 stays the fastest at rtol
    1e-8: Radau 19×, 12× and 5.4× slower on the elastic arm (5 s), the flexible arm (1 s) and the
    spin-up beam (5 s), BDF 5.8×, 3.3× and 4.1×, RK45 3.8×, 1.9× and 1.2× (one run of
    benchmarks/default_integrator.py).
    """

    rho, decays = measured_mode(evaluator, model, q0, s_dot0, t0) if mode is None else mode
    rho_T = rho * (t_end - t0)
    explicit_steps = rho_T / stability_limit("RK45")
    if rho_T > STIFF_STEPS * stability_limit("DOP853") or (decays and explicit_steps > FAST_MODE_STEPS):
        return "Radau"
    high_order = rtol <= HIGH_ORDER_RTOL and not hasattr(model, "mobility")  # no constraint equations
    return "DOP853" if explicit_steps > FAST_MODE_STEPS or high_order else "RK45"


FINISHED_MESSAGE = "The solver successfully reached the end of the integration interval."  # scipy's, status 0


def _segment(t: NDArray, rows: NDArray, a: float, reached: float) -> SimpleNamespace:
    """A segment stepped by the compiled loop or scipy's solver in the shape of solve_ivp's result: the
    output times ``t`` and ``rows`` (one state per row), status 0, from a to the time ``reached``."""
    return SimpleNamespace(t=t, y=rows.T, status=0, t_events=None, y_events=None,
                           sol=SimpleNamespace(ts=np.array([a, reached])), message=FINISHED_MESSAGE)


def _terminated(segment: SimpleNamespace, k: int, n_events: int, t: float, x: NDArray) -> None:
    """``segment`` ended by event k of ``n_events`` (all terminal) at time t in the state x, as
    solve_ivp gives a terminal event: status 1, its time and state in t_events and y_events."""
    segment.status, segment.message = 1, "A termination event occurred."
    segment.t_events = [np.array([t]) if i == k else np.zeros(0) for i in range(n_events)]
    segment.y_events = [x[None] if i == k else np.zeros((0, len(x))) for i in range(n_events)]


class _Interpolant:
    """The dense output of a solver's last step, formed at its first use (``formed``, or a call at
    times)."""

    def __init__(self, solver: OdeSolver):
        self.solver, self.dense = solver, None

    def formed(self):
        if self.dense is None:
            self.dense = self.solver.dense_output()
        return self.dense

    def __call__(self, t):
        return self.formed()(t)


def _fired(events: list, g: list, solver: OdeSolver, interpolant: _Interpolant) -> tuple:
    """(None, or (index, time, state) of the first of the terminal ``events`` that fired inside the
    solver's last step, located as solve_ivp locates it: brentq on the step's interpolant, xtol and rtol
    4 ε; the events' values at the step's end): solve_ivp's ``find_active_events`` and ``handle_events``."""
    if not events:
        return None, g
    g_new = [event(solver.t, solver.y) for event in events]
    roots = []
    for k, (event, before, after) in enumerate(zip(events, g, g_new)):
        direction = getattr(event, "direction", 0)
        up, down = before <= 0 <= after, before >= 0 >= after
        if up and direction > 0 or down and direction < 0 or (up or down) and direction == 0:
            t = brentq(lambda tau: event(tau, interpolant(tau)), solver.t_old, solver.t, xtol=4 * EPS, rtol=4 * EPS)
            roots.append((t, k, interpolant(t)))
    if not roots:
        return None, g_new
    t, k, x = min(roots, key=lambda root: root[0])
    return (k, t, x), g_new


def _step(solver: OdeSolver) -> None:
    """One step of scipy's ``solver``; an explicit step whose evaluation raises is retried with h × 0.2,
    ``loop.STAGE_RETRIES`` times at most (then the error raises), as the compiled loop rejects a step
    with a stage its kernel cannot evaluate (:func:`projeq.simulation.loop.segment`)."""
    for retry in range(loop.STAGE_RETRIES + 1):
        try:
            solver.step()
            return
        except Exception:  # noqa: BLE001 - a trial state far off: the step rejected, or the error raised
            if not hasattr(solver, "K") or retry == loop.STAGE_RETRIES:  # (Radau: no retry, as in the loop)
                raise
            solver.h_abs *= loop.MIN_FACTOR


def _scipy_class(solver) -> str | None:
    """The name of scipy's solver ``solver`` is (a method name or scipy's own OdeSolver class; None for
    another class, a user's subclass or a projected method)."""
    import scipy.integrate

    if isinstance(solver, str):
        return solver
    name = getattr(solver, "__name__", None)
    return name if getattr(scipy.integrate, name or "", None) is solver else None


def _counted(solver, run: _Run) -> type:
    """``solver`` (a method name of solve_ivp or an OdeSolver class) as a subclass that adds
    each step it takes to ``run.steps`` (solve_ivp counts steps only in a dense solution) and keeps
    its step size in ``run.step_size`` (the next segment starts with it, :meth:`_Run._continued`);
    scipy's Radau and BDF factorise by LAPACK directly
    (:func:`~projeq.simulation.integrators.with_direct_lu`: the same results, less overhead)."""
    import scipy.integrate

    base = (OWN_SOLVERS.get(solver) or getattr(scipy.integrate, solver)) if isinstance(solver, str) else solver

    class Counted(base):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            if base in (scipy.integrate.Radau, scipy.integrate.BDF):  # scipy's own, not a user's subclass
                with_direct_lu(self)

        def step(self):
            message = super().step()
            run.steps += self.status != "failed"
            run.step_size = getattr(self, "h_abs", None) or self.step_size  # the next step's, where it has one
            return message

    Counted.__name__ = Counted.__qualname__ = base.__name__
    return Counted


def _jac_option(method, jac, n_x: int):
    """``jac`` of :func:`simulate`: "exact", "differences" (scipy's own, None) or the user's
    callable or (n_x, n_x) matrix (a matrix compared with a string is an array, not a bool)."""
    if isinstance(jac, str):
        if jac not in ("exact", "differences"):
            raise ValueError(f"jac: expected 'exact', 'differences', a callable jac(t, x) or a matrix, got {jac!r}")
        return None if jac == "differences" else jac
    if jac is not None and method not in IMPLICIT:
        raise ValueError(f"jac: only the implicit methods {list(IMPLICIT)} use a Jacobian, not {method!r}")
    return jac if jac is None or callable(jac) else finite_array("jac", jac, (n_x, n_x))


class ValidityWarning(UserWarning):
    """A run left the range its model describes (a beam beyond moderate deflections)."""


class NonFiniteState(FloatingPointError):
    """The state x = (q, ṡ), its derivative or an output row's energy is not finite: the run
    ends with ``Result.status`` 4 (:data:`projeq.simulation.result.NON_FINITE`)."""


def warn_out_of_range(tree, q_rows: NDArray, t: float) -> bool:
    """Warn (:class:`ValidityWarning`) for each subsystem of ``tree`` whose internal
    coordinates in the rows ``q_rows`` (up to time t) leave its model's range; True if one did."""
    warned = False
    for n, sub in enumerate(tree.subsystems):
        problem = sub.out_of_range(q_rows[:, tree.e_q_slice[n]]) if sub.n_e else None
        if problem:
            warnings.warn(f"{tree.names[n]!r} by t = {t:.6g} s: {problem}", ValidityWarning, stacklevel=3)
            warned = True
    return warned


def _described(exc: Exception) -> str:
    """The message of a failure during a run: projeq's own errors (a NaN, a singular matrix, a
    user function's bad value, named where they are found) as they are; any other exception
    of a user's function with its type and where it was raised."""
    if isinstance(exc, (FloatingPointError, ValueError, np.linalg.LinAlgError)):
        return str(exc)
    return f"{type(exc).__name__} in {_raised_in(exc)}: {exc}"


def _raised_in(exc: BaseException) -> str:
    """Where ``exc`` was raised: the innermost frame outside projeq, numpy and scipy (the
    user's function), as 'name (file:line)'."""
    frames = [f for f, _ in traceback.walk_tb(exc.__traceback__)]
    mine = [f for f in frames if not any(part in f.f_code.co_filename for part in _LIBRARIES)] or frames[-1:]
    code = mine[-1].f_code
    return f"{getattr(code, 'co_qualname', code.co_name)} ({code.co_filename}:{mine[-1].f_lineno})"


_LIBRARIES = (f"{os.sep}projeq{os.sep}", f"{os.sep}numpy{os.sep}", f"{os.sep}scipy{os.sep}", f"{os.sep}sympy{os.sep}")


def _checked_events(events, t, q, s_dot) -> list:
    """The user's events, each called once at the initial state: a callable event(t, q, s_dot)
    returning one finite number."""
    events = [] if events is None else (list(events) if isinstance(events, (list, tuple)) else [events])
    for i, e in enumerate(events):
        if not callable(e):
            raise ValueError(f"events[{i}]: expected a callable event(t, q, s_dot), got {e!r}")
        try:
            value = e(t, q.copy(), s_dot.copy())
        except TypeError as exc:
            raise ValueError(f"events[{i}] ({callable_name(e)}): calling it as event(t, q, s_dot) at t = {t} failed: {exc}") from exc
        if np.ndim(value) != 0 or not np.isrealobj(value):
            raise ValueError(f"events[{i}] ({callable_name(e)}): must return one real number, returned {value!r}")
        if not np.isfinite(value):
            raise ValueError(f"events[{i}] ({callable_name(e)}): returned {value} at the initial state t = {t}; "
                             "an event function must be finite")
    return events


def _evaluator(system, evaluator):
    """The right-hand side's evaluator: a user object, or the system's by name."""
    if hasattr(evaluator, "accelerations"):
        return evaluator
    if evaluator is None or (isinstance(evaluator, str) and evaluator in EVALUATORS):
        return system.evaluator(evaluator)
    raise ValueError(
        f"evaluator: unknown evaluator {evaluator!r}; use one of {sorted(EVALUATORS)} "
        "or an object with accelerations(q, s_dot, t)"
    )


def _output_times(t_start, t_end, t_eval, n_points) -> NDArray:
    """The output rows' times: ``t_eval``, or ``n_points`` (501 if None) equally spaced; not both."""
    if t_eval is None:
        return np.linspace(t_start, t_end, count("n_points", 501 if n_points is None else n_points, 2))
    if n_points is not None:
        raise ValueError(f"n_points, t_eval: give one of them (t_eval's times are the output rows), got n_points = "
                         f"{n_points!r} beside t_eval")
    t_eval = finite_array("t_eval", t_eval)
    if t_eval.ndim != 1 or not t_eval.size:
        raise ValueError(f"t_eval: expected a 1-D array of output times, got shape {t_eval.shape}")
    if np.any(np.diff(t_eval) <= 0) or t_eval[0] < t_start or t_eval[-1] > t_end:
        raise ValueError(f"t_eval: must increase strictly within [{t_start}, {t_end}]")
    return t_eval


def _assemble(run: _Run, wall_time: float, dense_output: bool) -> Result:
    """One Result from the pieces: normalised q, and the energies and constraint residuals
    of each row in its own piece's model (its partition)."""
    system, pieces = run.user_model, run.pieces
    n_q, n_s = system.n_q, system.n_s
    rows = [(p.model, ti) for p in pieces for ti in p.t]
    x = np.vstack([p.x for p in pieces] + [np.zeros((0, n_q + n_s))])
    q, energies, residual, ranks = _row_values(run, rows, x)
    t, s_dot = np.array([ti for _, ti in rows[:len(q)]]), x[:len(q), n_q:]
    partitions = tuple(
        (float(p.sol.ts[0]), p.model.partition, p.model.formulation) for i, p in enumerate(pieces)
        if p.model.partition is not None and (i == 0 or p.model is not pieces[i - 1].model)
    )
    t_events, q_events, s_dot_events = (
        tuple(np.array(fired[k]).reshape((len(fired[k]),) + shape) for fired in run.fired)
        for k, shape in enumerate(((), (n_q,), (n_s,)))
    )
    return Result(
        t=t, q=q, s_dot=s_dot, kinetic=energies[:, 0], potential=energies[:, 1],
        constraint_residual=residual, nfev=int(run.nfev), njev=int(run.njev), wall_time=wall_time,
        status=int(run.status), message=run.note + str(run.message), t_events=t_events, q_events=q_events,
        s_dot_events=s_dot_events, names=system.names, method=run.switched or getattr(run.method, "__name__", str(run.method)),
        partitions=partitions, coordinates=system.coordinates(),
        velocities=system.velocities() if len(partitions) < 2 else tuple((f"s_dot[{i}]", "") for i in range(n_s)),
        sol=_dense_solution(pieces, n_q) if dense_output and pieces else None, system=system,
        **_rank_history(rows, ranks),
    )


def _rank_history(rows: list, ranks: list) -> dict:
    """Result's ``rank`` and ``mobility`` of a model with constraint equations: each output row's
    in its own piece's model (its partition, :meth:`projeq.system.Model.output_row`); nothing
    for other models."""
    if not rows or not hasattr(rows[0][0], "mobility"):
        return {}
    history = np.reshape(np.array(ranks, dtype=int), (len(ranks), 2))
    return {"rank": history[:, 0], "mobility": history[:, 1]}


def _row_values(run: _Run, rows: list, x: NDArray) -> tuple[NDArray, NDArray, NDArray, list]:
    """Normalised q, (T, V), constraint residuals (Φ, A q̇ − b) and (rank, mobility) of each
    output row in its own model (:meth:`projeq.system.Model.output_row`), the rows of each model's
    stretch together where it computes them so (:meth:`projeq.system.Model.rows`), up to the first row
    where a user function raises (a constraint or residual
    function that fails only late in the run, evaluated here for the first time at that
    row): the run is then a failure at that row's time (status, message naming the
    function, cause) and keeps the rows before it."""
    system, n_q = run.user_model, run.user_model.n_q
    q, energies, residual, ranks = [], [], [], []
    start = 0
    while start < len(rows):
        model = rows[start][0]
        end = next((i for i in range(start, len(rows)) if rows[i][0] is not model), len(rows))
        values = _rows_together(model, [t for _, t in rows[start:end]], x[start:end])
        if values is None:
            values = _rows_one_by_one(run, rows[start:end], x[start:end], n_q)
        for kept, new in zip((q, energies, residual, ranks), values):
            kept.extend(new)
        if len(values[0]) < end - start:
            break
        start = end
    n = len(q)
    return (np.reshape(q, (n, n_q)), np.reshape(energies, (n, 2)), np.reshape(residual, (n, system.n_c)), ranks)


def _rows_one_by_one(run: _Run, rows: list, x: NDArray, n_q: int) -> tuple[list, list, list, list]:
    """:func:`_row_values` of ``rows`` one by one, up to the first that fails (the run's status and
    message then name it)."""
    q, energies, residual, ranks = [], [], [], []
    for (model, t), xi in zip(rows, x):
        try:
            qi = model.normalized(xi[:n_q], t)
            values = model.output_row(qi, xi[n_q:], t)
            if not np.isfinite(values[0]).all():
                raise NonFiniteState(f"the energy (T, V) = {tuple(map(float, values[0]))} is not finite at t = "
                                     f"{t:.6g} (largest |q| {np.abs(qi).max():.3g}): the state is beyond "
                                     "floating-point range (the solution blew up)")
        except Exception as exc:  # noqa: BLE001 - a user's function: reported by name with the time
            run.status, run.cause, run.reached = NON_FINITE if isinstance(exc, NonFiniteState) else FAILED, exc, t
            run.message = _described(exc) + ("" if f"t = {t:.6g}" in str(exc) else f" (at the output time t = {t:.6g})")
            break
        q.append(qi)
        energies.append(values[0])
        residual.append(values[1])
        ranks.append(values[2])
    return q, energies, residual, ranks


def _rows_together(model, times: list, x: NDArray) -> tuple | None:
    """The rows (q, energies, residuals, ranks) at ``times`` and states ``x`` of one model that
    computes them together (:meth:`projeq.system.Model.rows`) where every energy is finite; None where
    the model does not, or a row fails (then row by row, which names the row)."""
    try:
        values = model.rows(x, np.array(times, dtype=float))
    except Exception:  # noqa: BLE001 - a user's function: row by row names it with its time
        return None
    if values is None or not np.isfinite(values[1]).all():
        return None
    q, energies, residuals, ranks = values
    return q, energies, residuals, [None] * len(times) if ranks is None else [tuple(row) for row in ranks]


def _failure(run: _Run, result: Result) -> SimulationError:
    """The error of a failed run, with the time reached and a hint for explicit methods."""
    kept = result.t[-1] if len(result.t) else run.t_start
    hint = ""
    if run.method in EXPLICIT and "step size" in run.message:
        hint = (
            "; the solution may blow up here, or the system is stiff for an explicit method "
            "(a very stiff beam): then try method='Radau' or 'BDF'"
        )
    return SimulationError(
        f"integration failed at t = {run.reached:.6g} s (t_end = {run.t_end}): {run.message}{hint}; "
        f"the trajectory up to t = {kept:.6g} s is in .result",
        result,
    )


def _dense_solution(pieces, n_q):
    """Join the segments' dense outputs into one ``sol(t) -> (q, s_dot)``."""
    ts = np.concatenate([p.sol.ts[:-1] for p in pieces] + [pieces[-1].sol.ts[-1:]])
    interpolants = [f for p in pieces for f in p.sol.interpolants]
    joined = OdeSolution(ts, interpolants)

    def sol(t):
        x = joined(t)
        return x[:n_q], x[n_q:]

    return sol
