"""Can an integrator bring the flexible arm to ≤ 10× the CPU time of its rigid twin (error ≤ 1e-5
in the final state after 5 s)? A time-boxed study: integrator loops compiled by numba around the
fast evaluator's compiled kernels (``chain_terms`` + ``passes`` for ẋ, ``tree_jacobian`` for the
exact ∂ẋ/∂x), no Python per step, measured against ``simulate``'s defaults in ONE run.

Methods (all in one compiled loop each):

* ``DOP853 (compiled)``: scipy's DOP853 step and step-size control (Hairer, Nørsett & Wanner,
  *Solving ODEs I*, §II.5 and §II.10; scipy.integrate's coefficients and its error norm), ported
  line by line — the same steps as scipy, without scipy's Python per step. What a compiled loop
  gives both arms.
* ``exprb43``: the exponential Rosenbrock method of order 4 with an exact Jacobian every step
  (Hochbruck, Ostermann & Schweitzer, "Exponential Rosenbrock-type methods", SIAM J. Numer.
  Anal. 47, 2009, §5.2), fixed steps; φ_k(hJ) v through the eigen-decomposition J = V Λ V⁻¹.
* ``ETDRK4(m)``: the exponential Runge–Kutta method of Cox & Matthews ("Exponential time
  differencing for stiff systems", J. Comput. Phys. 176, 2002, eq. (26)–(29)) with the linear part
  L = ∂ẋ/∂x frozen and refreshed every m steps (N(x) = ẋ(x) − L x), fixed steps: its φ-matrices
  are formed once per refresh, so a step costs 4 evaluations of ẋ and matrix-vector products.

Measured (benchmarks/results/2026-11-27/flexible_arm_integrators.txt, one run): the compiled
DOP853 takes scipy's steps and runs the rigid twin 13× faster than ``simulate``, so the honest
ratio is compiled against compiled; there the flexible arm stays 165–360× (DOP853), ≥ 329×
(exponential methods at error ≤ 1e-5, each step paying an exact Jacobian of ~21 ẋ and an
eigen-decomposition of ~8 ẋ), and ≥ 42× even if Jacobians and φ-functions cost nothing: the
fastest mode (ρ = 3144 1/s, 0.37 of ṡ_e) needs ρ h ≲ 1.6 to end within 1e-5 after 5 s.

    PYTHONPATH=. python benchmarks/flexible_arm_integrators.py            # 5 s, as in the issue
    PYTHONPATH=. python benchmarks/flexible_arm_integrators.py --t-end 1  # shorter
    PYTHONPATH=. python benchmarks/flexible_arm_integrators.py --quick    # 10 ms (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numba
import numpy as np
from numpy.typing import NDArray
from scipy.integrate import DOP853, solve_ivp

import projeq as pq
from projeq.analysis.differentiation import COMPLEX_STEP
from projeq.studies.table import Table

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0  # scipy.integrate's Runge–Kutta step control


def compiled_model(system):
    """(chain_terms, passes, tree_jacobian, model tuple, complex workspace with the (empty) force laws) of
    the system's fast evaluator, for the compiled loops: ẋ = (ṡ, s̈) (q̇ = ṡ: revolute joints only) and
    ∂ẋ/∂x by the kernels."""
    ev = system.evaluator().evaluator
    if ev._given or system.forces or system.coupled or system.n_q != system.n_s:
        raise ValueError("system: the compiled loops take trees of revolute/prismatic joints without force laws")
    ws, wc = ev._real, ev._workspace(complex)
    model = (ev._index, ev._geometry, ev._inertia, ev._gravity, ws.given_values, ev._elastic, ev._ports,
             ws.T, ws.zeta, ws.F, ws.M_n, ws.M_hat, ws.h_hat, ws.R, ws.r, ws.twist, ev._pivot_min, system.n_q)
    complex_ws = (ev._laws, ev._law_constants, wc.given_values, wc.T, wc.zeta, wc.F, wc.M_n, wc.M_hat,
                  wc.h_hat, wc.R, wc.r, wc.twist)
    return ev._chain_terms, ev._passes, ev._jacobian, model, complex_ws


@numba.njit(cache=True)
def x_dot(chain, passes, model, x, out):
    """ẋ = (ṡ, s̈) at x = (q, ṡ) into out, by the fast evaluator's compiled kernels."""
    (index, geometry, inertia, gravity, given, elastic, ports, T, zeta, F, M_n, M_hat, h_hat, R, r, twist,
     pivot_min, n_q) = model
    chain(index, geometry, inertia, gravity, x[:n_q], x[n_q:], given, elastic, ports, T, zeta, F, M_n, h_hat, R, r,
          twist)
    passes(index, T, zeta, F, M_n, M_hat, h_hat, pivot_min, out[n_q:])
    out[:n_q] = x[n_q:]


