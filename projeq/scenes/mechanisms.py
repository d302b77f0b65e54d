"""Closed loops and contacts given as constraint equations on a tree (docs/theory.md §7).

Each scene returns a :class:`projeq.constraints.partitioned.ConstrainedSystem`: a tree cut open at one
joint (or a free body on sliders) plus the constraint equations that close it.
"""

from __future__ import annotations

import numpy as np

from projeq.checks import count, positive, positives
from projeq.constraints.cut_joints import PinClosure
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.joints import Prismatic, Revolute
from projeq.subsystems import Frame, PlanarBody, PointMass, RigidBody, RitzBeam
from projeq.system import System


def slender_rod(m: float, L: float) -> PlanarBody:
    """A uniform slender rod of mass m and length L along the body x-axis from its joint,
    moving in the x–y plane (centroidal moment m L²/12)."""
    return PlanarBody(m, (L / 2, 0.0, 0.0), m * L * L / 12, plane="xy")


def quick_return(A: float = 1.0, H: float = 1.0 / 3.0, m_a: float = 0.5, m_b: float = 1.0, g: float = 9.81,
                 q0=(9 * np.pi / 20, 2.80729, 1.0034), **options) -> ConstrainedSystem:
    """Barhorst's planar quick-return mechanism (Barhorst §3.3, Fig. 9, eqs. (106)–(116)).

    A crank (mass ``m_a``, length H) turns q1 about a_o; a slotted follower (mass ``m_b``,
    length B = A + 1.5 H) turns q2 about b_o at distance A; the crank pin slides in the
    slot at q3 from b_o (massless slider). Loop closures (107): c1 = A − H cos q1 + q3 cos q2,
    c2 = q3 sin q2 − H sin q1; the crank angle q1 is the independent velocity. Gravity g
    along −y gives V = ½ m_b g B sin q2 + ½ m_a g H sin q1 (110). Both links are taken as
    uniform slender rods (centroidal moments m L²/12: Barhorst does not print A_i33, B_i33).
    Default q0: Barhorst's printed configuration (q1 = 9π/20, q2 = 2.80729, q3 = 1.0034,
    given to 5 digits), projected onto the loop closures; at rest, no drive (T_m = T_d = 0).
    ``options`` go to :class:`~projeq.constraints.partitioned.ConstrainedSystem` (``correction``, ``beta``).
    """
    A, H, m_a, m_b = positives(A=A, H=H, m_a=m_a, m_b=m_b)
    B = A + 1.5 * H
    tree = System(
        {"crank": slender_rod(m_a, H), "follower": slender_rod(m_b, B), "slider": Frame()},
        {"crank": Revolute(axis="z"), "follower": Revolute(axis="z", r_pn=(A, 0.0, 0.0)),
         "slider": Prismatic(parent="follower", axis="x")},
        gravity=(0.0, -g, 0.0),
    )

    def c(q, t):
        return [A - H * np.cos(q[0]) + q[2] * np.cos(q[1]), q[2] * np.sin(q[1]) - H * np.sin(q[0])]

    return ConstrainedSystem(tree, phi=c, independent=[0], q0=q0, project_q0=True, **options)


