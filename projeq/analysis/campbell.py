"""Modal data at a state and Campbell diagrams of rotating systems.

:func:`modes` turns the linearisation δẋ = A δx of :func:`projeq.analysis.linearize.linearize`
into modes: each complex pair λ, λ̄ of eigenvalues of A with Im λ > 0 is one mode of frequency
ω = Im λ (rad/s, in the frame of the model's coordinates), damping ratio ζ = −Re λ/|λ| and
shape φ, the coordinate part of λ's eigenvector.

:func:`campbell` repeats this over rotation speeds Ω and follows each mode from speed to
speed by its shape: the modal assurance criterion MAC(φ_a, φ_b) = |φ_aᴴ φ_b|² /
((φ_aᴴ φ_a)(φ_bᴴ φ_b)) (Allemang & Brown (1982), "A correlation coefficient for modal vector
analysis", Proc. 1st IMAC) between neighbouring speeds, the branches' frequencies
extrapolated linearly as a tie-breaker (degenerate pairs, whose shapes are any
combination). Where modes veer (approach and exchange shapes) a branch keeps its shape,
not its rank in frequency. A mode whose frequency passes through zero (a backward whirl in
the co-rotating frame, |ω_k − Ω|) continues as the conjugate pair: its frequency is signed
while tracking and reported as |ω|.

Branches of a system with one :class:`projeq.RitzBeam` are labelled by the beam's tip
motion at the lowest nonzero speed, relative to the beam frame's angular velocity ω_b:

- ω_b across the beam's axis x (a blade on a hub): *flapwise* if the tip moves mostly along
  ω_b, *lead-lag* if in the plane of rotation (along ω_b × e_x);
- ω_b along x (a shaft spinning about its own axis): *forward* or *backward whirl* by the
  sense of the whirl in the inertial frame: the tip's orbit turns at w = σ ω about ω_b in the
  co-rotating frame (σ = sign Im(e·(d × d̄)), d the tip's complex displacement, e = ω_b/|ω_b|)
  and at w + |ω_b| in the inertial frame: forward if that is positive;
- *axial* or *torsion* where those coordinates dominate the shape; numbered by frequency
  within each kind. Other systems: ``mode 1, 2, …`` by frequency at the first speed.

A whirl seen from the inertial (stationary) frame turns at |w + Ω_b| (Ω_b = ω_b·e the spin, e
the beam's axis at the labelling speed): the co-rotating whirl w = σ Im λ signed along the
branch (through zero), so a forward whirl is seen at ω_k and a backward one at ω_k again where
the co-rotating frame shows |ω_k ∓ Ω| (a shaft without rotary inertia: G. Genta, *Dynamics of
Rotating Systems*, Springer, New York, 2005, on the fixed and the rotating frame).
:attr:`CampbellDiagram.stationary` holds these, NaN for branches that are no whirl.

Critical speeds are where a branch's frequency equals an engine order k Ω (k = 1, 2, …: an
excitation k times per revolution; k = 0: a frequency through zero), bracketed by neighbouring speeds of the sweep and found
by Brent's method on the branch (or by linear interpolation, ``refine=False``).
"""

from __future__ import annotations

import csv
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.linearize import linearize
from projeq.checks import callable_name, finite_array
from projeq.system import Model, check_model

_OSCILLATING = 1e-9  # Im λ above this fraction of max |λ|: a mode (below: real eigenvalues)


class Modes(NamedTuple):
    """Modal data at one state (:func:`modes`), modes ordered by frequency.

    Attributes
    ----------
    frequencies : ndarray (n_modes,)
        ω = Im λ in rad/s (damped natural frequencies, in the frame of the coordinates).
    damping : ndarray (n_modes,)
        Damping ratios ζ = −Re λ / |λ| (negative: the mode grows).
    eigenvalues : ndarray (n_modes,), complex
        λ with Im λ > 0, one of each conjugate pair.
    shapes : ndarray (n_coordinates, n_modes), complex
        Column k: the coordinate part of λ_k's eigenvector, scaled so that its largest
        entry is 1.
    coordinates : tuple of str
        The rows of ``shapes`` (the linearisation's kept coordinates, ``"beam.q[3]"``).
    real_eigenvalues : ndarray
        The eigenvalues that are not oscillatory (rigid-body motion, divergence, overdamped
        motion): no modes here.
    """

    frequencies: NDArray
    damping: NDArray
    eigenvalues: NDArray
    shapes: NDArray
    coordinates: tuple
    real_eigenvalues: NDArray


