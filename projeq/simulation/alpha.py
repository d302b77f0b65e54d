"""The generalized-α method with fixed steps, as scipy's ``OdeSolver``: ``simulate(system, t_end,
method="GeneralizedAlpha", step=h)`` — stepped by the compiled loop where the model has a compiled ẋ
(:func:`projeq.simulation.loop.alpha_segment`, the same steps: the double pendulum's q to 1e-15), by this
class through solve_ivp otherwise (events of the user's, a dense output, ``jac`` not "exact").

For first-order systems ẏ = f(t, y) (Jansen, Whiting & Hulbert, "A generalized-α method for integrating
the filtered Navier–Stokes equations with a stabilized finite element method", Comput. Methods Appl.
Mech. Engrg. 190, 2000, eq. (14)–(21)): with the unknown ẏ_{n+1},

    y_{n+1} = y_n + h ẏ_n + γ h (ẏ_{n+1} − ẏ_n),
    ẏ_n + α_m (ẏ_{n+1} − ẏ_n) = f(t_n + α_f h, y_n + α_f (y_{n+1} − y_n)),
    α_m = (3 − ρ∞) / (2 (1 + ρ∞)),  α_f = 1 / (1 + ρ∞),  γ = 1/2 + α_m − α_f,

second-order accurate, A-stable, and damping the modes a step does not resolve (hω → ∞) to the
spectral radius ρ∞ per step (1: none; 0: at once) while it barely touches the resolved ones — the
method Exudyn and Chrono integrate elastic multibody models with (there in its second-order form,
Chung & Hulbert 1993). The step is the user's (as there): the stiff bending modes of a Ritz beam need not
be resolved for the motion they carry, which an error estimate per component cannot see
(benchmarks/flexible_arm_alpha.py: the flexible arm's tip within 3.2e-4 of the converged run over 0.5 s
with steps of 1e-2 s, where a step chosen by an error estimate at rtol 1e-2 is 1e-4 s). ``rtol`` and
``atol`` set only the Newton iteration's tolerance.

Each step solves for ẏ_{n+1} by Newton's method with the iteration matrix α_m E − α_f γ h J, J = ∂ẋ/∂x
(``jac``: simulate's exact one by default; else forward differences), factorised once per J and h and
formed again only where an iteration fails (on the flexible arm as cheap as Radau's rule, which forms it
again after a slow iteration: 26 Jacobians in 50 steps of 1e-2 s against 41, 342 evaluations against 265); a step
whose iteration fails with a fresh J is halved (a trial state the model cannot evaluate ends the run,
naming why, as in Radau). The dense output is the cubic Hermite interpolant of
(y, ẏ) at the step's ends. ẏ_n is the method's own (ẏ_0 = f(t_0, y_0)), not f(t_n, y_n).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.integrate import DenseOutput, OdeSolver

from projeq.simulation.loop import coefficients, grid_step, hermite_weights, newton_tolerance

#: LAPACK's LU factorisation and solve of real matrices
GETRF, GETRS = scipy.linalg.get_lapack_funcs(("getrf", "getrs"), (np.zeros(1),))

#: Newton iterations per step at most (scipy's Radau's)
NEWTON_MAXITER = 6
#: the spectral radius at infinity by default (Exudyn's)
RHO_INF = 0.9


class GeneralizedAlpha(OdeSolver):
    """The generalized-α method (module docstring) with steps of ``step`` on the grid t_0 + k h (a step
    halved where Newton's iteration fails goes on to the next grid point; the last one shorter, to reach
    t_bound) and spectral radius at infinity ``rho_inf`` in [0, 1] (default 0.9, Exudyn's);
    ``jac`` a callable jac(t, y) or None (forward differences). ``first_step`` and ``max_step`` are
    taken for scipy's interface and do not change the steps."""

    def __init__(self, fun, t0, y0, t_bound, step=None, rho_inf=RHO_INF, jac=None, rtol=1e-3, atol=1e-6,
                 first_step=None, max_step=np.inf, vectorized=False, **extraneous):
        if extraneous:
            raise ValueError(f"GeneralizedAlpha: unknown options {sorted(extraneous)}; it takes step, rho_inf")
        super().__init__(fun, t0, y0, t_bound, vectorized)
        self.check_options({"step": step, "rho_inf": rho_inf})
        self.h_abs, self.rho_inf, self.t_start = float(step), float(rho_inf), float(t0)
        self.alpha_m, self.alpha_f, self.gamma = coefficients(self.rho_inf)
        self.jac, self.njev, self.nlu = jac, 0, 0
        self.rtol, self.atol = rtol, atol
        self.newton_tol = newton_tolerance(rtol)
        self.f = self.fun(self.t, self.y)  # ẏ_0
        self.J, self.lu, self.factorised_for = None, None, None
        self.t_old = self.y_old = self.f_old = None

    @staticmethod
    def check_options(options: dict) -> None:
        """ValueError naming ``step`` (missing, or not a positive number) or ``rho_inf`` (outside [0, 1])."""
        step, rho_inf = options.get("step"), options.get("rho_inf", RHO_INF)
        if isinstance(step, bool) or not isinstance(step, (int, float, np.number)) or not 0 < step < np.inf:
            raise ValueError(f"step: GeneralizedAlpha takes fixed steps: give step=h (projeq run: --step H), a "
                             f"positive number of seconds, got {step!r}")
        if isinstance(rho_inf, bool) or not isinstance(rho_inf, (int, float, np.number)) or not 0 <= rho_inf <= 1:
            raise ValueError(f"rho_inf: the spectral radius at infinity must lie in [0, 1], got {rho_inf!r}")

    def _jacobian(self, t: float, y: np.ndarray) -> None:
        """J at (t, y): the user's ``jac`` or forward differences (n evaluations of f) with the increments
        √(ε max(10⁻⁵, |y_j|)) of Hairer & Wanner's RADAU5, as the compiled loop's
        (:func:`projeq.simulation.loop._jacobian`)."""
        self.njev += 1
        if self.jac is not None:
            self.J = np.asarray(self.jac(t, y), dtype=float)
            return
        f0, J = self.fun(t, y), np.empty((self.n, self.n))
        for j in range(self.n):
            delta = np.sqrt(np.finfo(float).eps * max(1e-5, abs(y[j])))
            shifted = y.copy()
            shifted[j] += delta
            J[:, j] = (self.fun(t, shifted) - f0) / delta
        self.J = J

    def _newton(self, h: float):
        """(y_{n+1}, ẏ_{n+1}) of a step of size h from (t, y, ẏ_n = f), or None where the iteration
        fails: scipy's Radau's test (Hairer & Wanner, *Solving ODEs II*, §IV.8) on the increments of
        y_{n+1} scaled by atol + rtol |y| — converged where θ/(1 − θ) times the last is below the tolerance
        (θ: the ratio of the last two), failed where θ ≥ 1 or convergence within NEWTON_MAXITER iterations
        is out of reach."""
        t, y, rate = self.t, self.y, self.f
        if self.factorised_for != h:
            matrix = self.alpha_m * np.eye(self.n) - (self.alpha_f * self.gamma * h) * self.J
            self.lu, self.factorised_for = GETRF(matrix)[:2], h  # LAPACK's own: scipy's wrappers cost 40 µs a solve
            self.nlu += 1
        v, scale = rate.copy(), self.atol + self.rtol * np.abs(y)
        norm_old, theta = None, None
        for k in range(NEWTON_MAXITER):
            y_new = y + h * rate + self.gamma * h * (v - rate)
            residual = rate + self.alpha_m * (v - rate) - self.fun(t + self.alpha_f * h,
                                                                   y + self.alpha_f * (y_new - y))
            dv = GETRS(*self.lu, -residual)[0]
            with np.errstate(over="ignore"):  # (an overflow: not converging, as NaN is)
                scaled = self.gamma * h * dv / scale
                norm = float(np.sqrt(scaled @ scaled / self.n))
            if not np.isfinite(norm):
                return None
            if norm_old is not None:
                theta = norm / norm_old
                if theta >= 1 or theta ** (NEWTON_MAXITER - k) / (1 - theta) * norm > self.newton_tol:
                    return None
            v += dv
            if norm == 0 or theta is not None and theta / (1 - theta) * norm < self.newton_tol:
                return y + h * rate + self.gamma * h * (v - rate), v
            norm_old = norm
        return None

    def _step_impl(self):
        t, span = self.t, abs(self.t_bound - self.t)
        h = grid_step(t, self.t_start, self.h_abs, self.t_bound)
        fresh = self.J is None
        if fresh:
            self._jacobian(t, self.y)
            self.factorised_for = None
        while (found := self._newton(h * self.direction)) is None:
            if not fresh:  # a stale J: formed again at the step's start
                self._jacobian(t, self.y)
                self.factorised_for, fresh = None, True
                continue
            h *= 0.5
            if h < 10 * np.abs(np.nextafter(t, self.direction * np.inf) - t):
                return False, self.TOO_SMALL_STEP
        y_new, v = found
        self.t_old, self.y_old, self.f_old = t, self.y, self.f
        self.t = t + h * self.direction if h < span else self.t_bound
        self.y, self.f = y_new, v
        return True, None

    def _dense_output_impl(self):
        return HermiteOutput(self.t_old, self.t, self.y_old, self.f_old, self.y, self.f)


class HermiteOutput(DenseOutput):
    """The cubic Hermite interpolant of (y, ẏ) at a step's ends."""

    def __init__(self, t_old, t, y_old, f_old, y, f):
        super().__init__(t_old, t)
        self.y_old, self.f_old, self.y_new, self.f_new = y_old, f_old, y, f

    def _call_impl(self, t):
        h = self.t - self.t_old
        h00, h10, h01, h11 = hermite_weights((np.asarray(t, dtype=float) - self.t_old) / h)
        return (np.multiply.outer(self.y_old, h00) + np.multiply.outer(h * self.f_old, h10)
                + np.multiply.outer(self.y_new, h01) + np.multiply.outer(h * self.f_new, h11))
