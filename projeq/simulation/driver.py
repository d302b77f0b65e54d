"""Simulation: integrate q̇ = K(q) ṡ + k, s̈ from the Projection Equation, with solve_ivp.

The state is x = (q, ṡ). The run is split into segments (``n_segments``) so that a
failure, a non-finite state or Ctrl-C keeps everything computed up to the last finished
segment; each segment is one ``scipy.integrate.solve_ivp`` call with the user's method,
tolerances and events. Quaternions are normalised where the pose is evaluated and in the
output.
"""

from __future__ import annotations

import json
import time as _time
from collections import deque
from dataclasses import dataclass, field, fields
from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import OdeSolution, OdeSolver, solve_ivp

from projeq.assembly import EVALUATORS
from projeq.checks import count, finite_array, positive, state_vector
from projeq.simulation.integrators import EXPLICIT, PROJECTED, projected_solver, warn_if_stiff


INTEGRATORS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")  # the methods of solve_ivp


def _check_method(method) -> None:
    if isinstance(method, str) and (method in INTEGRATORS or method in PROJECTED):
        return
    if isinstance(method, type) and issubclass(method, OdeSolver):
        return
    raise ValueError(
        f"method: unknown integrator {method!r}; use one of {list(INTEGRATORS) + list(PROJECTED)} or an OdeSolver class"
    )


class SimulationError(RuntimeError):
    """The integration failed; ``.result`` holds the trajectory up to ``.result.t[-1]``."""

    def __init__(self, message: str, result: "Result"):
        super().__init__(message)
        self.result = result


@dataclass(frozen=True)
class Result:
    """A simulated trajectory: one row per output time.

    Attributes
    ----------
    t : (n,) times; q : (n, n_q) coordinates; s_dot : (n, n_s) minimal velocities
    kinetic, potential : (n,) energies (``energy`` is their sum)
    constraint_residual : (n, m) residuals of velocity constraints (m = 0 without any)
    nfev : right-hand-side evaluations; wall_time : seconds
    status : 0 finished, 1 stopped by a terminal event, -1 failed, 2 interrupted
    message : the integrator's message; t_events : times of each event
    names : subsystem names; sol : dense output ``sol(t) -> (q, s_dot)`` or None
    partitions : ((t_k, independent_k), ...) of a ConstrainedSystem, one per partition used
    (more than one if it re-pivoted): rows (and ``sol(t)``) with t_k < t ≤ t_k+1 hold the
    tree velocities independent_k in ``s_dot`` (:mod:`projeq.constraints.partitioned`); empty for other systems
    """

    t: NDArray
    q: NDArray
    s_dot: NDArray
    kinetic: NDArray
    potential: NDArray
    constraint_residual: NDArray
    nfev: int = 0
    wall_time: float = 0.0
    status: int = 0
    message: str = ""
    t_events: tuple = ()
    names: tuple = ()
    method: str = ""
    partitions: tuple = ()
    sol: object = field(default=None, repr=False, compare=False)
    system: object = field(default=None, repr=False, compare=False)  # in memory only, not saved

    @property
    def energy(self) -> NDArray:
        """Total mechanical energy kinetic + potential along the trajectory."""
        return self.kinetic + self.potential

    @property
    def energy_drift(self) -> float:
        """max |E(t) − E(t₀)| relative to the largest kinetic or potential energy of the run
        (a scale that stays meaningful when E(t₀) = 0)."""
        if len(self.t) == 0:
            return 0.0
        scale = max(np.abs(self.kinetic).max(), np.abs(self.potential).max(), 1e-300)
        return float(np.abs(self.energy - self.energy[0]).max() / scale)

    @property
    def success(self) -> bool:
        """True when the run reached its end or a terminal event."""
        return self.status in (0, 1)

    def save(self, path) -> None:
        """Write the arrays and metadata to an ``.npz`` file (readable by numpy alone)."""
        arrays = {f.name: getattr(self, f.name) for f in fields(self) if isinstance(getattr(self, f.name), np.ndarray)}
        meta = {
            "nfev": self.nfev, "wall_time": self.wall_time, "status": self.status,
            "message": self.message, "names": list(self.names), "method": self.method,
            "partitions": [[t, list(independent)] for t, independent in self.partitions],
        }
        events = {f"t_events_{i}": np.asarray(e) for i, e in enumerate(self.t_events)}
        np.savez(path, **arrays, **events, meta=json.dumps(meta))

    @classmethod
    def load(cls, path) -> "Result":
        """Read a Result written by :meth:`save` (without dense output)."""
        with np.load(path) as data:
            meta = json.loads(str(data["meta"]))
            n_events = sum(1 for k in data.files if k.startswith("t_events_"))
            arrays = {k: data[k] for k in data.files if k != "meta" and not k.startswith("t_events_")}
            t_events = tuple(data[f"t_events_{i}"] for i in range(n_events))
        meta["names"] = tuple(meta["names"])
        meta["partitions"] = tuple((t, tuple(independent)) for t, independent in meta.get("partitions", ()))
        return cls(**arrays, **meta, t_events=t_events)


