"""``method="auto"``: the best evaluator available for a System, picked once.

In this order: ``"fast"`` (the compiled order-n kernel, :mod:`projeq.assembly.fast`) when
numba is installed and the kernel knows every joint and subsystem; ``"hub_beam"``
(:mod:`projeq.assembly.beam_fast`) for one RitzBeam on a prescribed or fixed hub; else the
general evaluators, ``"dense"`` when joints share minimal velocities (coupled) and
``"recursive"`` otherwise. Each of them evaluates its systems or refuses them with the
reason; "auto" is the only place that chooses, and it says what it chose. The choice is
by cost per call: the compiled kernel is compiled on its first use in a fresh environment
(seconds; cached on disk afterwards), which the default evaluator (``method=None``:
recursive, or dense when coupled) never pays.

>>> import projeq as pq
>>> ev = AutoEvaluator(pq.scenes.atwood())
>>> ev.name, ev.reason
('dense', "the fast kernel cannot evaluate it: joint 'mass1' is coupled (shared minimal velocities)")
"""

from __future__ import annotations

from numpy.typing import NDArray

from projeq.assembly import kernels
from projeq.assembly.beam_fast import hub_beam_unsupported
from projeq.assembly.fast import unsupported


def pick(system) -> tuple[str, str]:
    """(name, reason): the evaluator "auto" picks for ``system`` and why (module docstring)."""
    why_not_fast = unsupported(system) or (None if kernels.has_numba() else "numba is not installed")
    if why_not_fast is None:
        return "fast", "the compiled order-n kernel knows every joint and subsystem"
    if hub_beam_unsupported(system) is None:
        return "hub_beam", "one RitzBeam on a prescribed or fixed hub"
    return ("dense" if system.coupled else "recursive"), f"the fast kernel cannot evaluate it: {why_not_fast}"


class AutoEvaluator:
    """The evaluator :func:`pick` chooses for ``system`` (the System's cached one), and which.

    Attributes: ``name`` (of the picked evaluator: "fast", "hub_beam", "dense" or
    "recursive"), ``reason`` (why), ``evaluator`` (the picked evaluator, which counts the calls).
    """

    def __init__(self, system):
        self.name, self.reason = pick(system)
        self.evaluator = system.evaluator(self.name)

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """s̈ at (q, ṡ, t) by the picked evaluator."""
        return self.evaluator.accelerations(q, s_dot, t)
