"""The integration loop compiled: the explicit Runge–Kutta methods of :func:`projeq.simulate` (RK23,
RK45, DOP853) stepping a segment in one compiled call around the model's compiled ẋ.

The algorithm is scipy's, line by line (``scipy.integrate`` 1.17: ``RungeKutta._step_impl``,
``rk_step``, ``select_initial_step``, the two dense outputs and ``solve_ivp``'s output at
``t_eval``), so a compiled segment takes the same steps as ``solve_ivp`` to round-off and costs
the same number of evaluations:

- the embedded pairs of Bogacki & Shampine (RK23), Dormand & Prince (RK45; J. Comput. Appl. Math.
  6, 1980, with Shampine's quartic interpolant, Math. Comp. 46, 1986) and DOP853 (Hairer, Nørsett &
  Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., §II.10, its error estimator mixing
  the 5th- and 3rd-order estimates, and the 7th-order dense output with three more stages);
- the step size control of HNW §II.4: h ← h · min(10, 0.9 · err^(−1/(p+1))) after an accepted step
  (≤ 1 after a rejection), h ← h · max(0.2, 0.9 · err^(−1/(p+1))) after a rejected one, with err the
  RMS norm of the error estimate over atol + rtol · max(|y|, |y_new|); the first step by HNW's
  starting-step algorithm (§II.4) unless the segment continues the previous one's;
- output rows at the requested times inside each step by the method's interpolant;
- and the implicit Radau IIA of order 5 (:func:`radau_segment`: scipy's ``Radau._step_impl``,
  ``solve_collocation_system``, ``predict_factor`` and ``RadauDenseOutput``; Hairer & Wanner, *Solving
  Ordinary Differential Equations II*, 2nd ed., §IV.8), whose ∂ẋ/∂x comes by forward differences of
  the model's compiled ẋ (scipy's Radau in projeq takes the exact one: the steps may differ slightly)
  and whose two Newton matrices are factorised by LAPACK (dgetrf/zgetrf, scipy's ``cython_lapack``);
- and the generalized-α method at fixed steps (:func:`alpha_segment`: the steps of
  :class:`projeq.simulation.alpha.GeneralizedAlpha`, Jansen, Whiting & Hulbert 2000), its Newton matrix
  factorised the same way and its J by the same differences.

The model enters as data: a first-class function (the compiled ẋ kernel of a tree,
:meth:`projeq.assembly.fast.FastEvaluator.loop_model`, or of a closed loop, partitioned or in the
null-space form, :meth:`projeq.constraints.compiled.CompiledClosure.loop_model`) and the tuples of arrays it takes, so the
loop is compiled once per signature of the ẋ kernel — once for every tree without joints of kind
GIVEN, once for those with them, once per variant of the closures' kernel (rigid or elastic tree, Φ
a user's function or cut joints) — and never per model, chain length or set of force laws; the
method's tableau is data too. It returns to Python once per segment of ``simulate`` (a chunk of
(t_end − t_start) / n_segments; on a tree of rigid bodies, as many segments as about
``driver.CHUNK_EVALUATIONS`` evaluations reach), after the first step that reaches the chunk's end — no step is cut short there,
and the next chunk goes on with the same steps (:class:`Carried`) —: there the rows are checked,
progress is reported and Ctrl-C takes effect, keeping every finished chunk.
"""

from __future__ import annotations

import contextlib
import functools
import signal
import threading
import types
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from projeq.assembly import compilation, kernels
from projeq.assembly.linalg import one_blas_thread

#: the explicit methods the compiled loop steps (scipy's names), and all of them (Radau IIA and the
#: generalized-α method the implicit ones)
EXPLICIT = ("RK23", "RK45", "DOP853")
METHODS = (*EXPLICIT, "Radau", "GeneralizedAlpha")

#: scipy's step-size control constants (``scipy.integrate._ivp.rk``)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0

#: failed stages in a row an explicit step retries (h × 0.2 each: 0.2⁸ ≈ 2.6e-6) before the segment ends there
STAGE_RETRIES = 8

#: what a compiled segment ended with (STOPPED: the monitor raised where the segment paused; MODEL_EVENT: the
#: model's own terminal event, located where it fired)
FINISHED, TOO_SMALL_STEP, EVALUATION_FAILED, PAUSED, STOPPED, MODEL_EVENT = 0, 1, 2, 3, 4, 5

#: scipy's tolerances of an event's root (``solve_ivp``'s ``solve_event_equation``: brentq's xtol and rtol)
EVENT_XTOL = EVENT_RTOL = 4 * np.finfo(float).eps
#: brentq's iteration limit (scipy's default maxiter)
EVENT_MAXITER = 100


class Stepped(NamedTuple):
    """What :meth:`CompiledLoop.run` did: how it ended (``status``), the time ``t`` and ``state`` reached (on
    EVALUATION_FAILED, of the last accepted step), the ``rows`` at the output times passed, the state
    and time where an evaluation failed (``x_failed``, ``t_failed``), the evaluations and steps taken,
    the next step size, the monitor's exception (status STOPPED), the Jacobians formed (Radau; their
    n_x evaluations each counted in nfev) and, where it paused past ``t_pause``, what the next run
    takes to go on with the same steps (:class:`Carried`)."""

    status: int
    t: float
    rows: NDArray
    state: NDArray
    x_failed: NDArray
    t_failed: float
    nfev: int
    steps: int
    h_abs: float
    stopped_by: Exception | None
    njev: int = 0
    carried: Carried | None = None


class Carried(NamedTuple):
    """Where a run paused past ``t_pause`` (:meth:`CompiledLoop.run`), what the next run from there keeps:
    the time and state it paused at, ẋ there, the next step size, the method's data (Radau's memory:
    ∂ẋ/∂x, its factorisations, the last step's interpolant) and the model event's value."""

    t: float
    state: NDArray
    rate: NDArray
    h_abs: float
    method: tuple
    event: tuple


@functools.cache
def tableau(name: str) -> tuple:
    """(dop853, A, B, C, E, E3, dense, n_stages, exponent) of scipy's method ``name``: the Butcher
    tableau (A, B, C; DOP853's A and C with the three rows of its dense output's extra stages), the
    error weights E (DOP853: E5) and E3 (DOP853 only), the dense output's matrix (P; DOP853: D) and
    the step-size exponent −1/(q + 1) of the error estimator's order q."""
    import scipy.integrate as si

    method = getattr(si, name)
    if name == "DOP853":
        from scipy.integrate._ivp import dop853_coefficients as d

        return (True, d.A, d.B, d.C, d.E5, d.E3, d.D, d.N_STAGES, -1.0 / (method.error_estimator_order + 1))
    A = np.asarray(method.A, dtype=float)
    return (False, A, np.asarray(method.B, float), np.asarray(method.C, float), np.asarray(method.E, float),
            np.zeros(0), np.asarray(method.P, float), method.n_stages, -1.0 / (method.error_estimator_order + 1))


def _rhs(f, pre, tree, post, n_q, t, x, x_dot):
    """ẋ at (t, x) into x_dot by the model's kernel f: −1, or the kernel's failure index."""
    return f(*pre, t, *tree, x, n_q, *post, x_dot)


def _stage(f, pre, tree, post, n_q, K, a, s, h, t, y, x, x_failed):
    """K[s] ← ẋ(t, x) at the stage x = y + h Σ_(j<s) a_j K[j] (:func:`_combine`); whether the kernel failed
    there (x then copied into x_failed)."""
    _combine(K, a, s, h, y, x)
    if _rhs(f, pre, tree, post, n_q, t, x, K[s]) < 0:
        return False
    _copy(x, x_failed)
    return True


