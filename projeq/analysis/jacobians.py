"""Jacobians of the equations of motion, exact to round-off: ∂s̈/∂q, ∂s̈/∂ṡ, ∂s̈/∂τ, ∂q̇/∂q, ∂q̇/∂ṡ.

The state derivative ẋ = f(x, τ) = (q̇, s̈) at x = (q, ṡ) is evaluated by the model's own
code in complex arithmetic and differentiated by the complex step, Im f(x + i h e_k) / h with
h = 1e-30 (Squire & Trapp, "Using complex variables to estimate derivatives of real
functions", SIAM Review 40, 1998; Martins, Sturdza & Alonso, ACM TOMS 29, 2003): no difference is taken, so the columns are exact to round-off
for every model whose evaluation is complex-safe — the tree evaluators, user joints, elastic
bodies and constraint equations are. Inner derivatives (a user joint's Ḟ, the constraints'
Φ_q and γ) cannot take a second complex step; they return the first-order imaginary part
by the complex step inside a sixth-order stencil
(:func:`projeq.analysis.differentiation.derivative_along`), ≈ 1e-14 relative.

The evaluation is the model's default one (:meth:`projeq.System.evaluator`): the compiled
kernels where they take the model (:mod:`projeq.assembly.kernels`, numba's complex128
specialization of the same source), all n columns in one compiled call where no Python runs
between the kernels (the evaluator's ``state_jacobian``: trees of revolute, prismatic and
fixed joints with elastic bodies and force laws that have compiled rows, the hub beam), else
column by column through its
``accelerations``; the interpreted reference evaluators for the models the kernels do not take
(their InterpretedWarning says so once) and for constrained systems.

Why the complex step (docs/theory.md, "Exact derivatives", has the measured tables): it
reuses the evaluation code unchanged (one source for s̈ and its derivatives) and costs n
complex evaluations. Compiled, one ∂ẋ/∂x cost 12 (chain of 10, n = 20), 16 (the chain with
every compiled force law), 14 (flexible arm, n = 14), 13 (spin-up beam, n = 16) and 7
(flyball governor, n = 8, two spring-dampers) real compiled evaluations of ẋ in one call;
column by column through ``accelerations`` 24, 43, 27, 39 and 15; forward differences on the
compiled path (n + 1 evaluations, not exact) 21, 29, 21, 31 and 13; the interpreted complex
step 789, 1413, 895, 496 and 420, in the same run (``python benchmarks/compiled_jacobians.py``).
Interpreted, n complex evaluations cost 2.6 (four-bar) and 3.3 (Whipple bicycle, with its
inner derivatives) real interpreted ones each. A symbolic alternative costs more before the
first number: sympy's KanesMethod derivation of the Whipple bicycle
(tests/bicycle/kane_whipple.py) took 110 s, projeq's whole exact linearisation 3.4 s, in one
run (``python benchmarks/jacobians.py`` measures the integrators).
Central differences (``derivatives="differences"``) remain on request, e.g. for user
callables that cannot take complex arguments (then they are used automatically).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import exact_jacobian, jacobian, raised_by, warn_differences
from projeq.system import CLOSED, check_model

DERIVATIVES = ("exact", "differences")


class StateJacobians(NamedTuple):
    """∂s̈/∂q, ∂s̈/∂ṡ, ∂s̈/∂τ, ∂q̇/∂q, ∂q̇/∂ṡ at one state, and how they were taken."""

    s_ddot_q: NDArray
    s_ddot_s_dot: NDArray
    s_ddot_tau: NDArray
    q_dot_q: NDArray
    q_dot_s_dot: NDArray
    derivatives: str


def check_point(system, q, s_dot, t: float, inputs) -> tuple[NDArray, NDArray, tuple]:
    """(q, ṡ, inputs) of a point to differentiate at, checked: the model, the state's shapes and
    values, q on the loop closures (:data:`projeq.system.CLOSED`: off Φ = 0 the Jacobians describe no
    motion of the mechanism), q off a coordinate singularity (``check_configuration``: there A would
    hold K's 1/cos(π/2) ≈ 1e16) and the inputs (:func:`check_inputs`)."""
    check_model(system)
    q, s_dot = system.check_state(q, s_dot, t)
    system.check_closed("q", q, t, CLOSED)
    system.check_configuration(q, t)
    return q, s_dot, check_inputs(system, inputs)


def check_inputs(system, inputs) -> tuple:
    """``inputs`` as a tuple of distinct joint names of ``system``; ValueError naming ``inputs``."""
    if isinstance(inputs, str):  # iterated, a name would be its letters
        raise ValueError(f"inputs: expected a sequence of joint names, got the string {inputs!r} "
                         f"(write [{inputs!r}])")
    inputs = tuple(inputs or ())
    if len(set(inputs)) != len(inputs):
        raise ValueError(f"inputs: each joint at most once, got {list(inputs)}")
    for name in inputs:
        if name not in system.names:
            raise ValueError(f"inputs: unknown joint {name!r}; the system has {list(system.names)}")
    return inputs


def state_derivative(system, x: NDArray, t: float, tau: NDArray | None = None, inputs=()) -> NDArray:
    """ẋ = (q̇, s̈) at x = (q, ṡ); ``tau`` are generalized forces on the joints ``inputs``
    (added to Q of the Gauss form M s̈ + b = Q; for a ConstrainedSystem projected with its F,
    Fᵀ Q_tree). s̈ by the model's default evaluator (the compiled kernels where they take the
    model, their complex128 specialization under a complex step). Complex-safe."""
    q, s_dot = x[: system.n_q], x[system.n_q :]
    if tau is None or not len(inputs):
        s_ddot = system.evaluator(None).accelerations(q, s_dot, t)
    else:
        M, b = system.gauss_form(q, s_dot, t)
        split = np.split(tau, np.cumsum([system.joint(j).n_s for j in inputs])[:-1])
        s_ddot = np.linalg.solve(M, system.generalized_force(q, t, dict(zip(inputs, split))) - b)
    return np.concatenate((system.q_dot(q, s_dot, t), s_ddot))


def differentiate(f, z0: NDArray, derivatives: str = "exact", piece: str = "system",
                  stacklevel: int = 4) -> tuple[NDArray, str]:
    """(∂f/∂z at z0, the method used): the complex step (:func:`exact_jacobian`) for
    ``"exact"``, falling back to Richardson's differences
    (:func:`projeq.analysis.differentiation.jacobian`) where f cannot take complex arguments,
    with one :class:`~projeq.analysis.differentiation.DifferencesWarning` per callable that
    failed (naming it and ``piece``, what is differentiated); the differences alone for
    ``"differences"``."""
    if derivatives not in DERIVATIVES:
        raise ValueError(f"derivatives: expected one of {list(DERIVATIVES)}, got {derivatives!r}")
    if derivatives == "exact":
        try:
            return exact_jacobian(f, z0), "exact"
        except (TypeError, np.exceptions.ComplexWarning) as exc:  # a user callable casts to float
            warn_differences(piece, raised_by(exc), f"{type(exc).__name__}: {exc}", stacklevel=stacklevel)
    return jacobian(f, z0), "differences"


def state_jacobian(system, x: NDArray, t: float, derivatives: str = "exact") -> tuple[NDArray, str]:
    """(∂ẋ/∂x at (x, t), the method used) of ẋ = (q̇, s̈) (:func:`state_derivative`): by the
    complex step through the model's default evaluator — all columns in one compiled call where
    it has one (its ``state_jacobian``: the order-n kernel without Python between its calls, the
    hub beam), else column by column through its ``accelerations`` (compiled, complex128, where
    the kernels take the model) — as :func:`differentiate` says."""
    if derivatives == "exact" and getattr(system, "exact", True) is False:
        derivatives = "differences"  # its constraint callables take no complex arguments (warned when built)
    if derivatives == "exact":
        one_call = getattr(system.evaluator(None), "state_jacobian", None)
        J = None if one_call is None else one_call(t, np.asarray(x, dtype=float))
        if J is not None:
            return J, "exact"
    return differentiate(lambda y: state_derivative(system, y, t), x, derivatives)


def state_jacobians(system, q: NDArray, s_dot: NDArray, t: float = 0.0, inputs=(),
                    derivatives: str = "exact") -> StateJacobians:
    """The Jacobians of q̇ and s̈ at (q, ṡ, t) (module docstring); ``inputs`` name the joints
    whose generalized forces τ are differentiated for (∂s̈/∂τ, zero columns without)."""
    q, s_dot, inputs = check_point(system, q, s_dot, t, inputs)
    x0 = np.concatenate((q, s_dot))
    J, used = state_jacobian(system, x0, t, derivatives)
    n_u = sum(system.joint(name).n_s for name in inputs)
    B, used_B = differentiate(lambda u: state_derivative(system, x0, t, u, inputs), np.zeros(n_u), used)
    n_q = system.n_q
    return StateJacobians(J[n_q:, :n_q], J[n_q:, n_q:], B[n_q:], J[:n_q, :n_q], J[:n_q, n_q:],
                          used if used == used_B else "differences")
