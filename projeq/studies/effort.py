"""The effort of a derivation, measured alike for every row of a comparison table.

Each derivation starts from the same state (sympy's cache and projeq's memoised derivations
emptied), is repeated, and its median wall time reported; its operation count is
``sympy.count_ops`` after one ``sympy.cse`` with the parameters as numbers and functions of time
as symbols. Shared by :mod:`projeq.studies.compare` and :mod:`projeq.studies.compare_multipliers`.
"""

from __future__ import annotations

import contextvars
import sys
import time

import numpy as np
import sympy as sp

__all__ = ["DERIVATION_REPEATS", "EFFORT", "as_symbols", "cold_start", "cse_ops", "derivation_timed", "derivation_repeats",
           "timed"]


def cse_ops(expressions, values=None) -> int:
    """The operation count of every row: ``sympy.count_ops`` over the output of ``sympy.cse``
    (replacements and reduced expressions) of ``expressions`` with the parameters replaced by
    the numbers ``values`` and functions of time (or space) and their derivatives by symbols."""
    from projeq.symbolic.projection import operation_count

    numbers = {k: sp.Float(v) for k, v in (values or {}).items()}
    return operation_count(*sp.cse([as_symbols(sp.sympify(e).xreplace(numbers)) for e in expressions]))


def as_symbols(expression):
    """``expression`` with every applied undefined function (x(t), w(x, t)) and its derivatives
    as a plain symbol: x, x_t, alpha_tt, w_xx."""
    from sympy.core.function import AppliedUndef

    expression = sp.sympify(expression)
    expression = expression.xreplace({
        d: sp.Symbol(f"{d.expr.func.__name__}_" + "".join(str(v) * n for v, n in d.variable_count))
        for d in expression.atoms(sp.Derivative) if isinstance(d.expr, AppliedUndef)})
    return expression.xreplace({f: sp.Symbol(f.func.__name__) for f in expression.atoms(AppliedUndef)})


def timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


DERIVATION_REPEATS = 3  # the CLI's default
derivation_repeats = contextvars.ContextVar("derivation_repeats", default=DERIVATION_REPEATS)
EFFORT = ("derivation_s: median of {repeats} runs, each from the same state: sympy.core.cache.clear_cache() and "
          "projeq's memoised derivations (functools caches in projeq.symbolic, projeq.scenes) emptied first. "
          "n_ops: sympy.count_ops after sympy.cse of the derived equations (Gauss form: M and rhs; multiplier form: "
          "its residuals; Hamilton's canonical form: q̇ and ṗ; Barhorst's: p and ṗ; beam: every intermediate "
          "expression of the field equations and the Ritz model, summed over the steps), "
          "parameters replaced by their numbers, functions of time by symbols; numeric evaluators derive nothing.")


def cold_start() -> None:
    """The same starting state for every derivation: sympy's cache and the functools caches of
    projeq's symbolic and scene modules emptied (a derivation met before is derived again)."""
    from sympy.core.cache import clear_cache

    clear_cache()
    for name, module in list(sys.modules.items()):
        if module is None or not name.startswith(("projeq.symbolic", "projeq.scenes")):
            continue
        for obj in list(vars(module).values()):
            if getattr(obj, "__module__", None) == name and callable(getattr(obj, "cache_clear", None)):
                obj.cache_clear()


def derivation_timed(derive):
    """(the result of ``derive()``, the median of its wall times over ``repeats`` runs), each run
    after :func:`cold_start` — the effort procedure of every row (``EFFORT``)."""
    times = []
    for _ in range(derivation_repeats.get()):
        cold_start()
        out, seconds = timed(derive)
        times.append(seconds)
    return out, float(np.median(times))
