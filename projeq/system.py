"""The System: a validated, immutable tree of subsystems, joints and forces; and the Model
protocol that it shares with :class:`~projeq.constraints.partitioned.ConstrainedSystem`.

Subsystems are numbered in topological order (``parent[n] < n``; ``GROUND = -1``): the
declared order when each parent is declared before its children (else a UserWarning says
the order q follows; :meth:`Model.coordinates` names its entries). Each
joint owns a slice of the coordinates q and of the minimal velocities ṡ (``q_slice[n]``,
``s_slice[n]``) unless it is *coupled* (gears, ropes), in which case its coordinate is a
linear combination of other joints' coordinates and ∂ẏ/∂ṡ is no longer block-triangular
(docs/theory.md §4): such systems are evaluated by the dense Gauss form.

All validation happens here, where input enters; the kernels trust what they get.
"""

from __future__ import annotations

import copy
import math
import warnings
from abc import ABC, abstractmethod
from collections import Counter

import numpy as np
from numpy.typing import NDArray

from projeq.assembly.kinematics import Plan
from projeq.checks import all_finite, finite_array, finite_result, kernel_state, not_finite, state_vector
from projeq.constraints.nonholonomic import check_configuration
from projeq.joints import Joint
from projeq.spatial import numeric
from projeq.subsystems.base import conform
from projeq.subsystems.rigid import RigidBody, gravity_potential

GROUND = -1
_GROUND_S = np.zeros((0, 6))


#: |Φ(q, t)| / max(1, |q|) up to which the analyses (linearize, state_jacobians, joint_reactions)
#: take q as on a model's loop closures (Model.check_closed): far above the drift of a stabilised
#: run (the four-bar with Baumgarte's correction: 8.8e-9 over 5 s), far below a loop left open
CLOSED = 1e-6