def _event_wrapper(event, n_q):
    def wrapped(t, x):
        return event(t, x[:n_q], x[n_q:])

    for attr in ("terminal", "direction"):
        if hasattr(event, attr):
            setattr(wrapped, attr, getattr(event, attr))
    return wrapped


def simulate(
    system,
    t_end: float,
    q0=None,
    s_dot0=None,
    method="RK45",
    rtol: float = 1e-8,
    atol: float = 1e-10,
    events=None,
    *,
    t_start: float = 0.0,
    t_eval=None,
    n_points: int = 501,
    dense_output: bool = False,
    evaluator: str | object | None = None,
    n_segments: int = 20,
    progress=None,
    **options,
) -> Result:
    """Integrate the equations of motion of ``system`` from ``t_start`` to ``t_end``.

    Parameters
    ----------
    system : System
    t_end : float
        End time (s), > t_start.
    q0, s_dot0 : arrays, optional
        Initial coordinates and minimal velocities (default: the system's q0, ṡ0).
    method : str or scipy OdeSolver class
        Any method of ``scipy.integrate.solve_ivp`` (RK45, DOP853, Radau, BDF, LSODA, ...),
        or ``"RK45-projected"`` / ``"DOP853-projected"``: that method with each step projected
        onto the initial energy, so that a conservative scleronomic system's energy error
        stays at round-off over long runs (:mod:`projeq.simulation.integrators`; ValueError for a
        system whose energy is not conserved). An explicit method whose steps crawl at its
        stability limit (a stiff model) gets a :class:`projeq.simulation.integrators.StiffnessWarning`
        suggesting Radau or BDF.
    rtol, atol : float
        Tolerances passed to the integrator.
    events : callable or list of callables ``event(t, q, s_dot)``
        Zero crossings; ``terminal`` and ``direction`` attributes as in solve_ivp.
    t_eval : array, optional
        Output times (default ``n_points`` equally spaced).
    dense_output : bool
        Keep a continuous solution ``result.sol(t) -> (q, s_dot)``.
    evaluator : "recursive", "dense" or an object with ``accelerations(q, s_dot, t)``
        Right-hand side (default: recursive for trees, dense for coupled joints).
    progress : callable ``progress(t)``, optional
        Called after each segment with the time reached.
    **options
        Further options for the integrator (max_step, first_step, ...).

    Returns
    -------
    Result
        On failure of the integrator or a non-finite state, :class:`SimulationError` is
        raised with ``.result`` holding the trajectory computed so far and a message giving
        the time reached; Ctrl-C returns the partial trajectory with ``status = 2``. Bad
        arguments raise ``ValueError`` naming the argument before the run starts, and a
        model that cannot be evaluated at the initial state raises its own error there
        (:class:`projeq.SingularMassError`, a force law's ``ValueError``).
    """
    q0 = system.normalized(system.check_q("q0", system.q0 if q0 is None else q0))
    s_dot0 = state_vector("s_dot0", system.s_dot0 if s_dot0 is None else s_dot0, system.n_s)
    t_start = float(finite_array("t_start", t_start, ()))
    if not float(finite_array("t_end", t_end, ())) > t_start:
        raise ValueError(f"t_end: must be after t_start = {t_start}, got {t_end}")
    positive("rtol", rtol)
    positive("atol", atol)
    _check_method(method)
    t_eval = _output_times(t_start, float(t_end), t_eval, count("n_points", n_points, 2))
    n_segments = count("n_segments", n_segments)
    if progress is not None and not callable(progress):
        raise ValueError(f"progress: expected a callable progress(t), got {progress!r}")
    events = [] if events is None else (list(events) if isinstance(events, (list, tuple)) else [events])
    for i, e in enumerate(events):
        if not callable(e):
            raise ValueError(f"events[{i}]: expected a callable event(t, q, s_dot), got {e!r}")
    ev = _evaluator(system, evaluator)
    system.check_configuration(q0, t_start)  # a coordinate singularity (or a degenerate partition) by name
    ev.accelerations(q0, s_dot0, t_start)  # a singular model or a failing force law raises here, by name
    solver = projected_solver(method, system, q0, s_dot0, t_start) if method in PROJECTED else method
    n_q = system.n_q
    reached = [t_start]  # time of the latest right-hand side evaluation, for error messages

    def rhs(t, x):
        reached[0] = t
        q, s_dot = x[:n_q], x[n_q:]
        x_dot = np.concatenate((system.q_dot(q, s_dot, t), ev.accelerations(q, s_dot, t)))
        if not np.all(np.isfinite(x_dot)):
            raise FloatingPointError(f"non-finite state derivative at t = {t:.6g} (q = {q}, s_dot = {s_dot})")
        return x_dot

    wrapped_events = [_event_wrapper(e, n_q) for e in events] or None
    bounds = np.linspace(t_start, float(t_end), n_segments + 1)
    pieces, nfev, status, message = [], 0, 0, "The solver successfully reached the end of the integration interval."
    t_events = [[] for _ in events]
    cause = None  # the exception that stopped the run, if any
    stiff_warned = False  # one StiffnessWarning per run at most
    x = np.concatenate((q0, s_dot0))
    started = _time.perf_counter()
    try:
        segments = deque(zip(bounds[:-1], bounds[1:]))  # a re-partition splits one (below)
        while segments:
            a, b = segments.popleft()
            inside = t_eval[(t_eval > a) & (t_eval <= b)] if pieces else t_eval[(t_eval >= a) & (t_eval <= b)]
            sol = solve_ivp(
                rhs, (a, b), x, method=solver, t_eval=inside, rtol=rtol, atol=atol,
                events=_with_partition_event(wrapped_events, system, n_q), dense_output=True, **options,
            )
            nfev += sol.nfev
            sol.system = system  # the partition of a ConstrainedSystem its s_dot rows are in
            if pieces and not dense_output:  # the previous segment's interpolants are no longer needed
                pieces[-1].sol = SimpleNamespace(ts=pieces[-1].sol.ts[[0, -1]])
            pieces.append(sol)
            for collected, te in zip(t_events, sol.t_events or []):
                collected.extend(te)
            if sol.status == 1 and len(sol.t_events) > len(events) and len(sol.t_events[-1]):
                # a ConstrainedSystem's partition degenerates: go on in a new one (or its ValueError)
                x, a = sol.y_events[-1][0], sol.t_events[-1][0]
                system, s_dot = system.repartitioned(x[:n_q], x[n_q:], a)
                x, ev = np.concatenate((x[:n_q], s_dot)), _evaluator(system, evaluator)
                if method in PROJECTED:  # the same energy, now in the new partition's s_dot
                    solver = projected_solver(method, system, x[:n_q], s_dot, a)
                if a < b:
                    segments.appendleft((a, b))
                continue
            if sol.status != 0:
                status, message = sol.status, sol.message
                break
            x = sol.sol(b).copy()  # the state at the segment's end, not at its last output time
            stiff_warned = stiff_warned or warn_if_stiff(rhs, sol, method, rtol)
            x[:n_q] = system.normalized(x[:n_q])
            if progress is not None:
                progress(b)
    except KeyboardInterrupt:
        status, message = 2, "interrupted (Ctrl-C): the trajectory up to the last finished segment is kept"
    except (FloatingPointError, ValueError, np.linalg.LinAlgError) as exc:
        status, message, cause = -1, str(exc), exc
    except Exception as exc:  # noqa: BLE001 - a user's force law or event failed: keep the trajectory
        status, message, cause = -1, f"{type(exc).__name__}: {exc}", exc
    result = _assemble(system, pieces, nfev, status, message, t_events, _time.perf_counter() - started, method, dense_output)
    if status == -1:
        kept = result.t[-1] if len(result.t) else t_start
        hint = ""
        if method in EXPLICIT and "step size" in message:
            hint = (
                "; the solution may blow up here, or the system is stiff for an explicit method "
                "(a very stiff beam): then try method='Radau' or 'BDF'"
            )
        raise SimulationError(
            f"integration failed at t = {reached[0]:.6g} s (t_end = {t_end}): {message}{hint}; "
            f"the trajectory up to t = {kept:.6g} s is in .result",
            result,
        ) from cause
    return result