def _step_to(t, h_abs, t_bound):
    """(t_new, h, |h|) of the next step of size h_abs from t, cut at t_bound (scipy's ``_step_impl``)."""
    t_new = t + h_abs
    if t_new - t_bound > 0:
        t_new = t_bound
    h = t_new - t
    return t_new, h, abs(h)


def _rms(v, scale):
    """scipy's norm of v / scale: the root mean square."""
    total = 0.0
    for i in range(v.shape[0]):
        total += (v[i] / scale[i]) ** 2
    return np.sqrt(total / v.shape[0])


def _copy(source, target):
    """target ← source, entry by entry (numba compiles a slice assignment's shape check for a second
    each)."""
    for i in range(source.shape[0]):
        target[i] = source[i]


def _combine(K, a, s, h, y, out):
    """out ← y + (Σ_{j<s} a_j K_j) h: a stage's state (rk_step's ``y + np.dot(K[:s].T, a[:s]) * h``)."""
    for i in range(y.shape[0]):
        total = 0.0
        for j in range(s):
            total += K[j, i] * a[j]
        out[i] = y[i] + total * h


def _first_guess(y, f0, interval, rtol, atol, scale, y1):
    """The first half of scipy's ``select_initial_step`` (HNW §II.4): the trial step h₀ from ‖y‖ and
    ‖ẏ‖, y1 ← y + h₀ ẏ (where the caller evaluates ẏ once more), scale ← atol + rtol |y|; (h₀, ‖ẏ‖)."""
    for i in range(y.shape[0]):
        scale[i] = atol + abs(y[i]) * rtol
    d0, d1 = _rms(y, scale), _rms(f0, scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for i in range(y.shape[0]):
        y1[i] = y[i] + h0 * f0[i]
    return h0, d1


def _first_choice(f0, f1, scale, h0, d1, interval, max_step, exponent):
    """The second half: the first step from the change of ẏ over h₀ (f1 − f0 is overwritten)."""
    for i in range(f0.shape[0]):
        f1[i] -= f0[i]
    d2 = _rms(f1, scale) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** -exponent
    return min(100 * h0, h1, interval, max_step)


def _error_norm(dop853, K, E, E3, n_stages, h, scale):
    """The step's error norm: scipy's RMS of (Σ E_j K_j) h / scale; DOP853's mix of its 5th- and
    3rd-order estimates, |h| ‖e₅‖² / √((‖e₅‖² + 0.01 ‖e₃‖²) n)."""
    n = scale.shape[0]
    if not dop853:
        total = 0.0
        for i in range(n):
            e = 0.0
            for j in range(n_stages + 1):
                e += K[j, i] * E[j]
            total += (e * h / scale[i]) ** 2
        return np.sqrt(total / n)
    e5, e3 = 0.0, 0.0
    for i in range(n):
        a, b = 0.0, 0.0
        for j in range(n_stages + 1):
            a += K[j, i] * E[j]
            b += K[j, i] * E3[j]
        e5 += (a / scale[i]) ** 2
        e3 += (b / scale[i]) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)


def _dense_rows(method, K, t_old, h, y_old, y, f_new, t_eval, first, last, rows, work):
    """rows[first:last] ← the step's interpolant at t_eval[first:last] (RK23/RK45: y_old + h Kᵀ P
    (θ, θ², …); DOP853, its extra stages in K: scipy's nested form over F)."""
    dop853, A, _, _, _, _, dense, n_stages, _ = method
    n = y.shape[0]
    if not dop853:
        Q = work[3][:dense.shape[1]]
        for i in range(n):
            for k in range(dense.shape[1]):
                total = 0.0
                for j in range(n_stages + 1):
                    total += K[j, i] * dense[j, k]
                Q[k, i] = total
        for r in range(first, last):
            theta = (t_eval[r] - t_old) / h
            for i in range(n):
                power, total = 1.0, 0.0
                for k in range(dense.shape[1]):
                    power *= theta
                    total += Q[k, i] * power
                rows[r, i] = h * total + y_old[i]
        return
    F = work[3][:dense.shape[0] + 3]
    for i in range(n):
        delta = y[i] - y_old[i]
        F[0, i] = delta
        F[1, i] = h * K[0, i] - delta
        F[2, i] = 2 * delta - h * (f_new[i] + K[0, i])
        for k in range(dense.shape[0]):
            total = 0.0
            for j in range(A.shape[0]):
                total += dense[k, j] * K[j, i]
            F[3 + k, i] = h * total
    for r in range(first, last):
        theta = (t_eval[r] - t_old) / h
        for i in range(n):
            value = 0.0
            for k in range(F.shape[0] - 1, -1, -1):
                value += F[k, i]
                value *= theta if (F.shape[0] - 1 - k) % 2 == 0 else 1 - theta
            rows[r, i] = value + y_old[i]


