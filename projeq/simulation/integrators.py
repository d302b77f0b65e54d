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
  region allows. :func:`stiff_steps` recognises such a crawl over the steps of a run of
  :func:`projeq.simulate` so far (whatever its segments): a run whose method simulate chose
  goes on with Radau, one whose explicit method the user chose gets a
  :class:`StiffnessWarning` (:func:`warn_stiff`) with the suggestion of an implicit method.

``PROJECTED`` maps the method names :func:`projeq.simulate` accepts to their base method.
"""

from __future__ import annotations

import functools

import warnings

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import BDF, DOP853, RK23, RK45, DenseOutput, OdeSolver, Radau
from scipy.linalg import LinAlgWarning, get_lapack_funcs

from projeq.analysis.differentiation import (attempt_complex, central, complex_step, exact_jacobian, forward,
                                             is_complex_safe)
from projeq.analysis.differentiation import jacobian as richardson_jacobian
from projeq.analysis.jacobians import DERIVATIVES, differentiate

PROJECTED = {"RK45-projected": RK45, "DOP853-projected": DOP853}
EXPLICIT = ("RK45", "RK23", "DOP853", *PROJECTED)


class StiffnessWarning(UserWarning):
    """An explicit integrator's steps are limited by stability, not accuracy."""


def energy_manifold(system, q0, s_dot0, t0: float = 0.0):
    """The projection x ↦ x* onto {E(x) = E₀} of a conservative scleronomic ``system``.

    E(x) = T + V = ½ṡᵀMṡ + V(q) (:meth:`projeq.System.energy`), E₀ = E(q0, ṡ0). The map
    does simplified Newton steps x ← x − (E(x) − E₀) ∇E/|∇E|² (HLW §IV.4, Algorithm 4.2,
    with one invariant; ∇E once, at the first iterate, exact by the complex step through
    the energy and q's normalisation, :func:`energy_gradient`) until |E − E₀| is at
    round-off (≤ 4 ε (|T| + |V|)), at most 4 steps, then normalises q. After a step of an
    integrator one or two Newton steps suffice: 2 real and n_x complex energy evaluations
    for a state of n_x entries.
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
    energy = _energy_function(system)
    x0 = np.concatenate((np.asarray(q0, dtype=float), np.asarray(s_dot0, dtype=float)))
    E0 = energy(x0, t0)[0]
    change = _energy_change(system, x0, t0)
    if change is not None:
        raise ValueError(
            f"method: the projected integrators keep the energy constant, but this system's energy "
            f"changes along its motion (dE/dt = {change[0]:.3g} at t = {change[1]:.3g}); it is not conservative "
            "and scleronomic (a driven or prescribed joint, a damper or a time-dependent load): use a "
            "method of solve_ivp"
        )

    def project(t: float, x) -> NDArray:
        x = np.array(x, dtype=float)
        E, scale = energy(x, t)
        grad = None
        for _ in range(4):
            if abs(E - E0) <= 4 * np.finfo(float).eps * max(scale, abs(E0)):
                break
            if grad is None:  # simplified Newton: ∇E at the first iterate serves all
                grad = energy_gradient(system, x, t)
            x -= (E - E0) * grad / (grad @ grad)
            E, scale = energy(x, t)
        x[:n_q] = system.normalized(x[:n_q], t)
        return x

    return project


def conserves_energy(system, q0, s_dot0, t0: float = 0.0) -> bool:
    """Whether the energy T + V of ``system`` stays constant along its motions: False for a
    prescribed (driven) motion, a damper or a time-dependent load, detected as dE/dt ≠ 0 at
    (q0, ṡ0, t0) or at the probes of :func:`_energy_change`."""
    x0 = np.concatenate((np.asarray(q0, dtype=float), np.asarray(s_dot0, dtype=float)))
    return _energy_change(system, x0, t0) is None


def _energy_function(system):
    """x ↦ (E, |T| + |V|) at time t, with q normalised."""
    n_q = system.n_q

    def energy(x: NDArray, t: float) -> tuple[float, float]:
        T, V = system.energy(system.normalized(x[:n_q], t), x[n_q:], t)
        return T + V, abs(T) + abs(V)

    return energy


def energy_gradient(system, x: NDArray, t: float) -> NDArray:
    """∇E at (x, t) of E = T + V with q normalised (as the projection evaluates it): exact to
    round-off by the complex step through the model's energy (complex-safe: the normalisation,
    a ConstrainedSystem's Gauss–Newton steps onto Φ = 0 and its F included), by Richardson's
    differences where the model's callables cannot take complex arguments
    (:func:`projeq.analysis.jacobians.differentiate`)."""
    return differentiate(lambda x_: _energy_value(system, x_, t), x)[0][0]


def _energy_value(system, x: NDArray, t) -> NDArray:
    """[E(x, t)] with q normalised, complex under a complex step in x or t."""
    T, V = system.energy(system.normalized(x[:system.n_q], t), x[system.n_q:], t)
    return np.atleast_1d(T + V)


def _energy_change(system, x0: NDArray, t0: float) -> tuple[float, float] | None:
    """(dE/dt, t) where dE/dt = ∇E · ẋ + ∂E/∂t is distinguishable from 0, relative to the
    size of its terms |∇E| |ẋ| + |∂E/∂t| (:func:`energy_gradient`: exact to round-off), at
    the initial state and at probes: later times (a prescribed motion may start from rest,
    with zero drive power at t0) and perturbed velocities (a damper does no work at rest);
    None where it is zero at all of them."""
    n_q = system.n_q
    rng = np.random.default_rng(0)
    s_dot_probe = x0[n_q:] + 0.1 * (1.0 + np.abs(x0[n_q:])) * rng.standard_normal(len(x0) - n_q)
    for t in (t0, t0 + 0.37, t0 + 1.9):
        for x in (x0, np.concatenate((x0[:n_q], s_dot_probe))):
            E_dot = _energy_rate(system, x, t)
            if E_dot is not None:
                return E_dot, t
    return None


def _energy_rate(system, x: NDArray, t: float) -> float | None:
    """dE/dt at (t, x) if it is distinguishable from zero, else None."""
    n_q = system.n_q
    q, s_dot = system.normalized(x[:n_q], t), x[n_q:]
    x_dot = np.concatenate((system.q_dot(q, s_dot, t), system.accelerations(q, s_dot, t)))
    grad = energy_gradient(system, x, t)
    # ∂E/∂t apart: a prescribed motion or a time-dependent load may take only real times
    E_t = differentiate(lambda t_: _energy_value(system, x, t_[0]), np.array([t]))[0][0, 0]
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


def spectral_radius(fun, t: float, x: NDArray, iterations: int = 32, jacobian=None,
                    derivatives: str = "exact") -> float:
    """ρ(∂f/∂x) at (t, x) (:func:`fastest_mode`, which says how and at what cost)."""
    return fastest_mode(fun, t, x, iterations, jacobian, derivatives)[0]


DECAYING = 0.1  # a fastest eigenvalue λ with |Im λ| ≤ DECAYING ρ and Re λ < 0 decays without oscillating


def fastest_mode(fun, t: float, x: NDArray, iterations: int = 32, jacobian=None,
                 derivatives: str = "exact") -> tuple[float, bool]:
    """(ρ, decays) of J = ∂f/∂x at (t, x): ρ the spectral radius, ``decays`` whether the fastest
    mode is a real eigenvalue λ ≈ −ρ (a stiff damper, not an oscillation: Re λ < 0 and
    |Im λ| ≤ 0.1 ρ, a damping ratio ≥ 0.995).

    Exact where the derivatives are (issue 16), the first of these that applies:

    * ``jacobian(t, x)``, the model's exact ∂f/∂x in one call (a compiled evaluator's
      ``state_jacobian``, :func:`projeq.analysis.jacobians.state_jacobian`), when given, not
      None and n_x ≤ 2 ``iterations`` (beyond, n_x columns and an O(n_x³) eigenvalue problem
      cost more than the power iteration: chain(30), n_x = 60, 6.5 vs 5.1 ms; chain(100),
      n_x = 200, 97 vs 11 ms): its eigenvalues (``numpy.linalg.eigvals``, LAPACK's QR
      algorithm), ρ = max |λ|;
    * for n_x ≤ ``iterations`` and a complex-safe f: the eigenvalues of J by the complex step
      column by column (:func:`projeq.analysis.differentiation.exact_jacobian`, n_x + 1 complex
      evaluations of f with the check, fewer than the power iteration's);
    * power iteration (Golub & Van Loan, "Matrix Computations", 4th ed. (2013), §7.3.1) on the
      products J v = Im f(x + i h v)/h, the complex step along v (exact to round-off,
      :func:`projeq.analysis.differentiation.complex_step`), for a complex-safe f;
    * power iteration on forward-difference products (f(x + εv) − f(x))/ε, ε = √ε_m (1 + |x|),
      only for an f that cannot take complex states (a user's callable that casts to float, a
      compiled right-hand side for real states such as simulate's fused ``state_derivative``).

    The power iteration: ρ is the geometric mean growth ‖J v_k‖ over an even number of the last
    iterations (for an undamped mode, a pair ±iω, the growth alternates between ω²|a|/|b| and
    |b|/|a| for a vector (a, b) of coordinate and rate: a pair's mean is ω), converged to a few
    per cent (the two close pairs of the spinning beam: 3 %; chain(100): 7.5 % low); the
    fastest mode decays when the last iterate v is an eigenvector, ‖J v − λ v‖ ≤ 0.1 ρ with the
    Rayleigh quotient λ = vᵀJv ≤ −0.5 ρ (the iterates of a complex pair rotate in its plane and
    fail the test).
    It costs ``iterations`` + 1 evaluations of f (complex ones with the complex step).

    ``derivatives="differences"``: f at real states only, for a guess that needs ρ to a few digits
    (simulate's choice of method and its stiffness check): for n_x ≤ 2 ``iterations`` the
    eigenvalues of Richardson's differences column by column
    (:func:`projeq.analysis.differentiation.jacobian`, 4 n_x evaluations; ρ within 1e-9 of the
    exact one on the models of tests/simulation/test_fastest_mode.py), beyond, power iteration on
    central-difference products (f(x + εv) − f(x − εv)) / 2ε, ε = ε_m^(1/3) (1 + |x|). A compiled
    model then never needs its complex128 specialization for the guess, which is about half of
    the first compilation of an explicit run (README's pendulum: the one-call ∂ẋ/∂x kernel).
    """
    if derivatives not in DERIVATIVES:
        raise ValueError(f"derivatives: expected one of {list(DERIVATIVES)}, got {derivatives!r}")
    x = np.asarray(x, dtype=float)
    if derivatives == "differences":
        return _mode_by_differences(fun, t, x, iterations)
    J = None if jacobian is None or len(x) > 2 * iterations else jacobian(t, x)
    if J is None and len(x) <= iterations:
        J = _by_complex_step(fun, t, x, lambda: exact_jacobian(lambda z: fun(t, z), x))
    if J is not None and np.all(np.isfinite(J)):
        return _eigen_mode(np.linalg.eigvals(J))
    found = _by_complex_step(fun, t, x, lambda: _power_iteration(
        lambda v: complex_step(lambda s: fun(t, x + s * v)), len(x), iterations))
    if found is not None:
        return found
    f0 = fun(t, x)
    eps = np.sqrt(np.finfo(float).eps) * (1.0 + np.linalg.norm(x))
    return _power_iteration(lambda v: forward(lambda e: fun(t, x + e * v), eps, f0), len(x), iterations)


def _mode_by_differences(fun, t: float, x: NDArray, iterations: int) -> tuple[float, bool]:
    """(ρ, decays) of :func:`fastest_mode` with ``derivatives="differences"``."""
    if len(x) <= 2 * iterations:
        J = richardson_jacobian(lambda z: fun(t, z), x)
        if np.all(np.isfinite(J)):
            return _eigen_mode(np.linalg.eigvals(J))
    eps = np.finfo(float).eps ** (1 / 3) * (1.0 + np.linalg.norm(x))
    return _power_iteration(lambda v: central(lambda e: fun(t, x + e * v), eps), len(x), iterations)


def _by_complex_step(fun, t: float, x: NDArray, run):
    """``run()``, a computation on f at complex states, or None where f is not complex-safe: it
    fails :func:`projeq.analysis.differentiation.is_complex_safe` at x (raises on a complex
    state, casts it to float, or returns real values, as a compiled right-hand side for real
    states does), or during the run raises TypeError or ValueError or casts a complex value to
    float (simulate's right-hand side checks the distance to a coordinate singularity every 200
    calls, on real states)."""
    return attempt_complex(run)[0] if is_complex_safe(lambda z: fun(t, z), x) else None


def _eigen_mode(eigenvalues: NDArray) -> tuple[float, bool]:
    """(ρ, decays) of the eigenvalues (:func:`fastest_mode`): every eigenvalue of the largest
    modulus (to 1e-9 relative: a pair, or a tie) decays."""
    moduli = np.abs(eigenvalues)
    rho = float(moduli.max(initial=0.0))
    fastest = eigenvalues[moduli >= (1 - 1e-9) * rho]
    return rho, bool(rho > 0 and np.all((fastest.real < 0) & (np.abs(fastest.imag) <= DECAYING * rho)))


def _power_iteration(product, n: int, iterations: int) -> tuple[float, bool]:
    """(ρ, decays) by power iteration on the products J v (:func:`fastest_mode`)."""
    v = np.cos(np.arange(n) + 1.0)  # a fixed start with components along every axis
    v /= np.linalg.norm(v)
    logs, w = [], v
    for _ in range(iterations):
        v = w / np.linalg.norm(w)
        w = product(v)
        norm = np.linalg.norm(w)
        if not norm > 0:
            return 0.0, False
        logs.append(np.log(norm))
    rho, rayleigh = float(np.exp(np.mean(logs[-2 * (iterations // 4):]))), float(v @ w)
    return rho, bool(rayleigh <= -0.5 * rho and np.linalg.norm(w - rayleigh * v) <= DECAYING * rho)


def stability_limit(method: str) -> float:
    """|x| of the explicit Runge–Kutta ``method``'s stability interval [x, 0] on the negative
    real axis: the root of |R(x)| = 1 for R(z) = 1 + z bᵀ (I − z A)⁻¹ 1 of its Butcher tableau
    (Hairer & Wanner, Solving ODEs II, §IV.2): RK23 2.51, RK45 3.31, DOP853 6.39."""
    return _stability_interval(PROJECTED[method].__name__ if method in PROJECTED else method)


@functools.cache  # ~1000 evaluations of R(x): once per method and process
def _stability_interval(name: str) -> float:
    from scipy.optimize import brentq  # scipy.optimize loads where it is used (import projeq stays fast)

    solver = {"RK23": RK23, "RK45": RK45, "DOP853": DOP853}[name]
    n = solver.n_stages
    A = np.zeros((n, n))
    A[:, : min(n, solver.A.shape[1])] = solver.A[:n, :n]

    def amplification(x: float) -> float:
        return abs(1 + x * solver.B[:n] @ np.linalg.solve(np.eye(n) - x * A, np.ones(n))) - 1.0

    grid = -np.linspace(0.1, 10.0, 991)
    first = int(np.argmax([amplification(x) > 0 for x in grid]))
    return -float(brentq(amplification, grid[first - 1], grid[first], xtol=1e-12))


def stiff_steps(fun, n_steps: int, t0: float, t: float, x: NDArray, method, rtol: float) -> str | None:
    """Whether an explicit ``method``'s ``n_steps`` steps from t0 to t (all of a run's segments
    so far, whatever the segmenting) sit at its stability limit: the evidence (mean step, ρ,
    ρh) as text, or None; ``x`` is the state at t.

    The criterion: mean step h with ρ h at least half the method's :func:`stability_limit`
    (ρ = :func:`spectral_radius` at (t, x) by differences of ``fun`` at real states, to a few
    digits at least: the test is a factor of 2), over at least 50 steps, at rtol ≤ 1e-5. At such
    tolerances a mode with ρ h that large would be integrated with a local error ≫ rtol, so
    the error control can only accept these steps because the fast mode is hardly excited:
    the step is set by stability, the definition of stiffness, and an implicit method could
    take far larger ones. (Below half the limit, measured on the spin-up beam at ρh = 1.6 with
    DOP853, whose limit is 6.39, Radau at equal accuracy was 1.7× slower:
    benchmarks/default_integrator.py.)
    """
    if method not in EXPLICIT or rtol > 1e-5 or n_steps < 50:
        return None
    h = (t - t0) / n_steps
    rho = spectral_radius(fun, t, x, derivatives="differences")
    if rho * h < 0.5 * stability_limit(method):
        return None
    return f"mean step {h:.3g} s, fastest mode {rho:.3g} 1/s, ρh = {rho * h:.2g}"


def warn_stiff(method, evidence: str) -> None:
    """The :class:`StiffnessWarning` of a run whose explicit ``method`` the user chose and whose
    steps crawl at its stability limit (``evidence``: :func:`stiff_steps`'), for the caller of
    :func:`projeq.simulate`."""
    warnings.warn(
        f"method: {method!r} is explicit and crawls at its stability limit ({evidence}): the model "
        "is stiff (a very stiff beam, or a pose near a coordinate singularity); try method='Radau' or 'BDF'",
        StiffnessWarning,
        stacklevel=3,
    )


# -- the dense LU factorisations of scipy's implicit methods -------------------------------
def lu_factorized(A: NDArray) -> tuple[NDArray, NDArray]:
    """(LU, pivots) of A = P L U by LAPACK's getrf (Golub & Van Loan, *Matrix Computations*,
    4th ed., 2013, Alg. 3.4.1): ``scipy.linalg.lu_factor(A, overwrite_a=True)``'s result, bit for
    bit, with its refusal of a non-finite A and its warning for an exactly singular U, without its
    handling of batches and array namespaces: 9 µs per call instead of 18 on the spin-up beam's
    18 × 18 iteration matrices."""
    finite(A)
    getrf, = get_lapack_funcs(("getrf",), (A,))
    lu, pivots, info = getrf(A, overwrite_a=True)
    if info > 0:
        warnings.warn(f"Diagonal number {info} is exactly zero. Singular matrix.", LinAlgWarning, stacklevel=3)
    return lu, pivots


def lu_solved(factors: tuple[NDArray, NDArray], b: NDArray) -> NDArray:
    """x of A x = b from A's :func:`lu_factorized` factors by LAPACK's getrs (forward and back
    substitution): ``scipy.linalg.lu_solve(factors, b, overwrite_b=True)``'s result, bit for bit,
    with its refusal of a non-finite b: 8 µs per call instead of 16."""
    finite(b)
    lu, pivots = factors
    getrs, = get_lapack_funcs(("getrs",), (lu, b))
    return getrs(lu, pivots, b, overwrite_b=True)[0]


def finite(a: NDArray) -> None:
    """ValueError, as scipy.linalg's ``check_finite``, when ``a`` holds an infinity or a NaN."""
    if not np.isfinite(a).all():
        raise ValueError("array must not contain infs or NaNs")


def with_direct_lu(solver: OdeSolver) -> None:
    """Give ``solver`` — scipy's Radau or BDF with a dense Jacobian — :func:`lu_factorized` and
    :func:`lu_solved` as its ``lu`` and ``solve_lu`` (the Newton iterations' factorisations
    and solves, counted in ``nlu`` as before): the same LAPACK calls on the same matrices, so
    the same steps and results, at half the cost per call (the spin-up beam, 362 factorisations
    and 1,826 solves in 20 s by Radau: 0.05 s CPU less). Other solvers,
    and sparse Jacobians (factorised by SuperLU), are left as they are."""
    if not isinstance(solver, (Radau, BDF)) or not isinstance(solver.J, np.ndarray):
        return

    def lu(A):
        solver.nlu += 1
        return lu_factorized(A)

    solver.lu, solver.solve_lu = lu, lu_solved


# -- Radau IIA for differential-algebraic equations ----------------------------------------
_S6 = np.sqrt(6.0)
RADAU_C = np.array([(4 - _S6) / 10, (4 + _S6) / 10, 1.0])
RADAU_A = np.array([[(88 - 7 * _S6) / 360, (296 - 169 * _S6) / 1800, (-2 + 3 * _S6) / 225],
                    [(296 + 169 * _S6) / 1800, (88 + 7 * _S6) / 360, (-2 - 3 * _S6) / 225],
                    [(16 - _S6) / 36, (16 + _S6) / 36, 1 / 9]])
_GAMMA0_INV = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)  # the real eigenvalue of A⁻¹
_E = np.array([-13 - 7 * _S6, -13 + 7 * _S6, -1.0]) / 3  # embedded error estimate (Hairer–Wanner IV.8)
_NODES = np.concatenate(([0.0], RADAU_C))


class DAEResult:
    """The output of :func:`radau_dae`: ``t``, ``y`` (n × len(t)), ``success``, ``message`` and the cost
    ``nfev`` (right-hand-side calls, Jacobian differences included), ``njev``, ``nlu``, ``n_steps``,
    ``n_rejected``."""

    def __init__(self, **fields):
        self.__dict__.update(fields)


def _dae_jacobian(fun, f, t: float, y: NDArray, f0: NDArray, exact: bool, counts: dict) -> NDArray:
    """∂f/∂y at (t, y) for :func:`radau_dae`'s Newton iterations: by the complex step column by
    column (exact to round-off, :func:`projeq.analysis.differentiation.exact_jacobian`) where
    ``exact`` (``fun`` is complex-safe), else by forward differences with the steps
    √ε_m max(1, |y_j|) through the counting ``f``; n evaluations of ``fun`` either way (counted)."""
    n = y.size
    if exact:
        counts["nfev"] += n
        return exact_jacobian(lambda z: np.asarray(fun(t, z)), y)
    step = np.sqrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(y))
    J = np.empty((n, n))
    for j in range(n):
        yj = y.copy()
        yj[j] += step[j]
        J[:, j] = (f(t, yj) - f0) / step[j]
    return J


def _collocation(y0: NDArray, Z: NDArray, theta) -> NDArray:
    """y0 + P(θ), P the collocation polynomial with P(0) = 0, P(c_i) = Z_i (θ = (t − t0)/h, may exceed 1)."""
    theta = np.atleast_1d(theta)
    values = np.vstack([np.zeros_like(Z[0]), Z])  # at the nodes 0, c1, c2, 1
    basis = np.ones((4, theta.size))
    for i in range(4):
        for j in range(4):
            if j != i:
                basis[i] *= (theta - _NODES[j]) / (_NODES[i] - _NODES[j])
    return y0[:, None] + values.T @ basis


def radau_dae(fun, t_span, y0, mass=None, index=None, rtol: float = 1e-6, atol: float = 1e-8, t_eval=None,
              first_step: float | None = None, max_step: float = np.inf, max_steps: int = 200_000) -> DAEResult:
    """Integrate M y′ = f(t, y) with a diagonal, possibly singular M by the 3-stage Radau IIA method
    (order 5; Hairer & Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., §IV.8 and §VII.4,
    the scheme of their RADAU5 code).

    ``mass``: the diagonal of M (1 for differential, 0 for algebraic components; default all 1, an ODE).
    ``index``: the differentiation index of each component's variable (1, 2 or 3; default 1): as in
    RADAU5 the error of index-2 (index-3) variables is scaled by h (h²). Semi-explicit index-2 DAEs
    (velocity constraints with their multipliers) and index-3 DAEs (position constraints) are
    integrated as they stand, without index reduction; the initial state must satisfy the constraints.

    Each step solves the 3n stage equations (I₃ ⊗ M) Z = h (A ⊗ I) F(Z) by simplified Newton
    iterations with one dense LU of I₃ ⊗ M − h A ⊗ ∂f/∂y (∂f/∂y once per step, :func:`_dae_jacobian`:
    exact by the complex step where ``fun`` takes complex states, else by forward differences),
    started from the previous step's collocation polynomial; the step size follows the embedded error
    estimate (M/(γ₀h) − ∂f/∂y)⁻¹ (f(t₀, y₀) + M Σ e_i Z_i / h). ``t_eval`` values come from the
    collocation polynomial (stage order 3).
    """
    from scipy.linalg import lu_factor, lu_solve

    t0, t_end = map(float, t_span)
    y = np.asarray(y0, dtype=float).copy()
    n = y.size
    m_diag = np.ones(n) if mass is None else np.asarray(mass, dtype=float).ravel()
    idx = np.ones(n) if index is None else np.asarray(index, dtype=float).ravel()
    if m_diag.size != n or idx.size != n:
        raise ValueError(f"mass, index: expected {n} values each (one per component of y0), got "
                         f"{m_diag.size} and {idx.size}")
    if not t_end > t0:
        raise ValueError(f"t_span: expected t_end > t0, got {t_span}")
    if not (0 < rtol < 1 and atol > 0):
        raise ValueError(f"rtol, atol: expected 0 < rtol < 1 and atol > 0, got {rtol}, {atol}")
    t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
    M = np.diag(m_diag)
    counts = dict(nfev=0, njev=0, nlu=0, n_steps=0, n_rejected=0)

    def f(t, x):
        counts["nfev"] += 1
        return np.asarray(fun(t, x), dtype=float)

    exact = is_complex_safe(lambda z: fun(t0, z), y)  # ∂f/∂y by the complex step (else forward differences)
    newton_tol = max(10 * np.finfo(float).eps / rtol, min(0.03, rtol**0.5))
    h = min(first_step or 1e-3 * (t_end - t0) * rtol ** 0.25, max_step, t_end - t0)
    t, f0 = t0, f(t0, y)
    ts, ys = ([t0], [y.copy()]) if t_eval is None else ([], [])
    if t_eval is not None and t_eval.size and t_eval[0] <= t0:
        ts, ys = [t0], [y.copy()]
    next_eval = 0 if t_eval is None else int(np.searchsorted(t_eval, t0, side="right"))
    previous = None  # (t, h, y, Z) of the last accepted step, for the starting guess
    first, rejected, message = True, False, "success"
    while t < t_end:
        if counts["n_steps"] >= max_steps:
            message = f"max_steps = {max_steps} reached at t = {t}"
            break
        h = min(h, max_step, t_end - t)
        counts["njev"] += 1
        J = _dae_jacobian(fun, f, t, y, f0, exact, counts)
        while True:
            if h < 1e-14 * max(1.0, abs(t)):
                message = f"step size underflow at t = {t}"
                break
            counts["nlu"] += 1
            lu = lu_factor(np.kron(np.eye(3), M) - h * np.kron(RADAU_A, J))
            if previous is None:
                Z = np.zeros((3, n))
            else:
                tp, hp, yp, Zp = previous
                Z = (_collocation(yp, Zp, (t + RADAU_C * h - tp) / hp) - y[:, None]).T
            scale = atol + rtol * np.abs(y)
            converged, rate, norm_old = False, None, None
            for _ in range(7):
                F = np.array([f(t + c * h, y + Zi) for c, Zi in zip(RADAU_C, Z)])
                G = (Z @ M) - h * RADAU_A @ F
                dZ = -lu_solve(lu, G.ravel()).reshape(3, n)
                Z += dZ
                norm = np.sqrt(np.mean((dZ / scale) ** 2))
                if norm_old is not None:
                    rate = norm / norm_old
                    if rate >= 1:
                        break
                if norm == 0 or (rate is not None and rate / (1 - rate) * norm < newton_tol):
                    converged = True
                    break
                norm_old = norm
            if not converged:
                h *= 0.5
                previous = None
                continue
            y_new = y + Z[-1]
            lu_err = lu_factor(_GAMMA0_INV / h * M - J)
            ZE = M @ (Z.T @ _E) / h
            error = lu_solve(lu_err, f0 + ZE)
            scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
            weight = h ** (idx - 1)
            err = np.sqrt(np.mean((weight * error / scale) ** 2))
            if err > 1 and (first or rejected):
                error = lu_solve(lu_err, f(t, y + error) + ZE)
                err = np.sqrt(np.mean((weight * error / scale) ** 2))
            factor = min(10.0, max(0.2, 0.9 * (err + 1e-10) ** -0.25))
            if err > 1:
                counts["n_rejected"] += 1
                rejected, h = True, h * min(factor, 0.9)
                continue
            break
        if message != "success":
            break
        if t_eval is not None:
            stop = int(np.searchsorted(t_eval, t + h, side="right"))
            if stop > next_eval:
                inside = t_eval[next_eval:stop]
                ts.extend(inside)
                ys.extend(_collocation(y, Z, (inside - t) / h).T)
                next_eval = stop
        previous = (t, h, y.copy(), Z.copy())
        t, y = t + h, y_new
        f0 = f(t, y)
        counts["n_steps"] += 1
        if t_eval is None:
            ts.append(t)
            ys.append(y.copy())
        first, rejected = False, False
        h *= factor
    return DAEResult(t=np.array(ts), y=np.array(ys).T.reshape(n, -1), success=message == "success",
                     message=message, **counts)
