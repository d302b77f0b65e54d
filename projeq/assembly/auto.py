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

Compiling costs 10–40 s of CPU, more than a short run costs interpreted (README's pendulum
example: 17 s to compile ẋ against about 6 s for the whole example interpreted). So the picked
compiled evaluator's methods run where numba has their kernels (in this process or in its
disk cache) and otherwise by the reference evaluators, until
:data:`projeq.assembly.compilation.BUDGET` seconds of CPU are spent so (counted over the runs
of the same numba cache; one line on standard error says so; ``PROJEQ_COMPILE=now`` compiles
at first use instead); past that they compile. The
two agree to round-off (the evaluators' property tests), so a run's result does not depend
on which one ran, beyond round-off.

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

import time
import warnings

import numpy as np

from projeq.assembly import compilation, kernels
from projeq.assembly.beam_fast import hub_beam_unsupported
from projeq.assembly.fast import InterpretedWarning, PythonPieceWarning, unsupported

__all__ = ["AutoEvaluator", "InterpretedWarning", "PythonPieceWarning", "pick", "why_not_compiled"]


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
    "recursive"), ``reason`` (why; and whether it runs interpreted until compiled), ``interpreting``,
    ``evaluator`` (the picked evaluator, which counts the calls);
    ``accelerations`` and, where the picked one has them, ``state_derivative``, ``state_jacobian``,
    ``energy`` and ``gauss_form``: the picked evaluator's own, through a :class:`Tier` where it is compiled (module
    docstring), else called without a layer between.
    """

    def __init__(self, system):
        self.name, self._reason = pick(system)
        self.evaluator = system.evaluator(self.name)
        pieces = getattr(self.evaluator, "interpreted", None)
        if pieces:  # a compiled kernel with pieces in Python (the order-n kernel's warned)
            kernel = "the compiled order-n kernel" if self.name == "fast" else f"{self._reason}: the compiled kernel"
            self._reason = f"{kernel}, with {', '.join(pieces)} in Python"
        self.accelerations = self.evaluator.accelerations  # the picked one's, called directly (one layer less per s̈)
        if hasattr(self.evaluator, "state_derivative"):  # ẋ in one call (projeq.simulate's right-hand side)
            self.state_derivative = self.evaluator.state_derivative
        if hasattr(self.evaluator, "state_jacobian"):  # ∂ẋ/∂x in one call (projeq.analysis.jacobians)
            self.state_jacobian = self.evaluator.state_jacobian
        if hasattr(self.evaluator, "gauss_form"):  # M, b of a closed loop's tree (its numpy path)
            self.gauss_form = self.evaluator.gauss_form
        if getattr(self.evaluator, "compiled", False):
            self._tiered(system)
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

    def _tiered(self, system) -> None:
        """The compiled evaluator's methods, each by the reference evaluator while its kernels are
        not compiled and the budget lasts (module docstring, :class:`Tier`)."""
        from projeq.assembly.beam_fast import HubBeamEvaluator

        reference = HubBeamEvaluator(system, compiled=False) if self.name == "hub_beam" else \
            system.evaluator("dense" if system.coupled else "recursive")
        picked, model = self.evaluator, f"the {self.name!r} evaluator"
        self.accelerations = Tier(picked.accelerations, reference.accelerations, model, 0)
        self.state_derivative = Tier(picked.state_derivative, _none, model, 1)  # None: ẋ by q̇ and s̈
        if hasattr(picked, "state_jacobian"):  # None: the caller's complex step through s̈
            self.state_jacobian = Tier(picked.state_jacobian, _none, model, 1)
        self.energy = Tier(picked.energy, lambda q, s_dot, t: system._energy(q, s_dot, t, "recursive"), model, 0)
        if hasattr(picked, "gauss_form"):
            self.gauss_form = Tier(picked.gauss_form, system.evaluator("dense").gauss_form, model, 0)

    def loop_model(self) -> "LoopModel | None":
        """The picked evaluator's model for the compiled integration loop
        (:meth:`projeq.assembly.fast.FastEvaluator.loop_model`) once its ẋ runs compiled; None while
        it runs interpreted, or where the picked evaluator has none."""
        tier = getattr(self, "state_derivative", None)
        if isinstance(tier, Tier) and not tier.real_ready:
            return None
        provider = getattr(self.evaluator, "loop_model", None)
        return None if provider is None else provider()

    def energies(self, q_rows, s_rows, times):
        """The picked evaluator's (T, V) of many rows at once
        (:meth:`projeq.assembly.fast.FastEvaluator.energies`) once its energy runs compiled; None while it
        runs interpreted, or where the picked evaluator cannot (then row by row). The first row's energy
        by the tier first: it compiles (or finds) the kernels where the compile policy lets it."""
        tier = getattr(self, "energy", None)
        if isinstance(tier, Tier) and not tier.real_ready and len(times):
            tier(q_rows[0], s_rows[0], times[0])
        if not (isinstance(tier, Tier) and tier.real_ready) or not hasattr(self.evaluator, "energies"):
            return None
        return self.evaluator.energies(q_rows, s_rows, times)

    @property
    def reason(self) -> str:
        """Why this evaluator (:func:`pick`), and, while its kernels are not compiled yet, that the
        reference evaluator runs in their place."""
        if self.interpreting:
            return f"{self._reason}; interpreted by the reference evaluator until its kernels are compiled"
        return self._reason

    @property
    def interpreting(self) -> bool:
        """Whether a method of the compiled evaluator last ran interpreted (its kernels not compiled yet)."""
        return any(getattr(getattr(self, name, None), "deferred", None) for name in Tier.METHODS)


_FLOAT = np.dtype(float)


def _none(*args) -> None:
    """No one-call result: the caller evaluates otherwise."""
    return None


class Tier:
    """One method of a compiled evaluator, ``compiled``, run by ``interpreted`` (same arguments, same
    result to round-off) while numba has not compiled its kernels for the dtype of argument
    ``state`` (real or complex) and the budget of interpreted CPU lasts
    (:func:`projeq.assembly.compilation.compile_now`); past it, compiled (numba compiles then,
    announced). Once compiled (or loaded from the cache) for a dtype, the compiled method is
    called directly."""

    METHODS = ("accelerations", "state_derivative", "state_jacobian", "energy")

    def __init__(self, compiled, interpreted, what: str, state: int):
        self.compiled, self.interpreted, self.what, self.state = compiled, interpreted, what, state
        self.ready, self.deferred = set(), set()  # dtype kinds ("f", "c") compiled, and found not compiled
        self.real_ready = False

    def __call__(self, *args):
        if self.real_ready and getattr(args[self.state], "dtype", None) is _FLOAT:  # the common case, first
            return self.compiled(*args)
        return self._tiered(args)

    def _tiered(self, args):
        kind = "c" if getattr(args[self.state], "dtype", _FLOAT).kind == "c" else "f"
        if kind in self.ready:
            return self.compiled(*args)
        if compilation.compile_now():
            value = self.compiled(*args)  # compiles where numba has not (announced)
        elif kind in self.deferred:
            return self._interpreted(args)
        else:
            try:
                with compilation.cached_only():
                    value = self.compiled(*args)
            except compilation.NotCompiled:
                self.deferred.add(kind)
                return self._interpreted(args)
        self.ready.add(kind)
        self.deferred.discard(kind)
        self.real_ready = "f" in self.ready
        return value

    def _interpreted(self, args):
        started = time.process_time()
        try:
            return self.interpreted(*args)
        finally:
            compilation.spend(time.process_time() - started, self.what)
