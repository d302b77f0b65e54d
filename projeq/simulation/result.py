"""The outcome of :func:`projeq.simulate`: a :class:`Result` (one row per output time), or a
:class:`SimulationError` that carries the Result computed up to the failure."""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

_EVENT_ARRAYS = ("t_events", "q_events", "s_dot_events")  # tuples of arrays, one per event

FINISHED, STOPPED, FAILED, INTERRUPTED, OUT_OF_RANGE, NON_FINITE = 0, 1, -1, 2, 3, 4
#: Result.status → what it means (the ``status`` of ``projeq run``'s run.json)
STATUSES = {FINISHED: "finished", STOPPED: "stopped by an event", FAILED: "failed", INTERRUPTED: "interrupted",
            OUT_OF_RANGE: "out of range", NON_FINITE: "non-finite state"}


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
    njev : Jacobians of an implicit method, each n_q + n_s evaluations
        by the complex step through solve_ivp (complex ones), by forward differences in the compiled
        loop's Radau (counted in nfev)
    status : 0 finished, 1 stopped by an event, -1 failed, 2 interrupted, 3 out of range, 4 non-finite
    (:data:`STATUSES`; 3: stopped where a subsystem left the range its model describes, 4: the solution blew up)
    message : the integrator's message
    t_events, q_events, s_dot_events : for each of the user's events, the times where it
    fired and the states (k, n_q) and (k, n_s) there. A terminal event's state is also the
    last row: the output ends at the event, not at the last output time before it.
    names : subsystem names; sol : dense output ``sol(t) -> (q, s_dot)`` or None
    coordinates, velocities : (name, unit) of each column of q and of s_dot
    (:meth:`projeq.system.Model.coordinates`, e.g. ``("elbow.angle", "rad")``); a run that
    changed its partition has velocities ``("s_dot[i]", "")`` (see ``partitions``)
    metadata : what the caller records with the run (the command line: scene, parameters,
    tolerances, method, evaluator, projeq version), saved with it
    partitions : ((t_k, independent_k, formulation_k), ...) of a ConstrainedSystem, one per
    partition used (more than one if it re-pivoted, or went on in the null-space form from a
    singular position: formulation_k "partitioned" or "null space"): rows (and ``sol(t)``)
    with t_k < t ≤ t_k+1 hold the tree velocities independent_k in ``s_dot``
    (:mod:`projeq.constraints.partitioned`); empty for other systems
    rank, mobility : (n,) integers, for a model with constraint equations (a ConstrainedSystem,
    TangentSystem, ...): the numerical rank of its constraint matrix A_s at each output time
    (singular values above RANK_TOLERANCE times the largest,
    :meth:`projeq.constraints.partitioned.ConstrainedSystem.rank`) and the degrees of freedom
    there, n_s,tree − rank (:meth:`~projeq.constraints.partitioned.ConstrainedSystem.mobility`):
    a redundant row keeps the rank below the rows' count all along, a singular position drops it
    where the run passes; empty for other models and in files saved before they were recorded
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
    q_events: tuple = ()
    s_dot_events: tuple = ()
    names: tuple = ()
    method: str = ""
    partitions: tuple = ()
    coordinates: tuple = ()
    velocities: tuple = ()
    metadata: dict = field(default_factory=dict)
    njev: int = 0
    rank: NDArray = field(default_factory=lambda: np.zeros(0, dtype=int))
    mobility: NDArray = field(default_factory=lambda: np.zeros(0, dtype=int))
    sol: object = field(default=None, repr=False, compare=False)
    system: object = field(default=None, repr=False, compare=False)  # in memory only, not saved

    @property
    def energy(self) -> NDArray:
        """Total mechanical energy kinetic + potential along the trajectory."""
        return self.kinetic + self.potential

    @property
    def energy_drift(self) -> float:
        """max |E(t) − E(t₀)| relative to the largest kinetic or potential energy of the run
        (a scale that stays meaningful when E(t₀) = 0); NaN for a run without output rows (one
        stopped in its first segment), which conserved nothing: a check ``drift < tol`` fails."""
        if len(self.t) == 0:
            return float("nan")
        scale = max(np.abs(self.kinetic).max(), np.abs(self.potential).max(), 1e-300)
        return float(np.abs(self.energy - self.energy[0]).max() / scale)

    def column_names(self, units: bool = False) -> tuple[list[str], list[str]]:
        """(names of q's columns, names of ṡ's columns), ``"elbow.angle"`` or with
        ``units`` ``"elbow.angle (rad)"``; ``q[i]``, ``s_dot[i]`` where none are known."""
        def label(named, i, default):
            name, unit = named[i] if i < len(named) else (default, "")
            return f"{name} ({unit})" if units and unit else name

        return ([label(self.coordinates, i, f"q[{i}]") for i in range(self.q.shape[1])],
                [label(self.velocities, i, f"s_dot[{i}]") for i in range(self.s_dot.shape[1])])

    @property
    def success(self) -> bool:
        """True when the run reached its end or a terminal event."""
        return self.status in (0, 1)

    def animate(self, path, system=None, stations: int = 21, **options):
        """Write the motion to ``path``: ``.html`` a self-contained page that plays it in a browser,
        offline (three.js inlined; bodies as solids of their inertia, beams as deformed tubes, joint
        frames, time slider, play/pause, speed), ``.gif`` or ``.mp4`` a movie
        (:func:`projeq.simulation.animation.animate`). ``system``: the model, default the Result's
        own or the scene its run record names. Returns the path."""
        from projeq.simulation.animation import animate

        return animate(self, path, system, stations, **options)

    def save(self, path) -> None:
        """Write the arrays and metadata to an ``.npz`` file (readable by numpy alone; ``.npz``
        is appended to a name without it, as numpy does), under a temporary name renamed when
        complete: a full disk or a killed process never leaves a truncated file. A Result that
        :meth:`load` would refuse (arrays of the wrong shapes, t not increasing, an unknown
        status) is a ValueError naming the field, and nothing is written."""
        arrays = {f.name: getattr(self, f.name) for f in fields(self) if isinstance(getattr(self, f.name), np.ndarray)}
        meta = {
            "nfev": self.nfev, "njev": self.njev, "wall_time": self.wall_time, "status": self.status,
            "message": self.message, "names": list(self.names), "method": self.method,
            "partitions": [[t, list(independent), formulation] for t, independent, formulation in self.partitions],
            "coordinates": [list(c) for c in self.coordinates], "velocities": [list(v) for v in self.velocities],
            "metadata": self.metadata,
        }
        events = {f"{name}_{i}": np.asarray(e) for name in _EVENT_ARRAYS for i, e in enumerate(getattr(self, name))}
        _check_fields(arrays, meta, {name: tuple(map(np.asarray, getattr(self, name))) for name in _EVENT_ARRAYS},
                      f"Result.save({str(getattr(path, 'name', path) if hasattr(path, 'write') else path)!r})")
        if hasattr(path, "write"):  # an open file
            np.savez(path, **arrays, **events, meta=json.dumps(meta))
            return
        from projeq.simulation.export import written_atomically

        path = Path(path)
        with written_atomically(path if path.suffix == ".npz" else path.with_name(path.name + ".npz")) as temporary:
            np.savez(temporary, **arrays, **events, meta=json.dumps(meta))

    @classmethod
    def load(cls, path) -> "Result":
        """Read a Result written by :meth:`save` (without dense output). ValueError saying what
        the file is and what is wrong when it is not one: not an .npz archive (random or
        truncated bytes), an archive without a Result's arrays, metadata without a field of
        the Result or with an unknown one, arrays whose shapes do not match t and the coordinate
        names (one row per output time, one column per coordinate), t not increasing, a status
        not in :data:`STATUSES`.
        A name without ``.npz`` is read as :meth:`save` wrote it, with the suffix appended."""
        if isinstance(path, (str, Path)) and Path(path).suffix != ".npz" and not Path(path).exists():
            path = Path(path).with_name(Path(path).name + ".npz")  # save's name for it
        try:
            with np.load(path, allow_pickle=False) as data:
                meta, events, arrays = _read(data, path)
        except (EOFError, zipfile.BadZipFile) as exc:
            raise ValueError(f"path: {str(path)!r} is a truncated or damaged archive, not a readable projeq "
                             f"Result (.npz written by Result.save): {exc}") from exc
        except ValueError as exc:  # numpy's words for bytes that are no .npy/.npz, or the checks of _read
            raise ValueError(f"path: {str(path)!r} is not a projeq Result (.npz written by Result.save): {exc}") from exc
        _check_fields(arrays, meta, events, f"path: {str(path)!r}")
        meta["names"] = tuple(meta["names"])
        meta["partitions"] = tuple((entry[0], tuple(entry[1]), entry[2] if len(entry) > 2 else "partitioned")
                                   for entry in meta.get("partitions", ()))  # files before the null-space form: 2
        for key in ("coordinates", "velocities"):  # absent from files of earlier versions
            meta[key] = tuple(tuple(pair) for pair in meta.get(key, ()))
        return cls(**arrays, **meta, **events)


