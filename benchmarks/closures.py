"""The constrained scenes' s̈ in one compiled call against the numpy path it replaces, both next
to the compiled ``scenes.chain(k)`` (k = the scene's minimal velocities), timed alternately in one
run (:func:`projeq.studies.timing.time_per_call`: ratios, not absolute times, hold on a loaded
machine), each at eight states near q0 in turn (:func:`projeq.studies.bench_scenes.moving_states`,
as ``projeq bench``). "numpy path": Φ's batched complex-step derivatives, the partition (or the null space)
and the projection by numpy on the compiled tree's Gauss form (the default before
:mod:`projeq.constraints.compiled`); "default": what ``system.evaluator()`` does now.

    python benchmarks/closures.py                 # every constrained scene
    python benchmarks/closures.py four_bar        # some of them
    python benchmarks/closures.py --quick         # four-bar and Andrews' squeezer, 0.02 s each (a test)
"""

from __future__ import annotations

import os
import argparse
import itertools
import warnings

import numpy as np

from projeq import scenes
from projeq.studies.bench_scenes import STATES, moving_states
from projeq.studies.table import Table
from projeq.studies.timing import time_per_call

CONSTRAINED = ("whipple_bicycle", "quick_return", "four_bar", "simple_pendulum", "n_four_bar", "bricard",
               "andrews_squeezer")


def row(name: str, budget: float) -> dict:
    """µs per s̈ of the scene by its default and by the numpy path, and of chain(k)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a Φ that does not compile says so once; the row shows it
        system = scenes.SCENES[name].build()
        ev = system.evaluator()
    k, rng = system.n_s, np.random.default_rng(system.n_s)
    chain = scenes.chain(k)
    chain_ev = chain.evaluator("fast")
    states, chain_states = (itertools.cycle(moving_states(m, STATES, rng)) for m in (system, chain))
    seconds = time_per_call({
        "default": lambda _q, _s: ev.accelerations(*next(states), 0.0),
        "numpy": lambda _q, _s: system._projected_accelerations(*next(states), 0.0, None),
        "chain": lambda _q, _s: chain_ev.accelerations(*next(chain_states), 0.0),
    }, None, None, budget)
    return {"scene": name, "k": k, **{f"{key}_us": value * 1e6 for key, value in seconds.items()},
            "compiled": system.compiled_kernel() is not None}


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", default=CONSTRAINED, help="scene names (default: the constrained ones)")
    parser.add_argument("--budget", type=float, default=0.5, help="seconds of timing per scene (default 0.5)")
    parser.add_argument("--quick", action="store_true", help="four-bar and Andrews' squeezer, 0.02 s each")
    args = parser.parse_args(argv)
    names, budget = (("four_bar", "andrews_squeezer"), 0.02) if args.quick else (args.scenes, args.budget)
    rows = [row(name, budget) for name in names]
    print(Table(("scene", "k", "chain_us", "numpy_us", "default_us", "numpy/chain", "default/chain", "one compiled call"),
                [(r["scene"], r["k"], r["chain_us"], r["numpy_us"], r["default_us"], r["numpy_us"] / r["chain_us"],
                  r["default_us"] / r["chain_us"], "yes" if r["compiled"] else "no") for r in rows],
                units={"chain_us": "µs", "numpy_us": "µs", "default_us": "µs"},
                formats={"chain_us": ".1f", "numpy_us": ".1f", "default_us": ".1f", "numpy/chain": ".1f",
                         "default/chain": ".2f"}).to_text())
    return rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
