"""Sympy algebra: the sympy twins of :mod:`projeq.spatial` that the plug-ins' symbolic
statements (``Joint.symbolic_relative``, the force laws' ``symbolic_*``) and
:mod:`projeq.symbolic` share.

It sits below the joints, so that a joint or a force law states its symbolic terms next
to its numeric ones without importing :mod:`projeq.symbolic` (which imports them).

The numbers a plug-in was built with become exact integers where they are integral (axes
along x, y, z stay 0 and ±1), floats otherwise (:func:`exact`). Products skip exact zeros
(:func:`mul`, :func:`cross`): ``0 * x`` makes sympy ask whether x is finite, which
dominated the derivation time of long chains.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

__all__ = ["exact", "mul", "cross", "skew", "rotation", "quaternion_matrices"]


def exact(value) -> sp.Matrix | sp.Expr:
    """A number or array as sympy: integral floats become integers (0, ±1 stay exact)."""
    if isinstance(value, sp.Basic):
        return value
    array = np.asarray(value, dtype=float)
    convert = np.vectorize(lambda x: sp.Integer(int(x)) if float(x).is_integer() else sp.Float(x),
                           otypes=[object])
    return convert(array).item() if array.ndim == 0 else sp.Matrix(convert(array))


def _times(x, y):
    """x y, or 0 without asking sympy (sympy's EXRAW matrix product multiplies zeros on purpose)."""
    return 0 if x == 0 or y == 0 else x * y


def mul(*matrices) -> sp.Matrix:
    """The product of sympy matrices, skipping the exact zeros."""
    out = matrices[0]
    for B in matrices[1:]:
        out = sp.Matrix(out.rows, B.cols,
                        lambda i, j: sp.Add(*(_times(out[i, k], B[k, j]) for k in range(B.rows))))
    return out


def cross(a, b) -> sp.Matrix:
    """a × b of 3-vectors, skipping the exact zeros."""
    times = _times
    return sp.Matrix([times(a[1], b[2]) - times(a[2], b[1]), times(a[2], b[0]) - times(a[0], b[2]),
                      times(a[0], b[1]) - times(a[1], b[0])])


def skew(a) -> sp.Matrix:
    """Spin matrix ã of a 3-vector of sympy expressions (ã b = a × b)."""
    return sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def rotation(e: sp.Matrix, angle) -> sp.Matrix:
    """Rotation by ``angle`` about the unit axis e: E + sin φ ẽ + (1 − cos φ) ẽẽ (Rodrigues,
    as :func:`projeq.spatial.rotation`)."""
    E = skew(e)
    return sp.eye(3) + sp.sin(angle) * E + (1 - sp.cos(angle)) * mul(E, E)


def quaternion_matrices(quat) -> tuple[sp.Matrix, sp.Matrix]:
    """Rotation and rate matrix Γ (q̇ = Γ ω) of a unit quaternion (w, x, y, z), as
    :func:`projeq.spatial.quaternion_matrix` and :func:`projeq.spatial.quaternion_rate_matrix`."""
    w, x, y, z = quat
    A = sp.Matrix([[1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                   [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
                   [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)]])
    Gamma = sp.Matrix([[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]]) / 2
    return A, Gamma
