"""Problems of the IFToMM library of computational benchmark problems for multibody dynamics
(M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody System Dynamics 16
(2006) 179–190; problems A01 simple pendulum, A02 N-four-bar mechanism, A04 Bricard's mechanism),
as :class:`~projeq.constraints.tangent.TangentSystem` s: trees closed by constraint equations,
run through singular positions and with redundant constraints.

Each problem also has a reference that does not use the constraint equations: the pendulum's
closed form (Jacobi's elliptic functions) and the N-four-bar's parallelogram motion in one
coordinate (:func:`parallelogram_motion`).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipk

from projeq.checks import count, positive
from projeq.constraints.tangent import TangentSystem
from projeq.joints import Prismatic, Revolute
from projeq.scenes.mechanisms import slender_rod
from projeq.subsystems import Frame, PointMass, RigidBody
from projeq.system import System


def simple_pendulum(m: float = 1.0, L: float = 1.0, g: float = 9.81, **options) -> TangentSystem:
    """IFToMM A01: a point mass m on a massless rod of length L, in natural coordinates — the
    mass on x and y sliders held at distance L from the pivot by Φ = x² + y² − L² = 0;
    gravity −y. Starts at rest with the rod horizontal, (x, y) = (L, 0), the benchmark's start.
    ``options`` go to :class:`~projeq.constraints.tangent.TangentSystem`."""
    tree = System({"x": Frame(), "mass": PointMass(positive("m", m))},
                  {"x": Prismatic(axis="x"), "mass": Prismatic(parent="x", axis="y")}, gravity=(0.0, -g, 0.0))
    return TangentSystem(tree, phi=lambda q, t: [q[0] ** 2 + q[1] ** 2 - L * L], q0=(positive("L", L), 0.0),
                         **options)


def pendulum_angle(t, L: float = 1.0, g: float = 9.81, theta0: float = np.pi / 2) -> np.ndarray:
    """The angle from the downward vertical of a simple pendulum released from rest at θ0:
    sin(θ/2) = k sn(K(k) − ω t, k), k = sin(θ0/2), ω = √(g/L) (Jacobi's elliptic functions;
    e.g. Lawden, "Elliptic Functions and Applications", 1989, §5.2)."""
    k = np.sin(theta0 / 2)
    sn = ellipj(ellipk(k * k) - np.sqrt(g / L) * np.asarray(t, dtype=float), k * k)[0]
    return 2 * np.arcsin(k * sn)


def n_four_bar(n: int = 2, m: float = 1.0, L: float = 1.0, g: float = 9.81, speed: float = 1.0,
               **options) -> TangentSystem:
    """IFToMM A02: n four-bar linkages in a row, 2n + 1 uniform bars of mass m and length L in the
    x–y plane, gravity −y: cranks ``crank0`` … ``crank<n>`` turn about (i L, 0) (absolute angles
    θ_i), coupler i hangs at the tip of crank i − 1 (angle relative to it) and is pinned at its
    other end to the tip of crank i (cut, Φ = 0: 2n rows). Where the bars are horizontal the 2n
    rows have rank n and the mobility jumps from 1 to n + 1 (the benchmark's singular
    positions). Starts with the cranks vertical and point B0 (the tip of crank0) moving at
    ``speed`` along +x. The benchmark specifies n = 40 (and 2 in the double four-bar of
    González, Dopico, Pastorino & Cuadrado, Nonlinear Dynamics 85 (2016) 1491–1508).
    ``options`` go to :class:`~projeq.constraints.tangent.TangentSystem`."""
    n = count("n", n)
    rod = slender_rod(positive("m", m), positive("L", L))
    cranks, couplers = [f"crank{i}" for i in range(n + 1)], [f"coupler{i}" for i in range(1, n + 1)]
    joints = {name: Revolute(axis="z", r_pn=(i * L, 0.0, 0.0)) for i, name in enumerate(cranks)}
    joints |= {name: Revolute(parent=cranks[i], axis="z", r_pn=(L, 0.0, 0.0))
               for i, name in enumerate(couplers)}
    tree = System(dict.fromkeys(cranks + couplers, rod), joints, gravity=(0.0, -g, 0.0))
    crank, coupler = (np.array([tree.q_slice[tree.index(name)].start for name in names])
                      for names in (cranks, couplers))

    def closure(q, t):  # tip of coupler i − (tip of crank i), i = 1 … n: x rows, then y rows
        theta, phi = q[crank], q[coupler]
        absolute = theta[:-1] + phi
        x = L * (np.cos(theta[:-1]) + np.cos(absolute) - 1.0 - np.cos(theta[1:]))  # pivots 1 apart
        y = L * (np.sin(theta[:-1]) + np.sin(absolute) - np.sin(theta[1:]))
        return np.concatenate((x, y))

    q0, s_dot0 = np.zeros(tree.n_q), np.zeros(tree.n_s)
    q0[crank], q0[coupler] = np.pi / 2, -np.pi / 2
    s_dot0[crank], s_dot0[coupler] = -speed / L, speed / L  # ẋ_B0 = −L sin θ0 θ̇0; couplers translate
    return TangentSystem(tree, phi=closure, q0=q0, independent=[tree.s_slice[tree.index("crank0")].start],
                         s_dot0=[-speed / L], **options)


def point_b0(system, q, s_dot) -> np.ndarray:
    """(x, y, ẋ, ẏ) of point B0, the tip of crank0 of :func:`n_four_bar`, for each row of q and
    of the model's velocities ṡ (any formulation of the same tree)."""
    i = system.tree.index("crank0")
    L = 2 * system.tree.subsystems[i].r_c[0]
    q, s_dot = np.atleast_2d(q), np.atleast_2d(s_dot)
    theta = q[:, system.tree.q_slice[i].start]
    column = system.tree.s_slice[i].start
    omega = np.array([system.tree_velocities(qi, si)[column] for qi, si in zip(q, s_dot)])
    return _tip(L, theta, omega)