def modes(system, q=None, s_dot=None, t: float = 0.0, **options) -> Modes:
    """Frequencies, damping ratios and mode shapes of ``system`` linearised about (q, ṡ) at t.

    Parameters
    ----------
    system : System or ConstrainedSystem
    q, s_dot : arrays, optional
        An equilibrium or steady motion (default: the system's q0, ṡ0).
    t : float
        Time (for a prescribed rotation).
    **options
        Passed to :func:`projeq.linearize` (``ignore``, ``tol``, ``derivatives``).

    Returns
    -------
    Modes

    Examples
    --------
    >>> import projeq as pq
    >>> from projeq.analysis.campbell import modes
    >>> round(float(modes(pq.scenes.rotating_blade(omega=0.0)).frequencies[0]), 4)  # 1.8751², Blevins
    3.516
    """
    lin = linearize(system, q, s_dot, t, **options)
    lam, vectors = np.linalg.eig(lin.A)
    names = system.state_names()[: system.n_q]
    rows = [i for i, state in enumerate(lin.states) if state in names]
    oscillating = lam.imag > _OSCILLATING * max(1.0, np.abs(lam).max(initial=0.0))
    paired = np.abs(lam.imag) > _OSCILLATING * max(1.0, np.abs(lam).max(initial=0.0))
    order = np.flatnonzero(oscillating)[np.argsort(lam.imag[oscillating])]
    shapes = vectors[np.ix_(rows, order)]
    largest = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(len(order))]
    return Modes(lam.imag[order], -lam.real[order] / np.abs(lam[order]), lam[order], shapes / largest,
                 tuple(lin.states[i] for i in rows), np.sort_complex(lam[~paired]))


def mac(a: NDArray, b: NDArray) -> NDArray:
    """MAC(a_i, b_j) = |a_iᴴ b_j|² / ((a_iᴴ a_i)(b_jᴴ b_j)) of the columns of a and b: 1 for
    the same shape, 0 for orthogonal ones."""
    cross = np.abs(a.conj().T @ b) ** 2
    return cross / np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))


class CriticalSpeed(NamedTuple):
    """A branch crossing an engine order: ω(Ω) = k Ω at ``speed`` Ω (rad/s)."""

    mode: str
    order: int
    speed: float
    frequency: float