def segment(f, pre, tree, post, n_q, method, t, t_bound, known, h_abs, max_step, rtol, atol, pause, t_pause, retries,
            t_eval, first_row, rows, state, rate, x_failed, event):
    """Steps from (t, state) towards t_bound by the explicit method ``method`` (:func:`tableau`) on the ẋ
    kernel f (``f(*pre, t, *tree, x, n_q, *post, x_dot)``, −1 or a failure index), with ``rate`` its ẋ
    there where ``known`` (else evaluated); h_abs > 0 the next step (else HNW's first step). Writes
    the rows at the output times t_eval[first_row:] (increasing, inside [t, t_bound]) into rows, and
    leaves in state and rate the state and ẋ where it stopped. A step with a stage the kernel cannot
    evaluate (a trial state far off: a step past a stiff mode's stability limit) is rejected as one of
    infinite error (h × 0.2), ``retries`` times in a row at most. Returns (status, rows written,
    evaluations, steps, time reached, next step size, time of x_failed), the status FINISHED; PAUSED
    after the first step that brings the evaluations to ``pause`` (> 0), or after the first step that
    reaches ``t_pause`` (the end of a segment of :func:`projeq.simulate`; the caller checks the state and
    goes on with ``known`` True: the same steps as without the pause); TOO_SMALL_STEP (scipy's failure:
    the step size fell below the spacing of the numbers near t); or EVALUATION_FAILED (a stage failed
    more than ``retries`` times in a row), the state evaluated in x_failed (the caller's checked
    evaluation names why), the state and time reached those of the last accepted step (the caller may
    go on from there); or MODEL_EVENT: the model's own terminal event ``event`` (:func:`_event_fired`)
    located inside the last step, the state and time reached its root's, the rows up to it written."""
    dop853, A, B, C, E, E3, dense, n_stages, exponent = method
    n = state.shape[0]
    K = np.empty((max(A.shape[0], n_stages + 1), n))
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty((max(dense.shape[1], dense.shape[0] + 3), n)),
            np.empty((1, n)))
    y, y_new = state.copy(), np.empty(n)
    nfev, steps, n_rows, failed = 0, 0, first_row, -1
    if not known:
        nfev += 1
        failed = _rhs(f, pre, tree, post, n_q, t, y, rate)
        event[2][0] = event[0][0] - event[1]  # the event's value where the segment starts
    if failed < 0 and h_abs <= 0.0:  # scipy's select_initial_step
        h0, d1 = _first_guess(y, rate, abs(t_bound - t), rtol, atol, work[0], work[1])
        nfev += 1
        failed = _rhs(f, pre, tree, post, n_q, t + h0, work[1], work[2])
        h_abs = _first_choice(rate, work[2], work[0], h0, d1, abs(t_bound - t), max_step, exponent)
    if failed >= 0:
        _copy(y, x_failed)
        return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t
    while t != t_bound:
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_abs = max_step if h_abs > max_step else (min_step if h_abs < min_step else h_abs)
        accepted, rejected, failures, t_failed = False, False, 0, t
        while not accepted:
            if h_abs < min_step:  # (where a stage failed, it is the cause: named by the caller)
                _copy(y, state)
                return (EVALUATION_FAILED if failures else TOO_SMALL_STEP), n_rows, nfev, steps, t, h_abs, t_failed
            t_new, h, h_abs = _step_to(t, h_abs, t_bound)
            _copy(rate, K[0])
            stage_failed = False
            for s in range(1, n_stages + 1):
                nfev += 1
                last = s == n_stages  # the stage at the step's end, of weights B
                t_failed = t + h if last else t + C[s] * h
                if _stage(f, pre, tree, post, n_q, K, B if last else A[s], s, h, t_failed, y,
                          y_new if last else work[1], x_failed):
                    stage_failed = True
                    break
            if stage_failed:  # rejected as a step of infinite error, or the run stops where it keeps failing
                failures += 1
                if failures > retries:
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t_failed
                h_abs *= MIN_FACTOR
                rejected = True
                continue
            scale = work[0]
            for i in range(n):
                scale[i] = atol + max(abs(y[i]), abs(y_new[i])) * rtol
            error_norm = _error_norm(dop853, K, E, E3, n_stages, h, scale)
            if error_norm < 1:
                factor = MAX_FACTOR if error_norm == 0 else min(MAX_FACTOR, SAFETY * error_norm ** exponent)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * error_norm ** exponent)
                rejected = True
        steps += 1
        fired = _event_fired(event)  # at y_new: the step's last stage was evaluated there
        t_end = t_new
        if fired:
            t_end = _event_root(f, pre, tree, post, n_q, method, K, t, h, y, y_new, work, event)
        last = n_rows
        while last < t_eval.shape[0] and t_eval[last] <= t_end:  # solve_ivp's searchsorted(side="right")
            last += 1
        if fired:  # the root's search formed the dense output (DOP853: its extra stages, which scipy counts)
            nfev += A.shape[0] - n_stages - 1
        elif last > n_rows:
            for s in range(n_stages + 1, A.shape[0]):  # DOP853's extra stages of its dense output
                nfev += 1
                if _stage(f, pre, tree, post, n_q, K, A[s], s, h, t + C[s] * h, y, work[1], x_failed):
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t + C[s] * h
        if last > n_rows:
            _dense_rows(method, K, t, h, y, y_new, K[n_stages], t_eval, n_rows, last, rows, work)
            n_rows = last
        if fired:  # solve_ivp's terminal event: the rows up to its root, the state there
            _dense_rows(method, K, t, h, y, y_new, K[n_stages], np.array([t_end]), 0, 1, work[4], work)
            _copy(work[4][0], state)
            return MODEL_EVENT, n_rows, nfev, steps, t_end, h_abs, t_end
        t = t_new
        y, y_new = y_new, y
        _copy(K[n_stages], rate)
        if (pause > 0 and nfev >= pause or t >= t_pause) and t != t_bound:
            _copy(y, state)
            return PAUSED, n_rows, nfev, steps, t, h_abs, t
    _copy(y, state)
    return FINISHED, n_rows, nfev, steps, t, h_abs, t


def _event_fired(event) -> bool:
    """Whether the model's terminal event g = value − limit (``event`` = (the model's value array, its
    limit, [g where the last step started]), rising, as a ConstrainedSystem's κ − limit; limit ∞: none)
    rose through zero over the last step, from the value its last evaluation wrote; keeps the new g
    (scipy's ``find_active_events``: g_old ≤ 0 ≤ g_new)."""
    value, limit, kept = event
    if limit == np.inf:
        return False
    g_old, g_new = kept[0], value[0] - limit
    kept[0] = g_new
    return g_old <= 0.0 and g_new >= 0.0


def _event_root(f, pre, tree, post, n_q, method, K, t_old, h, y_old, y_new, work, event) -> float:
    """The time of the event's root inside the step (t_old, t_old + h) by scipy's brentq (its C code, step
    by step: Brent's inverse quadratic interpolation and bisection, xtol = rtol = 4 ε) on g(τ) = the value
    the kernel writes at the step's interpolant at τ, minus the limit (scipy's ``solve_event_equation``);
    DOP853's dense stages computed first (their evaluations are the caller's to count)."""
    dop853, A, _, C, _, _, _, n_stages, _ = method
    for s in range(n_stages + 1, A.shape[0]):
        _stage(f, pre, tree, post, n_q, K, A[s], s, h, t_old + C[s] * h, y_old, work[1], work[2])
    x_pre, x_cur = t_old, t_old + h
    f_pre = _event_at(f, pre, tree, post, n_q, method, K, t_old, h, y_old, y_new, work, event, x_pre)
    f_cur = _event_at(f, pre, tree, post, n_q, method, K, t_old, h, y_old, y_new, work, event, x_cur)
    if f_pre == 0.0:
        return x_pre
    if f_cur == 0.0:
        return x_cur
    x_blk, f_blk, s_pre, s_cur = 0.0, 0.0, 0.0, 0.0
    for _ in range(EVENT_MAXITER):
        if f_pre != 0.0 and f_cur != 0.0 and (f_pre < 0.0) != (f_cur < 0.0):
            x_blk, f_blk = x_pre, f_pre
            s_pre = s_cur = x_cur - x_pre
        if abs(f_blk) < abs(f_cur):
            x_pre, x_cur, x_blk = x_cur, x_blk, x_cur
            f_pre, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (EVENT_XTOL + EVENT_RTOL * abs(x_cur)) / 2
        s_bis = (x_blk - x_cur) / 2
        if f_cur == 0.0 or abs(s_bis) < delta:
            return x_cur
        if abs(s_pre) > delta and abs(f_cur) < abs(f_pre):
            if x_pre == x_blk:  # interpolate
                s_try = -f_cur * (x_cur - x_pre) / (f_cur - f_pre)
            else:  # extrapolate
                d_pre = (f_pre - f_cur) / (x_pre - x_cur)
                d_blk = (f_blk - f_cur) / (x_blk - x_cur)
                s_try = -f_cur * (f_blk * d_blk - f_pre * d_pre) / (d_blk * d_pre * (f_blk - f_pre))
            if 2 * abs(s_try) < min(abs(s_pre), 3 * abs(s_bis) - delta):  # a good short step
                s_pre, s_cur = s_cur, s_try
            else:
                s_pre = s_cur = s_bis
        else:
            s_pre = s_cur = s_bis
        x_pre, f_pre = x_cur, f_cur
        x_cur += s_cur if abs(s_cur) > delta else (delta if s_bis > 0 else -delta)
        f_cur = _event_at(f, pre, tree, post, n_q, method, K, t_old, h, y_old, y_new, work, event, x_cur)
    return x_cur


def _event_at(f, pre, tree, post, n_q, method, K, t_old, h, y_old, y_new, work, event, time) -> float:
    """g at ``time`` inside the step: the kernel evaluated at the step's interpolant there (into scratch),
    its written value minus the limit (∞ where the kernel flags: the kernels write an infinite value)."""
    _dense_rows(method, K, t_old, h, y_old, y_new, K[method[7]], np.array([time]), 0, 1, work[4], work)
    _rhs(f, pre, tree, post, n_q, time, work[4][0], work[2])
    return event[0][0] - event[1]


# -- Radau IIA of order 5 (scipy.integrate._ivp.radau, compiled) --------------------------------------------

#: scipy's Newton iteration limit of the collocation system (``radau.NEWTON_MAXITER``)
NEWTON_MAXITER = 6


