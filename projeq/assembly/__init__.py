"""Evaluators of the Projection Equation: the same System, two algorithms, one signature.

``EVALUATORS`` maps a name to a class whose instances take ``(q, s_dot, t)`` in
``accelerations``; they agree to round-off (tests/assembly/test_recursive_vs_dense.py).
"""

from projeq.assembly.dense import DenseEvaluator
from projeq.assembly.linalg import SingularMassError
from projeq.assembly.recursive import RecursiveEvaluator

EVALUATORS = {"recursive": RecursiveEvaluator, "dense": DenseEvaluator}

__all__ = ["EVALUATORS", "DenseEvaluator", "RecursiveEvaluator", "SingularMassError"]