@numba.njit(cache=True)
def jacobian(jac, model, complex_ws, x, J):
    """∂ẋ/∂x at x into J by the complex step through the kernels (kernels.tree_jacobian)."""
    (index, geometry, inertia, gravity, _, elastic, ports, _, _, _, _, _, _, _, _, _, pivot_min, n_q) = model
    laws, constants, given, T, zeta, F, M_n, M_hat, h_hat, R, r, twist = complex_ws
    J[:] = 0.0
    for i in range(n_q):
        J[i, n_q + i] = 1.0
    jac(0.0, index, geometry, inertia, gravity, laws, constants, x, n_q, COMPLEX_STEP, given, elastic, ports,
        T, zeta, F, M_n, M_hat, h_hat, R, r, twist, pivot_min, J[n_q:])  # the arm has gravity only: no laws


@numba.njit(cache=True)
def _rms(v):
    return np.sqrt(np.sum(v * v) / v.size)


@numba.njit(cache=True)
def dop853(chain, passes, model, x0, t0, t1, rtol, atol, A, B, C, E3, E5):
    """scipy's DOP853 from t0 to t1 (its initial step, steps and error norm): (x(t1), nfev, steps, rejected)."""
    n, stages = x0.size, B.size
    K = np.zeros((stages + 1, n))
    x, y, f1 = x0.copy(), np.empty(n), np.empty(n)
    x_dot(chain, passes, model, x, K[0])
    nfev = 1
    scale = atol + np.abs(x) * rtol  # select_initial_step (Hairer, Nørsett & Wanner §II.4)
    d0, d1 = _rms(x / scale), _rms(K[0] / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, t1 - t0)
    x_dot(chain, passes, model, x + h0 * K[0], f1)
    nfev += 1
    d2 = _rms((f1 - K[0]) / scale) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    h_abs = min(100 * h0, h1, t1 - t0)
    t, steps, rejected = t0, 0, 0
    while t < t1:
        accepted, was_rejected = False, False
        while not accepted:
            t_new = min(t + h_abs, t1)
            h = t_new - t
            for s in range(1, stages):
                for i in range(n):
                    total = 0.0
                    for j in range(s):
                        total += A[s, j] * K[j, i]
                    y[i] = x[i] + h * total
                x_dot(chain, passes, model, y, K[s])
            for i in range(n):
                total = 0.0
                for j in range(stages):
                    total += B[j] * K[j, i]
                y[i] = x[i] + h * total
            x_dot(chain, passes, model, y, K[stages])
            nfev += stages
            err5, err3 = 0.0, 0.0
            for i in range(n):
                sc = atol + max(abs(x[i]), abs(y[i])) * rtol
                e5, e3 = 0.0, 0.0
                for j in range(stages + 1):
                    e5 += K[j, i] * E5[j]
                    e3 += K[j, i] * E3[j]
                err5 += (e5 / sc) ** 2
                err3 += (e3 / sc) ** 2
            error = 0.0 if err5 == 0.0 and err3 == 0.0 else h * err5 / np.sqrt((err5 + 0.01 * err3) * n)
            if error < 1.0:
                factor = MAX_FACTOR if error == 0.0 else min(MAX_FACTOR, SAFETY * error ** (-1.0 / 8.0))
                h_abs *= min(1.0, factor) if was_rejected else factor
                accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * error ** (-1.0 / 8.0))
                was_rejected = True
                rejected += 1
        t = t_new
        x[:] = y
        K[0] = K[stages]
        steps += 1
    return x, nfev, steps, rejected


@numba.njit(cache=True)
def phi(k, z):
    """φ_k(z) = Σ_j z^j/(j+k)! (φ_0 = exp): Taylor series for |z| < 1, else φ_{j+1} = (φ_j − 1/j!)/z."""
    if abs(z) < 1.0:
        total, term = 0.0j, 1.0 + 0.0j
        for j in range(k):
            term /= j + 1
        for j in range(30):
            total += term
            term *= z / (j + k + 1)
        return total
    value, factorial = np.exp(z), 1.0
    for j in range(k):
        value = (value - 1.0 / factorial) / z
        factorial *= j + 1
    return value