@functools.cache
def radau_tableau() -> tuple:
    """(C, E, T, TI, P, μ_real, μ_complex) of scipy's Radau IIA of order 5 (Hairer & Wanner, *Solving
    Ordinary Differential Equations II*, 2nd ed., §IV.8): the nodes C, the embedded error weights E, the
    eigen-decomposition A⁻¹ = T diag(μ_real, μ_complex, μ̄_complex) T⁻¹ (TI = T⁻¹) that splits the
    simplified Newton iteration into one real and one complex system of size n (eq. IV.8.16–8.18), and
    the collocation polynomial's coefficients P of the dense output."""
    from scipy.integrate._ivp import radau as r

    return (np.asarray(r.C, float), np.asarray(r.E, float), np.asarray(r.T, float), np.asarray(r.TI, float),
            np.asarray(r.P, float), float(r.MU_REAL), complex(r.MU_COMPLEX))


def radau_memory(n: int) -> tuple:
    """What a Radau run keeps from step to step (and over the pauses of :meth:`CompiledLoop.run`): ∂ẋ/∂x
    J, the LU factorisations (LU, pivots) of μ_real/h − J and μ_complex/h − J, the last step's interpolant (its coefficients Q
    and its start y_old) and the numbers ``RADAU_*`` (``scalars``); a fresh one: no Jacobian yet."""
    scalars = np.zeros(RADAU_SCALARS)
    scalars[RADAU_H_OLD] = scalars[RADAU_ERROR_OLD] = -1.0  # scipy's None
    return (np.zeros((n, n)), (np.zeros((n, n)), np.zeros(n, np.int32)),
            (np.zeros((n, n), np.complex128), np.zeros(n, np.int32)), np.zeros((3, n)), np.zeros(n), scalars)


#: the entries of a Radau run's scalars: the last step's start and size (its interpolant's), the previous
#: step size and error norm (−1: none, scipy's None), whether the interpolant, the factorisations and J exist,
#: whether J is the current one (at the step's start), and the Jacobians formed
(RADAU_T_OLD, RADAU_STEP, RADAU_H_OLD, RADAU_ERROR_OLD, RADAU_HAS_SOL, RADAU_HAS_LU, RADAU_HAS_J,
 RADAU_CURRENT_J, RADAU_NJEV, RADAU_SCALARS) = range(10)


def _jacobian(f, pre, tree, post, n_q, t, y, rate, J, x, column, x_failed):
    """J ← ∂ẋ/∂x at (t, y) by forward differences of the kernel f column by column, ẋ(t, y) = rate given,
    the increment δ_j = √(ε max(10⁻⁵, |y_j|)) of Hairer & Wanner's RADAU5 (*Solving ODEs II*, §IV.8):
    n evaluations; whether one failed (its state in x_failed)."""
    n = y.shape[0]
    eps = np.finfo(np.float64).eps
    _copy(y, x)
    for j in range(n):
        delta = np.sqrt(eps * max(1e-5, abs(y[j])))
        x[j] = y[j] + delta
        if _rhs(f, pre, tree, post, n_q, t, x, column) >= 0:
            _copy(x, x_failed)
            return True
        for i in range(n):
            J[i, j] = (column[i] - rate[i]) / delta
        x[j] = y[j]
    return False


def _factorise(J, h, mu_real, mu_complex, real, complex_):
    """LU factorisations of μ_real/h I − J and μ_complex/h I − J into ``real`` and ``complex_`` (each (LU,
    pivots)), for the simplified Newton iteration's real and complex systems (:func:`_shifted_lu`)."""
    _shifted_lu(J, mu_real / h, real)
    _shifted_lu(J, mu_complex / h, complex_)


def _shifted_lu(J, shift, factorised):
    """The LU factorisation (LU, pivots) of shift I − J into ``factorised`` by LAPACK's dgetrf or zgetrf (by
    the dtype; scipy's ``cython_lapack``, :func:`_lapack`). LAPACK reads the C-ordered matrix as its
    transpose: :func:`_solve` solves with the transpose of that (``trans = 'T'``)."""
    n, M = J.shape[0], factorised[0]
    for i in range(n):
        for j in range(n):
            M[i, j] = -J[i, j]
        M[i, i] += shift
    sizes = np.array([n, 1, 0], np.int32)  # n (also the leading dimension), right-hand sides, LAPACK's info
    if M.itemsize == 8:  # float64 (complex128: 16)
        DGETRF(sizes.ctypes, sizes.ctypes, M.ctypes, sizes.ctypes, factorised[1].ctypes, sizes[2:].ctypes)
    else:
        ZGETRF(sizes.ctypes, sizes.ctypes, M.ctypes, sizes.ctypes, factorised[1].ctypes, sizes[2:].ctypes)


def _solve(factorised, b, out):
    """out ← M⁻¹ b by the factorisation (LU, pivots) of :func:`_factorise` (LAPACK's dgetrs or zgetrs, by
    the dtype: the transpose of LAPACK's column-major view of the C-ordered LU)."""
    _copy(b, out)
    sizes, trans = np.array([b.shape[0], 1, 0], np.int32), np.array([84], np.uint8)  # 84: 'T'
    if out.itemsize == 8:  # float64 (complex128: 16)
        DGETRS(trans.ctypes, sizes.ctypes, sizes[1:].ctypes, factorised[0].ctypes, sizes.ctypes, factorised[1].ctypes,
               out.ctypes, sizes.ctypes, sizes[2:].ctypes)
    else:
        ZGETRS(trans.ctypes, sizes.ctypes, sizes[1:].ctypes, factorised[0].ctypes, sizes.ctypes, factorised[1].ctypes,
               out.ctypes, sizes.ctypes, sizes[2:].ctypes)


#: LAPACK's dgetrf, dgetrs, zgetrf and zgetrs as numba's external functions (:func:`_lapack`; None until the
#: Radau segment is compiled: its namespace holds them)
DGETRF = DGETRS = ZGETRF = ZGETRS = None


@functools.cache
def _lapack() -> dict:
    """LAPACK's LU factorisation and solve, real and complex, as numba external functions by symbol name:
    scipy's ``scipy.linalg.cython_lapack`` entry points registered with LLVM under projeq's names (per
    process, so that a Radau segment cached on disk links to this process's addresses)."""
    import llvmlite.binding as llvm

    numba = kernels.numba_module()
    pointer, functions = numba.types.voidptr, {}
    for name, n_args in (("dgetrf", 6), ("dgetrs", 9), ("zgetrf", 6), ("zgetrs", 9)):
        llvm.add_symbol(f"projeq_{name}",
                        numba.extending.get_cython_function_address("scipy.linalg.cython_lapack", name))
        functions[name.upper()] = numba.types.ExternalFunction(f"projeq_{name}",
                                                               numba.types.void(*(pointer,) * n_args))
    return functions


def _transformed(M, Z, W):
    """W ← M Z for a 3 × 3 M and 3 × n Z (scipy's ``TI.dot(Z)``, ``T.dot(W)``)."""
    for a in range(3):
        for i in range(Z.shape[1]):
            W[a, i] = M[a, 0] * Z[0, i] + M[a, 1] * Z[1, i] + M[a, 2] * Z[2, i]


