"""Integrators for long runs and stiff models, beside the methods of ``solve_ivp``.

Two concerns of the numerics at the extremes (issue 7, item 4):

* **Drift over long runs.** An explicit Runge–Kutta method lets the energy of a
  conservative scleronomic system random-walk and drift: its error grows with the number
  of steps. The *projection methods* ``"RK45-projected"`` and ``"DOP853-projected"`` take
  the base method's step and then project the state x = (q, ṡ) back onto the invariant
  manifold E(q, ṡ) = E₀ (Hairer, Lubich, Wanner, *Geometric Numerical Integration*,
  2nd ed., §IV.4, Algorithm 4.2: standard projection), with Newton steps along ∇E, and
  normalise q (unit quaternions, :meth:`projeq.System.normalized`). Velocity constraints
  need no projection: with minimal velocities q̇ = K(q)ṡ satisfies them identically. The
  energy error then stays at round-off over any number of steps; the phase error still
  grows linearly, as for the base method.
* **Stiffness.** An explicit method on a stiff model (a beam whose axial modes are 10³
  times faster than its bending modes) does not fail: it crawls at the step its stability
  region allows. :func:`warn_if_stiff` recognises such a crawl after a segment of
  :func:`projeq.simulate` and warns (:class:`StiffnessWarning`) with the suggestion of an
  implicit method.

``PROJECTED`` maps the method names :func:`projeq.simulate` accepts to their base method.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import DOP853, RK45, DenseOutput, OdeSolver

from projeq.analysis.differentiation import central, forward, gradient

PROJECTED = {"RK45-projected": RK45, "DOP853-projected": DOP853}
EXPLICIT = ("RK45", "RK23", "DOP853", *PROJECTED)


class StiffnessWarning(UserWarning):
    """An explicit integrator's steps are limited by stability, not accuracy."""


def energy_manifold(system, q0, s_dot0, t0: float = 0.0):
    """The projection x ↦ x* onto {E(x) = E₀} of a conservative scleronomic ``system``.

    E(x) = T + V = ½ṡᵀMṡ + V(q) (:meth:`projeq.System.energy`), E₀ = E(q0, ṡ0). The map
    does simplified Newton steps x ← x − (E(x) − E₀) ∇E/|∇E|² (HLW §IV.4, Algorithm 4.2,
    with one invariant; ∇E once, at the first iterate, by forward differences) until
    |E − E₀| is at round-off (≤ 4 ε (|T| + |V|)), at most 4 steps, then normalises q.
    After a step of an integrator one or two Newton steps suffice: 2 + n_x (+1) energy
    evaluations for a state of n_x entries.
    ValueError if E changes along the flow at the initial state (a driven joint or a
    non-conservative force): its energy is not an invariant to project on.

    >>> import projeq as pq
    >>> system = pq.scenes.double_pendulum()
    >>> project = energy_manifold(system, system.q0, [0.0, 0.0])
    >>> x = project(0.0, [1.5, 0.1, 0.01, -0.02])  # a state near the manifold
    >>> bool(abs(sum(system.energy(x[:2], x[2:])) - sum(system.energy(system.q0, [0.0, 0.0]))) < 1e-14)
    True
    """
    n_q = system.n_q

    def energy(x: NDArray, t: float) -> tuple[float, float]:
        T, V = system.energy(system.normalized(x[:n_q]), x[n_q:], t)
        return T + V, abs(T) + abs(V)

    x0 = np.concatenate((np.asarray(q0, dtype=float), np.asarray(s_dot0, dtype=float)))
    E0 = energy(x0, t0)[0]
    _check_conservative(system, x0, t0, energy)

    def project(t: float, x) -> NDArray:
        x = np.array(x, dtype=float)
        E, scale = energy(x, t)
        grad = None
        for _ in range(4):
            if abs(E - E0) <= 4 * np.finfo(float).eps * max(scale, abs(E0)):
                break
            if grad is None:  # simplified Newton: ∇E at the first iterate serves all
                # forward differences (given E): O(h) error, ample for Newton steps, whose
                # error shrinks by that factor per step
                grad = gradient(lambda x_: energy(x_, t)[0], x, E)
            x -= (E - E0) * grad / (grad @ grad)
            E, scale = energy(x, t)
        x[:n_q] = system.normalized(x[:n_q])
        return x

    return project


def _check_conservative(system, x0: NDArray, t0: float, energy) -> None:
    """ValueError unless dE/dt = ∇E · ẋ + ∂E/∂t ≈ 0, relative to the size of its terms
    |∇E| |ẋ| + |∂E/∂t| (central differences are good to ~1e-10 of it), at the initial
    state and at probes: later times (a prescribed motion may start from rest, with zero
    drive power at t0) and perturbed velocities (a damper does no work at rest)."""
    n_q = system.n_q
    rng = np.random.default_rng(0)
    s_dot_probe = x0[n_q:] + 0.1 * (1.0 + np.abs(x0[n_q:])) * rng.standard_normal(len(x0) - n_q)
    for t in (t0, t0 + 0.37, t0 + 1.9):
        for x in (x0, np.concatenate((x0[:n_q], s_dot_probe))):
            E_dot = _energy_rate(system, x, t, energy)
            if E_dot is not None:
                raise ValueError(
                    f"method: the projected integrators keep the energy constant, but this system's energy "
                    f"changes along its motion (dE/dt = {E_dot:.3g} at t = {t:.3g}); it is not conservative "
                    "and scleronomic (a driven or prescribed joint, a damper or a time-dependent load): use a "
                    "method of solve_ivp"
                )


