"""Evaluators of the Projection Equation: the same System, three evaluators, one signature.

``EVALUATORS`` maps a name to a class whose instances take ``(q, s_dot, t)`` in
``accelerations``; they agree to round-off (tests/assembly/test_recursive_vs_dense.py).
"""

from projeq.assembly.dense import DenseEvaluator
from projeq.assembly.fast import FastEvaluator
from projeq.assembly.linalg import SingularMassError
from projeq.assembly.recursive import RecursiveEvaluator

EVALUATORS = {"recursive": RecursiveEvaluator, "dense": DenseEvaluator, "fast": FastEvaluator}

__all__ = ["EVALUATORS", "DenseEvaluator", "FastEvaluator", "RecursiveEvaluator", "SingularMassError"]
