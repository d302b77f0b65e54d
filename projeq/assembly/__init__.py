"""Evaluators of the Projection Equation: the same System, several evaluators, one signature.

``EVALUATORS`` maps a name to a class whose instances take ``(q, s_dot, t)`` in
``accelerations``; they agree to round-off (tests/assembly/test_recursive_vs_dense.py,
test_fast.py). Each evaluates the systems it knows and refuses the others with a
ValueError saying why, when it is built; ``"auto"`` picks one (:mod:`projeq.assembly.auto`).
"""

from projeq.assembly.auto import AutoEvaluator, InterpretedWarning, PythonPieceWarning
from projeq.assembly.beam_fast import HubBeamEvaluator
from projeq.assembly.dense import DenseEvaluator
from projeq.assembly.fast import FastEvaluator
from projeq.assembly.linalg import SingularMassError
from projeq.assembly.recursive import RecursiveEvaluator

EVALUATORS = {
    "recursive": RecursiveEvaluator,
    "dense": DenseEvaluator,
    "fast": FastEvaluator,
    "hub_beam": HubBeamEvaluator,
    "auto": AutoEvaluator,
}

__all__ = [
    "EVALUATORS", "AutoEvaluator", "DenseEvaluator", "FastEvaluator", "HubBeamEvaluator", "InterpretedWarning",
    "PythonPieceWarning", "RecursiveEvaluator",
    "SingularMassError",
]
