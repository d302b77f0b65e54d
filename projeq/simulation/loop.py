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
- output rows at the requested times inside each step by the method's interpolant.

The model enters as data: a first-class function (the compiled ẋ kernel of a tree,
:meth:`projeq.assembly.fast.FastEvaluator.loop_model`, or of a closed loop, partitioned or in the
null-space form, :meth:`projeq.constraints.compiled.CompiledClosure.loop_model`) and the tuples of arrays it takes, so the
loop is compiled once per signature of the ẋ kernel — once for every tree without joints of kind
GIVEN, once for those with them, once per variant of the closures' kernel (rigid or elastic tree, Φ
a user's function or cut joints) — and never per model, chain length or set of force laws; the
method's tableau is data too. It returns to Python once per segment of ``simulate`` (a chunk of
(t_end − t_start) / n_segments): there the rows are checked, progress is reported and Ctrl-C
takes effect, keeping every finished segment.
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

#: the methods the compiled loop steps (scipy's names)
METHODS = ("RK23", "RK45", "DOP853")

#: scipy's step-size control constants (``scipy.integrate._ivp.rk``)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0

#: what a compiled segment ended with (STOPPED: the monitor raised where the segment paused)
FINISHED, TOO_SMALL_STEP, EVALUATION_FAILED, PAUSED, STOPPED = 0, 1, 2, 3, 4


class Stepped(NamedTuple):
    """What :meth:`CompiledLoop.run` did: how it ended (``status``), the time ``t`` and ``state`` reached (on
    EVALUATION_FAILED, of the last accepted step), the ``rows`` at the output times passed, the state
    and time where an evaluation failed (``x_failed``, ``t_failed``), the evaluations and steps taken,
    the next step size and the monitor's exception (status STOPPED)."""

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


def segment(f, pre, tree, post, n_q, method, t, t_bound, known, h_abs, max_step, rtol, atol, pause, t_eval, first_row,
            rows, state, rate, x_failed):
    """Steps from (t, state) towards t_bound by the explicit method ``method`` (:func:`tableau`) on the ẋ
    kernel f (``f(*pre, t, *tree, x, n_q, *post, x_dot)``, −1 or a failure index), with ``rate`` its ẋ
    there where ``known`` (else evaluated); h_abs > 0 the next step (else HNW's first step). Writes
    the rows at the output times t_eval[first_row:] (increasing, inside [t, t_bound]) into rows, and
    leaves in state and rate the state and ẋ where it stopped. Returns (status, rows written,
    evaluations, steps, time reached, next step size, time of x_failed), the status FINISHED; PAUSED after the first
    step that brings the evaluations to ``pause`` (> 0; the caller checks the state and goes on with
    ``known`` True: the same steps as without the pause); TOO_SMALL_STEP (scipy's failure: the step
    size fell below the spacing of the numbers near t); or EVALUATION_FAILED, the state evaluated in
    x_failed (the caller's checked evaluation names why), the state and time reached those of the last
    accepted step (the caller may go on from there)."""
    dop853, A, B, C, E, E3, dense, n_stages, exponent = method
    n = state.shape[0]
    K = np.empty((max(A.shape[0], n_stages + 1), n))
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty((max(dense.shape[1], dense.shape[0] + 3), n)))
    y, y_new = state.copy(), np.empty(n)
    nfev, steps, n_rows, failed = 0, 0, first_row, -1
    if not known:
        nfev += 1
        failed = _rhs(f, pre, tree, post, n_q, t, y, rate)
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
        accepted, rejected = False, False
        while not accepted:
            if h_abs < min_step:
                _copy(y, state)
                return TOO_SMALL_STEP, n_rows, nfev, steps, t, h_abs, t
            t_new = t + h_abs
            if t_new - t_bound > 0:
                t_new = t_bound
            h = t_new - t
            h_abs = abs(h)
            _copy(rate, K[0])
            for s in range(1, n_stages):
                nfev += 1
                if _stage(f, pre, tree, post, n_q, K, A[s], s, h, t + C[s] * h, y, work[1], x_failed):
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t + C[s] * h
            nfev += 1
            if _stage(f, pre, tree, post, n_q, K, B, n_stages, h, t + h, y, y_new, x_failed):
                _copy(y, state)
                return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t + h
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
        last = n_rows
        while last < t_eval.shape[0] and t_eval[last] <= t_new:  # solve_ivp's searchsorted(side="right")
            last += 1
        if last > n_rows:
            for s in range(n_stages + 1, A.shape[0]):  # DOP853's extra stages of its dense output
                nfev += 1
                if _stage(f, pre, tree, post, n_q, K, A[s], s, h, t + C[s] * h, y, work[1], x_failed):
                    _copy(y, state)
                    return EVALUATION_FAILED, n_rows, nfev, steps, t, h_abs, t + C[s] * h
            _dense_rows(method, K, t, h, y, y_new, K[n_stages], t_eval, n_rows, last, rows, work)
            n_rows = last
        t = t_new
        y, y_new = y_new, y
        _copy(K[n_stages], rate)
        if pause > 0 and nfev >= pause and t != t_bound:
            _copy(y, state)
            return PAUSED, n_rows, nfev, steps, t, h_abs, t
    _copy(y, state)
    return FINISHED, n_rows, nfev, steps, t, h_abs, t