class Model(ABC):
    """What :func:`projeq.simulate`, :func:`projeq.linearize`, the reactions
    (:mod:`projeq.constraints.reactions`) and the ParaView export ask of a model, and all
    they ask: a :class:`System` (a tree whose joints hold every constraint) and a
    :class:`~projeq.constraints.partitioned.ConstrainedSystem` (a tree with constraint
    equations, in partitioned minimal velocities) are Models.

    The state is x = (q, ṡ): the tree's coordinates q (``n_q``) and the minimal
    velocities ṡ (``n_s``), with q̇ = K(q) ṡ + k(q, t) and the Gauss form
    M(q) s̈ + b(q, ṡ, t) = Q (docs/theory.md §4, §5, §7).

    Attributes
    ----------
    names : tuple of str
        The tree's subsystem names in topological order (the order of q and ṡ).
    n_q, n_s : int
        Lengths of q and ṡ.
    n_c : int
        Rows of :meth:`constraint_residual`.
    n_lambda : int
        Constraint equations with multipliers λ (:meth:`accelerations_tree`); 0 for a
        System, whose constraints are built into its joints' K and F.
    q0, s_dot0 : ndarray
        The default initial state.
    tree : System
        The tree whose kinematics place the bodies (a System is its own tree).

    Events. A model may stop a run by its own terminal :meth:`events` and say how the run
    goes on (:meth:`after_event`): a ConstrainedSystem re-partitions there when its
    partition degenerates; a System has none.
    """

    names: tuple
    n_q: int
    n_s: int
    n_c: int
    n_lambda: int = 0
    q0: NDArray
    s_dot0: NDArray
    tree: "System"

    # -- states ---------------------------------------------------------------------------
    @abstractmethod
    def check_q(self, name: str, q) -> NDArray:
        """q as a float array of length n_q with finite entries; ValueError naming ``name``."""

    def check_state(self, q, s_dot, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """q and ṡ as float arrays of the right lengths with finite entries (q checked by
        :meth:`check_q`), and a finite time t."""
        if not (type(t) is float and math.isfinite(t)):  # noqa: E721 — the common case in one test
            finite_array("t", t, ())
        return self.check_q("q", q), state_vector("s_dot", s_dot, self.n_s)

    @abstractmethod
    def normalized(self, q: NDArray, t: float = 0.0) -> NDArray:
        """q moved onto its manifold at time t (unit quaternions; a ConstrainedSystem's loop
        closures Φ(q, t) = 0, which depend on t across a joint prescribed in time)."""

    @abstractmethod
    def check_configuration(self, q: NDArray, t: float = 0.0) -> None:
        """ValueError naming what makes (q, t) singular (a joint's K or F, a partition)."""

    def check_closed(self, name: str, q: NDArray, t: float = 0.0, tol: float = 1e-9) -> None:
        """ValueError naming ``name`` if q violates the model's constraint equations Φ(q, t) = 0
        by more than ``tol`` relative (a tree has none)."""

    # -- names ----------------------------------------------------------------------------
    @abstractmethod
    def joint(self, name: str) -> Joint:
        """The tree joint that attaches subsystem ``name``."""

    @property
    def partition(self) -> tuple | None:
        """The tree velocities that are the minimal velocities ṡ, when ṡ is a choice among
        them (a ConstrainedSystem's independent velocities); None for a System."""
        return None

    def state_names(self) -> list[str]:
        """Names of x = (q, ṡ): ``"<subsystem>.q[i]"``, then ``"<subsystem>.s_dot[i]"`` (i
        within the subsystem's joint and internal coordinates; ṡ: the :attr:`partition`'s
        tree velocities when there is one)."""
        tree = self.tree
        names = {}
        for kind, slices in (("q", tree.q_slice), ("s_dot", tree.s_slice)):
            names[kind] = [f"{name}.{kind}[{i}]" for name, sl in zip(tree.names, slices)
                           for i in range(sl.stop - sl.start)]
        if self.partition is not None:
            names["s_dot"] = [names["s_dot"][i] for i in self.partition]
        return names["q"] + names["s_dot"]

    def coordinates(self) -> tuple:
        """(name, unit) of each entry of q, in the order of q: ``"<subsystem>.<coordinate>"``
        as its joint and the subsystem declare them (:meth:`projeq.joints.Joint.coordinates`,
        :meth:`projeq.Subsystem.coordinates`), e.g. ``("elbow.angle", "rad")``,
        ``("forearm.v[2]", "m")``; a coupled joint owns none."""
        return self.tree.named_coordinates[0]

    def velocities(self) -> tuple:
        """(name, unit) of each entry of ṡ, as :meth:`coordinates` (``"elbow.angle_dot"``,
        ``"forearm.v[2]_dot"``); a ConstrainedSystem's are the tree velocities of its
        :attr:`partition`."""
        names = self.tree.named_coordinates[1]
        return names if self.partition is None else tuple(names[i] for i in self.partition)

    def q_index(self, name: str):
        """Where ``name`` sits in q: the index of a coordinate ``"<subsystem>.<coordinate>"``
        (:meth:`coordinates`), or the slice of all of a subsystem's coordinates. For
        functions of q that should not depend on the tree's order, e.g. a constraint
        ``phi = lambda q, t: [q[i] - q[j]]`` with ``i = tree.q_index("crank.angle")``."""
        return _index_by_name("q", self.coordinates(), name)

    def s_index(self, name: str):
        """Where ``name`` sits in ṡ (:meth:`velocities`), as :meth:`q_index`."""
        return _index_by_name("s_dot", self.velocities(), name)

    def state(self, q=None, s_dot=None, **by_subsystem) -> tuple[NDArray, NDArray]:
        """(q, ṡ): the default initial state (``q0``, ``s_dot0``) with entries set by name,
        for :func:`projeq.simulate`.

        ``by_subsystem``: ``elbow=0.3`` sets the coordinates of subsystem ``elbow`` (a number
        when it has one, else a sequence of all of them); ``q`` and ``s_dot``: dicts by
        subsystem name or by full name (:meth:`coordinates`, :meth:`velocities`), e.g.
        ``s_dot={"elbow": 1.0, "forearm.v[2]_dot": 0.0}``. An unknown name is a ValueError
        listing the valid ones. A ConstrainedSystem's q must still close its loops (or be
        given to it with ``project_q0=True``).

        >>> import projeq as pq
        >>> q0, s_dot0 = pq.scenes.double_pendulum().state(bob1=0.3, s_dot={"bob2.angle_dot": -1.0})
        >>> q0.tolist(), s_dot0.tolist()
        ([0.3, 0.0], [0.0, -1.0])
        """
        q_values, s_values = _by_name("q", q), _by_name("s_dot", s_dot)
        twice = sorted(set(q_values) & set(by_subsystem))
        if twice:
            raise ValueError(f"q: {twice} set both in q and by keyword; give each once")
        state = (_set_by_name("q", np.array(self.q0, dtype=float), self.coordinates(), q_values | by_subsystem),
                 _set_by_name("s_dot", np.array(self.s_dot0, dtype=float), self.velocities(), s_values))
        self.check_closed("q", state[0])
        return state

    # -- kinematics -----------------------------------------------------------------------
    @abstractmethod
    def q_dot(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> NDArray:
        """q̇ = K(q) ṡ + k(q, t)."""

    @abstractmethod
    def tree_velocities(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> NDArray:
        """The tree's minimal velocities ṡ_tree at the state (ṡ itself for a System)."""

    @abstractmethod
    def constraint_residual(self, q: NDArray, q_dot: NDArray, t: float = 0.0) -> NDArray:
        """The n_c residuals of the constraints at (q, q̇, t) (zero on the motion)."""

    # -- dynamics -------------------------------------------------------------------------
    @abstractmethod
    def evaluator(self, method: str | None = None):
        """An object whose ``accelerations(q, s_dot, t)`` gives s̈ by ``method``
        (``"recursive"``, ``"dense"``, ``"fast"``, ``"hub_beam"`` or ``"auto"``; None: the
        model's default), without checking the state's values: the right-hand side that
        :func:`projeq.simulate` calls (it checks x and ẋ). Its type, dtype and shape are checked
        (:func:`projeq.checks.kernel_state`: ValueError naming q or s_dot; a strided array is
        copied, a complex one is the complex step); a non-finite state gives a non-finite s̈ or
        an error, never a finite number. One that cannot evaluate the model raises why."""

    def accelerations(self, q, s_dot, t: float = 0.0, method: str | None = None) -> NDArray:
        """Minimal accelerations s̈ from the Projection Equation at (q, ṡ, t) by the
        evaluator ``method``: ``"recursive"`` (order n, docs/theory.md "The recursive pass
        in augmented form"), ``"dense"`` (the Gauss form M s̈ + b = 0 of Bremer's B(14)) or
        ``"fast"`` (the recursive pass compiled, :mod:`projeq.assembly.fast`), ``"hub_beam"``
        (a beam on a prescribed hub, :mod:`projeq.assembly.beam_fast`) or ``"auto"`` (the
        fastest of them that can, :mod:`projeq.assembly.auto`); for a ConstrainedSystem the
        evaluator of its tree, projected (see its :meth:`evaluator`). ValueError naming the state
        where s̈ is not finite (an entry such as ṡ = 1e200 whose products overflow)."""
        q, s_dot = self.check_state(q, s_dot, t)
        try:
            s_ddot = self.evaluator(method).accelerations(q, s_dot, float(t))
        except FloatingPointError as exc:  # a pivot or M_ee that overflowed: the state's doing, named
            raise not_finite("s̈", q=q, s_dot=s_dot) from exc
        if not all_finite(s_ddot):
            raise not_finite("s̈", q=q, s_dot=s_dot)
        return s_ddot

    @abstractmethod
    def accelerations_tree(self, q: NDArray, s_dot: NDArray, t: float = 0.0,
                           method: str | None = None) -> tuple[NDArray, NDArray]:
        """(s̈_tree, λ): the tree's accelerations and the n_lambda multipliers."""

    @abstractmethod
    def gauss_form(self, q, s_dot, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """M and b of the Gauss form M s̈ + b = Q in the minimal velocities ṡ."""

    @abstractmethod
    def generalized_force(self, q: NDArray, t: float, joint_forces: dict) -> NDArray:
        """Q (n_s) of generalized forces τ_j {joint name: τ_j} along each joint's own
        velocities ṡ_j (the virtual power Σ τ_jᵀ ṡ_j = Qᵀ ṡ)."""

    @abstractmethod
    def energy(self, q, s_dot, t: float = 0.0) -> tuple[float, float]:
        """(kinetic, potential) energy at (q, ṡ, t)."""

    def output_row(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple:
        """What :func:`projeq.simulate` records at an output row (q normalised): the energies
        (:meth:`energy`), the constraint residuals at q̇ (:meth:`constraint_residual`) and, for a
        model with constraint equations, (rank, mobility) of its constraint matrix (else None)."""
        return self.energy(q, s_dot, t), self.constraint_residual(q, self.q_dot(q, s_dot, t), t), None

    def rows(self, x_rows: NDArray, times: NDArray) -> tuple | None:
        """:meth:`output_row` of many output rows x = (q, ṡ) at ``times`` at once, q normalised first:
        (q normalised (k, n_q), energies (k, 2), residuals (k, n_c), (rank, mobility) (k, 2) or None),
        where the model computes them together; None (the default) where it does not (then row by
        row, which names a row that fails)."""
        return None

    # -- events ---------------------------------------------------------------------------
    def events(self) -> tuple:
        """The model's own terminal events ``event(t, q, s_dot)`` (none by default); where
        one fires :func:`projeq.simulate` goes on with :meth:`after_event`."""
        return ()

    def after_event(self, q: NDArray, s_dot: NDArray, t: float) -> tuple["Model", NDArray]:
        """(model, ṡ) to go on with after one of :meth:`events` fired at (q, ṡ, t)
        (unchanged by default)."""
        return self, s_dot

    def row_models(self, result) -> list:
        """The model each row of ``result`` is in (this one, unless :meth:`after_event`
        changed it during the run: ``Result.partitions``)."""
        return [self] * len(result.t)


def _rows_by_name(kind: str, named: tuple, key: str) -> list[int]:
    """The entries of q or ṡ (``kind``) called ``key`` (a full name) or belonging to the
    subsystem ``key``; ValueError listing the valid names when there are none."""
    full = [name for name, _ in named]
    rows = [i for i, name in enumerate(full) if name == key or name.partition(".")[0] == key]
    if not rows:
        subsystems = list(dict.fromkeys(name.partition(".")[0] for name in full))
        raise ValueError(f"{key}: no entry of {kind} has that name; valid are the subsystems {subsystems} "
                         f"and the entries {full}")
    return rows


def _index_by_name(kind: str, named: tuple, key: str):
    """An entry's index, or the slice of a subsystem's entries (:func:`_rows_by_name`)."""
    rows = _rows_by_name(kind, named, key)
    return rows[0] if named[rows[0]][0] == key else slice(rows[0], rows[-1] + 1)


def _by_name(kind: str, values) -> dict:
    """{name: value} of :meth:`Model.state`'s ``q`` or ``s_dot`` (None: none)."""
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise ValueError(f"{kind}: expected a dict {{name: value}} of the entries to set, got {values!r} "
                         f"(a whole {kind} goes to simulate as is)")
    return dict(values)


def _set_by_name(kind: str, vector: NDArray, named: tuple, values: dict) -> NDArray:
    """``vector`` with the entries named in ``values`` (by full name, or by subsystem: all of
    its entries) replaced; ValueError for an unknown name or a wrong number of values."""
    for key, value in values.items():
        rows = _rows_by_name(kind, named, key)
        label = f"{kind}[{key!r}] ({', '.join(named[i][0] for i in rows)})"
        vector[rows] = state_vector(label, np.atleast_1d(finite_array(label, value)), len(rows))
    return vector


def _named_coordinates(system) -> tuple[tuple, tuple]:
    """((name, unit) of q, (name, unit) of ṡ) of a System from its joints' and subsystems'
    declarations (elastic velocities: ``"<name>_dot"``, unit per second); ValueError for a
    declaration of the wrong length or a name used twice."""
    q_named, s_named = [], []
    for name, joint, sub in zip(system.names, system.joints, system.subsystems):
        own_q, own_s = ((), ()) if joint.coupling else (tuple(joint.coordinates()), tuple(joint.velocities()))
        elastic = tuple(sub.coordinates())
        for where, declared, n in ((f"joints[{name!r}].coordinates()", own_q, 0 if joint.coupling else joint.n_q),
                                   (f"joints[{name!r}].velocities()", own_s, 0 if joint.coupling else joint.n_s),
                                   (f"subsystems[{name!r}].coordinates()", elastic, sub.n_e)):
            if len(declared) != n or not all(isinstance(c, str) and isinstance(u, str) for _, (c, u) in
                                             zip(range(n), declared)):
                raise ValueError(f"{where}: declares {declared!r}; expected {n} (name, unit) pairs of strings")
        q_named += [(f"{name}.{c}", u) for c, u in own_q + elastic]
        s_named += [(f"{name}.{c}", u) for c, u in own_s]
        s_named += [(f"{name}.{c}_dot", f"{u}/s" if u else "") for c, u in elastic]
    for named in (q_named, s_named):
        repeated = sorted(n for n, count in Counter(m for m, _ in named).items() if count > 1)
        if repeated:
            raise ValueError(f"joints: the coordinate names {repeated} are declared twice within one subsystem")
    return tuple(q_named), tuple(s_named)


def check_model(model) -> None:
    """ValueError unless ``model`` is a :class:`Model` (a System or a ConstrainedSystem)."""
    if not isinstance(model, Model):
        raise ValueError(f"system: expected a System or a ConstrainedSystem (a projeq.system.Model), got {model!r}")


class System(Model):
    """A multibody system for the Projection Equation Σ J_nᵀ (M_n ÿ_n + G_n ẏ_n − Q_n) = 0.

    Immutable: every attribute is set by the constructor (the kinematic plan of the forward
    pass included, :class:`projeq.assembly.kinematics.Plan`); assigning one raises
    AttributeError. Only the evaluators are made on first use (:meth:`evaluator`).

    Parameters
    ----------
    subsystems : dict[str, Subsystem]
        The bodies by name (:class:`projeq.Subsystem` s, or objects with its required
        members, :func:`projeq.subsystems.base.conform`).
    joints : dict[str, Joint]
        For each subsystem name the joint that attaches it to its ``parent``.
    gravity : 3-vector
        Gravitational acceleration in inertial coordinates (m/s²).
    forces : sequence
        Force laws (:mod:`projeq.forces`).
    q0, s_dot0 : arrays or dicts, optional
        Default initial state used by :func:`projeq.simulate` (zero configuration and rest);
        a dict sets entries by name as :meth:`Model.state` does (``{"upper": 0.3}``).

    Examples
    --------
    >>> import numpy as np, projeq as pq
    >>> rod = pq.RigidBody(m=1.0, r_c=(0, 0, -0.5), I_c=np.diag([1/12, 1/12, 1e-4]))
    >>> system = pq.System(
    ...     subsystems={"upper": rod, "lower": rod},
    ...     joints={"upper": pq.Revolute(parent=None, axis="y"),
    ...             "lower": pq.Revolute(parent="upper", axis="y", r_pn=(0, 0, -1))},
    ...     gravity=(0, 0, -9.81))
    >>> s_ddot = system.accelerations(q=[0.3, -0.2], s_dot=[0.0, 0.0])
    >>> bool(np.allclose(s_ddot, system.accelerations([0.3, -0.2], [0, 0], method="dense")))
    True
    """

    def __init__(self, subsystems: dict, joints: dict, gravity=(0.0, 0.0, 0.0), forces=(), q0=None, s_dot0=None):
        _check_names(subsystems, joints)
        order = _topological_order(joints)
        _warn_if_reordered(list(subsystems), order)
        self.names = tuple(order)
        self._index = {name: n for n, name in enumerate(order)}
        self.subsystems = tuple(subsystems[name] for name in order)
        self.joints = tuple(joints[name] for name in order)
        self.parent = tuple(GROUND if j.parent is None else self._index[j.parent] for j in self.joints)
        self.S = tuple(s.S for s in self.subsystems) + (_GROUND_S,)
        self.gravity = finite_array("gravity", gravity, (3,))
        self._layout_coordinates()
        self.named_coordinates = _named_coordinates(self)  # ((name, unit) of q, of ṡ): coordinates()
        self.coupled = any(j.coupling for j in self.joints)
        self.forces = tuple(_bound(i, f, self) for i, f in enumerate(_check_forces(forces)))
        if isinstance(q0, dict):  # by name, the rest at the joints' defaults
            q0 = _set_by_name("q0", self._default_q(), self.named_coordinates[0], q0)
        if isinstance(s_dot0, dict):
            s_dot0 = _set_by_name("s_dot0", np.zeros(self.n_s), self.named_coordinates[1], s_dot0)
        self.q0 = self.normalized(self.check_q("q0", self._default_q() if q0 is None else q0))
        self.s_dot0 = state_vector("s_dot0", np.zeros(self.n_s) if s_dot0 is None else s_dot0, self.n_s)
        for a in (self.gravity, self.q0, self.s_dot0):
            a.flags.writeable = False
        self._evaluators: dict = {}  # the one cache: an evaluator per method (not thread-safe)
        self.plan = Plan(self)  # what the forward pass needs, once (projeq.assembly.kinematics)
        self._frozen = True
        self._check_planar()
        self._check_slender()
        self.check_configuration(self.q0)  # K(q0), F(q0) regular: no coordinate singularity at the start

    def __setattr__(self, name: str, value) -> None:
        if self.__dict__.get("_frozen"):
            raise AttributeError(
                f"System is immutable: cannot set {name!r} after construction; build a new System "
                "(or use SystemBuilder) with what should change"
            )
        super().__setattr__(name, value)

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"System is immutable: cannot delete {name!r}")

    @property
    def tree(self) -> "System":
        """A System is its own tree."""
        return self

    # -- names and indexing -------------------------------------------------------------
    def index(self, name: str) -> int:
        """Position of the subsystem ``name`` in the topological order."""
        if name not in self._index:
            raise ValueError(f"name: unknown subsystem {name!r}; the system has {list(self.names)}")
        return self._index[name]

    def subsystem(self, name: str):
        """The subsystem added under ``name``."""
        return self.subsystems[self.index(name)]

    def joint(self, name: str) -> Joint:
        """The joint that attaches subsystem ``name``."""
        return self.joints[self.index(name)]

    def _layout_coordinates(self) -> None:
        """Each subsystem owns q_n = (joint coordinates, internal coordinates q_e) and
        ṡ_n = (joint velocities, ṡ_e = q̇_e); coupled joints own none of their own."""
        q_slice, s_slice, e_q, e_s, n_q, n_s = [], [], [], [], 0, 0
        for joint, sub in zip(self.joints, self.subsystems):
            own_q, own_s = (0, 0) if joint.coupling else (joint.n_q, joint.n_s)
            n_e = sub.n_e
            q_slice.append(slice(n_q, n_q + own_q + n_e))
            s_slice.append(slice(n_s, n_s + own_s + n_e))
            e_q.append(slice(n_q + own_q, n_q + own_q + n_e))
            e_s.append(slice(n_s + own_s, n_s + own_s + n_e))
            n_q, n_s = n_q + own_q + n_e, n_s + own_s + n_e
        self.q_slice, self.s_slice, self.n_q, self.n_s = tuple(q_slice), tuple(s_slice), n_q, n_s
        self.e_q_slice, self.e_s_slice = tuple(e_q), tuple(e_s)
        self._q_get = tuple(self.joint_q_getter(n) for n in range(len(self.joints)))
        self._s_get = tuple(self.joint_s_dot_getter(n) for n in range(len(self.joints)))
        self._identity_q, self._identity_s, self._general_kinematics = self._kinematics_split()
        self._q_dot_is_s_dot = (not self._general_kinematics and np.array_equal(self._identity_q, np.arange(n_q))
                                and np.array_equal(self._identity_s, np.arange(n_s)))
        self._normalizing = tuple(  # joints whose coordinates live on a manifold (quaternions)
            n for n, j in enumerate(self.joints)
            if type(j).normalized is not Joint.normalized and not j.coupling and self.e_q_slice[n].start > self.q_slice[n].start
        )
        self._constrained = tuple(n for n, j in enumerate(self.joints) if j.n_c)  # joints with velocity constraints
        rigid = [n for n, sub in enumerate(self.subsystems) if type(sub).potential_energy is RigidBody.potential_energy]
        self._rigid_potential = (np.array(rigid, dtype=int), np.array([self.subsystems[n].m for n in rigid]),
                                 np.array([self.subsystems[n].r_c for n in rigid]).reshape(-1, 3))
        self._own_potential = tuple(sorted(set(range(len(self.subsystems))) - set(rigid)))

    def _coupling_rows(self, n: int, slices) -> tuple[NDArray, NDArray]:
        """Indices into the global vector and weights for coupled joint n."""
        joint = self.joints[n]
        if joint.n_q != 1 or joint.n_s != 1:
            raise ValueError(f"coupling: joint of {self.names[n]!r} must have one dof")
        idx, weights = [], []
        for other, ratio in joint.coupling.items():
            if other not in self._index:
                raise ValueError(f"coupling: {self.names[n]!r} follows {other!r}, which is not in the system; "
                                 f"known subsystems are {list(self.names)}")
            m = self.index(other)
            if self.joints[m].coupling or self.joints[m].n_s != 1 or self.joints[m].n_q != 1:
                raise ValueError(f"coupling: {self.names[n]!r} may follow only uncoupled one-dof joints, not {other!r}")
            idx.append(slices[m].start)
            weights.append(ratio)
        return np.array(idx), np.array(weights)

    def joint_q_getter(self, n: int):
        """A function q ↦ q_n (the joint's coordinates, coupled ones computed)."""
        if not self.joints[n].coupling:
            sl = slice(self.q_slice[n].start, self.e_q_slice[n].start)
            return lambda q: q[sl]
        idx, w = self._coupling_rows(n, self.q_slice)
        return lambda q: np.array([w @ q[idx]])

    def joint_s_dot_getter(self, n: int):
        """A function ṡ ↦ ṡ_n (the joint's minimal velocities, coupled ones computed)."""
        if not self.joints[n].coupling:
            sl = slice(self.s_slice[n].start, self.e_s_slice[n].start)
            return lambda s_dot: s_dot[sl]
        idx, w = self._coupling_rows(n, self.s_slice)
        return lambda s_dot: np.array([w @ s_dot[idx]])

    def joint_s_columns(self, n: int) -> tuple[NDArray, NDArray]:
        """(columns of ṡ, weights P) with ṡ_n = P ṡ[columns]: the joint's place in ∂ẏ/∂ṡ."""
        internal = np.arange(self.n_s)[self.e_s_slice[n]]
        if not self.joints[n].coupling:
            cols = np.arange(self.n_s)[self.s_slice[n]]
            return cols, np.eye(len(cols))
        idx, w = self._coupling_rows(n, self.s_slice)
        P = np.zeros((1 + len(internal), len(idx) + len(internal)))
        P[0, : len(idx)] = w
        P[1:, len(idx):] = np.eye(len(internal))
        return np.concatenate((idx, internal)), P

    # -- states ---------------------------------------------------------------------------
    def _default_q(self) -> NDArray:
        parts = [
            np.concatenate(([] if j.coupling else j.default_q(), np.zeros(sub.n_e)))
            for j, sub in zip(self.joints, self.subsystems)
        ]
        return np.concatenate(parts) if parts else np.zeros(0)

    def normalized(self, q: NDArray, t: float = 0.0) -> NDArray:
        """q with every joint's coordinates projected onto their manifold (unit quaternions, the
        same at any time t)."""
        q = numeric(np.array(q))  # complex under a complex step (the energy projection's exact gradient)
        for n in self._normalizing:  # the others' normalized is the identity
            sl = slice(self.q_slice[n].start, self.e_q_slice[n].start)
            q[sl] = self.joints[n].normalized(q[sl])
        return q

    def normalized_rows(self, q_rows: NDArray) -> NDArray:
        """:meth:`normalized` of each row of ``q_rows`` (k, n_q): only the joints that project touched."""
        q = np.array(q_rows, dtype=float).reshape(-1, self.n_q)
        for n in self._normalizing:
            sl = slice(self.q_slice[n].start, self.e_q_slice[n].start)
            q[:, sl] = [self.joints[n].normalized(row) for row in q[:, sl]]
        return q

    def check_q(self, name: str, q) -> NDArray:
        """q as a float array of the right length with finite entries that every joint can
        normalise (no zero quaternion)."""
        q = state_vector(name, q, self.n_q)
        for n in self._normalizing:
            sl = slice(self.q_slice[n].start, self.e_q_slice[n].start)
            with np.errstate(all="ignore"):
                ok = np.all(np.isfinite(self.joints[n].normalized(q[sl])))
            if not ok:
                raise ValueError(
                    f"{name}: the coordinates {q[sl].tolist()} of joint {self.names[n]!r} (entries "
                    f"{sl.start}..{sl.stop - 1}) cannot be normalised (a zero quaternion?)"
                )
        return q

    def check_configuration(self, q: NDArray, t: float = 0.0) -> None:
        """ValueError naming the joint whose K(q) or F(q) is singular or not finite at q
        (:func:`projeq.constraints.nonholonomic.check_configuration`)."""
        check_configuration(self, q, t)

    def _kinematics_split(self) -> tuple[NDArray, NDArray, tuple]:
        """(rows of q, rows of ṡ) where q̇ = ṡ — joints with the identity K of the Joint base
        class (revolute, prismatic) and elastic coordinates — and the other uncoupled joints."""
        q_rows, s_rows, general = [], [], []
        for n, j in enumerate(self.joints):
            if not j.coupling and j.n_q == j.n_s and type(j).K is Joint.K and type(j).q_dot is Joint.q_dot:
                q_rows += range(self.q_slice[n].start, self.e_q_slice[n].start)
                s_rows += range(self.s_slice[n].start, self.e_s_slice[n].start)
            elif not j.coupling:
                general.append(n)
            q_rows += range(self.e_q_slice[n].start, self.e_q_slice[n].stop)
            s_rows += range(self.e_s_slice[n].start, self.e_s_slice[n].stop)
        return np.array(q_rows, dtype=int), np.array(s_rows, dtype=int), tuple(general)

    def q_dot(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> NDArray:
        """q̇ = K(q) ṡ + k(q, t): q̇ = ṡ in one step where K = E (revolute and prismatic
        joints, elastic coordinates), joint by joint elsewhere. q and ṡ given otherwise than as
        arrays (lists, tuples) are checked as :meth:`check_state` does; arrays, as the
        integrators pass them (complex under a complex step), go straight on once their shapes are
        right."""
        if not (isinstance(q, np.ndarray) and isinstance(s_dot, np.ndarray)):
            q, s_dot = self.check_state(q, s_dot, t)
        elif q.shape != (self.n_q,) or s_dot.shape != (self.n_s,) or q.dtype.kind not in "fc" or \
                s_dot.dtype.kind not in "fc":
            q, s_dot = kernel_state("q", q, self.n_q), kernel_state("s_dot", s_dot, self.n_s)
        if self._q_dot_is_s_dot:  # K = E throughout (one copy: the right-hand side of every step calls it)
            return np.array(s_dot, dtype=np.result_type(q, s_dot, float))
        q_dot = np.empty(self.n_q, dtype=np.result_type(q, s_dot, float))  # complex for a complex step
        q_dot[self._identity_q] = np.asarray(s_dot)[self._identity_s]
        for n in self._general_kinematics:
            j = self.joints[n]
            q_dot[self.q_slice[n].start : self.e_q_slice[n].start] = j.q_dot(self._q_get[n](q), self._s_get[n](s_dot), t)
        return q_dot

    @property
    def n_c(self) -> int:
        """Number of velocity constraints whose residuals are reported."""
        return sum(j.n_c for j in self.joints)

    def constraint_residual(self, q: NDArray, q_dot: NDArray, t: float = 0.0) -> NDArray:
        """Residuals of the joints' original velocity constraints at (q, q̇, t)."""
        parts = [
            self.joints[n].constraint_residual(self._q_get[n](q), self._q_get[n](q_dot), t)
            for n in self._constrained
        ]
        return np.concatenate(parts) if parts else np.zeros(0)

    def K(self, q: NDArray, t: float = 0.0) -> NDArray:
        """K(q) of q̇ = K ṡ + k (block-diagonal over the joints), complex for a complex q (a complex step);
        q given otherwise than as an array is checked as :meth:`check_q` does, an array's shape and dtype
        (:func:`projeq.checks.kernel_state`)."""
        q = kernel_state("q", q, self.n_q) if isinstance(q, np.ndarray) else self.check_q("q", q)
        K = np.zeros((self.n_q, self.n_s), dtype=np.result_type(q, float))
        for n, j in enumerate(self.joints):
            if not j.coupling:
                rows = slice(self.q_slice[n].start, self.e_q_slice[n].start)
                cols = slice(self.s_slice[n].start, self.e_s_slice[n].start)
                K[rows, cols] = j.K(self._q_get[n](q), t)
            K[self.e_q_slice[n], self.e_s_slice[n]] = np.eye(self.e_q_slice[n].stop - self.e_q_slice[n].start)
        return K

    # -- evaluation -----------------------------------------------------------------------
    def evaluator(self, method: str | None = None):
        """The cached evaluator ``"recursive"``, ``"dense"``, ``"fast"`` (compiled order n,
        :mod:`projeq.assembly.fast`), ``"hub_beam"`` or ``"auto"`` (the best of them available,
        :mod:`projeq.assembly.auto`; also ``None``, the default: the compiled evaluator where it
        knows every piece, else the reference one with one warning naming the piece). One
        that cannot evaluate this system raises why."""
        evaluator = self._evaluators.get("auto" if method is None else method)
        if evaluator is not None:  # made before: the public calls' common case, first
            return evaluator
        from projeq.assembly import EVALUATORS

        if method is None:
            method = "auto"
        if method not in EVALUATORS:
            raise ValueError(f"method: unknown evaluator {method!r}; use one of {sorted(EVALUATORS)}")
        if method not in self._evaluators:
            self._evaluators[method] = EVALUATORS[method](self)
        return self._evaluators[method]

    def accelerations_tree(self, q, s_dot, t: float = 0.0, method: str | None = None) -> tuple[NDArray, NDArray]:
        """(s̈, λ) with no multipliers λ: a System is its own tree."""
        return self.accelerations(q, s_dot, t, method), np.zeros(0)

    def tree_velocities(self, q, s_dot, t: float = 0.0) -> NDArray:
        """ṡ: a System is its own tree."""
        return np.asarray(s_dot, dtype=float)

    def generalized_force(self, q, t: float, joint_forces: dict) -> NDArray:
        """Q with Q[columns] = Σ_j P_jᵀ τ_j, ṡ_j = P_j ṡ[columns] (:meth:`joint_s_columns`:
        a coupled joint's τ acts on the velocities it follows)."""
        Q = np.zeros(self.n_s, dtype=np.result_type(float, *map(np.asarray, joint_forces.values())))  # complex step
        for name, tau in joint_forces.items():
            n = self.index(name)
            cols, P = self.joint_s_columns(n)
            state_vector(f"inputs[{name!r}]", np.real(tau), self.joints[n].n_s)
            Q[cols] += P[: self.joints[n].n_s].T @ numeric(tau)
        return Q

    def gauss_form(self, q, s_dot, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """M(q) and b(q, ṡ, t) of the Gauss form M s̈ + b = 0 (docs/theory.md §5); ValueError naming the
        state where they are not finite."""
        q, s_dot = self.check_state(q, s_dot, t)
        M_b = self.evaluator("dense").gauss_form(q, s_dot, float(t))
        return finite_result("the Gauss form (M, b)", M_b, q=q, s_dot=s_dot)

    def mass_matrix(self, q, t: float = 0.0) -> NDArray:
        """M(q) = Σ J_nᵀ M_n J_n (docs/theory.md §5)."""
        return self.gauss_form(q, np.zeros(self.n_s), t)[0]

    def energy(self, q, s_dot, t: float = 0.0, method: str | None = None) -> tuple[float, float]:
        """(kinetic, potential): Σ ½ ẏ_nᵀ M_n ẏ_n and :meth:`potential_energy` (gravity, strain,
        springs), by ``method``: "fast" (on the compiled kinematics,
        :meth:`projeq.assembly.fast.FastEvaluator.energy`), "hub_beam" (a beam on a prescribed
        hub, compiled: :meth:`projeq.assembly.beam_fast.HubBeamEvaluator.energy`), "recursive"
        (on the reference kinematics, :func:`projeq.assembly.kinematics.poses`, and each
        subsystem's own ``kinetic_energy``) or None: that of the system's default evaluator
        where it is a compiled one, else "recursive". Complex for complex (q, ṡ, t), by the
        reference (unchecked then: a complex step, as for the exact energy gradient of
        :mod:`projeq.simulation.integrators`)."""
        if method not in (None, "fast", "hub_beam", "recursive"):
            raise ValueError(f"method: unknown energy evaluation {method!r}; use 'fast', 'hub_beam', 'recursive' "
                             "or None")
        complex_step = np.iscomplexobj(q) or np.iscomplexobj(s_dot) or np.iscomplexobj(t)
        if complex_step:
            q, s_dot = kernel_state("q", q, self.n_q), kernel_state("s_dot", s_dot, self.n_s)
            return self._energy(q, s_dot, t, "recursive")
        q, s_dot = self.check_state(q, s_dot, t)
        try:
            energies = self._energy(q, s_dot, float(t), method)
        except FloatingPointError as exc:
            raise not_finite("the energy", q=q, s_dot=s_dot) from exc
        return finite_result("the energy", energies, q=q, s_dot=s_dot)

    def _energy(self, q: NDArray, s_dot: NDArray, t, method: str | None = None) -> tuple:
        """:meth:`energy` at a checked (q, ṡ, t), or by the reference at a complex one."""
        if method is None:  # the default evaluator's own where it is a compiled one (tiered: projeq.assembly.auto)
            default = self.evaluator(None)
            if getattr(default.evaluator, "compiled", False):
                return default.energy(q, s_dot, t)
        elif method != "recursive":
            return self.evaluator(method).energy(q, s_dot, t)
        from projeq.assembly.kinematics import poses

        complex_step = np.iscomplexobj(q) or np.iscomplexobj(s_dot) or np.iscomplexobj(t)
        kin = poses(self, q, s_dot, t)
        q_e = [q[sl] for sl in self.e_q_slice]
        kinetic = sum(sub.kinetic_energy(kin.y_dot[n], q_e[n]) for n, sub in enumerate(self.subsystems))
        potential = self.potential_energy(kin, q)
        return (complex(kinetic), complex(potential)) if complex_step else (float(kinetic), float(potential))

    def output_row(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple:
        """:meth:`Model.output_row`, the energy unchecked (the row's state is the integrator's)."""
        return self._energy(q, s_dot, float(t)), self.constraint_residual(q, self.q_dot(q, s_dot, t), t), None

    def output_rows(self, q_rows: NDArray, s_rows: NDArray, times: NDArray) -> tuple | None:
        """:meth:`output_row` of many rows (q normalised) at once, (energies (k, 2), residuals (k, n_c)),
        where the default evaluator computes the energies together (compiled: :meth:`projeq.assembly.fast.
        FastEvaluator.energies`); None where it does not (then row by row)."""
        energies = getattr(self.evaluator(None), "energies", lambda *rows: None)(q_rows, s_rows, times)
        if energies is None:
            return None
        residuals = [self.constraint_residual(q, self.q_dot(q, s_dot, t), t) for q, s_dot, t in
                     zip(q_rows, s_rows, times)] if self._constrained else np.zeros((len(times), 0))
        return energies, np.reshape(residuals, (len(times), self.n_c))

    def rows(self, x_rows: NDArray, times: NDArray) -> tuple | None:
        """:meth:`Model.rows`: :meth:`normalized_rows`, then :meth:`output_rows` (no rank)."""
        x_rows = np.asarray(x_rows, dtype=float)
        q = self.normalized_rows(x_rows[:, :self.n_q])
        values = self.output_rows(q, x_rows[:, self.n_q:], times)
        return None if values is None else (q, values[0], values[1], None)

    def potential_energy(self, kin, q: NDArray):
        """V at the poses ``kin`` (R_n, r_n, twists, ẏ_n; the ground's last) and q: each
        subsystem's ``potential_energy`` (gravity, strain) and each force law's ``potential``;
        the rigid bodies' (:meth:`RigidBody.potential_energy
        <projeq.subsystems.rigid.RigidBody.potential_energy>`) stacked in one call of
        :func:`~projeq.subsystems.rigid.gravity_potential`."""
        rigid, m, r_c = self._rigid_potential
        V = gravity_potential(m, r_c, np.asarray(kin.R)[rigid], np.asarray(kin.r)[rigid], self.gravity) \
            if len(rigid) else 0.0
        return V + sum(
            self.subsystems[n].potential_energy(kin.R[n], kin.r[n], self.gravity, q[self.e_q_slice[n]])
            for n in self._own_potential
        ) + sum(f.potential(kin, q) for f in self.forces)

    def _check_planar(self) -> None:
        """A subsystem with a selection S must not be driven out of its plane by its joint
        (F⁶ and T⁶_np Sₚᵀ must lie in the span of Sₙᵀ), checked at q0 and a perturbed q."""
        from projeq.assembly.kinematics import forward

        rng = np.random.default_rng(1)
        for q in (self.q0, self.normalized(self.q0 + 0.3 * rng.standard_normal(self.n_q))):
            kin = forward(self, q, rng.standard_normal(self.n_s), 0.0)
            for n, sub in enumerate(self.subsystems):
                if sub.S is None:
                    continue
                out_of_plane = np.eye(6) - sub.S.T @ sub.S
                p = self.parent[n]
                if np.abs(out_of_plane @ kin.twist[n]).max() > 1e-9 * (1 + np.abs(kin.twist[n]).max()):
                    parent = "the ground" if p == GROUND else repr(self.names[p])
                    raise ValueError(
                        f"joints[{self.names[n]!r}]: the planar body {self.names[n]!r} (plane "
                        f"{getattr(sub, 'plane', '?')}) would move out of its plane: its joint axis "
                        f"or its parent {parent} is not in the same plane"
                    )

    def _check_slender(self) -> None:
        """A body with a zero principal moment (``slender_axis``, a slender rod) is accepted
        when its joint cannot turn it about that axis: F_nᵀ M_n F_n positive definite at q0
        (else the mass matrix is singular whatever the rest of the tree)."""
        slender = [n for n, sub in enumerate(self.subsystems) if getattr(sub, "slender_axis", None) is not None]
        if not slender:
            return
        from projeq.assembly.kinematics import forward

        kin = forward(self, self.q0, self.s_dot0, 0.0)
        for n in slender:
            sub, F = self.subsystems[n], kin.F[n]
            M = sub.gauss_terms(np.zeros(sub.n_y), np.eye(3), np.zeros(3))[0]
            block = F.T @ M @ F
            if block.size and np.linalg.eigvalsh(block)[0] <= 1e-12 * np.abs(M).max():
                axis = np.round(sub.slender_axis, 12) + 0.0
                raise ValueError(
                    f"joints[{self.names[n]!r}]: the body {self.names[n]!r} has no inertia about its axis "
                    f"{axis.tolist()} (body coordinates; a zero principal moment of I_c) and its joint "
                    f"{type(self.joints[n]).__name__} can turn it about that axis (F_nᵀ M_n F_n is singular "
                    f"at q0): give I_c a moment about that axis or use a joint that cannot turn it so"
                )

    def __repr__(self) -> str:
        return f"System({len(self.names)} subsystems, n_q={self.n_q}, n_s={self.n_s})"


def _check_names(subsystems, joints) -> None:
    if not isinstance(subsystems, dict) or not subsystems:
        raise ValueError("subsystems: expected a non-empty dict {name: subsystem}")
    if not isinstance(joints, dict):
        raise ValueError("joints: expected a dict {subsystem name: joint}")
    missing, extra = set(subsystems) - set(joints), set(joints) - set(subsystems)
    if missing:
        raise ValueError(f"joints: no joint for subsystem(s) {sorted(missing)}")
    if extra:
        raise ValueError(f"joints: joint(s) for unknown subsystem(s) {sorted(extra)}")
    for name, sub in subsystems.items():
        _check_name(name, subsystems)
        conform(name, sub)
    for name, joint in joints.items():
        if not isinstance(joint, Joint):
            raise ValueError(f"joints[{name!r}]: {joint!r} is not a Joint")
        if joint.parent is not None and joint.parent not in subsystems:
            raise ValueError(
                f"joints[{name!r}]: parent {joint.parent!r} is not in the system; "
                f"known subsystems are {list(subsystems)}"
            )
        if joint.parent == name:
            raise ValueError(f"joints[{name!r}]: a subsystem cannot be its own parent")


def _check_name(name, subsystems: dict) -> None:
    """A subsystem's name: a non-empty string without ``.``, which separates a subsystem from its
    coordinate in the full names (``"elbow.angle"``, :meth:`Model.coordinates`): ``"a.b"`` beside
    ``"a"`` would make ``q_index("a")`` and ``state(a=...)`` span both."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"subsystems: a name must be a non-empty string, got {name!r}")
    if "." in name:
        shadowed = name.partition(".")[0]
        clash = f"; it would shadow the subsystem {shadowed!r}" if shadowed in subsystems else ""
        raise ValueError(f"subsystems[{name!r}]: a name must not contain '.', which separates a subsystem from its "
                         f"coordinate (a coordinate {name + '.angle'!r} would read as one of subsystem "
                         f"{shadowed!r}){clash}; use another character, e.g. {name.replace('.', '_')!r}")


def _check_forces(forces) -> tuple:
    try:
        forces = tuple(forces)
    except TypeError:
        raise ValueError(f"forces: expected a list of force laws, got {forces!r}") from None
    for i, f in enumerate(forces):
        if not all(hasattr(f, a) for a in ("bind", "add_to", "potential")):
            raise ValueError(f"forces[{i}]: {f!r} is not a force law (needs bind, add_to, potential)")
    return forces


def _bound(i: int, law, system) -> object:
    """A copy of force law ``law`` bound to ``system``: what its ``bind`` returns, which the
    contract (:class:`projeq.forces.ForceLaw`) makes the law itself."""
    bound = copy.copy(law).bind(system)
    if not all(hasattr(bound, a) for a in ("add_to", "potential")):
        raise ValueError(f"forces[{i}]: {type(law).__name__}.bind returned {bound!r}, not the bound law; "
                         "end bind with `return self`")
    return bound


def _cycle(joints: dict, start: str) -> list[str]:
    """The loop reached by following parents from ``start`` (which does not reach the ground)."""
    path = [start]
    while joints[path[-1]].parent not in path:
        path.append(joints[path[-1]].parent)
    loop = path[path.index(joints[path[-1]].parent):]
    return loop + loop[:1]


def _warn_if_reordered(declared: list, order: list) -> None:
    """A UserWarning when the tree's order (parents first), which q and ṡ follow, is not the
    order in which the user declared the subsystems: a function of q written in the declared
    order (a constraint Φ(q)) would read the wrong entries."""
    if declared != order:
        warnings.warn(
            f"System: q and s_dot follow the subsystems parents first, {order}, not in the declared order "
            f"{declared}; address coordinates by name (System.q_index, System.state, Result.coordinates) "
            "or declare each parent before its children", UserWarning, stacklevel=3)


def _topological_order(joints: dict) -> list[str]:
    """Names ordered so that every parent precedes its children: the declared order wherever
    it does so already (each step takes the first pending name whose parent is placed);
    cycles raise."""
    order, placed, pending = [], set(), list(joints)
    while pending:
        ready = next((n for n in pending if joints[n].parent is None or joints[n].parent in placed), None)
        if ready is None:
            loop = " -> ".join(repr(n) for n in _cycle(joints, pending[0]))
            raise ValueError(
                f"joints: the parents form a cycle (following parents: {loop}); "
                "a system must be a tree"
            )
        order.append(ready)
        placed.add(ready)
        pending.remove(ready)
    return order


class SystemBuilder:
    """Builds a :class:`System` one subsystem at a time; ``build()`` returns it frozen.

    >>> import projeq as pq
    >>> b = pq.SystemBuilder(gravity=(0, 0, -9.81))
    >>> b.add("bob", pq.PointMass(1.0, r_c=(0, 0, -1)), pq.Revolute(axis="y"))
    >>> b.build().n_s
    1
    """

    def __init__(self, gravity=(0.0, 0.0, 0.0)):
        self.gravity = gravity
        self._subsystems: dict = {}
        self._joints: dict = {}
        self._forces: list = []

    def add(self, name: str, subsystem, joint: Joint) -> None:
        """Attach ``subsystem`` under ``name`` by ``joint``."""
        if name in self._subsystems:
            raise ValueError(f"name: a subsystem {name!r} is attached already; each is attached once")
        self._subsystems[name] = subsystem
        self._joints[name] = joint

    def add_force(self, force) -> None:
        """Add a force law (:mod:`projeq.forces`)."""
        self._forces.append(force)

    def build(self, q0=None, s_dot0=None) -> System:
        """The validated System."""
        return System(self._subsystems, self._joints, self.gravity, self._forces, q0, s_dot0)