def _collocation(f, pre, tree, post, n_q, radau, t, y, h, Z, scale, tol, real, complex_, work,
                 x_failed):
    """scipy's ``solve_collocation_system``: the simplified Newton iteration on the collocation system of
    the step (t, y, h), the stage increments Z (3 × n) starting from the given guess, by the real and the
    complex system factorised by :func:`_factorise` (Hairer & Wanner, *Solving ODEs II*, §IV.8); at most
    NEWTON_MAXITER iterations, stopped early where the convergence rate θ predicts failure (θ ≥ 1, or
    θ^(k_max − k)/(1 − θ) ‖ΔW‖ > tol). Returns (converged, iterations, θ (−1: none), the time of a
    failed evaluation or NaN: its state in x_failed)."""
    C, _, T, TI, _, mu_real, mu_complex = radau
    n = y.shape[0]
    W, F, dW, x = work[0], work[1], work[2], work[3]
    f_real, f_complex, dW_complex = work[4], work[5], work[6]
    M_real, M_complex = mu_real / h, mu_complex / h
    _transformed(TI, Z, W)
    dW_norm_old, rate, converged, k = -1.0, -1.0, False, 0
    while k < NEWTON_MAXITER:
        for s in range(3):
            for i in range(n):
                x[i] = y[i] + Z[s, i]
            if _rhs(f, pre, tree, post, n_q, t + C[s] * h, x, F[s]) >= 0:
                _copy(x, x_failed)
                return False, k + 1, rate, t + C[s] * h
        for i in range(n):
            f_real[i] = F[0, i] * TI[0, 0] + F[1, i] * TI[0, 1] + F[2, i] * TI[0, 2] - M_real * W[0, i]
            f_complex[i] = (F[0, i] * (TI[1, 0] + 1j * TI[2, 0]) + F[1, i] * (TI[1, 1] + 1j * TI[2, 1])
                            + F[2, i] * (TI[1, 2] + 1j * TI[2, 2]) - M_complex * (W[1, i] + 1j * W[2, i]))
        _solve(real, f_real, dW[0])
        _solve(complex_, f_complex, dW_complex)
        total = 0.0
        for i in range(n):
            dW[1, i], dW[2, i] = dW_complex[i].real, dW_complex[i].imag
            total += (dW[0, i] / scale[i]) ** 2 + (dW[1, i] / scale[i]) ** 2 + (dW[2, i] / scale[i]) ** 2
        dW_norm = np.sqrt(total / (3 * n))
        if dW_norm_old >= 0.0:
            rate = dW_norm / dW_norm_old
        if rate >= 0.0 and (rate >= 1 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dW_norm > tol):
            break
        for a in range(3):
            for i in range(n):
                W[a, i] += dW[a, i]
        _transformed(T, W, Z)
        if dW_norm == 0 or rate >= 0.0 and rate / (1 - rate) * dW_norm < tol:
            converged = True
            break
        dW_norm_old = dW_norm
        k += 1
    return converged, min(k, NEWTON_MAXITER - 1) + 1, rate, np.nan


def _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old):
    """scipy's ``predict_factor``: Gustafsson's predictive step-size control (Hairer & Wanner, *Solving
    ODEs II*, §IV.8, eq. 8.25) where the previous step is known (h_abs_old, error_norm_old ≥ 0), else
    the classical err^(−1/4)."""
    if error_norm == 0:
        return np.inf
    multiplier = 1.0
    if error_norm_old >= 0 and h_abs_old >= 0:
        multiplier = h_abs / h_abs_old * (error_norm_old / error_norm) ** 0.25
    return min(1.0, multiplier) * error_norm ** -0.25


def _interpolated(Q, t_old, step, y_old, time, out):
    """out ← the collocation polynomial of the step from t_old of size ``step`` at ``time``: y_old + Σ_k
    Q_k θ^(k+1), θ = (time − t_old) / step (scipy's ``RadauDenseOutput``)."""
    theta = (time - t_old) / step
    for i in range(y_old.shape[0]):
        out[i] = y_old[i] + theta * (Q[0, i] + theta * (Q[1, i] + theta * Q[2, i]))


def radau_segment(f, pre, tree, post, n_q, method, t, t_bound, known, h_abs, max_step, rtol, atol, pause,
                  t_pause, retries, t_eval, first_row, rows, state, rate, x_failed, event):
    """:func:`segment` by scipy's Radau IIA of order 5 (``scipy.integrate.Radau._step_impl``, step by
    step): ``method`` = (:func:`radau_tableau`, :func:`radau_memory`), the memory kept over pauses.
    Each step solves the collocation system by :func:`_collocation`; a step whose Newton iteration
    fails is retried with a fresh Jacobian (if J is not current) or halved; the error estimate
    (HNW IV.8, eq. 8.19–8.20: (μ_real/h − J)⁻¹ (ẋ + Zᵀ E / h), once more through ẋ after a rejection)
    drives Gustafsson's predictive control (:func:`_predict_factor`, safety 0.9 (2 k_max + 1) /
    (2 k_max + iterations)); the step size is kept (and the factorisation reused) when it would grow by
    less than 1.2; J is formed again (:func:`_jacobian`, n evaluations) when the Newton iteration took
    more than two iterations at a rate above 10⁻³. The first step: HNW's starting-step algorithm for
    order 3; the stage guess: the last step's collocation polynomial extrapolated. ``retries`` is the
    explicit methods' (:func:`segment`); here a failed evaluation ends the segment."""
    radau, memory = method
    C, E, _, _, P, mu_real, mu_complex = radau
    J, real, complex_, Q, y_old, scalars = memory
    n = state.shape[0]
    work = (np.empty((3, n)), np.empty((3, n)), np.empty((3, n)), np.empty(n), np.empty(n),
            np.empty(n, np.complex128), np.empty(n, np.complex128))
    Z, scale, error, ZE, f_new = np.empty((3, n)), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    y, y_new = state.copy(), np.empty(n)
    nfev, steps, n_rows, failed = 0, 0, first_row, -1
    newton_tol = newton_tolerance(rtol)
    if not known:
        nfev += 1
        failed = _rhs(f, pre, tree, post, n_q, t, y, rate)
    if failed < 0 and h_abs <= 0.0:  # scipy's select_initial_step, for the error estimator's order 3
        h0, d1 = _first_guess(y, rate, abs(t_bound - t), rtol, atol, scale, error)
        nfev += 1
        failed = _rhs(f, pre, tree, post, n_q, t + h0, error, ZE)
        h_abs = _first_choice(rate, ZE, scale, h0, d1, abs(t_bound - t), max_step, -0.25)
    if failed >= 0:
        _copy(y, x_failed)
        return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t
    if scalars[RADAU_HAS_J] == 0.0:
        nfev += n
        scalars[RADAU_NJEV] += 1
        if _jacobian(f, pre, tree, post, n_q, t, y, rate, J, error, ZE, x_failed):
            _copy(y, state)
            return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t
        scalars[RADAU_HAS_J], scalars[RADAU_CURRENT_J] = 1.0, 1.0
    while t != t_bound:
        min_step = 10 * abs(np.nextafter(t, np.inf) - t)
        h_abs_old, error_norm_old, h_abs_start = scalars[RADAU_H_OLD], scalars[RADAU_ERROR_OLD], h_abs
        if h_abs > max_step or h_abs < min_step:
            h_abs = max_step if h_abs > max_step else min_step
            h_abs_old, error_norm_old = -1.0, -1.0
        current_jac = scalars[RADAU_CURRENT_J] != 0.0
        rejected, accepted, n_iter, rate_newton, error_norm, safety = False, False, 0, -1.0, 0.0, 0.0
        while not accepted:
            if h_abs < min_step:
                _copy(y, state)
                return TOO_SMALL_STEP, n_rows, nfev, steps, t, h_abs, t
            t_new, h, h_abs = _step_to(t, h_abs, t_bound)
            for s in range(3):
                if scalars[RADAU_HAS_SOL] != 0.0:
                    _interpolated(Q, scalars[RADAU_T_OLD], scalars[RADAU_STEP], y_old, t + h * C[s], Z[s])
                    for i in range(n):
                        Z[s, i] -= y[i]
                else:
                    for i in range(n):
                        Z[s, i] = 0.0
            for i in range(n):
                scale[i] = atol + abs(y[i]) * rtol
            converged = False
            while not converged:
                if scalars[RADAU_HAS_LU] == 0.0:
                    _factorise(J, h, mu_real, mu_complex, real, complex_)
                    scalars[RADAU_HAS_LU] = 1.0
                converged, n_iter, rate_newton, t_failed = _collocation(
                    f, pre, tree, post, n_q, radau, t, y, h, Z, scale, newton_tol, real, complex_,
                    work, x_failed)
                nfev += 3 * n_iter
                if not np.isnan(t_failed):
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t_failed
                if not converged:
                    if current_jac:
                        break
                    nfev += n
                    scalars[RADAU_NJEV] += 1
                    if _jacobian(f, pre, tree, post, n_q, t, y, rate, J, work[3], work[4], x_failed):
                        _copy(y, state)
                        return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t
                    current_jac = True
                    scalars[RADAU_HAS_LU] = 0.0
            if not converged:
                h_abs *= 0.5
                scalars[RADAU_HAS_LU] = 0.0
                continue
            for i in range(n):
                y_new[i] = y[i] + Z[2, i]
                ZE[i] = (Z[0, i] * E[0] + Z[1, i] * E[1] + Z[2, i] * E[2]) / h
                f_new[i] = rate[i] + ZE[i]
            _solve(real, f_new, error)
            for i in range(n):
                scale[i] = atol + max(abs(y[i]), abs(y_new[i])) * rtol
            error_norm = _rms(error, scale)
            safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
            if rejected and error_norm > 1:
                for i in range(n):
                    work[3][i] = y[i] + error[i]
                nfev += 1
                if _rhs(f, pre, tree, post, n_q, t, work[3], f_new) >= 0:
                    _copy(work[3], x_failed)
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t
                for i in range(n):
                    f_new[i] += ZE[i]
                _solve(real, f_new, error)
                error_norm = _rms(error, scale)
            if error_norm > 1:
                factor = _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old)
                h_abs *= max(MIN_FACTOR, safety * factor)
                scalars[RADAU_HAS_LU] = 0.0
                rejected = True
            else:
                accepted = True
        recompute_jac = n_iter > 2 and rate_newton > 1e-3
        factor = min(MAX_FACTOR, safety * _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old))
        if not recompute_jac and factor < 1.2:
            factor = 1.0
        else:
            scalars[RADAU_HAS_LU] = 0.0
        nfev += 1
        if _rhs(f, pre, tree, post, n_q, t_new, y_new, f_new) >= 0:
            _copy(y_new, x_failed)
            _copy(y, state)
            return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t_new
        if recompute_jac:
            nfev += n
            scalars[RADAU_NJEV] += 1
            if _jacobian(f, pre, tree, post, n_q, t_new, y_new, f_new, J, work[3], work[4], x_failed):
                _copy(y, state)
                return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t_new
        scalars[RADAU_CURRENT_J] = 1.0 if recompute_jac else 0.0
        scalars[RADAU_H_OLD], scalars[RADAU_ERROR_OLD] = h_abs_start, error_norm
        h_abs *= factor
        for i in range(n):  # the step's collocation polynomial: Q = Zᵀ P (scipy's _compute_dense_output)
            for k in range(3):
                Q[k, i] = Z[0, i] * P[0, k] + Z[1, i] * P[1, k] + Z[2, i] * P[2, k]
        _copy(y, y_old)
        scalars[RADAU_T_OLD], scalars[RADAU_STEP], scalars[RADAU_HAS_SOL] = t, h, 1.0
        steps += 1
        while n_rows < t_eval.shape[0] and t_eval[n_rows] <= t_new:  # solve_ivp's searchsorted(side="right")
            _interpolated(Q, t, h, y_old, t_eval[n_rows], rows[n_rows])
            n_rows += 1
        t = t_new
        y, y_new = y_new, y
        _copy(f_new, rate)
        if (pause > 0 and nfev >= pause or t >= t_pause) and t != t_bound:
            _copy(y, state)
            return PAUSED, n_rows, nfev, steps, t, h_abs, t
    _copy(y, state)
    return FINISHED, n_rows, nfev, steps, t, h_abs, t