def _energy_rate(system, x: NDArray, t: float, energy) -> float | None:
    """dE/dt at (t, x) if it is distinguishable from zero, else None."""
    n_q = system.n_q
    q, s_dot = system.normalized(x[:n_q]), x[n_q:]
    x_dot = np.concatenate((system.q_dot(q, s_dot, t), system.accelerations(q, s_dot, t)))
    E_t = central(lambda eps: energy(x, t + eps)[0], 1e-6 * (1.0 + abs(t)))
    grad = gradient(lambda x_: energy(x_, t)[0], x)
    E_dot = grad @ x_dot + E_t
    return E_dot if abs(E_dot) > 1e-6 * (np.linalg.norm(grad) * np.linalg.norm(x_dot) + abs(E_t)) else None


def projected_solver(name: str, system, q0, s_dot0, t0: float = 0.0) -> type[OdeSolver]:
    """The OdeSolver class for ``simulate(..., method=name)``, name in :data:`PROJECTED`:
    the base method's steps followed by the projection of :func:`energy_manifold`."""
    project = energy_manifold(system, q0, s_dot0, t0)
    return type(name, (_ProjectedSolver,), {"base": PROJECTED[name], "project": staticmethod(project)})


class _ProjectedSolver(OdeSolver):
    """Steps of ``base`` (an explicit RK class), each followed by ``project(t, y)``.

    The base keeps its own step-size control; after the projection its state y and its
    first-same-as-last derivative f are replaced (one extra evaluation per step). Dense
    output is the base's interpolant, projected at each requested time.
    """

    base: type[OdeSolver]
    project = None

    def __init__(self, fun, t0, y0, t_bound, vectorized=False, **options):
        options.pop("jac", None)  # explicit bases take no Jacobian
        self._inner = self.base(fun, t0, y0, t_bound, **options)
        super().__init__(fun, t0, y0, t_bound, vectorized)
        self.nfev = self._inner.nfev

    def _step_impl(self):
        inner = self._inner
        inner.step()
        self.nfev = inner.nfev
        if inner.status == "failed":
            return False, "the base method failed: step size too small"
        inner.y = self.project(inner.t, inner.y)
        inner.f = inner.fun(inner.t, inner.y)
        self.nfev = inner.nfev
        self.t, self.y = inner.t, inner.y.copy()
        return True, None

    def _dense_output_impl(self):
        return _ProjectedDenseOutput(self.t_old, self.t, self._inner.dense_output(), self.project)


class _ProjectedDenseOutput(DenseOutput):
    def __init__(self, t_old, t, interpolant, project):
        super().__init__(t_old, t)
        self._interpolant, self._project = interpolant, project

    def _call_impl(self, t):
        y = self._interpolant(t)
        if y.ndim == 1:
            return self._project(t, y)
        return np.column_stack([self._project(ti, yi) for ti, yi in zip(np.atleast_1d(t), y.T)])


def spectral_radius(fun, t: float, x: NDArray, iterations: int = 32) -> float:
    """ρ(∂f/∂x) at (t, x) by power iteration on finite-difference products
    Jv ≈ (f(x + εv) − f(x))/ε: the geometric mean growth ‖J v_k‖ over an even number of
    the last iterations (for an undamped mode, a pair ±iω, the growth alternates between
    ω²|a|/|b| and |b|/|a| for a vector (a, b) of coordinate and rate: a pair's mean is ω).
    Costs ``iterations`` + 1 evaluations of f."""
    x = np.asarray(x, dtype=float)
    f0 = fun(t, x)
    v = np.cos(np.arange(len(x)) + 1.0)  # a fixed start with components along every axis
    v /= np.linalg.norm(v)
    logs = []
    for _ in range(iterations):
        eps = np.sqrt(np.finfo(float).eps) * (1.0 + np.linalg.norm(x))
        w = forward(lambda e: fun(t, x + e * v), eps, f0)
        norm = np.linalg.norm(w)
        if not norm > 0:
            return 0.0
        logs.append(np.log(norm))
        v = w / norm
    return float(np.exp(np.mean(logs[-2 * (iterations // 4):])))


def warn_if_stiff(fun, segment, method, rtol: float) -> bool:
    """Warn (:class:`StiffnessWarning`) if an explicit ``method``'s steps in ``segment``
    (a solve_ivp result with dense output) sit at its stability limit; True if it warned.

    The criterion: mean step h with ρ h ≥ 1 (ρ = :func:`spectral_radius` at the segment's
    end), over at least 50 steps, at rtol ≤ 1e-5. At such tolerances a mode with ρ h ≥ 1
    would be integrated with a local error of order (ρh)⁵ ≫ rtol, so the error control can
    only accept these steps because the fast mode is hardly excited: the step is set by
    stability, the definition of stiffness, and an implicit method could take far larger
    ones.
    """
    if method not in EXPLICIT or rtol > 1e-5:
        return False
    n_steps = len(segment.sol.ts) - 1
    if n_steps < 50:
        return False
    h = (segment.sol.ts[-1] - segment.sol.ts[0]) / n_steps
    rho = spectral_radius(fun, segment.sol.ts[-1], segment.sol(segment.sol.ts[-1]))
    if rho * h < 1.0:
        return False
    warnings.warn(
        f"method: {method!r} is explicit and crawls at its stability limit (mean step {h:.3g} s, "
        f"fastest mode {rho:.3g} 1/s, ρh = {rho * h:.2g}): the model is stiff (a very stiff beam, or a "
        "pose near a coordinate singularity); try method='Radau' or 'BDF'",
        StiffnessWarning,
        stacklevel=3,
    )
    return True