def four_bar_angles(theta1: float, a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """Closed-form loop of the four-bar (open branch): absolute angles (θ2, θ3) of coupler
    and rocker for crank angle θ1, by intersecting the circles |X − P| = b, |X − D| = c
    about the crank pin P = a e(θ1) and the rocker pivot D = (d, 0)."""
    P = a * np.array([np.cos(theta1), np.sin(theta1)])
    e_vec = np.array([d, 0.0]) - P
    e = np.linalg.norm(e_vec)
    u = e_vec / e
    along = (b * b - c * c + e * e) / (2 * e)
    if along * along > b * b:
        raise ValueError(f"theta1: the four-bar cannot close at crank angle {theta1} "
                         f"(links {a}, {b}, {c}, {d})")
    X = P + along * u + np.sqrt(b * b - along * along) * np.array([-u[1], u[0]])
    return float(np.arctan2(*(X - P)[::-1])), float(np.arctan2(*(X - np.array([d, 0.0]))[::-1]))


def four_bar(a: float = 0.3, b: float = 1.0, c: float = 0.8, d: float = 1.0, m=(1.0, 2.0, 1.5),
             g: float = 9.81, theta1: float = 0.5, omega1: float = 3.0, **options) -> ConstrainedSystem:
    """A four-bar linkage in the x–y plane (gravity −y): crank a about the origin (q1), coupler
    b at the crank pin (q2, relative), rocker c about D = (d, 0) (q3, absolute), uniform
    rods of masses ``m``; the loop coupler tip = rocker tip is cut and given as Φ = 0.
    The tree orders its coordinates q = (q1, q3, q2) (``system.tree.names``).
    Initial state: crank at ``theta1`` turning at ``omega1`` (the independent velocity ṡ = q̇1;
    ``four_bar().with_independent([1], repivot=True)`` starts the same motion in the rocker's
    rate q̇3, which degenerates at the rocker's extreme positions).
    """
    a, b, c, d = positives(a=a, b=b, c=c, d=d)
    m = _link_masses(m)
    tree = System(
        {"crank": slender_rod(m[0], a), "rocker": slender_rod(m[2], c), "coupler": slender_rod(m[1], b)},
        {"crank": Revolute(axis="z"), "rocker": Revolute(axis="z", r_pn=(d, 0.0, 0.0)),
         "coupler": Revolute(parent="crank", axis="z", r_pn=(a, 0.0, 0.0))},
        gravity=(0.0, -g, 0.0),
    )

    def closure(q, t):  # q = (q1, q3, q2): crank, rocker (both on the ground), coupler (parents first)
        return [a * np.cos(q[0]) + b * np.cos(q[0] + q[2]) - d - c * np.cos(q[1]),
                a * np.sin(q[0]) + b * np.sin(q[0] + q[2]) - c * np.sin(q[1])]

    theta2, theta3 = four_bar_angles(theta1, a, b, c, d)
    return ConstrainedSystem(tree, phi=closure, independent=[0], q0=(theta1, theta3, theta2 - theta1),
                             s_dot0=[omega1], **options)


def flexible_four_bar(a: float = 0.3, b: float = 1.0, c: float = 0.8, d: float = 1.0, m=(1.0, 2.0, 1.5),
                      EI: float = 200.0, n_v: int = 2, g: float = 9.81, theta1: float = 0.5, omega1: float = 3.0,
                      **options) -> ConstrainedSystem:
    """:func:`four_bar` with an elastic coupler: a RitzBeam of length b and mass m[1] (ρA = m[1]/b),
    bending stiffness ``EI`` (N m²) and ``n_v`` clamped–free bending functions in the plane
    (n_w = 0; docs/theory.md §10), clamped at the crank pin; its tip is held on the rocker's by a
    cut joint (:class:`~projeq.constraints.cut_joints.PinClosure` at the beam's station x = b,
    which moves with the bending, Φ = (P_coupler − P_rocker) in x, y: docs/theory.md §7).
    The tree orders q = (q1, q3, q2, q_e): crank, rocker, coupler relative to the crank, the
    beam's amplitudes; the independent velocities are the crank's rate and the amplitudes'.
    Initial state: the undeformed loop at crank angle ``theta1``, the crank turning at ``omega1``.
    """
    a, b, c, d, EI = positives(a=a, b=b, c=c, d=d, EI=EI)
    m_crank, m_coupler, m_rocker = _link_masses(m)
    n_v = count("n_v", n_v)
    beam = RitzBeam(b, rho_A=m_coupler / b, EI_z=EI, n_v=n_v, n_w=0, family="clamped_free")
    tree = System({"crank": slender_rod(m_crank, a), "rocker": slender_rod(m_rocker, c), "coupler": beam},
                  {"crank": Revolute(axis="z"), "rocker": Revolute(axis="z", r_pn=(d, 0.0, 0.0)),
                   "coupler": Revolute(parent="crank", axis="z", r_pn=(a, 0.0, 0.0))},
                  gravity=(0.0, -g, 0.0))
    pin = PinClosure(tree, "coupler", (b, 0.0, 0.0), "rocker", (c, 0.0, 0.0), axes="xy")
    theta2, theta3 = four_bar_angles(theta1, a, b, c, d)
    amplitudes = list(range(3, 3 + n_v))
    return ConstrainedSystem(tree, phi=pin, independent=[0, *amplitudes], q0=(theta1, theta3, theta2 - theta1, *[0.0] * n_v),
                             s_dot0=[omega1, *[0.0] * n_v], **options)


def _link_masses(m) -> tuple[float, float, float]:
    """The four-bar's masses (crank, coupler, rocker), each positive: ValueError naming m[i]."""
    if np.ndim(m) != 1 or len(m) != 3:
        raise ValueError(f"m: expected the three masses (crank, coupler, rocker) in kg, got {m!r}")
    return tuple(positive(f"m[{i}]", value) for i, value in enumerate(m))


def _sliders(body) -> tuple[dict, dict]:
    """(subsystems, joints) of a body on x and z sliders, turning about y: q = (x, z, ψ)."""
    return (
        {"x": Frame(), "z": Frame(), "body": body},
        {"x": Prismatic(axis="x"), "z": Prismatic(parent="x", axis="z"),
         "body": Revolute(parent="z", axis="y")},
    )


def sphere_on_sphere(a: float = 0.1, b: float = 1.0, m: float = 1.0, g: float = 9.81,
                     theta0: float = 0.1) -> ConstrainedSystem:
    """A solid sphere (radius a, mass m) rolling without slipping on a fixed sphere of radius
    b > a (Lagrange seminars, Problem 19), in the x–z plane with gravity −z: q = (x, z, ψ) of its
    centre and its turn about y. Constraints: Φ = √(x² + z²) − (a + b) = 0 (contact; its
    multiplier is the normal force) and the rolling condition n_z ẋ − n_x ż − a ψ̇ = 0
    (contact point at rest, n = (x, z)/|(x, z)|). Starts at rest at angle ``theta0`` from the top.
    """
    a, b, m = positives(a=a, b=b, m=m)
    if not a < b:
        raise ValueError(f"a: the rolling sphere's radius must be in (0, b = {b}), got {a}")
    subsystems, joints = _sliders(RigidBody(m, (0.0, 0.0, 0.0), np.eye(3) * 0.4 * m * a * a))
    tree = System(subsystems, joints, gravity=(0.0, 0.0, -g))
    rho = a + b

    def contact(q, t):
        return [np.sqrt(q[0] ** 2 + q[1] ** 2) - rho]

    def rolling(q, t):
        n = q[:2] / np.sqrt(q[0] ** 2 + q[1] ** 2)
        return [[n[1], -n[0], -a]]

    q0 = (rho * np.sin(theta0), rho * np.cos(theta0), 0.0)
    return ConstrainedSystem(tree, phi=contact, A=rolling, q0=q0)


def bar_on_wall(l: float = 0.5, m: float = 1.0, g: float = 9.81, theta0: float = 0.2) -> ConstrainedSystem:
    """A uniform bar of length 2l and mass m with its upper end on a frictionless wall x = 0
    and its lower end on a frictionless floor z = 0 (Lagrange seminars, Problem 20), in the x–z plane
    with gravity −z: q = (x, z, ψ) of its centre and its turn about y, the bar along the
    body z-axis, ψ = −θ with θ its tilt from the vertical. Constraints: Φ_wall = x + l sin ψ
    (multiplier: the wall's push along +x) and Φ_floor = z − l cos ψ. Starts at rest at tilt θ0.
    """
    l, m = positives(l=l, m=m)
    subsystems, joints = _sliders(RigidBody(m, (0.0, 0.0, 0.0), np.eye(3) * m * l * l / 3))
    tree = System(subsystems, joints, gravity=(0.0, 0.0, -g))

    def ends(q, t):
        return [q[0] + l * np.sin(q[2]), q[1] - l * np.cos(q[2])]

    return ConstrainedSystem(tree, phi=ends, q0=(l * np.sin(theta0), l * np.cos(theta0), -theta0))


def slider_pendulum(l: float = 1.0, m: float = 1.0, g: float = 9.81, theta0: float = 0.5,
                    **options) -> ConstrainedSystem:
    """A point mass on x and z sliders held at distance l from the origin by Φ = √(x² + z²) − l
    (a pendulum whose rod is a constraint equation; the multiplier is minus the rod tension).
    Starts at rest at angle θ0 from the downward vertical; gravity −z."""
    l, m = positives(l=l, m=m)
    tree = System({"x": Frame(), "bob": PointMass(m)},
                  {"x": Prismatic(axis="x"), "bob": Prismatic(parent="x", axis="z")}, gravity=(0.0, 0.0, -g))
    return ConstrainedSystem(tree, phi=lambda q, t: [np.sqrt(q[0] ** 2 + q[1] ** 2) - l],
                             q0=(l * np.sin(theta0), -l * np.cos(theta0)), independent=[0], **options)