def _with_partition_event(wrapped_events, system, n_q):
    """The user's events plus, last, a ConstrainedSystem's partition event (κ reaches its limit)."""
    partition_event = getattr(system, "partition_event", lambda: None)()
    if partition_event is None:
        return wrapped_events
    return (wrapped_events or []) + [_event_wrapper(partition_event, n_q)]


def _evaluator(system, evaluator):
    """The right-hand side's evaluator: a user object, or the system's cached one by name."""
    if hasattr(evaluator, "accelerations"):
        return evaluator
    if evaluator is None or (isinstance(evaluator, str) and evaluator in EVALUATORS):
        return system.evaluator(evaluator)
    raise ValueError(
        f"evaluator: unknown evaluator {evaluator!r}; use one of {sorted(EVALUATORS)} "
        "or an object with accelerations(q, s_dot, t)"
    )


def _output_times(t_start, t_end, t_eval, n_points) -> NDArray:
    if t_eval is None:
        return np.linspace(t_start, t_end, n_points)
    t_eval = finite_array("t_eval", t_eval)
    if t_eval.ndim != 1 or np.any(np.diff(t_eval) <= 0) or t_eval[0] < t_start or t_eval[-1] > t_end:
        raise ValueError(f"t_eval: must increase strictly within [{t_start}, {t_end}]")
    return t_eval


