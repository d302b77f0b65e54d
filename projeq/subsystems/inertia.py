"""Inertia tensors about the mass centre of common homogeneous shapes (kg m²).

``axis`` names the body axis of symmetry (``"x"``, ``"y"`` or ``"z"``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import positive

_INDEX = {"x": 0, "y": 1, "z": 2}


def _axial(axial: float, transverse: float, axis: str) -> NDArray:
    if axis not in _INDEX:
        raise ValueError(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    I = np.full(3, transverse)
    I[_INDEX[axis]] = axial
    return np.diag(I)


def cylinder(m: float, radius: float, length: float, axis: str = "z") -> NDArray:
    """Solid cylinder: ½ m r² about its axis, m (3r² + ℓ²)/12 across."""
    m, r, l = positive("m", m), positive("radius", radius), positive("length", length)
    return _axial(0.5 * m * r**2, m * (3 * r**2 + l**2) / 12.0, axis)


def disk(m: float, radius: float, axis: str = "z") -> NDArray:
    """Thin disk: ½ m r² about its axis, ¼ m r² across."""
    m, r = positive("m", m), positive("radius", radius)
    return _axial(0.5 * m * r**2, 0.25 * m * r**2, axis)


def sphere(m: float, radius: float) -> NDArray:
    """Solid sphere: ⅖ m r²."""
    m, r = positive("m", m), positive("radius", radius)
    return np.eye(3) * 0.4 * m * r**2


def box(m: float, a: float, b: float, c: float) -> NDArray:
    """Box with edges a, b, c along x, y, z: m (b² + c²)/12, …"""
    m, a, b, c = positive("m", m), positive("a", a), positive("b", b), positive("c", c)
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12.0