def newton_tolerance(rtol):
    """scipy's Radau's tolerance of the simplified Newton iteration, relative to atol + rtol |y|:
    max(10 ε / rtol, min(0.03, √rtol)) (its ``newton_tol``; :func:`radau_segment`, :func:`alpha_segment`)."""
    return max(10 * np.finfo(np.float64).eps / rtol, min(0.03, rtol ** 0.5))


def grid_step(t, t_start, step, t_bound):
    """The next step of the generalized-α method from t on the grid t_0 + k h (``t_start``, ``step``): to
    the next grid point (the rest of a step halved before it), cut at t_bound."""
    done = abs(t - t_start) / step  # grid steps passed
    return min((np.floor(done + 1e-9) + 1 - done) * step, abs(t_bound - t))


def hermite_weights(theta):
    """(h₀₀, h₁₀, h₀₁, h₁₁) of the cubic Hermite interpolant at θ ∈ [0, 1] of a step of size h:
    y(θ) = h₀₀ y_old + h₁₀ h ẏ_old + h₀₁ y_new + h₁₁ h ẏ_new (θ a number, or an array of them)."""
    return ((2 * theta - 3) * theta * theta + 1, ((theta - 2) * theta + 1) * theta,
            (3 - 2 * theta) * theta * theta, (theta - 1) * theta * theta)


def coefficients(rho_inf: float) -> tuple[float, float, float]:
    """(α_m, α_f, γ) of the first-order generalized-α method for the spectral radius at infinity ρ∞
    (Jansen, Whiting & Hulbert 2000, eq. (18), (20))."""
    alpha_m, alpha_f = 0.5 * (3.0 - rho_inf) / (1.0 + rho_inf), 1.0 / (1.0 + rho_inf)
    return alpha_m, alpha_f, 0.5 + alpha_m - alpha_f


def alpha_constants(rho_inf: float, step: float, t_start: float) -> NDArray:
    """(α_m, α_f, γ, the step, the grid's start t_0) of a run of :func:`alpha_segment`
    (:func:`coefficients` of ρ∞)."""
    return np.array([*coefficients(rho_inf), step, t_start])


def alpha_memory(n: int) -> tuple:
    """What a generalized-α run keeps from step to step (and over pauses): ∂ẋ/∂x J, the LU factorisation
    (LU, pivots) of μ/h I − J and the numbers ``ALPHA_*`` (``scalars``); a fresh one: no Jacobian yet."""
    return np.zeros((n, n)), (np.zeros((n, n)), np.zeros(n, np.int32)), np.zeros(ALPHA_SCALARS)


#: the entries of a generalized-α run's scalars: whether J exists, the step its factorisation is for (0:
#: none), the Jacobians formed
ALPHA_HAS_J, ALPHA_FACTORED, ALPHA_NJEV, ALPHA_SCALARS = range(4)