@numba.njit(cache=True)
def phi_matrix(V, V_inv, lam, h, weights, out):
    """Re V diag(Σ_k w_k φ_k(h λ)) V⁻¹ into out (weights: w_0 … w_4 for φ_0 … φ_4)."""
    d = np.zeros(lam.size, np.complex128)
    for i in range(lam.size):
        for k in range(weights.size):
            if weights[k] != 0.0:
                d[i] += weights[k] * phi(k, h * lam[i])
    out[:] = ((V * d) @ V_inv).real


@numba.njit(cache=True)
def etdrk4(chain, passes, jac, model, complex_ws, x0, t0, t1, n_steps, refresh):
    """Cox & Matthews' ETDRK4 (2002, eq. (26)–(29)) with L = ∂ẋ/∂x refreshed every ``refresh``
    steps: (x(t1), nfev, steps, Jacobians)."""
    n = x0.size
    h = (t1 - t0) / n_steps
    J, E, E2, Q = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    F1, F2, F3 = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    x, a, b, c = x0.copy(), np.empty(n), np.empty(n), np.empty(n)
    Nx, Na, Nb, Nc = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    nfev, njev = 0, 0
    for step in range(n_steps):
        if step % refresh == 0:
            jacobian(jac, model, complex_ws, x, J)
            njev += 1
            lam, V = np.linalg.eig(J.astype(np.complex128))
            V_inv = np.linalg.inv(V)
            phi_matrix(V, V_inv, lam, h, np.array([1.0, 0.0, 0.0, 0.0]), E)
            phi_matrix(V, V_inv, lam, h / 2, np.array([1.0, 0.0, 0.0, 0.0]), E2)
            phi_matrix(V, V_inv, lam, h / 2, np.array([0.0, h / 2, 0.0, 0.0]), Q)
            phi_matrix(V, V_inv, lam, h, np.array([0.0, h, -3 * h, 4 * h]), F1)
            phi_matrix(V, V_inv, lam, h, np.array([0.0, 0.0, 2 * h, -4 * h]), F2)
            phi_matrix(V, V_inv, lam, h, np.array([0.0, 0.0, -h, 4 * h]), F3)
        x_dot(chain, passes, model, x, Nx)
        Nx -= J @ x
        Ex = E2 @ x
        a[:] = Ex + Q @ Nx
        x_dot(chain, passes, model, a, Na)
        Na -= J @ a
        b[:] = Ex + Q @ Na
        x_dot(chain, passes, model, b, Nb)
        Nb -= J @ b
        c[:] = E2 @ a + Q @ (2 * Nb - Nx)
        x_dot(chain, passes, model, c, Nc)
        Nc -= J @ c
        nfev += 4
        x[:] = E @ x + F1 @ Nx + F2 @ (Na + Nb) + F3 @ Nc
    return x, nfev, n_steps, njev


@numba.njit(cache=True)
def _phi_apply(V, V_inv, lam, h, k, v):
    """Re V φ_k(h Λ) V⁻¹ v."""
    w = V_inv @ v.astype(np.complex128)
    for i in range(lam.size):
        w[i] *= phi(k, h * lam[i])
    return (V @ w).real


@numba.njit(cache=True)
def exprb43(chain, passes, jac, model, complex_ws, x0, t0, t1, n_steps):
    """Hochbruck, Ostermann & Schweitzer's exprb43 (2009, §5.2) with fixed steps and an exact
    Jacobian every step: (x(t1), nfev, steps, Jacobians)."""
    n = x0.size
    h = (t1 - t0) / n_steps
    J, x, f, fU = np.zeros((n, n)), x0.copy(), np.empty(n), np.empty(n)
    nfev = 0
    for step in range(n_steps):
        jacobian(jac, model, complex_ws, x, J)
        lam, V = np.linalg.eig(J.astype(np.complex128))
        V_inv = np.linalg.inv(V)
        x_dot(chain, passes, model, x, f)
        g = f - J @ x  # g_n(x) = ẋ(x) − J_n x; D_n(U) = g_n(U) − g_n(x_n)
        U2 = x + (h / 2) * _phi_apply(V, V_inv, lam, h / 2, 1, f)
        x_dot(chain, passes, model, U2, fU)
        D2 = fU - J @ U2 - g
        step1 = h * _phi_apply(V, V_inv, lam, h, 1, f)
        U3 = x + step1 + h * _phi_apply(V, V_inv, lam, h, 1, D2)
        x_dot(chain, passes, model, U3, fU)
        D3 = fU - J @ U3 - g
        nfev += 3
        x = x + step1 + h * (_phi_apply(V, V_inv, lam, h, 3, 16 * D2 - 2 * D3)
                             + _phi_apply(V, V_inv, lam, h, 4, -48 * D2 + 12 * D3))
    return x, nfev, n_steps, n_steps


