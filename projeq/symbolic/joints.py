"""The joints of :mod:`projeq.joints` in sympy: their relative kinematics (THEORY §4).

For a joint at (q_n, ṡ_n, t) :func:`relative` returns a :class:`SymbolicRelative`:
``A`` (child → joint frame), ``r`` (J → O_n, joint-frame coordinates), ``F`` (F⁶_n, the
relative twist (v, ω) per unit ṡ_n in child coordinates), ``f`` (f⁶, the rheonomic part
of the twist) and the kinematics q̇_n = K ṡ_n + k — the same quantities the numeric
``Joint.relative`` and ``Joint.K`` give, as expressions.

The numbers a joint was built with become exact integers where they are integral (axes
along x, y, z stay 0 and ±1), floats otherwise.
"""

from __future__ import annotations

from typing import NamedTuple

import sympy as sp

from ..joints import Fixed, Free, Planar, Prescribed, Prismatic, Revolute, UserJoint
from .algebra import exact, mul, quaternion_matrix, quaternion_rate_matrix, rotation

__all__ = ["SymbolicRelative", "relative"]


class SymbolicRelative(NamedTuple):
    """Relative kinematics of one joint, sympy matrices (see the module docstring)."""

    A: sp.Matrix
    r: sp.Matrix
    F: sp.Matrix
    f: sp.Matrix
    K: sp.Matrix
    k: sp.Matrix


def _one_axis(joint, q_n) -> tuple:
    """(A, r, F) of a Revolute or Prismatic joint at the coordinate q_n[0]."""
    e = exact(joint.axis)
    if isinstance(joint, Revolute):
        return rotation(e, q_n[0]), sp.zeros(3, 1), sp.Matrix.vstack(sp.zeros(3, 1), e)
    return sp.eye(3), e * q_n[0], sp.Matrix.vstack(e, sp.zeros(3, 1))


def _user(joint, name, q_n, s_n, t) -> SymbolicRelative:
    """A ``UserJoint.from_sympy``: its own expressions with projeq's symbols put in."""
    symbols = getattr(joint, "symbols", None)
    if symbols is None:
        raise ValueError(f"system: joint {name!r} (UserJoint from callables) has no expressions; "
                         "build it with UserJoint.from_sympy to derive it symbolically")
    rename = dict(zip(symbols["q"], q_n)) | dict(zip(symbols["s"], s_n)) | {symbols["t"]: t}
    A, r, F, K, f, k = (symbols[key].xreplace(rename) for key in ("A", "r", "F", "K", "f", "k"))
    return SymbolicRelative(A, r, F, f, K, k)


def relative(joint, name: str, q_n, s_n, t, motion=None) -> SymbolicRelative:
    """Relative kinematics of ``joint`` (named ``name``) at the symbols or expressions
    q_n, s_n and time t; ``motion`` is θ(t) of a :class:`Prescribed` joint."""
    no_k, no_f = sp.zeros(len(q_n), 1), sp.zeros(6, 1)
    if isinstance(joint, (Revolute, Prismatic)):
        A, r, F = _one_axis(joint, q_n)
        return SymbolicRelative(A, r, F, no_f, sp.eye(1), no_k)
    if isinstance(joint, Fixed):
        return SymbolicRelative(sp.eye(3), sp.zeros(3, 1), sp.zeros(6, 0), no_f, sp.zeros(0, 0), no_k)
    if isinstance(joint, Planar):
        P, n = exact(joint._P), exact(joint.normal)
        A = rotation(n, q_n[2])
        K = sp.diag(mul(P, A, P.T), 1)
        return SymbolicRelative(A, mul(P.T, sp.Matrix(q_n[:2])), exact(joint._F), no_f, K, no_k)
    if isinstance(joint, Free):
        A, Gamma = quaternion_matrix(q_n[3:]), quaternion_rate_matrix(q_n[3:])
        return SymbolicRelative(A, sp.Matrix(q_n[:3]), sp.eye(6), no_f, sp.diag(A, Gamma), no_k)
    if isinstance(joint, Prescribed):
        if motion is None:
            raise ValueError(f"parameters: joint {name!r} (Prescribed) needs its motion θ(t) as a sympy "
                             f"expression: parameters={{'{name}.motion': ...}}")
        A, r, F = _one_axis(joint.joint, [motion])
        return SymbolicRelative(A, r, sp.zeros(6, 0), F * motion.diff(t), sp.zeros(0, 0), no_k)
    if isinstance(joint, UserJoint):
        return _user(joint, name, q_n, s_n, t)
    raise ValueError(f"system: joint {name!r} ({type(joint).__name__}) is not supported symbolically; "
                     "use projection_equation with its velocity expressions")
