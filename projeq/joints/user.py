"""User-defined joints: the door for non-holonomic minimal velocities (docs/theory.md §4).

The pose, F, K (and the rheonomic f, k) are given as sympy expressions or as callables and
compiled once by :mod:`projeq.joints.user_compiler`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np

from projeq.checks import callable_name, count, finite_array
from projeq.joints.base import Joint, SymbolicRelative

if TYPE_CHECKING:
    import sympy as sp


class UserJoint(Joint):
    """A joint defined by its pose and minimal velocities: the door for non-holonomic ṡ.

    The child's pose relative to the joint frame is (A(q, t), r(q, t)); its relative twist
    (v, ω) in child coordinates is F⁶(q, t) ṡ + f⁶(q, t); positions follow
    q̇ = K(q, t) ṡ + k(q, t). The minimal velocities ṡ may be quasi-velocities, and a
    velocity constraint goes in *before* the derivation by leaving its direction out of F
    (Bremer's car: ṡ = (v_x, ω_z), B(11)). Ḟ ṡ + ḟ is obtained by differentiation along
    q̇ (symbolically, or by complex-step for callables), and the pose is checked against
    F and K at construction.

    Build with :meth:`from_sympy` or :meth:`from_functions`. ``symbols`` holds the
    expressions of a joint from sympy ({"q", "s", "t", "A", "r", "F", "K", "f", "k"}),
    None for one from callables.
    """

    def __init__(self, parent, n_q, n_s, relative, K, q_dot, q0=None, r_pn=(0, 0, 0), orientation=None,
                 constraints=None, n_c=0, symbols: dict | None = None, values=None, rates=None, compiled=None):
        super().__init__(parent, r_pn, orientation)
        self.n_q, self.n_s, self.n_c = n_q, n_s, count("n_c", n_c, 0)
        if n_c and constraints is None:  # the residuals' rows would be announced but never given
            raise ValueError(f"n_c: {n_c} constraint residual(s) announced, but no constraints function gives "
                             "them; pass constraints=... or leave n_c = 0")
        self._relative, self._K, self._q_dot = relative, K, q_dot
        self._values = values  # (q_n, ṡ_n, t) as lists -> relative_values, or None: relative packed
        self._rates = rates  # (q_n, ṡ_n, t) as lists -> q̇_n as a list, or None: q_dot alone
        self._compiled = compiled  # () -> compiled_values(), or None: none
        self._constraints = constraints
        self._q0 = np.zeros(n_q) if q0 is None else finite_array("q0", q0, (n_q,))
        self.symbols = symbols

    def relative(self, q_n, s_dot_n, t):
        return self._relative(q_n, s_dot_n, t)

    def K(self, q_n, t):
        return self._K(q_n, t)

    def relative_values(self, q_n, s_dot_n, t):
        """:meth:`Joint.relative_values`; from sympy at real arrays: the same expressions as
        :meth:`relative`, compiled to scalar code (``math``) on Python floats, about ten times
        faster (complex ones, of a complex step, take the numpy form)."""
        if self._values is None or not (_real(q_n) and _real(s_dot_n)) or isinstance(t, complex):
            return super().relative_values(q_n, s_dot_n, t)
        return self._values(q_n.tolist(), s_dot_n.tolist(), t)

    def symbolic_relative(self, q_n, s_n, t):
        """The expressions of :meth:`from_sympy` with the given symbols put in."""
        if self.symbols is None:
            raise NotImplementedError("(UserJoint from callables) has no expressions; build it with "
                                      "UserJoint.from_sympy to derive it symbolically")
        symbols = self.symbols
        rename = dict(zip(symbols["q"], q_n)) | dict(zip(symbols["s"], s_n)) | {symbols["t"]: t}
        return SymbolicRelative(*(symbols[key].xreplace(rename) for key in ("A", "r", "F", "f", "K", "k")))

    def compiled_values(self):
        """``values(q_n, ṡ_n, t)`` -> the array of :meth:`relative_values` (A, r, w, ζ, F⁶) and q̇_n =
        K ṡ_n + k (:meth:`projeq.joints.base.Joint.compiled_values`), the same expressions printed as scalar numpy code that numba compiles
        (:func:`projeq.joints.user_compiler.printed_values`), printed once per statement and
        made once per parameter values in a process (:func:`projeq.joints.user_compiler.derive`);
        None for a joint from callables."""
        return None if self._compiled is None else self._compiled()

    @property
    def rates_are_speeds(self) -> bool:
        """Whether q̇ = ṡ identically (a joint from sympy with K = E and k = 0)."""
        symbols = self.symbols
        return symbols is not None and bool(symbols["K"].is_Identity) and bool(symbols["k"].is_zero_matrix)

    def q_dot(self, q_n, s_dot_n, t):
        """q̇_n = K ṡ_n + k; from sympy at real arrays: the same expressions compiled to scalar
        code (``math``) on Python floats, as :meth:`relative_values` (complex ones, of a complex
        step, take the numpy form)."""
        if self._rates is not None and _real(q_n) and _real(s_dot_n) and not isinstance(t, complex):
            return np.array(self._rates(q_n.tolist(), s_dot_n.tolist(), t))
        return self._q_dot(q_n, s_dot_n, t)

    def default_q(self):
        return self._q0.copy()

    def coordinates(self):
        """A joint from sympy: its symbols' names (units unknown); else the default q[i]."""
        if self.symbols is None:
            return super().coordinates()
        return tuple((str(symbol), "") for symbol in self.symbols["q"])

    def velocities(self):
        if self.symbols is None:
            return super().velocities()
        return tuple((str(symbol), "") for symbol in self.symbols["s"])

    def constraint_residual(self, q_n, q_dot_n, t):
        if self._constraints is None:
            return np.zeros(0)
        try:
            residual = self._constraints(q_n, q_dot_n, t)
        except Exception as exc:  # noqa: BLE001 - the user's callable, reported by name
            raise ValueError(f"constraints: {callable_name(self._constraints)} raised {type(exc).__name__}: {exc} "
                             f"at t = {t:.6g}, q = {np.round(q_n, 6).tolist()}") from exc
        return finite_array(f"constraints ({callable_name(self._constraints)}) at t = {t:.6g}",
                            np.ravel(residual), (self.n_c,))

    @classmethod
    def from_sympy(
        cls,
        q: Sequence[sp.Symbol],
        s: Sequence[sp.Symbol],
        A,
        r,
        F,
        K,
        *,
        f=None,
        k=None,
        t: sp.Symbol | None = None,
        parameters: dict | None = None,
        constraints=None,
        q_dot: Sequence[sp.Symbol] | None = None,
        parent=None,
        q0=None,
        r_pn=(0.0, 0.0, 0.0),
        orientation=None,
    ) -> "UserJoint":
        """A user joint from sympy expressions in the coordinates ``q``, the minimal
        velocities ``s`` (ṡ), time ``t`` and ``parameters`` ({symbol: value}).

        ``A`` (3×3) and ``r`` (3) give the pose, ``F`` (6×n_s) and ``f`` (6) the relative
        twist F ṡ + f in child coordinates, ``K`` (n_q×n_s) and ``k`` (n_q) give q̇.
        Ḟ ṡ + ḟ = (∂F/∂q q̇ + ∂F/∂t) ṡ + ∂f/∂q q̇ + ∂f/∂t is derived and lambdified once per
        process for the same statement (symbols, expressions, constraints, the parameters'
        symbols: :func:`projeq.joints.user_compiler.derive`, which keeps the last
        :data:`~projeq.joints.user_compiler.DERIVED_SIZE`), the parameters' values passed at
        run time; their values, ``parent``, ``q0``, ``r_pn`` and ``orientation`` are each joint's
        own. ``constraints`` lists the original velocity constraints (expressions in q, the
        symbols ``q_dot`` for q̇, and t) whose residuals every Result reports.
        """
        from projeq.joints.user_compiler import compile_user_joint

        return compile_user_joint(
            cls, q, s, A, r, F, K, f=f, k=k, t=t, parameters=parameters or {},
            parent=parent, q0=q0, r_pn=r_pn, orientation=orientation,
            constraints=constraints, q_dot=q_dot,
        )

    @classmethod
    def from_functions(
        cls,
        n_q: int,
        n_s: int,
        pose: Callable,
        F: Callable,
        K: Callable,
        *,
        f: Callable | None = None,
        k: Callable | None = None,
        constraints: Callable | None = None,
        n_c: int = 0,
        parent=None,
        q0=None,
        r_pn=(0.0, 0.0, 0.0),
        orientation=None,
    ) -> "UserJoint":
        """A user joint from callables ``pose(q, t) -> (A, r)``, ``F(q, t)``, ``K(q, t)``
        (and optionally ``f(q, t)``, ``k(q, t)``).

        Ḟ ṡ + ḟ is taken by complex-step differentiation along (q̇, 1), exact to
        round-off, so the callables must accept complex arguments (numpy ufuncs do).
        ``constraints(q, q_dot, t)`` returns the ``n_c`` residuals of the original velocity
        constraints, reported along every simulated trajectory.
        """
        from projeq.joints.user_compiler import wrap_user_functions

        return wrap_user_functions(
            cls, n_q, n_s, pose, F, K, f=f, k=k, parent=parent, q0=q0, r_pn=r_pn,
            orientation=orientation, constraints=constraints, n_c=n_c,
        )


def _real(x) -> bool:
    """Whether x is a real float array (what the scalar code of a joint from sympy takes)."""
    return isinstance(x, np.ndarray) and x.dtype == np.float64