def _assemble(system, pieces, nfev, status, message, t_events, wall_time, method, dense_output) -> Result:
    """One Result from the segments' solutions: normalised q, energies along the path."""
    n_q = system.n_q
    if pieces:
        t = np.concatenate([p.t for p in pieces])
        n_x = n_q + system.n_s  # a segment without output times has y = []
        x = np.concatenate([np.reshape(p.y, (n_x, len(p.t))) for p in pieces], axis=1).T
    else:
        t, x = np.zeros(0), np.zeros((0, n_q + system.n_s))
    q = np.array([system.normalized(row) for row in x[:, :n_q]]).reshape(len(t), n_q)
    s_dot = x[:, n_q:]
    rows = [(p.system, ti) for p in pieces for ti in p.t]  # each row in its piece's partition
    energies = np.array([s.energy(qi, si, ti) for (s, ti), qi, si in zip(rows, q, s_dot)]).reshape(len(t), 2)
    residual = np.array(
        [s.constraint_residual(qi, s.q_dot(qi, si, ti), ti) for (s, ti), qi, si in zip(rows, q, s_dot)]
    ).reshape(len(t), system.n_c)
    partitions = tuple(
        (float(p.sol.ts[0]), tuple(p.system.independent.tolist())) for i, p in enumerate(pieces)
        if hasattr(p.system, "independent") and (i == 0 or p.system is not pieces[i - 1].system)
    )
    system = pieces[0].system if pieces else system  # the user's, before any re-partition
    sol = _dense_solution(pieces, n_q) if dense_output and pieces else None
    return Result(
        t=t, q=q, s_dot=s_dot, kinetic=energies[:, 0], potential=energies[:, 1],
        constraint_residual=residual, nfev=int(nfev), wall_time=wall_time,
        status=int(status), message=str(message), t_events=tuple(np.array(e) for e in t_events),
        names=system.names, method=getattr(method, "__name__", str(method)), partitions=partitions,
        sol=sol, system=system,
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
