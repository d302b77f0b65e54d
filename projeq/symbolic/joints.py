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

import numpy as np
import sympy as sp

from ..joints import Fixed, Free, Planar, Prescribed, Prismatic, Revolute, UserJoint
from projeq.joints.user_compiler import skew

__all__ = ["SymbolicRelative", "relative", "exact", "skew", "cross", "mul"]


class SymbolicRelative(NamedTuple):
    """Relative kinematics of one joint, sympy matrices (see the module docstring)."""

    A: sp.Matrix
    r: sp.Matrix
    F: sp.Matrix
    f: sp.Matrix
    K: sp.Matrix
    k: sp.Matrix


def exact(value) -> sp.Matrix | sp.Expr:
    """A number or array as sympy: integral floats become integers (0, ±1 stay exact)."""
    if isinstance(value, sp.Basic):
        return value
    array = np.asarray(value, dtype=float)
    convert = np.vectorize(lambda x: sp.Integer(int(x)) if float(x).is_integer() else sp.Float(x),
                           otypes=[object])
    return convert(array).item() if array.ndim == 0 else sp.Matrix(convert(array))


def _times(x, y):
    """x y, or 0 without asking sympy: ``0 * x`` makes sympy query whether x is finite,
    which dominated the derivation time of long chains (and sympy's EXRAW matrix product
    multiplies zeros on purpose)."""
    return 0 if x == 0 or y == 0 else x * y


def mul(*matrices) -> sp.Matrix:
    """The product of sympy matrices, skipping the exact zeros (see :func:`_times`)."""
    out = matrices[0]
    for B in matrices[1:]:
        out = sp.Matrix(out.rows, B.cols,
                        lambda i, j: sp.Add(*(_times(out[i, k], B[k, j]) for k in range(B.rows))))
    return out


def cross(a, b) -> sp.Matrix:
    """a × b of 3-vectors, skipping the exact zeros (see :func:`_times`)."""
    times = _times
    return sp.Matrix([times(a[1], b[2]) - times(a[2], b[1]), times(a[2], b[0]) - times(a[0], b[2]),
                      times(a[0], b[1]) - times(a[1], b[0])])


def _about(e: sp.Matrix, angle) -> sp.Matrix:
    """Rotation by ``angle`` about the unit axis e (Rodrigues, as the numeric joints)."""
    E = skew(e)
    return sp.eye(3) + sp.sin(angle) * E + (1 - sp.cos(angle)) * mul(E, E)


def _one_axis(joint, q_n) -> tuple:
    """(A, r, F) of a Revolute or Prismatic joint at the coordinate q_n[0]."""
    e = exact(joint.axis)
    if isinstance(joint, Revolute):
        return _about(e, q_n[0]), sp.zeros(3, 1), sp.Matrix.vstack(sp.zeros(3, 1), e)
    return sp.eye(3), e * q_n[0], sp.Matrix.vstack(e, sp.zeros(3, 1))


def _quaternion(quat) -> tuple[sp.Matrix, sp.Matrix]:
    """Rotation and rate matrix Γ (q̇ = Γ ω) of a quaternion (w, x, y, z), assumed unit."""
    w, x, y, z = quat
    A = sp.Matrix([[1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                   [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
                   [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)]])
    Gamma = sp.Matrix([[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]]) / 2
    return A, Gamma


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
        A = _about(n, q_n[2])
        K = sp.diag(mul(P, A, P.T), 1)
        return SymbolicRelative(A, mul(P.T, sp.Matrix(q_n[:2])), exact(joint._F), no_f, K, no_k)
    if isinstance(joint, Free):
        A, Gamma = _quaternion(q_n[3:])
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
