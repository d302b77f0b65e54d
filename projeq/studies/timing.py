"""CPU time of one call of several functions, timed alternately in one run, so that their
ratios hold on a loaded machine (:func:`time_per_call`, used by every benchmark of
:mod:`projeq.studies`)."""

from __future__ import annotations

import time
import timeit

import numpy as np


def right_hand_side(system, evaluator=None):
    """simulate's ẋ(t, x) of ``system`` as a benchmark times it: the evaluator's one-call ẋ
    (``state_derivative``; ``evaluator`` None: the system's default one), else q̇ and its s̈, as
    :meth:`projeq.simulation.driver._Run.rhs` takes them."""
    ev = system.evaluator() if evaluator is None else evaluator
    fused = getattr(ev, "state_derivative", None)
    n_q = system.n_q

    def x_dot(t, x):
        found = None if fused is None else fused(t, x)
        if found is None:
            found = np.concatenate((system.q_dot(x[:n_q], x[n_q:], t), ev.accelerations(x[:n_q], x[n_q:], t)))
        return found

    return x_dot


def per_call(f, seconds: float) -> float:
    """µs per call of ``f()`` over about ``seconds`` (after one call that compiles or warms it),
    by :func:`timeit.timeit`: wall time, for the alternating rounds of a benchmark."""
    f()
    number = max(1, int(seconds / max(timeit.timeit(f, number=20) / 20, 1e-7)))
    return timeit.timeit(f, number=number) / number * 1e6


def time_per_call(funcs: dict, q, s_dot, budget: float, clock=time.process_time, batch: float = 2e-3) -> dict:
    """Minimum CPU time of one call per function, alternating them until ``budget``
    seconds are spent (at least 3 rounds, after one warm-up call each).

    Each function is timed in batches of repeated calls lasting about ``batch`` seconds, so
    that the clock's granularity (a CPU-time clock may tick in coarse steps on virtual
    machines) cannot round a short call to zero; the result is the fastest batch's mean.

    By default CPU time of this process (``time.process_time``), not wall time: on a loaded
    machine a call that is preempted would otherwise count the other processes' time
    slices, which hits long calls more often than short ones and biases the slopes
    upwards. CPU time counts every thread, though, so calls into multithreaded BLAS (the
    dense evaluator at n ≳ 100) are better timed with ``clock=time.perf_counter``.
    """
    best = dict.fromkeys(funcs, np.inf)
    repeats = {name: _repeats(f, q, s_dot, batch) for name, f in funcs.items()}
    started, rounds = time.perf_counter(), 0
    while rounds < 3 or time.perf_counter() - started < budget:
        for name, f in funcs.items():
            t0 = clock()
            for _ in range(repeats[name]):
                f(q, s_dot)
            best[name] = min(best[name], (clock() - t0) / repeats[name])
        rounds += 1
    return best


def _repeats(f, q, s_dot, batch: float) -> int:
    """How many calls of f (after a warm-up call) take about ``batch`` seconds of wall time."""
    f(q, s_dot)
    t0 = time.perf_counter()
    f(q, s_dot)
    return max(1, int(batch / max(time.perf_counter() - t0, 1e-9)))