def _tip(L: float, theta, omega) -> np.ndarray:
    """(x, y, ẋ, ẏ) of a crank's tip at angle θ turning at θ̇ (rows)."""
    return np.stack((L * np.cos(theta), L * np.sin(theta), -L * np.sin(theta) * omega, L * np.cos(theta) * omega),
                    axis=-1)


def parallelogram_motion(t, n: int = 2, m: float = 1.0, L: float = 1.0, g: float = 9.81, speed: float = 1.0,
                         rtol: float = 1e-12) -> np.ndarray:
    """(x, y, ẋ, ẏ) of B0 at times t for :func:`n_four_bar` moving as parallelograms — every crank
    at the same angle θ, the couplers translating —, the motion through the singular positions
    that keeps its velocity (the benchmark's). Lagrange's equation in θ alone:
    T = ½ ((n + 1)/3 + n) m L² θ̇², V = ((n + 1)/2 + n) m g L sin θ, integrated to ``rtol``."""
    inertia, weight = ((n + 1) / 3 + n) * m * L * L, ((n + 1) / 2 + n) * m * g * L
    t = np.asarray(t, dtype=float)
    sol = solve_ivp(lambda _, x: [x[1], -weight * np.cos(x[0]) / inertia], (0.0, t.max()),
                    [np.pi / 2, -speed / L], t_eval=t, rtol=rtol, atol=rtol * 1e-2, method="DOP853")
    theta, omega = sol.y
    return _tip(L, theta, omega)


# Bricard's mechanism: the joints at the corners of the benchmark's figure, their axes, and the
# rods from each corner to the next (at q = 0 every body frame is parallel to the inertial one)
_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]], dtype=float)
_AXES = "yzxyzx"


def _rotation(axis: str, angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the coordinate axis ``axis`` ("x", "y" or "z")."""
    k = "xyz".index(axis)
    i, j = (k + 1) % 3, (k + 2) % 3
    R = np.eye(3, dtype=np.result_type(angle, float))  # complex under a complex step
    R[[i, i, j, j], [i, j, i, j]] = np.cos(angle), -np.sin(angle), np.sin(angle), np.cos(angle)
    return R


def bricard(m: float = 1.0, L: float = 1.0, side: float = 0.1, g: float = 9.81, **options) -> TangentSystem:
    """IFToMM A04: Bricard's overconstrained mechanism, five rods (mass m, length L, square section
    ``side``) in a chain of revolute joints from the ground at the origin (axis y) over the
    corners (L, 0, 0) z, (L, −L, 0) x, (L, −L, L) y, (0, −L, L) z back to the ground at (0, 0, L),
    axis x — the benchmark's figure; gravity −y. The last joint is cut: rod5's end on (0, 0, L)
    (3 rows) and its x-axis perpendicular to the ground's y and z (2 rows). Grübler's count is
    5 − 5 = 0, but the five rows have rank 4 everywhere: mobility 1, one row redundant (not
    removed). Starts at rest in the figure's configuration (q = 0).
    ``options`` go to :class:`~projeq.constraints.tangent.TangentSystem`."""
    m, L, side = positive("m", m), positive("L", L), positive("side", side)
    corners = L * _CORNERS
    names = [f"rod{i}" for i in range(1, 6)]
    subsystems, joints = {}, {}
    for i, name in enumerate(names):
        along = corners[i + 1] - corners[i]  # the rod in body axes (parallel to inertial ones at q = 0)
        edges = np.where(np.abs(along) > 0, L, side)  # the cuboid's edges along x, y, z
        I_c = np.diag(m * (np.sum(edges**2) - edges**2) / 12)
        subsystems[name] = RigidBody(m, along / 2, I_c)
        joints[name] = Revolute(parent=names[i - 1] if i else None, axis=_AXES[i],
                                r_pn=corners[i] - (corners[i - 1] if i else 0.0))
    tree = System(subsystems, joints, gravity=(0.0, -g, 0.0))
    columns = [tree.q_slice[tree.index(name)].start for name in names]

    def closure(q, t):  # the chain's forward kinematics to rod5's far end, in closed form
        R, r = np.eye(3), np.zeros(3)
        for i, column in enumerate(columns):
            r = r + R @ (corners[i] - (corners[i - 1] if i else 0.0))
            R = R @ _rotation(_AXES[i], q[column])
        return np.concatenate((r + R @ (corners[5] - corners[4]) - corners[5], R[1:, 0]))

    return TangentSystem(tree, phi=closure, q0=np.zeros(tree.n_q), **options)