class CampbellDiagram:
    """Frequencies and damping of tracked modes against rotation speed (:func:`campbell`).

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        Ω in rad/s.
    frequencies, damping : ndarray (n_speeds, n_branches)
        ω in rad/s and ζ of each branch (column) at each speed.
    eigenvalues : ndarray (n_speeds, n_branches), complex
        λ of each branch (Im λ > 0).
    labels : tuple of str
        Each branch's name (``"flapwise 1"``, ``"forward whirl 2"``, ``"mode 3"``); the
        columns in the order of the frequencies at the lowest nonzero speed.
    orders : tuple of int
        The engine orders k of :attr:`critical_speeds`.
    critical_speeds : list of CriticalSpeed
        Where a branch crosses k Ω, by speed (in the frame of the coordinates).
    stationary : ndarray (n_speeds, n_branches)
        Each whirl branch's frequency seen from the inertial frame, |w + Ω_b| in rad/s (module
        docstring); NaN in the columns of branches that are no whirl.
    """

    def __init__(self, speeds, frequencies, damping, eigenvalues, labels, orders, critical, stationary=None):
        self.speeds, self.frequencies, self.damping, self.eigenvalues = speeds, frequencies, damping, eigenvalues
        self.labels, self.orders, self.critical_speeds = tuple(labels), tuple(orders), list(critical)
        self.stationary = np.full_like(frequencies, np.nan) if stationary is None else stationary

    def branch(self, label: str, frame: str = "rotating") -> NDArray:
        """The frequencies (rad/s) of the branch ``label`` at every speed, in the frame of the
        coordinates (``frame="rotating"``) or, for a whirl, the inertial one (``"stationary"``)."""
        if label not in self.labels:
            raise ValueError(f"label: no branch {label!r}; the branches are {', '.join(self.labels)}")
        column = self.labels.index(label)
        if _frame(frame) == "rotating":
            return self.frequencies[:, column]
        if np.isnan(self.stationary[:, column]).all():
            raise ValueError(f"label: {label!r} is no whirl; only a whirl (forward/backward) has a "
                             "stationary frequency")
        return self.stationary[:, column]

    def write_csv(self, path) -> None:
        """One row per speed: Ω, then each branch's frequency (rad/s) and damping ratio, and a
        whirl's frequency seen from the inertial frame (``stationary frequency (rad/s)``)."""
        whirls = [int(not np.isnan(column).all()) for column in self.stationary.T]
        kinds = ("frequency (rad/s)", "damping ratio")
        header = [f"{label} {kind}" for label, whirl in zip(self.labels, whirls)
                  for kind in kinds + ("stationary frequency (rad/s)",) * whirl]
        with open(path, "w", newline="", encoding="utf-8") as stream:
            writer = csv.writer(stream)
            writer.writerow(["speed (rad/s)"] + header)
            for k, speed in enumerate(self.speeds):
                row = [repr(float(speed))]
                for j in range(len(self.labels)):
                    row += [repr(float(x)) for x in (self.frequencies[k, j], self.damping[k, j])]
                    row += [repr(float(self.stationary[k, j]))] * whirls[j]
                writer.writerow(row)

    def write_critical_speeds(self, path) -> None:
        """The critical speeds as CSV: mode, engine order, speed (rad/s), frequency (rad/s)."""
        with open(path, "w", newline="", encoding="utf-8") as stream:
            writer = csv.writer(stream)
            writer.writerow(["mode", "engine order", "speed (rad/s)", "frequency (rad/s)"])
            for c in self.critical_speeds:
                writer.writerow([c.mode, c.order, repr(c.speed), repr(c.frequency)])

    def plot(self, frame: str = "rotating"):
        """The Campbell diagram as a :class:`matplotlib.figure.Figure` (not shown; save it with
        ``fig.savefig(path)``): each branch's frequency against Ω, the engine orders k Ω dashed,
        the critical speeds marked; ``frame="stationary"``: the whirls seen from the inertial
        frame (no critical speeds: they are the co-rotating frame's)."""
        from matplotlib.figure import Figure  # no pyplot: no GUI backend, no global state

        stationary = _frame(frame) == "stationary"
        shown = self.stationary if stationary else self.frequencies
        fig = Figure(figsize=(8.0, 5.0), layout="constrained")
        ax = fig.subplots()
        for label, column in zip(self.labels, shown.T):
            if not np.isnan(column).all():
                ax.plot(self.speeds, column, marker=".", markersize=3, label=label)
        top = 1.05 * np.nanmax(shown, initial=0.0)
        for k in self.orders:
            ax.plot(self.speeds, k * np.abs(self.speeds), color="0.6", linestyle="--", linewidth=0.8)
            end = min(abs(self.speeds[-1]), top / k)
            ax.annotate(f"{k}Ω", (end, k * end), fontsize="small", color="0.4", xytext=(2, 0),
                        textcoords="offset points")
        if self.critical_speeds and not stationary:
            ax.plot([c.speed for c in self.critical_speeds], [c.frequency for c in self.critical_speeds], "o",
                    color="k", markerfacecolor="none", label="critical speeds")
        ax.set_ylim(0.0, top)
        ax.set_xlabel("rotation speed Ω (rad/s)")
        ax.set_ylabel("frequency ω (rad/s)" + (", seen from the inertial frame" if stationary else ""))
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        return fig

    def table(self) -> str:
        """The diagram as text: one row per speed, one column per branch (rad/s)."""
        header = f"{'speed':>10} " + " ".join(f"{label:>18}" for label in self.labels)
        rows = [f"{s:10.4g} " + " ".join(f"{f:18.6g}" for f in row) for s, row in zip(self.speeds, self.frequencies)]
        return "\n".join([header] + rows)