_CALLEES = (_rhs, _stage, _rms, _copy, _combine, _first_guess, _first_choice, _error_norm, _dense_rows)


@functools.cache
def _compiled(signature):
    """:func:`segment` compiled by numba for the argument types ``signature`` (the ẋ kernel's as a
    first-class function type first), cached on disk; its callees compiled with it."""
    numba = kernels.numba_module()
    namespace = dict(globals())

    def rebound(function):
        return types.FunctionType(function.__code__, namespace, function.__name__, function.__defaults__)

    for callee in _CALLEES:
        namespace[callee.__name__] = numba.extending.register_jitable(rebound(callee))
    return numba.njit([signature], cache=True)(rebound(segment))


class CompiledLoop:
    """The compiled :func:`segment` for one model's ẋ kernel (``model``: the evaluator's ``loop_model``)
    and one method of :data:`METHODS`; :meth:`run` steps a segment."""

    def __init__(self, model, method: str):
        self.model, self.method = model, tableau(method)
        self.kernel, self.compiled = _specialised(model, method)

    def run(self, n_q: int, t: float, x: NDArray, t_bound: float, h_abs: float, max_step: float, rtol: float,
            atol: float, t_eval: NDArray, monitor=None, every: int = 0) -> Stepped:
        """One segment from (t, x) to t_bound; ``monitor(t, x)`` called after the first step past each
        ``every`` evaluations (``every`` > 0), as :func:`segment` pauses: where it raises, the segment
        ends there (status STOPPED) with the rows computed so far."""
        t_eval, state = np.ascontiguousarray(t_eval, dtype=float).ravel(), np.array(x, dtype=float).ravel()
        rows, rate, x_failed = np.empty((len(t_eval), len(state))), np.empty(len(state)), np.empty(len(state))
        status, n_rows, nfev, steps, known, stopped_by = PAUSED, 0, 0, 0, False, None
        model = self.model
        if model.before is not None:
            model.before()
        while status == PAUSED:
            with _signals_held():  # the arguments of the types compiled for (the entry point checks none)
                status, n_rows, more, taken, t, h_abs, t_failed = self.compiled(
                    self.kernel, model.pre, model.tree, model.post, int(n_q), self.method, float(t), float(t_bound),
                    known, float(h_abs), float(max_step), float(rtol), float(atol), int(every), t_eval, n_rows, rows,
                    state, rate, x_failed)
            nfev, steps, known = nfev + more, steps + taken, True
            if status == PAUSED:
                try:
                    monitor(t, state)
                except Exception as exc:  # noqa: BLE001 - the caller raises it, keeping the rows
                    status, stopped_by = STOPPED, exc
        return Stepped(status, t, rows[:n_rows], state, x_failed, t_failed, nfev, steps, h_abs, stopped_by)


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
        compiled = _compiled(tuple(numba.typeof(a) for a in (
            kernel, model.pre, model.tree, model.post, 0, tableau(method), 0.0, 0.0, True, 0.0, 0.0, 0.0, 0.0, 0,
            np.zeros(1), 0, np.zeros((1, 1)), np.zeros(1), np.zeros(1), np.zeros(1))))
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
    if model is None or not isinstance(method, str) or method not in METHODS:
        return None
    if method not in model.loops:
        if compilation.compile_now():
            model.loops[method] = CompiledLoop(model, method)
        else:
            with compilation.cached_only():
                model.loops[method] = CompiledLoop(model, method)
    return model.loops[method]
