"""Cost of s̈ of every scene of ``projeq list`` with the default evaluator, against
``scenes.chain(k)`` with k = the scene's number of minimal velocities (issue 15: "every
scene at most 3× the cost of chain(k)").

For each scene (default parameters, t = 0, at ``STATES`` states near its q0 taken in turn:
:func:`moving_states`): which evaluator the default
(``method=None``, :mod:`projeq.assembly.auto`) picks — "fast" (compiled), "hub_beam",
or an interpreted reference ("recursive", "dense"; a ConstrainedSystem projects its tree's
Gauss form, compiled or dense: "partitioned(fast)", "partitioned(dense)") — and the CPU time of one s̈ call next to the
compiled chain of the same k, both timed alternately in one run
(:func:`projeq.studies.timing.time_per_call`), so the ratio holds on a loaded machine.

    projeq bench                              # includes this table
    python benchmarks/scene_costs.py          # this table alone (--json: the rows)
"""

from __future__ import annotations

import itertools
import math
import os
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

from projeq import scenes
from projeq.assembly.auto import InterpretedWarning
from projeq.studies.table import Table
from projeq.studies.timing import time_per_call

#: the evaluators that are not the interpreted reference path (a ConstrainedSystem's
#: "partitioned(fast)" projects the compiled Gauss form of its tree)
COMPILED = ("fast", "hub_beam", "partitioned(fast)")


def default_evaluator(system) -> tuple[str, str]:
    """(name, reason) of the evaluator a model's default picks, without the warning it
    would show."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InterpretedWarning)
        ev = system.evaluator()
    return ev.name, ev.reason


STATES = 8  # the states each s̈ is timed at, in turn (moving_states)


def moving_states(system, count: int, rng) -> list:
    """``count`` states (q, ṡ) near the model's initial one, as a run visits them: q0 moved by
    1e-2 along random directions and put back onto the model's manifold (``normalized``: unit
    quaternions, a closed loop's Φ = 0), ṡ uniform in [−1, 1]. Each call of a timing meets
    another state, so no evaluator serves it from what it kept of the last (a closed loop's
    decomposition, its partition), and no scene is timed at rest only."""
    q0 = np.asarray(system.q0, dtype=float)
    return [(system.normalized(q0 + 1e-2 * rng.standard_normal(q0.size)), rng.uniform(-1, 1, system.n_s))
            for _ in range(count)]


def scene_row(name: str, budget: float) -> dict:
    """One scene: evaluator, k = n_s, µs per s̈ call, the chain(k)'s, and their ratio, each
    over :data:`STATES` states taken in turn (:func:`moving_states`)."""
    system = scenes.SCENES[name].build()
    evaluator, reason = default_evaluator(system)
    k = system.n_s
    chain = scenes.chain(k)
    scene_ev, chain_ev = system.evaluator(), chain.evaluator("fast")
    rng = np.random.default_rng(k)
    scene_states = itertools.cycle(moving_states(system, STATES, rng))
    chain_states = itertools.cycle(moving_states(chain, STATES, rng))
    seconds = time_per_call({
        "scene": lambda _q, _s: scene_ev.accelerations(*next(scene_states), 0.0),
        "chain": lambda _q, _s: chain_ev.accelerations(*next(chain_states), 0.0),
    }, None, None, budget)
    return {"scene": name, "evaluator": evaluator, "k": k, "scene_us": seconds["scene"] * 1e6,
            "chain_us": seconds["chain"] * 1e6, "ratio": seconds["scene"] / seconds["chain"], "reason": reason}


def scene_costs(budget: float = 0.2, deadline: float = math.inf, show=None) -> tuple[list, bool]:
    """(rows, complete): :func:`scene_row` for every scene of :data:`projeq.scenes.SCENES`
    until ``deadline`` (``time.perf_counter``); ``show`` receives the table."""
    rows = []
    for name in scenes.SCENES:
        if time.perf_counter() > deadline:
            break
        rows.append(scene_row(name, budget))
    if show is not None:
        show(table(rows).to_text())
    return rows, len(rows) == len(scenes.SCENES)


def table(rows) -> Table:
    """The rows as a :class:`~projeq.studies.table.Table`."""
    columns = ("scene", "evaluator", "k", "scene_us", "chain_us", "ratio")
    return Table.from_columns(
        {c: [r[c] for r in rows] for c in columns},
        units={"scene_us": "µs", "chain_us": "µs"}, formats={"ratio": ".2f", "scene_us": ".1f", "chain_us": ".1f"},
        title="s̈ per call with the default evaluator vs the compiled chain(k), k = n_s (ratio = scene/chain)",
    )


_FIRST_CALL = (
    "import time; t0 = time.perf_counter(); import projeq; t1 = time.perf_counter(); "
    "s = projeq.scenes.chain(3); s.accelerations(s.q0, s.s_dot0); "
    "print(t1 - t0, time.perf_counter() - t1)"
)


def first_call_latency(python: str = sys.executable) -> dict:
    """Seconds from ``import projeq`` to the first compiled s̈ of ``scenes.chain(3)`` in a
    fresh process: with an empty numba cache (``NUMBA_CACHE_DIR`` a new directory: the
    kernel is compiled, what a fresh install pays once) and again with that cache filled
    (what every later process pays); and the import time itself."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PROJEQ_COMPILE": "now"}  # compiled at the first call
        runs = [subprocess.run([python, "-c", _FIRST_CALL], env=env, capture_output=True, text=True, check=True)
                for _ in range(2)]
    (import_s, cold), (_, warm) = (map(float, run.stdout.split()) for run in runs)
    return {"import_s": import_s, "first_call_cold_cache_s": cold, "first_call_warm_cache_s": warm}