def campbell(system, speeds, joint: str | None = None, orders=(1, 2, 3), n_modes: int | None = None,
             refine: bool = True, t: float = 0.0, **options) -> CampbellDiagram:
    """The Campbell diagram: frequencies and damping of the modes against rotation speed Ω,
    each mode tracked by its shape (module docstring), labelled, with its critical speeds.

    Parameters
    ----------
    system : callable or System
        ``build(speed)`` returning the System (or ConstrainedSystem) turning at Ω = ``speed``,
        linearised about its q0, ṡ0 (e.g. ``lambda omega: scenes.rotating_blade(omega=omega)``),
        or a tuple ``(system, q, s_dot)``; or a System whose one-dof ``joint`` turns at the
        speed (ṡ of the joint = Ω, the rest of the state q0, ṡ0: a steady motion of a free hub).
    speeds : sequence of float
        Ω in rad/s, increasing.
    joint : str, optional
        With a System: the joint whose velocity is the speed.
    orders : sequence of int
        Engine orders k ≥ 0 whose lines k Ω give the critical speeds. In the co-rotating frame
        of the scenes a load fixed in space (a blade passing k obstacles, gravity on a shaft)
        has the frequency k Ω; a load fixed in the rotor (an unbalance) the frequency 0:
        k = 0 finds where a frequency passes through zero (the forward whirl's critical speed
        of a shaft: its whirl in the inertial frame turns at Ω).
    n_modes : int, optional
        Keep the lowest ``n_modes`` branches (by frequency at the first speed); default all.
        All modes are tracked either way.
    refine : bool
        Find each critical speed by Brent's method on the branch (a linearisation per step,
        the branch followed by its shape; to 1e-12 relative), not by linear interpolation
        between the speeds of the sweep (error O(ΔΩ²)).
    t : float
        Time of the linearisation (a prescribed rotation is steady: any t).
    **options
        Passed to :func:`projeq.linearize`.

    Returns
    -------
    CampbellDiagram

    Raises
    ------
    ValueError
        Bad speeds, orders, n_modes or joint; or a number of oscillatory modes that changes
        along the sweep (a mode stops oscillating: a divergence, or a frequency through zero
        exactly at a speed of the sweep), naming the speed.
    """
    speeds = _speeds(speeds)
    orders = _orders(orders)
    build = _builder(system, joint)
    found = []
    for speed in speeds:
        model, q, s_dot = build(speed)
        found.append((model, q, s_dot, modes(model, q, s_dot, t, **options)))
        if len(found) == 1:  # its ignorable coordinates dropped at every speed (where K − Ω² M is
            kept = found[0][3].coordinates  # singular an elastic coordinate's column of A vanishes too)
            options.setdefault("ignore", [c for c in model.state_names()[: model.n_q] if c not in kept])
    counts = [len(m.frequencies) for *_, m in found]
    if len(set(counts)) > 1:
        k = next(i for i, c in enumerate(counts) if c != counts[0])
        raise ValueError(f"speeds: {counts[0]} oscillatory modes at Ω = {speeds[0]:g} but {counts[k]} at "
                         f"Ω = {speeds[k]:g} (a mode stops oscillating: a divergence, or a frequency through "
                         f"zero at that speed); sweep the speeds on either side of it")
    lam, shapes = track([m for *_, m in found], speeds)
    keep = np.arange(lam.shape[1]) if n_modes is None else np.argsort(np.abs(lam[0].imag))[: _count(n_modes, lam)]
    lam = lam[:, keep]
    reference = _labelling_speed(speeds)
    model, q, s_dot, _ = found[reference]
    labels, senses = branch_labels(model, q, s_dot, t, lam[reference], shapes[reference][:, keep],
                                   found[reference][3].coordinates)
    by_frequency = np.argsort(np.abs(lam[reference].imag), kind="stable")  # the order of the labels' numbers
    lam, labels, senses = lam[:, by_frequency], [labels[j] for j in by_frequency], senses[by_frequency]
    shapes = shapes[:, :, keep][:, :, by_frequency]

    def branch_at(j: int, i: int, speed: float) -> float:
        """Branch j's signed frequency at ``speed`` in (speeds[i], speeds[i + 1]): the mode there
        that continues it best from speeds[i] (:func:`track`'s costs)."""
        model, q, s_dot = build(speed)
        found_here = modes(model, q, s_dot, t, **options)
        predicted = np.interp(speed, speeds[i: i + 2], lam[i: i + 2, j].imag)
        direct, conjugate = _costs(shapes[i][:, [j]], np.array([predicted]), found_here)
        best = np.minimum(direct, conjugate)[0].argmin()
        return float(found_here.frequencies[best] * (-1.0 if conjugate[0, best] < direct[0, best] else 1.0))

    frequencies = np.abs(lam.imag)
    critical = critical_speeds(speeds, lam.imag, labels, orders, branch_at if refine else None)
    return CampbellDiagram(speeds, frequencies, -lam.real / np.abs(lam), lam, labels, orders, critical,
                           _stationary(found, lam.imag, senses, reference, t))


