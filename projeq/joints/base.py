"""How subsystems connect: the kinematic chain ẏ_n = T_np ẏ_p + F_n ṡ_n (docs/theory.md §4).

A joint describes the motion of the child frame n relative to a *joint frame* J fixed in
the parent p (placed at ``r_pn`` with ``orientation`` J → p). Every joint returns, at
(q_n, ṡ_n, t), a :class:`Relative`:

- ``A``: child → joint-frame rotation; ``r``: J → O_n in joint-frame coordinates;
- ``F``: F⁶_n, the relative twist (v, ω) of n per unit ṡ_n, in child coordinates;
- ``w``: the relative twist F⁶ ṡ_n + f⁶(t) (f⁶ ≠ 0 for prescribed, rheonomic motion);
- ``zeta``: Ḟ⁶ ṡ_n + ḟ⁶, the joint's own part of ζ_n.

The chain matrix T_np follows from (A, r) once, in :mod:`projeq.assembly.kinematics`, for every
joint alike; positions follow q̇_n = K_n(q) ṡ_n + k_n(q, t).

A joint states its terms once, in ``statement(q_n, t, m)``: the pose (A, r), F⁶ and, where
they are not zero or the identity, f⁶, K and k, as plain scalar code over the namespace ``m``
(:mod:`projeq.joints.statement`). Everything else follows from it: ``relative``, ``K`` and
``q_dot`` (numpy, the reference evaluators; ζ by the complex step through the statement),
``symbolic_relative`` (the statement traced with sympy, for :func:`projeq.symbolic.gauss_form`)
and ``compiled_values`` (the traced form printed for numba: the compiled kernels' C callbacks).
A joint may instead state ``relative`` (and ``K``) and its sympy form ``symbolic_relative``
beside it; its compiled values are then printed from that sympy form. The standard Revolute,
Prismatic and Fixed joints name the compiled kernel that computes the same kinematics,
``compiled_kind`` (:mod:`projeq.assembly.kernels`). A subclass that restates ``statement``,
``relative``, ``K`` or ``q_dot`` loses the forms it inherits that were derived from the
restated terms, unless it restates them as well, so an override is never bypassed.

Letters: ``K`` is q̇ = K ṡ (never a stiffness); ``A`` a rotation; ``t`` time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import central
from projeq.checks import drop_inherited_twins, finite_array
from projeq.joints import statement
from projeq.joints.statement import Stated
from projeq.spatial import vee

if TYPE_CHECKING:
    import sympy as sp


class Relative(NamedTuple):
    """Relative kinematics of a joint at one instant (see the module docstring)."""

    A: NDArray
    r: NDArray
    F: NDArray
    w: NDArray
    zeta: NDArray


class SymbolicRelative(NamedTuple):
    """Relative kinematics of a joint in sympy, at symbols (q_n, ṡ_n, t): ``A``, ``r``,
    ``F`` as in :class:`Relative`, the rheonomic twist ``f`` (f⁶: w = F ṡ + f) and the
    kinematics q̇_n = ``K`` ṡ_n + ``k``. Ḟ ṡ + ḟ follows by differentiation."""

    A: Any  # sp.Matrix (3, 3)
    r: Any  # sp.Matrix (3, 1)
    F: Any  # sp.Matrix (6, n_s)
    f: Any  # sp.Matrix (6, 1)
    K: Any  # sp.Matrix (n_q, n_s)
    k: Any  # sp.Matrix (n_q, 1)


class Joint:
    """Base class: placement on the parent and the bookkeeping shared by all joints.

    Parameters
    ----------
    parent : str or None
        Name of the parent subsystem; ``None`` is the inertial ground.
    r_pn : 3-vector
        Origin of the joint frame in parent coordinates (m).
    orientation : 3×3 rotation, optional
        Joint-frame → parent coordinates (default: aligned).
    coupling : dict, optional
        ``{joint_name: ratio}``: the joint has no coordinate of its own; its coordinate is
        Σ ratio · (that joint's coordinate) — gears, pulleys and ropes. Only for one-dof
        joints with q̇ = ṡ. Shared minimal velocities make ∂ẏ/∂ṡ non-triangular, so such
        systems are evaluated by the dense Gauss form (docs/theory.md §4).
    """

    n_q = 0
    n_s = 0
    n_c = 0  # number of velocity constraints whose residual the joint reports
    # the kind of the compiled kernel (projeq.assembly.kernels.KINDS) computing the same ``relative``:
    # "fixed", or "revolute" / "prismatic" about / along the joint's unit ``axis``; None: none
    compiled_kind: str | None = None
    symbolic_parameters: dict = {}  # {field: what it is} that symbolic_relative takes from gauss_form's parameters

    def __init__(self, parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        if parent is not None and not isinstance(parent, str):
            raise ValueError(f"parent: expected a subsystem name or None, got {parent!r}")
        self.parent = parent
        self.r_pn = finite_array("r_pn", r_pn, (3,))
        self.orientation = _rotation_matrix("orientation", orientation)
        self.coupling = _coupling(coupling, self)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        drop_inherited_twins(cls, Joint, ("statement",), ("relative", "K", "q_dot"))
        drop_inherited_twins(cls, Joint, ("statement", "relative", "K", "q_dot"),
                             ("symbolic_relative", "symbolic_parameters", "compiled_kind", "relative_values",
                              "compiled_values"))

    def statement(self, q_n, t, m) -> Stated:
        """The joint's one statement: pose, F⁶ (and f⁶, K, k) at (q_n, t), written over the
        namespace ``m`` (numpy, or sympy when traced; :mod:`projeq.joints.statement`). A joint that
        states it gets :meth:`relative`, :meth:`K`, :meth:`q_dot`, :meth:`symbolic_relative` and
        :meth:`compiled_values` from it."""
        raise NotImplementedError

    @classmethod
    def states_motion(cls) -> bool:
        """Whether the class's :meth:`statement` is all it says of its motion (it states one and
        restates none of :meth:`relative`, :meth:`K`, :meth:`q_dot`): then its symbolic and
        compiled forms are traced from the statement."""
        return cls.statement is not Joint.statement and all(
            getattr(cls, member) is getattr(Joint, member) for member in ("relative", "K", "q_dot"))

    def relative(self, q_n: NDArray, s_dot_n: NDArray, t: float) -> Relative:
        """Relative kinematics (A, r, F⁶, w, ζ) at (q_n, ṡ_n, t): by default from :meth:`statement`
        (:func:`projeq.joints.statement.relative`)."""
        if type(self).statement is Joint.statement:
            raise NotImplementedError(f"{type(self).__name__}: state its statement(q_n, t, m) or its relative")
        return Relative(*statement.relative(self, q_n, s_dot_n, t))

    def relative_values(self, q_n: NDArray, s_dot_n: NDArray, t: float):
        """The numbers of :meth:`relative` at (q_n, ṡ_n, t) as one flat sequence of 24 + 6 n_s
        floats (complex under a complex step) — A (row by row), r, w, ζ, then F⁶ column by
        column — which the compiled evaluator reads for a joint whose kinematics it does not
        compute itself (kind GIVEN, :mod:`projeq.assembly.fast`). By default :meth:`relative`,
        packed; a joint may state the same numbers faster (a UserJoint from sympy: scalar code
        of its expressions)."""
        rel = self.relative(q_n, s_dot_n, t)
        return np.concatenate((rel.A.ravel(), rel.r, rel.w, rel.zeta, rel.F.T.ravel()))

    def compiled_values(self):
        """``values(q_n, ṡ_n, t)`` -> the numbers of :meth:`relative_values` followed by q̇_n = K ṡ_n + k
        (n_q entries), printed as scalar numpy code that numba compiles
        (:func:`projeq.joints.statement.printed`), for the compiled kernels (:mod:`projeq.assembly.given`):
        by default from the joint's sympy form (:meth:`symbolic_relative`, traced from its statement
        or its own, built once per joint; its numbers passed to the compiled code as data); None
        where the joint has no sympy form, or one that needs ``symbolic_parameters`` (it is then
        stated in Python only)."""
        if not (self.states_motion() or type(self).symbolic_relative is not Joint.symbolic_relative) \
                or self.symbolic_parameters:
            return None
        if "_printed" not in self.__dict__:
            self._printed = statement.printed(self)
        return self._printed

    def symbolic_relative(self, q_n, s_n, t: sp.Symbol, **parameters) -> SymbolicRelative:
        """The same kinematics as :meth:`relative` and :meth:`K` in sympy, at the symbols or
        expressions q_n, ṡ_n (``s_n``) and t; ``parameters`` are the fields named in
        ``symbolic_parameters``; by default the :meth:`statement` traced with sympy. Raises
        NotImplementedError with the reason (completing "joint 'name' ...") when the joint has no
        symbolic form."""
        if self.states_motion():
            return SymbolicRelative(*statement.traced(self, q_n, t))
        raise NotImplementedError(
            f"({type(self).__name__}) is not supported symbolically; state its symbolic_relative, "
            "or use projection_equation with its velocity expressions"
        )

    def K(self, q_n: NDArray, t: float) -> NDArray:
        """K_n(q) of q̇_n = K_n ṡ_n + k_n: the statement's, else the identity (q̇ = ṡ)."""
        if type(self).statement is not Joint.statement:
            return statement.stated(self, q_n, t).K
        return np.eye(self.n_q, self.n_s)

    def q_dot(self, q_n: NDArray, s_dot_n: NDArray, t: float) -> NDArray:
        """q̇_n = K_n(q) ṡ_n + k_n(q, t)."""
        if type(self).statement is not Joint.statement and type(self).K is Joint.K:
            return statement.rates(self, q_n, s_dot_n, t)
        return self.K(q_n, t) @ s_dot_n

    def coordinates(self) -> tuple:
        """(name, unit) of each coordinate q_n, in order: what results, tables and plots call
        them (``"<subsystem>.<name>"``). Default ``("q[i]", "")``, unit unknown; the standard
        joints state theirs (a revolute joint's ``("angle", "rad")``)."""
        return tuple((f"q[{i}]", "") for i in range(self.n_q))

    def velocities(self) -> tuple:
        """(name, unit) of each minimal velocity ṡ_n, in order (default ``("s_dot[i]", "")``)."""
        return tuple((f"s_dot[{i}]", "") for i in range(self.n_s))

    def default_q(self) -> NDArray:
        """Coordinates of the reference configuration (zero unless a joint says otherwise)."""
        return np.zeros(self.n_q)

    def constraint_residual(self, q_n: NDArray, q_dot_n: NDArray, t: float) -> NDArray:
        """Residuals of the velocity constraints the minimal velocities are meant to
        satisfy, evaluated on (q, q̇) (none for the built-in joints)."""
        return np.zeros(0)

    def normalized(self, q_n: NDArray) -> NDArray:
        """q_n projected back onto its manifold (unit quaternions); identity otherwise."""
        return q_n

    def __repr__(self) -> str:
        return f"{type(self).__name__}(parent={self.parent!r})"