@numba.njit(cache=True)
def piece_costs(chain, passes, jac, model, complex_ws, x, repeats):
    """CPU seconds of one ẋ, one ∂ẋ/∂x and one eigen-decomposition with V⁻¹ inside a compiled loop
    (each the mean of ``repeats``), and ρ(∂ẋ/∂x)."""
    n = x.size
    out, J = np.empty(n), np.zeros((n, n))
    costs = np.empty(3)
    with numba.objmode(started="f8"):
        started = time.process_time()
    for _ in range(repeats):
        x_dot(chain, passes, model, x, out)
    with numba.objmode(now="f8"):
        now = time.process_time()
    costs[0], started = (now - started) / repeats, now
    for _ in range(repeats):
        jacobian(jac, model, complex_ws, x, J)
    with numba.objmode(now="f8"):
        now = time.process_time()
    costs[1], started = (now - started) / repeats, now
    for _ in range(repeats):
        lam, V = np.linalg.eig(J.astype(np.complex128))
        np.linalg.inv(V)
    with numba.objmode(now="f8"):
        now = time.process_time()
    costs[2] = (now - started) / repeats
    return costs, np.abs(lam).max()


def timed(f, *args, repeat: int = 1):
    """(f(*args), CPU seconds): the best of ``repeat`` calls (short runs: the machine is shared)."""
    best = np.inf
    for _ in range(repeat):
        started = time.process_time()
        out = f(*args)
        best = min(best, time.process_time() - started)
    return out, best


def simulate_default(system, t_end):
    """(x(t_end), Result) of simulate's defaults (the evaluator must be compiled)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", pq.assembly.InterpretedWarning)
        result = pq.simulate(system, t_end, n_points=2)
    return np.concatenate((result.q[-1], result.s_dot[-1])), result


def scipy_dop853(system, x0, T):
    """(x(T), nfev, steps) of scipy's solve_ivp DOP853 at rtol 1e-8, atol 1e-10 on one interval,
    ẋ by the fast evaluator called from Python."""
    ev, n_q = system.evaluator(), system.n_q
    result = solve_ivp(lambda t, x: np.concatenate((x[n_q:], ev.accelerations(x[:n_q], x[n_q:], t))), (0.0, T), x0,
                       method="DOP853", rtol=1e-8, atol=1e-10)
    return result.y[:, -1], result.nfev, len(result.t) - 1


def arm_runs(system, T: float, flexible: bool) -> tuple[list, NDArray, tuple]:
    """The runs of one arm [(method, cpu, nfev, steps, njev, x(T))], its reference x_ref(T) with
    the reference's own error, and the per-piece costs in the compiled loop."""
    chain, passes, jac, model, complex_ws = compiled_model(system)
    x0 = np.concatenate((system.q0, system.s_dot0))
    dop = (chain, passes, model, x0, 0.0)
    exp = (chain, passes, jac, model, complex_ws, x0, 0.0)
    for warm in (lambda: dop853(*dop, 1e-3, 1e-8, 1e-10, *COEFFICIENTS), lambda: etdrk4(*exp, 1e-3, 2, 1),
                 lambda: exprb43(*exp, 1e-3, 2)):
        warm()  # compile (or load from numba's cache) outside the timings
    simulate_default(system, 0.01)
    reference = dop853(*dop, T, 1e-11, 1e-13, *COEFFICIENTS)[0]
    own_error = np.abs(dop853(*dop, T, 1e-10, 1e-12, *COEFFICIENTS)[0] - reference).max()
    (x, result), seconds = timed(simulate_default, system, T, repeat=1 if flexible else 3)
    runs = [(f"simulate default ({result.method})", seconds, result.nfev, float("nan"), result.njev, x)]
    (x, nfev, steps, _), seconds = timed(dop853, *dop, T, 1e-8, 1e-10, *COEFFICIENTS, repeat=1 if flexible else 3)
    runs.append(("DOP853 compiled, rtol 1e-8", seconds, nfev, steps, 0, x))
    if not flexible:  # the port takes scipy's steps: solve_ivp's DOP853 on one interval, the same tolerances
        (x, nfev, steps), seconds = timed(scipy_dop853, system, x0, T, repeat=3)
        runs.append(("solve_ivp DOP853, rtol 1e-8", seconds, nfev, steps, 0, x))
    if flexible:
        for h in EXPRB43_STEPS:
            (x, nfev, steps, njev), seconds = timed(exprb43, *exp, T, int(round(T / h)))
            runs.append((f"exprb43, h = {h:.1e}", seconds, nfev, steps, njev, x))
        for h, refresh in ETDRK4_STEPS:
            (x, nfev, steps, njev), seconds = timed(etdrk4, *exp, T, int(round(T / h)), refresh)
            runs.append((f"ETDRK4, J every {refresh}, h = {h:.1e}", seconds, nfev, steps, njev, x))
    costs = piece_costs(chain, passes, jac, model, complex_ws, x0, 2000)
    return runs, (reference, own_error), costs