def track(found: list, speeds: NDArray) -> tuple[NDArray, NDArray]:
    """Branches through the :class:`Modes` found at each speed: (λ (n_speeds, n), shapes
    (n_speeds, n_coordinates, n)) with column j one branch, in the order of the first speed.

    At each speed the modes are assigned to the branches by the least total cost (Hungarian
    algorithm, :func:`scipy.optimize.linear_sum_assignment`) of 1 − MAC plus the distance of
    the frequency from the branch's linear extrapolation, over the diagram's largest frequency;
    a mode may also continue a branch as its conjugate (λ̄, φ̄: signed frequency −ω), which is
    how a frequency passes through zero."""
    from scipy.optimize import linear_sum_assignment

    first = found[0]
    lam = [first.eigenvalues.copy()]
    shapes = [first.shapes.copy()]
    for k in range(1, len(found)):
        current = found[k]
        predicted = lam[-1].imag
        if k >= 2:
            slope = (lam[-1].imag - lam[-2].imag) / (speeds[k - 1] - speeds[k - 2])
            predicted = predicted + slope * (speeds[k] - speeds[k - 1])
        direct, conjugate = _costs(shapes[-1], predicted, current)
        rows, columns = linear_sum_assignment(np.minimum(direct, conjugate))
        flip = conjugate[rows, columns] < direct[rows, columns]
        chosen_lam = np.where(flip, current.eigenvalues[columns].conj(), current.eigenvalues[columns])
        chosen_shapes = np.where(flip, current.shapes[:, columns].conj(), current.shapes[:, columns])
        lam.append(chosen_lam[np.argsort(rows)])
        shapes.append(chosen_shapes[:, np.argsort(rows)])
    return np.array(lam), np.array(shapes)


def _costs(previous: NDArray, predicted: NDArray, current: Modes) -> tuple[NDArray, NDArray]:
    """Costs of continuing the branches (shapes ``previous``, signed frequencies ``predicted``)
    with each of ``current``'s modes as it is (λ, φ) or as its conjugate (λ̄, φ̄, frequency −ω):
    1 − MAC plus the frequency's distance from the prediction over the largest frequency."""
    scale = max(np.abs(current.frequencies).max(initial=0.0), 1e-300)
    direct = 1.0 - mac(previous, current.shapes) + np.abs(predicted[:, None] - current.frequencies) / scale
    conjugate = 1.0 - mac(previous, current.shapes.conj()) + np.abs(predicted[:, None] + current.frequencies) / scale
    return direct, conjugate


def critical_speeds(speeds: NDArray, signed: NDArray, labels, orders, branch_at=None) -> list[CriticalSpeed]:
    """Where |ω_j(Ω)| − k |Ω| changes sign between neighbouring speeds (or vanishes at one);
    for k = 0 where the signed frequency ω_j of :func:`track` does (a frequency through zero).
    By linear interpolation, or, given ``branch_at(j, i, speed)`` (branch j's signed frequency
    at a speed between ``speeds[i]`` and ``speeds[i + 1]``), by Brent's method to 1e-12
    relative; sorted by speed."""
    from scipy.optimize import brentq

    def gap(omega, speed, k):
        return omega - 0.0 * speed if k == 0 else np.abs(omega) - k * np.abs(speed)

    found = []
    for k in orders:
        for j, label in enumerate(labels):
            g = gap(signed[:, j], speeds, k)
            for i in range(len(speeds) - 1):
                if g[i] == 0.0 or g[i] * g[i + 1] < 0.0:
                    a = g[i] / (g[i] - g[i + 1])
                    speed = speeds[i] + a * (speeds[i + 1] - speeds[i])
                    if branch_at is not None and g[i] != 0.0:
                        tol = 1e-12 * max(abs(speeds[i]), abs(speeds[i + 1]))
                        speed = brentq(lambda x, i=i, j=j, k=k: gap(branch_at(j, i, x), x, k), speeds[i],
                                       speeds[i + 1], xtol=tol, rtol=1e-12)
                    found.append(CriticalSpeed(label, k, float(speed), float(k * abs(speed))))
            if g[-1] == 0.0:
                found.append(CriticalSpeed(label, k, float(speeds[-1]), float(k * abs(speeds[-1]))))
    return sorted(found, key=lambda c: (c.speed, c.order))


