"""Spatial algebra in sympy: the symbolic twin of :mod:`projeq.spatial`.

Spin matrices, cross products, rotations (Rodrigues about an axis, about the coordinate
axes, from a unit quaternion), motion cross products, the conversion of numbers to exact
sympy values and a normal form of trigonometric polynomials (:func:`trig_normal`), written
once for every symbolic derivation (``gauss_form``, the symbolic joints and loads, user
joints, the scenes derived with sympy, the comparisons' symbolic checks). The same conventions as
the numeric module: ``skew(a) b = a × b``; a rotation maps rotated-frame coordinates into
the original frame (its columns are the rotated axes).

Products skip exact zeros (:func:`mul`, :func:`cross`): ``0 * x`` makes sympy ask whether
x is finite, which dominated the derivation time of long chains (and sympy's EXRAW matrix
product multiplies zeros on purpose).

Only sympy and numpy are imported here, so the numeric packages (joints, scenes) can use
this module without importing the symbolic derivations.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

__all__ = ["exact", "mul", "cross", "skew", "cross_motion", "rotation", "rotation_x", "rotation_y", "rotation_z",
           "quaternion_matrix", "quaternion_rate_matrix", "trig_normal"]


def exact(value) -> sp.Matrix | sp.Expr:
    """A number or array as sympy: integral floats become integers (0, ±1 stay exact)."""
    if isinstance(value, sp.Basic):
        return value
    array = np.asarray(value, dtype=float)
    convert = np.vectorize(lambda x: sp.Integer(int(x)) if float(x).is_integer() else sp.Float(x),
                           otypes=[object])
    return convert(array).item() if array.ndim == 0 else sp.Matrix(convert(array))


def _times(x, y):
    """x y, or 0 without asking sympy (see the module docstring)."""
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
    """Spin matrix ã of a 3-vector (ã b = a × b)."""
    return sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def cross_motion(u: sp.Matrix, w: sp.Matrix) -> sp.Matrix:
    """Motion cross product u × w = (u_ω × w_v + u_v × w_ω, u_ω × w_ω) of two twists (v, ω)
    (:func:`projeq.spatial.cross_motion`)."""
    return sp.Matrix.vstack(cross(u[3:, :], w[:3, :]) + cross(u[:3, :], w[3:, :]), cross(u[3:, :], w[3:, :]))


def rotation(e, angle) -> sp.Matrix:
    """Rodrigues' rotation R = E + sin φ ẽ + (1 − cos φ) ẽ² by ``angle`` about the unit axis e."""
    E = skew(e)
    return sp.eye(3) + sp.sin(angle) * E + (1 - sp.cos(angle)) * mul(E, E)


def rotation_x(angle) -> sp.Matrix:
    """Rotation by ``angle`` about the x-axis (right-hand rule)."""
    c, s = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rotation_y(angle) -> sp.Matrix:
    """Rotation by ``angle`` about the y-axis (right-hand rule)."""
    c, s = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rotation_z(angle) -> sp.Matrix:
    """Rotation by ``angle`` about the z-axis (right-hand rule)."""
    c, s = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def quaternion_matrix(quat) -> sp.Matrix:
    """Rotation matrix of a unit quaternion (w, x, y, z), body → reference coordinates."""
    w, x, y, z = quat
    return sp.Matrix([[1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)]])


def quaternion_rate_matrix(quat) -> sp.Matrix:
    """The 4×3 matrix Γ with q̇ = Γ ω for ω in body coordinates (q̇ = ½ q ⊗ (0, ω))."""
    w, x, y, z = quat
    return sp.Matrix([[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]]) / 2


def trig_normal(expression, q) -> sp.Expr:
    """A normal form of ``expression`` that is 0 exactly when it vanishes identically in q:
    trigonometric sums expanded, the numerator written as a polynomial in sᵢ = sin qᵢ,
    cᵢ = cos qᵢ and reduced modulo sᵢ² + cᵢ² − 1 (these form a Gröbner basis — their leading
    terms sᵢ² are coprime —, so the remainder is unique), then factored."""
    sines = {x: sp.Dummy(f"sin_{x}") for x in q}
    cosines = {x: sp.Dummy(f"cos_{x}") for x in q}
    polynomial = sp.expand_trig(sp.sympify(expression)).xreplace({sp.sin(x): sines[x] for x in q})
    numerator, denominator = sp.fraction(sp.together(polynomial.xreplace({sp.cos(x): cosines[x] for x in q})))
    generators = [g for x in q for g in (sines[x], cosines[x])]
    _, remainder = sp.reduced(sp.expand(numerator), [sines[x] ** 2 + cosines[x] ** 2 - 1 for x in q], *generators)
    back = {sines[x]: sp.sin(x) for x in q} | {cosines[x]: sp.cos(x) for x in q}
    return sp.factor(remainder.xreplace(back)) / denominator.xreplace(back)
