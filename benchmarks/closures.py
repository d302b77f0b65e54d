"""The constrained scenes' s̈ in one compiled call against the numpy path it replaces, both next
to the compiled ``scenes.chain(k)`` (k = the scene's minimal velocities), timed alternately in one
run (:func:`projeq.studies.timing.time_per_call`: ratios, not absolute times, hold on a loaded
machine). "numpy path": Φ's batched complex-step derivatives, the partition (or the null space)
and the projection by numpy on the compiled tree's Gauss form (the default before
:mod:`projeq.constraints.compiled`); "default": what ``system.evaluator()`` does now.

    python benchmarks/closures.py                 # every constrained scene
    python benchmarks/closures.py four_bar        # some of them
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from projeq import scenes
from projeq.studies.timing import time_per_call

CONSTRAINED = ("whipple_bicycle", "quick_return", "four_bar", "simple_pendulum", "n_four_bar", "bricard",
               "andrews_squeezer")


def row(name: str, budget: float) -> dict:
    """µs per s̈ of the scene by its default and by the numpy path, and of chain(k)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a Φ that does not compile says so once; the row shows it
        system = scenes.SCENES[name].build()
        ev = system.evaluator()
    q, s_dot = system.q0, system.s_dot0
    chain = scenes.chain(system.n_s).evaluator("fast")
    chain_q, chain_s = np.random.default_rng(system.n_s).uniform(-1, 1, (2, system.n_s))
    seconds = time_per_call({
        "default": lambda _q, _s: ev.accelerations(q, s_dot, 0.0),
        "numpy": lambda _q, _s: system._projected_accelerations(q, s_dot, 0.0, None),
        "chain": lambda _q, _s: chain.accelerations(chain_q, chain_s, 0.0),
    }, None, None, budget)
    return {"scene": name, "k": system.n_s, **{f"{key}_us": value * 1e6 for key, value in seconds.items()},
            "compiled": system.compiled_kernel() is not None}


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", default=CONSTRAINED, help="scene names (default: the constrained ones)")
    parser.add_argument("--budget", type=float, default=0.5, help="seconds of timing per scene (default 0.5)")
    args = parser.parse_args(argv)
    rows = [row(name, args.budget) for name in args.scenes]
    print(f"{'scene':18s} {'k':>2s} {'chain µs':>9s} {'numpy µs':>9s} {'default µs':>10s} "
          f"{'numpy/chain':>11s} {'default/chain':>13s}  one compiled call")
    for r in rows:
        print(f"{r['scene']:18s} {r['k']:2d} {r['chain_us']:9.1f} {r['numpy_us']:9.1f} {r['default_us']:10.1f} "
              f"{r['numpy_us'] / r['chain_us']:11.1f} {r['default_us'] / r['chain_us']:13.2f}  "
              f"{'yes' if r['compiled'] else 'no'}")
    return rows


if __name__ == "__main__":
    main()