EXPRB43_STEPS = (1e-3, 5e-4, 3.5e-4)  # fixed steps h (s)
ETDRK4_STEPS = ((1e-3, 1), (5e-4, 1), (5e-4, 4))  # (h, Jacobian every ... steps)
COEFFICIENTS = (DOP853.A, DOP853.B, DOP853.C, DOP853.E3, DOP853.E5)


def main(argv=None) -> tuple[Table, Table]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=5.0, help="simulated seconds (default 5)")
    parser.add_argument("--quick", action="store_true", help="10 ms (--t-end 0.01)")
    args = parser.parse_args(argv)
    T = 0.01 if args.quick else args.t_end
    arms = {}
    for label, system, flexible in (("rigid twin", pq.scenes.flexible_arm(rigid_last_link=True), False),
                                    ("flexible", pq.scenes.flexible_arm(), True)):
        arms[label] = arm_runs(system, T, flexible)
    rigid_default, rigid_compiled = arms["rigid twin"][0][0][1], arms["rigid twin"][0][1][1]
    rows, own = [], []
    for label, (runs, (reference, own_error), _) in arms.items():
        own.append(f"{label} {own_error:.1e}")
        per_x_dot = runs[1][1] / runs[1][2]  # CPU per ẋ in the compiled DOP853 loop
        for method, seconds, nfev, steps, njev, x in runs:
            rows.append((label, method, seconds, nfev, steps, njev, 1e6 * seconds / steps, seconds / rigid_default,
                         seconds / rigid_compiled, nfev * per_x_dot / rigid_compiled, float(np.abs(x - reference).max())))
    runs_table = Table(
        ("arm", "method", "cpu", "nfev", "steps", "njev", "per step", "/ rigid default", "/ rigid compiled",
         "ẋ alone / rigid compiled", "error"),
        rows, units={"cpu": "s", "per step": "µs"},
        formats={"cpu": ".3f", "per step": ".1f", "/ rigid default": ".1f", "/ rigid compiled": ".1f",
                 "ẋ alone / rigid compiled": ".1f", "error": ".1e"},
        title=(f"flexible arm and rigid twin over {T:g} s, one run; ratios: CPU / the rigid twin's simulate default "
               f"({rigid_default:.3f} s) and / its compiled DOP853 ({rigid_compiled:.4f} s); error = max |x(T) − x_ref|, "
               f"x_ref by compiled DOP853 at rtol 1e-11, atol 1e-13 (its own error, against rtol 1e-10: "
               f"{', '.join(own)}); ẋ alone: the run's evaluations at the compiled DOP853 loop's CPU per ẋ, "
               "the bound if Jacobians and φ-functions cost nothing"))
    cost_rows = [(label, *(1e6 * costs), costs[1] / costs[0], costs[2] / costs[0], rho)
                 for label, (_, _, (costs, rho)) in arms.items()]
    costs_table = Table(("arm", "ẋ", "∂ẋ/∂x", "eig + V⁻¹", "∂ẋ/∂x / ẋ", "eig / ẋ", "ρ(∂ẋ/∂x)"), cost_rows,
                        units={"ẋ": "µs", "∂ẋ/∂x": "µs", "eig + V⁻¹": "µs", "ρ(∂ẋ/∂x)": "1/s"},
                        formats={"ẋ": ".1f", "∂ẋ/∂x": ".1f", "eig + V⁻¹": ".1f", "∂ẋ/∂x / ẋ": ".1f",
                                 "eig / ẋ": ".1f", "ρ(∂ẋ/∂x)": ".0f"},
                        title="costs inside a compiled loop at x0 (mean of 2000 calls each)")
    print(runs_table.to_text())
    print()
    print(costs_table.to_text())
    return runs_table, costs_table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