def _alpha_newton(f, pre, tree, post, n_q, constants, real, t, y, rate, h, scale, tol, work, x_failed):
    """The step of size h from (t, y, ẏ_n = ``rate``) of :class:`projeq.simulation.alpha.GeneralizedAlpha`
    (its ``_newton``: the iteration matrix α_m E − α_f γ h J = α_f γ h (μ/h E − J), μ = α_m/(α_f γ),
    factorised in ``real``) into work[0] (y_{n+1}) and work[1] (ẏ_{n+1}): (converged, evaluations, the time
    of a failed evaluation or NaN: its state in x_failed)."""
    alpha_m, alpha_f, gamma = constants[0], constants[1], constants[2]
    n = y.shape[0]
    y_new, v, x, residual, dv = work[0], work[1], work[2], work[3], work[4]
    _copy(rate, v)
    norm_old, theta = -1.0, -1.0
    for k in range(NEWTON_MAXITER):
        for i in range(n):
            y_new[i] = y[i] + h * rate[i] + gamma * h * (v[i] - rate[i])
            x[i] = y[i] + alpha_f * (y_new[i] - y[i])
        if _rhs(f, pre, tree, post, n_q, t + alpha_f * h, x, residual) >= 0:
            _copy(x, x_failed)
            return False, k + 1, t + alpha_f * h
        for i in range(n):
            residual[i] = (residual[i] - rate[i] - alpha_m * (v[i] - rate[i])) / (alpha_f * gamma * h)
        _solve(real, residual, dv)  # dv = −W⁻¹ (ẏ_{n+α_m} − f)
        total = 0.0
        for i in range(n):
            total += (gamma * h * dv[i] / scale[i]) ** 2
        norm = np.sqrt(total / n)
        if not np.isfinite(norm):
            return False, k + 1, np.nan
        if norm_old >= 0.0:
            theta = norm / norm_old
            if theta >= 1 or theta ** (NEWTON_MAXITER - k) / (1 - theta) * norm > tol:
                return False, k + 1, np.nan
        for i in range(n):
            v[i] += dv[i]
        if norm == 0 or theta >= 0.0 and theta / (1 - theta) * norm < tol:
            for i in range(n):
                y_new[i] = y[i] + h * rate[i] + gamma * h * (v[i] - rate[i])
            return True, k + 1, np.nan
        norm_old = norm
    return False, NEWTON_MAXITER, np.nan


def alpha_segment(f, pre, tree, post, n_q, method, t, t_bound, known, h_abs, max_step, rtol, atol, pause,
                  t_pause, retries, t_eval, first_row, rows, state, rate, x_failed, event):
    """:func:`segment` by the generalized-α method at fixed steps on the grid t_0 + k h, as
    :class:`projeq.simulation.alpha.GeneralizedAlpha` steps (``method`` = (:func:`alpha_constants`,
    :func:`alpha_memory`), the memory kept over pauses; ``rate`` the method's own ẏ_n): J by forward
    differences of the kernel (:func:`_jacobian`, n evaluations and one at the step's start) formed again
    only where an iteration fails, then the step halved where it fails with a fresh J; the rows by the
    cubic Hermite interpolant of (y, ẏ). ``h_abs``, ``max_step`` and ``retries`` are the other methods'."""
    constants, memory = method
    J, real, scalars = memory
    step, t_start = constants[3], constants[4]
    n = state.shape[0]
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    scale, f0, column = np.empty(n), np.empty(n), np.empty(n)
    y = state.copy()
    nfev, steps, n_rows = 0, 0, first_row
    tol = newton_tolerance(rtol)
    if not known:
        nfev += 1
        if _rhs(f, pre, tree, post, n_q, t, y, rate) >= 0:
            _copy(y, x_failed)
            return EVALUATION_FAILED, n_rows, nfev, steps, t, step, t
    while t != t_bound:
        h = grid_step(t, t_start, step, t_bound)
        for i in range(n):
            scale[i] = atol + abs(y[i]) * rtol
        fresh = scalars[ALPHA_HAS_J] == 0.0
        while True:
            if fresh and scalars[ALPHA_HAS_J] == 0.0:
                nfev += n + 1
                scalars[ALPHA_NJEV] += 1
                failed = _rhs(f, pre, tree, post, n_q, t, y, f0) >= 0
                if failed or _jacobian(f, pre, tree, post, n_q, t, y, f0, J, work[2], column, x_failed):
                    if failed:
                        _copy(y, x_failed)
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, step, t
                scalars[ALPHA_HAS_J], scalars[ALPHA_FACTORED] = 1.0, 0.0
            if scalars[ALPHA_FACTORED] != h:
                _shifted_lu(J, constants[0] / (constants[1] * constants[2] * h), real)
                scalars[ALPHA_FACTORED] = h
            converged, evaluations, t_failed = _alpha_newton(f, pre, tree, post, n_q, constants, real, t, y, rate,
                                                             h, scale, tol, work, x_failed)
            nfev += evaluations
            if not np.isnan(t_failed):
                _copy(y, state)
                return EVALUATION_FAILED, n_rows, nfev, steps, t, step, t_failed
            if converged:
                break
            if not fresh:  # a stale J: formed again at the step's start
                fresh, scalars[ALPHA_HAS_J] = True, 0.0
                continue
            h *= 0.5
            if h < 10 * abs(np.nextafter(t, np.inf) - t):
                _copy(y, state)
                return TOO_SMALL_STEP, n_rows, nfev, steps, t, step, t
        t_new = t + h if h < abs(t_bound - t) else t_bound
        y_new, v = work[0], work[1]
        while n_rows < t_eval.shape[0] and t_eval[n_rows] <= t_new:  # the cubic Hermite interpolant
            h00, h10, h01, h11 = hermite_weights((t_eval[n_rows] - t) / (t_new - t))
            for i in range(n):
                rows[n_rows, i] = (h00 * y[i] + h10 * (t_new - t) * rate[i] + h01 * y_new[i]
                                   + h11 * (t_new - t) * v[i])
            n_rows += 1
        _copy(y_new, y)
        _copy(v, rate)
        t = t_new
        steps += 1
        if (pause > 0 and nfev >= pause or t >= t_pause) and t != t_bound:
            _copy(y, state)
            return PAUSED, n_rows, nfev, steps, t, step, t
    _copy(y, state)
    return FINISHED, n_rows, nfev, steps, t, step, t


_CALLEES = (_rhs, _stage, _step_to, _rms, _copy, _combine, _first_guess, _first_choice, _error_norm, _dense_rows, _event_fired,
            _event_root, _event_at, _jacobian, _factorise, _shifted_lu, _solve, _transformed, _collocation,
            _predict_factor, _interpolated, _alpha_newton, newton_tolerance, grid_step, hermite_weights)


#: the segment function of each kind of method :func:`_compiled` compiles
SEGMENTS = {"explicit": segment, "Radau": radau_segment, "GeneralizedAlpha": alpha_segment}


@functools.cache
def _compiled(signature, kind: str):
    """The segment function of ``kind`` (:data:`SEGMENTS`: :func:`segment` of the explicit methods,
    :func:`radau_segment`, :func:`alpha_segment`) compiled by numba for the argument types ``signature``
    (the ẋ kernel's as a first-class function type first), cached on disk; its callees compiled with it."""
    numba = kernels.numba_module()
    namespace = {**globals(), **(_lapack() if kind != "explicit" else {})}

    def rebound(function):
        return types.FunctionType(function.__code__, namespace, function.__name__, function.__defaults__)

    for callee in _CALLEES:
        namespace[callee.__name__] = numba.extending.register_jitable(rebound(callee))
    return numba.njit([signature], cache=True)(rebound(SEGMENTS[kind]))


