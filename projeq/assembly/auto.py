"""``method="auto"``, the default evaluator: the best evaluator available for a System, picked once.

In this order: ``"hub_beam"`` (:mod:`projeq.assembly.beam_fast`, compiled) for one RitzBeam on a
prescribed or fixed hub (interpreted, with one :class:`InterpretedWarning`, for a user's
subsystem there); ``"fast"`` (the compiled order-n kernel, :mod:`projeq.assembly.fast`)
when the kernel knows every subsystem (rigid bodies, spatial or planar, on any joint, coupled
ones included, under any force law; RitzBeams, rotary inertia and torsion included, anywhere
in a tree under gravity and the force laws the kernel compiles); else the
reference evaluators, ``"dense"`` when joints share minimal velocities (coupled) and
``"recursive"`` otherwise, with one :class:`InterpretedWarning` per System naming the piece
the kernel does not know — the fall-back is never silent. Each evaluator evaluates its
systems or refuses them with the reason; "auto" is the only place that chooses, and it
says what it chose (``name``, ``reason``). The compiled kernel is compiled on its first
use and cached on disk (numba's ``cache=True``): a fresh environment pays the compilation
once (``projeq bench`` reports the first-call latency), later processes load it.

>>> import warnings, numpy as np, projeq as pq
>>> AutoEvaluator(pq.scenes.atwood()).name  # coupled joints: compiled
'fast'
>>> class Own(pq.RigidBody):  # its own gauss_terms: the kernel cannot know what they compute
...     def gauss_terms(self, y_dot, R, gravity, q_e=None):
...         return super().gauss_terms(y_dot, R, gravity, q_e)
>>> system = pq.System({"rod": Own(1.0, (0, 0, -0.5), np.eye(3) / 12)}, {"rod": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81))
>>> with warnings.catch_warnings(record=True) as said:
...     warnings.simplefilter("always")
...     ev = AutoEvaluator(system)
>>> ev.name
'recursive'
>>> [str(w.message) for w in said]  # doctest: +NORMALIZE_WHITESPACE
["system: evaluated by the interpreted 'recursive' evaluator, not the compiled one: subsystem 'rod' is a
Own (the kernel knows the terms of rigid bodies, rigid_inertia, spatial or selected by S, and of
RitzBeams)"]
"""

from __future__ import annotations

import warnings

from projeq.assembly import kernels
from projeq.assembly.beam_fast import hub_beam_unsupported
from projeq.assembly.fast import InterpretedWarning, unsupported

__all__ = ["AutoEvaluator", "InterpretedWarning", "pick", "why_not_compiled"]


def why_not_compiled(system) -> str | None:
    """Why the compiled kernel cannot evaluate ``system`` (None if it can)."""
    return unsupported(system) or (None if kernels.has_numba() else "numba is not installed")


def pick(system) -> tuple[str, str]:
    """(name, reason): the evaluator "auto" picks for ``system`` and why (module docstring)."""
    if hub_beam_unsupported(system) is None:
        return "hub_beam", "one RitzBeam on a prescribed or fixed hub"
    why_not_fast = why_not_compiled(system)
    if why_not_fast is None:
        return "fast", "the compiled order-n kernel knows every joint, subsystem and force law"
    return ("dense" if system.coupled else "recursive"), f"the fast kernel cannot evaluate it: {why_not_fast}"


class AutoEvaluator:
    """The evaluator :func:`pick` chooses for ``system`` (the System's cached one), and which;
    warns once (:class:`InterpretedWarning`) when that is an interpreted reference evaluator.

    Attributes: ``name`` (of the picked evaluator: "fast", "hub_beam", "dense" or
    "recursive"), ``reason`` (why), ``evaluator`` (the picked evaluator, which counts the calls);
    ``accelerations`` and, where the picked one has them, ``state_derivative`` and ``state_jacobian`` are the picked
    evaluator's own (called without a layer between).
    """

    def __init__(self, system):
        self.name, self.reason = pick(system)
        self.evaluator = system.evaluator(self.name)
        if getattr(self.evaluator, "interpreted", None):  # the compiled kernel with pieces in Python (it warned)
            self.reason = f"the compiled order-n kernel, with {', '.join(self.evaluator.interpreted)} in Python"
        self.accelerations = self.evaluator.accelerations  # the picked one's, called directly (one layer less per s̈)
        if hasattr(self.evaluator, "state_derivative"):  # ẋ in one call (projeq.simulate's right-hand side)
            self.state_derivative = self.evaluator.state_derivative
        if hasattr(self.evaluator, "state_jacobian"):  # ∂ẋ/∂x in one call (projeq.analysis.jacobians)
            self.state_jacobian = self.evaluator.state_jacobian
        if self.name in ("dense", "recursive"):
            warnings.warn(
                f"system: evaluated by the interpreted {self.name!r} evaluator, not the compiled one: "
                f"{why_not_compiled(system)}", InterpretedWarning, stacklevel=3,
            )
        elif self.name == "hub_beam" and not self.evaluator.compiled:
            warnings.warn(
                f"system: evaluated by the interpreted 'hub_beam' path, not the compiled one: "
                f"{self.evaluator.interpreted_reason}", InterpretedWarning, stacklevel=3,
            )