def _read(data, path) -> tuple[dict, dict, dict]:
    """meta, events and arrays of an open archive; ValueError for a file that is not one."""
    if not hasattr(data, "files"):
        raise ValueError(f"it holds a single array of shape {data.shape}, not an .npz archive")
    missing = [name for name in ("meta", *_ROWS) if name not in data.files]
    if missing:
        raise ValueError(f"the archive lacks {missing} (it holds {sorted(data.files)[:10]})")
    try:
        meta = json.loads(str(data["meta"]))
    except json.JSONDecodeError as exc:
        raise ValueError(f"its metadata is not the JSON Result.save writes: {exc}") from exc
    events = {name: _numbered(data, name) for name in _EVENT_ARRAYS}
    arrays = {k: data[k] for k in data.files if k != "meta" and not k.startswith(_EVENT_ARRAYS)}
    return meta, events, arrays


_ROWS = ("t", "q", "s_dot", "kinetic", "potential", "constraint_residual")  # one row per output time
_META = {"nfev", "njev", "wall_time", "status", "message", "names", "method", "partitions", "coordinates",
         "velocities", "metadata"}  # what save writes besides the arrays
_META_OPTIONAL = {"njev", "partitions", "coordinates", "velocities", "metadata"}  # absent from earlier versions


def _check_fields(arrays: dict, meta: dict, events: dict, where: str) -> None:
    """ValueError beginning with ``where`` (the file, or Result.save) and naming the field, unless
    the Result's fields fit together: the metadata's fields, each array one row per entry of t
    (rank and mobility: or none), q and s_dot one column per coordinate and velocity name where
    these are given, t increasing and finite, the status one of :data:`STATUSES`, and each event's
    times and states alike."""
    def refuse(field_name: str, problem: str):
        raise ValueError(f"{where}: field {field_name!r} {problem}; the file was not written by Result.save or "
                         "was altered" if where.startswith("path") else f"{where}: field {field_name!r} {problem}")

    if not isinstance(meta, dict):
        refuse("meta", f"is {type(meta).__name__}, not the dict of fields Result.save writes")
    for name in sorted(_META - _META_OPTIONAL - set(meta)):
        refuse(name, "is missing from the metadata")
    for name in sorted(set(meta) - _META):
        refuse(name, f"is not a field of a Result (they are {sorted(_META)})")
    if meta["status"] not in STATUSES or isinstance(meta["status"], bool):
        refuse("status", f"is {meta['status']!r}, not one of {STATUSES}")
    unknown = sorted(set(arrays) - set(_ROWS) - {"rank", "mobility"})
    if unknown:
        refuse(unknown[0], "is not an array of a Result")
    t = arrays["t"]
    if t.ndim != 1 or not np.issubdtype(t.dtype, np.number) or not np.isfinite(t).all():
        refuse("t", f"must be one finite time per output row, got shape {t.shape} ({t.dtype})")
    if np.any(np.diff(t) < 0):
        k = int(np.argmax(np.diff(t) < 0)) + 1
        refuse("t", f"runs backwards at row {k} ({t[k - 1]:.6g} s, then {t[k]:.6g} s); output times increase")
    if not isinstance(meta["names"], (list, tuple)) or not all(isinstance(n, str) for n in meta["names"]):
        refuse("names", f"must be the subsystems' names (strings), got {meta['names']!r}")
    columns = {"q": len(meta.get("coordinates") or ()) or None,  # None: any number of columns (older files)
               "s_dot": len(meta.get("velocities") or ()) or None}
    for name in _ROWS[1:] + ("rank", "mobility"):
        a = arrays.get(name, np.zeros(0))
        if name in ("rank", "mobility") and a.shape == (0,):  # a model without constraint equations
            continue
        expected = (len(t), columns.get(name)) if name in ("q", "s_dot", "constraint_residual") else (len(t),)
        if a.ndim != len(expected) or any(e is not None and n != e for n, e in zip(a.shape, expected)):
            shown = "(" + ", ".join("m" if e is None else str(e) for e in expected) + "," * (len(expected) == 1)
            shown += ")"
            per_name = {"q": ", one column per coordinate name", "s_dot": ", one column per velocity name"}
            refuse(name, f"has shape {a.shape} where t has {len(t)} rows: expected {shown}"
                         + (per_name[name] if columns.get(name) else ""))
    n_q, n_s = arrays["q"].shape[1], arrays["s_dot"].shape[1]
    counts = {len(events.get(name, ())) for name in _EVENT_ARRAYS}
    if len(counts) > 1:
        refuse("t_events", f"has {len(events.get('t_events', ()))} events but q_events and s_dot_events "
                           f"{len(events.get('q_events', ()))} and {len(events.get('s_dot_events', ()))}")
    for i, (te, qe, se) in enumerate(zip(*(events.get(name, ()) for name in _EVENT_ARRAYS))):
        if te.ndim != 1 or qe.shape != (len(te), n_q) or se.shape != (len(te), n_s):
            refuse(f"t_events_{i}", f"has shape {te.shape}, q_events_{i} {qe.shape} and s_dot_events_{i} {se.shape}: "
                                    f"expected ({len(te)},), ({len(te)}, {n_q}) and ({len(te)}, {n_s})")


def _numbered(data, name: str) -> tuple:
    """(data[name_0], data[name_1], ...) as far as they exist in the file."""
    arrays, i = [], 0
    while f"{name}_{i}" in data.files:
        arrays.append(data[f"{name}_{i}"])
        i += 1
    return tuple(arrays)