class CompiledLoop:
    """The compiled :func:`segment` (Radau: :func:`radau_segment`) for one model's ẋ kernel (``model``: the
    evaluator's ``loop_model``) and one method of :data:`METHODS`; :meth:`run` steps a segment."""

    def __init__(self, model, method: str):
        self.model, self.implicit, self.alpha = model, method not in EXPLICIT, method == "GeneralizedAlpha"
        self.method = None if self.alpha else radau_tableau() if self.implicit else tableau(method)
        self.kernel, self.compiled = _specialised(model, method)

    def run(self, n_q: int, t: float, x: NDArray, t_bound: float, h_abs: float, max_step: float, rtol: float,
            atol: float, t_eval: NDArray, monitor=None, every: int = 0, t_pause: float = np.inf,
            carried: Carried | None = None, alpha: tuple = ()) -> Stepped:
        """One segment from (t, x) to t_bound, or to the end of the first step that reaches ``t_pause``
        (status PAUSED, with ``Stepped.carried``); ``monitor(t, x)`` called after the first step past each
        ``every`` evaluations (``every`` > 0), as :func:`segment` pauses: where it raises, the segment ends
        there (status STOPPED) with the rows computed so far. With ``carried`` (the last run's, paused at
        t) the run goes on with the steps one run without the pause would take: its step size, Radau's
        memory and the event's value kept, and ẋ too where x is the state it paused at (not where the
        caller normalised it: then ẋ is evaluated again). The generalized-α method takes ``alpha`` = (ρ∞, the
        step, the grid's start) (:func:`alpha_constants`)."""
        t_eval, state = np.ascontiguousarray(t_eval, dtype=float).ravel(), np.array(x, dtype=float).ravel()
        rows, x_failed = np.empty((len(t_eval), len(state))), np.empty(len(state))
        status, n_rows, nfev, steps, stopped_by = PAUSED, 0, 0, 0, None
        model = self.model
        if carried is not None and carried.t == t and carried.state.shape == state.shape:
            known, rate, h_abs = bool(np.array_equal(carried.state, state)), carried.rate, carried.h_abs
            method, event = carried.method, carried.event
        else:  # a fresh run (Radau: its Jacobian formed at t)
            known, rate, method = False, np.empty(len(state)), self.method
            if self.alpha:
                method = (alpha_constants(*alpha), alpha_memory(len(state)))
            elif self.implicit:
                method = (method, radau_memory(len(state)))
            event = (model.event[0], float(model.event[1]), np.zeros(1))  # (value, limit, g kept over pauses)
        counted = ALPHA_NJEV if self.alpha else RADAU_NJEV
        njev = int(method[1][-1][counted]) if self.implicit else 0  # (a carried memory's count so far)
        retries = 0 if self.implicit or model.checks_events else STAGE_RETRIES  # a closed loop's kernel fails on purpose
        if model.before is not None:
            model.before()
        while status == PAUSED:
            with _signals_held(), one_blas_thread(model.lapack):  # the arguments of the types compiled for
                status, n_rows, more, taken, t, h_abs, t_failed = self.compiled(  # (the entry point checks none)
                    self.kernel, model.pre, model.tree, model.post, int(n_q), method, float(t), float(t_bound),
                    known, float(h_abs), float(max_step), float(rtol), float(atol), int(every), float(t_pause),
                    retries, t_eval, n_rows, rows, state, rate, x_failed, event)
            nfev, steps, known = nfev + more, steps + taken, True
            if status == PAUSED and t >= t_pause:
                break
            if status == PAUSED:
                try:
                    monitor(t, state)
                except Exception as exc:  # noqa: BLE001 - the caller raises it, keeping the rows
                    status, stopped_by = STOPPED, exc
        njev = int(method[1][-1][counted]) - njev if self.implicit else 0
        carry = Carried(t, state.copy(), rate, h_abs, method, event) if status == PAUSED else None
        return Stepped(status, t, rows[:n_rows], state, x_failed, t_failed, nfev, steps, h_abs, stopped_by, njev, carry)


def _layout(value):
    """What numba's type of ``value`` depends on, found cheaply: an array's dtype, dimensions, contiguity
    and writability, a tuple's element by element, another value's Python type."""
    if isinstance(value, tuple):
        return tuple(map(_layout, value))
    if isinstance(value, np.ndarray):
        flags = value.flags
        return value.dtype.str, value.ndim, flags.c_contiguous, flags.f_contiguous, flags.writeable, flags.aligned
    return type(value)


_SPECIALISED = {}


def _specialised(model, method: str) -> tuple:
    """(the ẋ kernel as a first-class function, the compiled :func:`segment`'s entry point) for the types
    of ``model``'s arrays, found by numba's typeof once per kernel, layout of those arrays and method (a
    new model of the same layout finds them by :func:`_layout`); the entry point skips numba's dispatch by
    type at each call, so :meth:`CompiledLoop.run` passes it exactly the types compiled for."""
    key = (model.kernel, _layout((model.pre, model.tree, model.post)), method)
    if key not in _SPECIALISED:
        numba = kernels.numba_module()
        arguments = (*model.pre, 0.0, *model.tree, np.zeros(1), 0, *model.post, np.zeros(1))
        signature = tuple(numba.typeof(a) for a in arguments)
        if signature not in model.kernel.overloads:  # a kernel Python has not called yet: compiled (or loaded) now
            model.kernel.compile(signature)
        kernel = _address(model.kernel, model.kernel.overloads[signature].signature)
        data = tableau(method) if method in EXPLICIT else (alpha_constants(0.9, 1.0, 0.0), alpha_memory(1)) \
            if method == "GeneralizedAlpha" else (radau_tableau(), radau_memory(1))
        compiled = _compiled(tuple(numba.typeof(a) for a in (
            kernel, model.pre, model.tree, model.post, 0, data, 0.0, 0.0, True, 0.0, 0.0, 0.0, 0.0, 0, 0.0, 0,
            np.zeros(1), 0, np.zeros((1, 1)), np.zeros(1), np.zeros(1), np.zeros(1),
            (np.zeros(1), 0.0, np.zeros(1)))), method if method not in EXPLICIT else "explicit")
        _SPECIALISED[key] = kernel, compiled.overloads[compiled.signatures[0]].entry_point
    return _SPECIALISED[key]


@contextlib.contextmanager
def _signals_held():
    """SIGINT and SIGTERM held back during a compiled call (on the main thread, where POSIX allows it) and
    delivered when it returns: numba runs Python while it unboxes a first-class function, and a signal's
    exception raised there surfaces as numba's TypeError; compiled code does not see signals anyway."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def _address(dispatcher, signature):
    """The compiled ``dispatcher``'s specialisation for ``signature`` as numba's first-class function: its C
    wrapper's address and its type, found once (numba would look both up at every call of the loop,
    ~0.5 ms each)."""
    compiled = dispatcher.get_compile_result(signature)
    return _address_type()(dispatcher, signature,
                           compiled.library.get_pointer_to_function(compiled.fndesc.llvm_cfunc_wrapper_name))


@functools.cache
def _address_type():
    """The class of :func:`_address`'s objects (numba's wrapper-address protocol), typed by numba from the
    type each keeps."""
    numba = kernels.numba_module()
    from numba.core.types.function_type import WrapperAddressProtocol

    class Address(WrapperAddressProtocol):
        def __init__(self, dispatcher, signature, address: int):
            self.dispatcher = dispatcher  # the address lives as long as its dispatcher
            self.address, self._signature = address, signature
            self.numba_type = numba.types.FunctionType(signature)

        def __wrapper_address__(self):
            return self.address

        def signature(self):
            return self._signature

    numba.extending.typeof_impl.register(Address)(lambda value, context: value.numba_type)
    return Address


def loop(model, method) -> CompiledLoop | None:
    """The compiled loop of ``method`` (a name of :data:`METHODS`) on ``model`` (the ẋ kernel's
    ``loop_model``, which keeps it: one per model and method), or None (no such model or method). Under
    the cold-start policy of :mod:`projeq.assembly.compilation` (its budget not spent) a loop numba
    would have to compile raises :class:`~projeq.assembly.compilation.NotCompiled` instead: the caller
    steps with solve_ivp (the same steps) and spends that CPU from the budget."""
    if model is None or not isinstance(method, str) or method not in METHODS or \
            method not in EXPLICIT and model.event[1] < np.inf:  # Radau locates no model event: solve_ivp's
        return None
    if method not in model.loops:
        if compilation.compile_now():
            model.loops[method] = CompiledLoop(model, method)
        else:
            with compilation.cached_only():
                model.loops[method] = CompiledLoop(model, method)
    return model.loops[method]
