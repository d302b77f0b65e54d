"""Linearisation of the equations of motion about an equilibrium or a steady motion.

The state is x = (q, ṡ) with ẋ = f(x, τ) = (K(q) ṡ + k, s̈(q, ṡ, t, τ)) (docs/theory.md §5, §7);
:func:`linearize` returns δẋ = A δx + B δτ. For non-holonomic systems ṡ are already the
minimal velocities (the constraints are in K and F), so A is the linearisation on the
constraint manifold, not of an unconstrained Lagrangian system with multipliers.

Ignorable coordinates. A vehicle's x, y, heading (a disc's spin angle ...) may not
enter the dynamics of the other states: their columns of A vanish. They are dropped
(detected, or named by the user), and the result says which states remain. Dropping
them also turns a steady motion into an equilibrium of the remaining states: e.g. the
upright rolling disc has θ̇ = −Ω ≠ 0, but θ (with x, y, ψ) is ignorable, and the kept
states (ϕ, ψ̇, ϕ̇, θ̇) are at rest. If the kept states' derivative does not vanish the
state is neither, and a :class:`NotSteadyError` reports the residual — which is what
happens with body-fixed quasi-velocities that rotate with a kept angle (Barhorst's
u1, u3 of the rolling disk with its roll angle q3): use speeds in which the motion is
steady (the knife-edge disc's Euler rates).

Accuracy. The Jacobians are taken by the complex step through the model's own evaluation
(:mod:`projeq.analysis.jacobians`), exact to round-off; the constraints' inner derivatives of
a ConstrainedSystem to ≈ 1e-14 relative. Measured: the Whipple bicycle's eigenvalues agree
with Meijaard et al. (2007), Table 2, to 3e-14 (``tests/bicycle/test_whipple_table2.py``),
the rolling disk's critical speed with its closed form to 1e-12. ``derivatives="differences"``
gives Richardson-extrapolated central differences (h = 1e-4 max(1, |z|): truncation O(h⁴),
round-off ≈ 3ε/h ≈ 1e-11 relative), used anyway for user callables that cannot take complex
arguments.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.jacobians import check_point, differentiate, state_derivative, state_jacobian
from projeq.checks import callable_name, finite_result, flag, positive
from projeq.system import check_model

_TOL = 1e-8  # relative threshold: zero columns of A, and the steady-motion residual


class NotSteadyError(ValueError):
    """The state to linearise about is neither an equilibrium nor a steady motion."""


class Linearization(tuple):
    """(A, B) of δẋ = A δx + B δτ; unpacks as ``A, B = linearize(...)``.

    Attributes
    ----------
    A, B : ndarray
        Jacobians of the kept states' derivative by the kept states and the inputs.
    states : tuple of str
        Names of the kept states, in the order of A's rows: ``"<subsystem>.q[i]"`` and
        ``"<subsystem>.s_dot[i]"`` (i within the subsystem's joint and internal coordinates).
    dropped : tuple of str
        Names of the ignorable coordinates left out.
    inputs : tuple of str
        The input joints (B's columns, each joint's n_s in order).
    """

    def __new__(cls, A, B, states, dropped, inputs):
        self = super().__new__(cls, (A, B))
        self.states, self.dropped, self.inputs = tuple(states), tuple(dropped), tuple(inputs)
        return self

    @property
    def A(self) -> NDArray:
        return self[0]

    @property
    def B(self) -> NDArray:
        return self[1]

    def eigenvalues(self) -> NDArray:
        """Eigenvalues of A, sorted by decreasing real part, then increasing imaginary part."""
        return sorted_eigenvalues(self[0])


def ignorable_coordinates(A: NDArray, n_q: int, tol: float = _TOL) -> list[int]:
    """Indices of the largest set D of coordinates q_i whose columns of A vanish in every
    row not in D (the derivatives of the remaining states do not depend on them).

    Start with the q_i that no s̈ depends on, then remove those that a kept q̇ depends on
    (e.g. a car's heading γ enters ẋ, ẏ but not s̈: γ is ignorable only with x, y).
    """
    zero = np.abs(A) <= tol * max(1.0, np.abs(A).max())
    D = {i for i in range(n_q) if zero[n_q:, i].all()}
    while True:
        kept_q_rows = [r for r in range(n_q) if r not in D]
        smaller = {i for i in D if zero[kept_q_rows, i].all()}
        if smaller == D:
            return sorted(D)
        D = smaller


def linearize(system, q=None, s_dot=None, t: float = 0.0, inputs=None, ignore="auto",
              tol: float = _TOL, require_steady: bool = True, derivatives: str = "exact") -> Linearization:
    """Linearisation δẋ = A δx + B δτ about the state (q, ṡ) at time t.

    Parameters
    ----------
    system : System or ConstrainedSystem
        (a ConstrainedSystem: x = (q, ṡ) with all of its tree's q, holonomically dependent
        ones included, and its minimal velocities ṡ; e.g. ``projeq.scenes.bicycle``)
    q, s_dot : arrays, optional
        The state (default: the system's q0, ṡ0).
    t : float
        Time (for rheonomic systems, e.g. a prescribed steady spin).
    inputs : sequence of joint names, optional
        Joints whose generalized forces τ are the inputs (B's columns).
    ignore : "auto", None or sequence of str/int
        Coordinates to drop: ``"auto"`` those detected by :func:`ignorable_coordinates`,
        ``None`` none, or names (``"car.q[0]"``, see :meth:`projeq.system.Model.state_names`) / indices into q.
    tol : float
        Relative threshold for a vanishing column of A and for the steady-motion residual.
    require_steady : bool
        If False, return the Jacobians at any state (no steady-motion checks).
    derivatives : "exact" or "differences"
        The complex step through the model's evaluation, exact to round-off (the default;
        :mod:`projeq.analysis.jacobians`), or Richardson's central differences on request
        (used anyway where a user callable cannot take complex arguments).

    Returns
    -------
    Linearization
        Unpacks as (A, B); ``.states`` names the kept states.

    Raises
    ------
    NotSteadyError
        If the kept states' derivative at (q, ṡ) exceeds ``tol`` (relative to the largest
        entry of ẋ and 1): neither an equilibrium nor a steady motion.
    ValueError
        If q does not close a ConstrainedSystem's loops (|Φ(q, t)| above
        :data:`projeq.system.CLOSED` relative): no state of the mechanism; or if q is a
        coordinate singularity (``check_configuration``: a joint's K or F loses rank).
    """
    check_model(system)
    q = system.q0 if q is None else q
    s_dot = system.s_dot0 if s_dot is None else s_dot
    q, s_dot, inputs = check_point(system, q, s_dot, t, inputs)
    tol = positive("tol", tol)  # a NaN threshold would pass every state as steady
    require_steady = flag("require_steady", require_steady)
    x0 = np.concatenate((q, s_dot))
    A, derivatives = state_jacobian(system, x0, t, derivatives)
    finite_result("A = ∂ẋ/∂x", A, q=q, s_dot=s_dot)  # a state whose products overflow gives NaN columns
    names = system.state_names()
    dropped = _dropped(system, names, A, ignore, tol)
    kept = [i for i in range(len(x0)) if i not in dropped]
    if require_steady:
        x_dot = state_derivative(system, x0, t)
        _check_steady(x_dot, kept, names, tol)
        _check_invariant(system, x0, x_dot, t, A, dropped, kept, names, derivatives)
    n_u = sum(system.joint(name).n_s for name in inputs)
    B = differentiate(lambda u: state_derivative(system, x0, t, u, inputs), np.zeros(n_u), derivatives)[0]
    finite_result("B = ∂ẋ/∂u", B, q=q, s_dot=s_dot)
    return Linearization(A[np.ix_(kept, kept)], B[kept], [names[i] for i in kept],
                         [names[i] for i in dropped], inputs)


def _dropped(system, names: list[str], A: NDArray, ignore, tol: float) -> list[int]:
    """Indices into x of the coordinates to drop (see :func:`linearize`'s ``ignore``)."""
    if ignore is None:
        return []
    if isinstance(ignore, str) and ignore == "auto":
        return ignorable_coordinates(A, system.n_q, tol)
    if isinstance(ignore, str) or not np.iterable(ignore):
        raise ValueError(f"ignore: must be 'auto', None or a sequence of coordinates, got {ignore!r}")
    indices = []
    for item in ignore:
        if isinstance(item, str) and item in names[: system.n_q]:
            indices.append(names.index(item))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < system.n_q:
            indices.append(int(item))
        else:
            raise ValueError(f"ignore: {item!r} is not a coordinate; use an index 0..{system.n_q - 1} "
                             f"or one of {names[: system.n_q]}")
    return sorted(set(indices))


def _check_steady(x_dot: NDArray, kept: list[int], names: list[str], tol: float) -> None:
    residual = x_dot[kept]
    bound = tol * max(1.0, np.abs(x_dot).max())
    if np.abs(residual).max(initial=0.0) > bound:
        moving = {names[i]: float(x_dot[i]) for i in kept if abs(x_dot[i]) > bound}
        raise NotSteadyError(
            f"q, s_dot: not a steady motion/equilibrium: the kept states' derivative is nonzero, "
            f"max |residual| = {np.abs(residual).max():.3e} > {bound:.1e} ({moving}); drop the "
            f"coordinates the motion does not depend on (ignore=...) or use speeds that are "
            f"constant along the motion"
        )


def _check_invariant(system, x0, x_dot, t, A, dropped, kept, names, derivatives) -> None:
    """Along a steady motion the dropped coordinates move at their rates ẋ_D; A must not
    change with them (ignorable in a neighbourhood of the motion, not only at x0). Checked
    at x0 + τ ẋ_D with τ such that the largest shift is 1; the bound 1e-6 max|A| is far
    above the Jacobians' error (~1e-11) and far below a physical dependence (O(1))."""
    rates = np.zeros_like(x0)
    rates[dropped] = x_dot[dropped]
    if not np.any(rates):
        return  # an equilibrium: nothing moves
    shifted = x0 + rates / np.abs(rates).max()
    A_shifted = state_jacobian(system, shifted, t, derivatives)[0][np.ix_(kept, kept)]
    change = np.abs(A_shifted - A[np.ix_(kept, kept)]).max()
    if change > 1e-6 * max(1.0, np.abs(A).max()):
        moving = [names[i] for i in dropped if x_dot[i]]
        raise NotSteadyError(
            f"q, s_dot: not a steady motion/equilibrium: A changes by {change:.3e} as the dropped "
            f"coordinates {moving} move (the kept speeds are not constant along the motion, e.g. "
            f"body-fixed quasi-velocities that rotate with a dropped angle)"
        )


def sorted_eigenvalues(A: NDArray) -> NDArray:
    lam = np.linalg.eigvals(A).astype(complex)
    return lam[np.lexsort((lam.imag, -lam.real))]


def eigenvalue_sweep(build, values, **options) -> NDArray:
    """Eigenvalues of the linearisation over a swept parameter.

    Parameters
    ----------
    build : callable
        ``build(value)`` returns a System (linearised about its q0, ṡ0) or a tuple
        ``(system, q, s_dot)``.
    values : sequence of float
        The parameter values.
    **options
        Passed to :func:`linearize` (``t``, ``ignore``, ``tol``, ``derivatives``).

    Returns
    -------
    ndarray, shape (len(values), n), complex
        Row k: the eigenvalues at ``values[k]``, sorted by decreasing real part (rows are
        sorted independently; branches are not tracked).
    """
    if not callable(build):
        raise ValueError(f"build: expected a callable build(value) returning a System, got {build!r}")
    if isinstance(values, str) or not np.iterable(values):
        raise ValueError(f"values: expected a sequence of parameter values, got {values!r}")
    values = list(values)
    if not values:
        raise ValueError("values: the sweep is empty; give at least one parameter value")
    rows = []
    for value in values:
        built = build(value)
        if isinstance(built, tuple) and len(built) != 3:
            raise ValueError(f"build: {callable_name(build)}({value!r}) returned a tuple of {len(built)}; "
                             "expected a System or (system, q, s_dot)")
        system, q, s_dot = built if isinstance(built, tuple) else (built, None, None)
        rows.append(linearize(system, q, s_dot, **options).eigenvalues())
    if len({len(r) for r in rows}) > 1:
        raise ValueError(f"values: the number of kept states changes along the sweep "
                         f"({[len(r) for r in rows]}); name the ignorable coordinates with ignore=...")
    return np.array(rows)