def branch_labels(system, q, s_dot, t: float, lam: NDArray, shapes: NDArray,
                  coordinates) -> tuple[list, NDArray]:
    """The labels of the module docstring, from the modes (λ, φ) of ``system`` at (q, ṡ, t), and
    each mode's whirl sense σ (±1: its co-rotating whirl is w = σ Im λ about ω_b; 0: no whirl)."""
    tree = system.tree
    n = _beam(tree)
    order = np.argsort(np.abs(lam.imag))
    if n is None:
        return _numbered(["mode"] * len(lam), order), np.zeros(len(lam))
    omega_b = _beam_angular_velocity(system, n, q, s_dot, t)
    names = system.state_names()[: system.n_q]
    full = np.zeros((system.n_q, shapes.shape[1]), dtype=complex)
    full[[names.index(c) for c in coordinates]] = shapes
    kinds, senses = zip(*(_kind(tree.subsystems[n], full[tree.e_q_slice[n], j], np.linalg.norm(full[:, j]),
                                lam[j], omega_b) for j in range(shapes.shape[1])))
    return _numbered(list(kinds), order), np.array(senses, dtype=float)


def _beam(tree) -> int | None:
    """The index of the tree's one RitzBeam (None: none or several)."""
    from projeq.subsystems.beam.beam import RitzBeam

    beams = [n for n, sub in enumerate(tree.subsystems) if isinstance(sub, RitzBeam)]
    return beams[0] if len(beams) == 1 else None


def _stationary(found: list, signed: NDArray, senses: NDArray, reference: int, t: float) -> NDArray:
    """|σ_j Im λ_j + Ω_b| of each whirl branch j at each speed (module docstring: Ω_b = ω_b·e,
    e the beam's axis of rotation at the labelling speed ``reference``); NaN for the others."""
    stationary = np.full(signed.shape, np.nan)
    whirls = senses != 0.0
    if whirls.any():
        n = _beam(found[reference][0].tree)
        omega_b = np.array([_beam_angular_velocity(model, n, q, s_dot, t) for model, q, s_dot, _ in found])
        spin = omega_b @ (omega_b[reference] / np.linalg.norm(omega_b[reference]))
        stationary[:, whirls] = np.abs(senses[whirls] * signed[:, whirls] + spin[:, None])
    return stationary


def _beam_angular_velocity(system, n: int, q, s_dot, t: float) -> NDArray:
    """ω of subsystem n's reference frame in its own coordinates at (q, ṡ, t)."""
    from projeq.assembly.kinematics import forward

    tree = system.tree
    return np.real(forward(tree, np.asarray(q, dtype=float), system.tree_velocities(q, s_dot, t), t).twist[n][3:])


def _kind(beam, a: NDArray, total: float, lam: complex, omega_b: NDArray) -> tuple[str, float]:
    """flapwise, lead-lag, forward/backward whirl, axial, torsion or mode (module docstring), and
    the whirl's sense σ (0 for the other kinds)."""
    offset = 6  # the beam's columns of ẏ after (v_O, ω)
    part = {key: a[cols.start - offset: cols.stop - offset]
            for key, cols in (("u", beam.u_cols), ("v", beam.v_cols), ("w", beam.w_cols), ("beta", beam.beta_cols))}
    norms = {"bending": np.linalg.norm(np.r_[part["v"], part["w"]]), "axial": np.linalg.norm(part["u"]),
             "torsion": np.linalg.norm(part["beta"])}
    kind = max(norms, key=norms.get)
    if sum(norms.values()) < 0.5 * total:
        return "mode", 0.0  # mostly outside the beam (a hub, other bodies)
    spin = np.linalg.norm(omega_b)
    if kind != "bending":
        return kind, 0.0
    if spin == 0.0:
        return "bending", 0.0
    Phi = beam.station_data(np.array([beam.length]))[0]
    d = np.array([0.0, Phi["v"][0][:, 0] @ part["v"], Phi["w"][0][:, 0] @ part["w"]])
    e = omega_b / spin
    across = np.cross(e, (1.0, 0.0, 0.0))
    if np.linalg.norm(across) < 1.0 / np.sqrt(2.0):  # ω_b within 45° of the beam's axis: whirl
        sense = float(np.sign(np.imag(e @ np.cross(d, d.conj()))))
        return ("forward whirl" if sense * lam.imag + spin > 0.0 else "backward whirl"), sense
    lag = abs(d @ across) / np.linalg.norm(across)
    return ("flapwise" if abs(d @ e) >= lag else "lead-lag"), 0.0