def _rotation_matrix(name: str, value) -> NDArray:
    if value is None:
        return np.eye(3)
    A = finite_array(name, value, (3, 3))
    if np.abs(A.T @ A - np.eye(3)).max() > 1e-9 or np.linalg.det(A) < 0:
        raise ValueError(f"{name}: not a proper rotation matrix (AᵀA ≠ E or det < 0):\n{A}")
    return A


def _coupling(coupling, joint) -> dict:
    if not coupling:
        return {}
    if not isinstance(coupling, dict):
        raise ValueError(f"coupling: expected {{joint_name: ratio}}, got {coupling!r}")
    ratios = {name: float(finite_array(f"coupling[{name!r}]", ratio, ())) for name, ratio in coupling.items()}
    for name, ratio in ratios.items():
        if ratio == 0.0:  # Σ ratio · q_other: this term is nothing
            raise ValueError(f"coupling[{name!r}]: a ratio of 0 couples nothing, got 0.0; leave {name!r} out "
                             "(a joint that follows no joint at all is a Fixed joint)")
    return ratios


def pose_twist_mismatch(joint: Joint, q_n: NDArray, s_dot_n: NDArray, t: float, h: float = 1e-7) -> float:
    """Largest difference between F⁶ ṡ + f⁶ and the relative twist obtained by
    differentiating the pose (A, r) along q̇ = K ṡ + k (central differences, step h).

    Used to validate user joints; for the built-in joints it is a test of their K.
    """
    q_dot = joint.q_dot(q_n, s_dot_n, t)

    def pose(eps):  # (A, r) at (q + ε q̇, t + ε), flattened
        rel = joint.relative(joint.normalized(q_n + eps * q_dot), s_dot_n, t + eps)
        return np.concatenate((rel.A.ravel(), rel.r))

    rates = central(pose, h)
    A_dot, r_dot = rates[:9].reshape(3, 3), rates[9:]
    now = joint.relative(q_n, s_dot_n, t)
    twist = np.concatenate((now.A.T @ r_dot, vee(now.A.T @ A_dot)))
    return float(np.abs(twist - now.w).max())