def _numbered(kinds: list[str], order: NDArray) -> list[str]:
    """``"kind i"``: i counts the branches of each kind by frequency (``order``)."""
    seen: dict = {}
    labels = [""] * len(kinds)
    for j in order:
        seen[kinds[j]] = seen.get(kinds[j], 0) + 1
        labels[j] = f"{kinds[j]} {seen[kinds[j]]}"
    return labels


def _builder(system, joint):
    """build(speed) → (model, q, ṡ) from campbell's ``system`` and ``joint``."""
    if not isinstance(system, Model):
        if not callable(system):
            raise ValueError(f"system: expected a System or a build function speed -> System, got {system!r}")
        if joint is not None:
            raise ValueError("joint: only with a System (a build function sets the speed itself)")

        def build(speed):
            built = system(float(speed))
            if isinstance(built, tuple):
                if len(built) != 3:
                    raise ValueError(f"system: {callable_name(system)}({speed!r}) returned a tuple of {len(built)}; "
                                     "expected a System or (system, q, s_dot)")
                check_model(built[0])
                model, q, s_dot = built
                return model, (model.q0 if q is None else q), (model.s_dot0 if s_dot is None else s_dot)
            check_model(built)
            return built, built.q0, built.s_dot0

        return build
    check_model(system)
    if joint is None:
        raise ValueError("joint: campbell of a System needs the joint that turns at the speed (joint='hub'), "
                         "or give a build function speed -> System")
    n = system.tree.index(joint)
    columns = range(system.tree.s_slice[n].start, system.tree.e_s_slice[n].start)
    if len(columns) != 1 or system is not system.tree:
        raise ValueError(f"joint: {joint!r} must be a joint with one velocity of a System (it has {len(columns)})")

    def at_speed(speed):
        s_dot = np.array(system.s_dot0, dtype=float)
        s_dot[columns[0]] = speed
        return system, system.q0, s_dot

    return at_speed


def _frame(frame: str) -> str:
    if frame not in ("rotating", "stationary"):
        raise ValueError(f"frame: expected 'rotating' (the coordinates' frame) or 'stationary' (inertial), "
                         f"got {frame!r}")
    return frame


def _speeds(speeds) -> NDArray:
    speeds = finite_array("speeds", speeds)
    if speeds.ndim != 1 or len(speeds) < 2:
        raise ValueError(f"speeds: expected at least two rotation speeds (rad/s), got {speeds.tolist()}")
    if np.any(np.diff(speeds) <= 0.0):
        raise ValueError(f"speeds: must increase (modes are followed from speed to speed), got {speeds.tolist()}")
    return speeds


def _orders(orders) -> tuple[int, ...]:
    values = finite_array("orders", orders)
    if values.ndim != 1 or np.any(values < 0) or np.any(values != np.round(values)):
        raise ValueError(f"orders: expected integers >= 0 (engine orders), got {np.asarray(orders).tolist()}")
    return tuple(int(k) for k in values)


def _count(n_modes, lam: NDArray) -> int:
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or not 1 <= n_modes:
        raise ValueError(f"n_modes: expected a positive integer, got {n_modes!r}")
    return int(min(n_modes, lam.shape[1]))


def _labelling_speed(speeds: NDArray) -> int:
    """The index of the lowest nonzero |Ω| (a direction of rotation; the modes least mixed)."""
    nonzero = np.flatnonzero(speeds != 0.0)
    return int(nonzero[np.argmin(np.abs(speeds[nonzero]))]) if nonzero.size else 0
