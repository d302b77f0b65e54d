"""Scenes with elastic subsystems (Ritz beams)."""

from __future__ import annotations

import cmath
import math

import numpy as np

from projeq.subsystems import inertia
from projeq.checks import count, finite_array, non_negative, positive, positives
from projeq.forces import JointSpring
from projeq.joints import Fixed, Prescribed, Revolute
from projeq.spatial import rotation_y, rotation_z
from projeq.subsystems.beam.beam import RitzBeam
from projeq.subsystems.rigid import Frame, PointMass, RigidBody
from projeq.system import System


def spin_up_motion(omega_s: float, t_s: float):
    """Hub angle θ(t) of the spin-up manoeuvre and its first two derivatives:
    θ = (Ωs/Ts)[t²/2 + (Ts/2π)²(cos(2πt/Ts) − 1)] for t ≤ Ts, Ωs (t − Ts/2) afterwards
    (smooth: θ̈ = (Ωs/Ts)(1 − cos 2πt/Ts) rises from and returns to zero)."""
    omega_s, t_s = float(finite_array("omega_s", omega_s, ())), positive("t_s", t_s)
    a, k = omega_s / t_s, 2.0 * np.pi / t_s

    def motion(t: float):
        if t.real <= t_s:  # math's cos and sin (cmath's for a complex step): a scalar, 10× cheaper than numpy's
            trig = cmath if isinstance(t, complex) else math
            cos, sin = trig.cos(k * t), trig.sin(k * t)
            return a * (0.5 * t * t + (cos - 1.0) / k**2), a * (t - sin / k), a * (1.0 - cos)
        return omega_s * (t - 0.5 * t_s), omega_s, 0.0

    return motion


def spin_up_beam(
    omega_s: float = 6.0,
    t_s: float = 15.0,
    length: float = 10.0,
    EI: float = 1.4e4,
    EA: float = 2.8e7,
    rho_A: float = 1.2,
    n_shapes: int = 4,
    n_axial: int = 0,
    family: str = "polynomial",
    stiffening: bool = True,
    gravity: float = 0.0,
    precomputed_integrals: bool = False,
) -> System:
    """A uniform cantilever clamped on the rotation axis (hub radius 0), spun up in the
    horizontal plane by the prescribed hub angle of :func:`spin_up_motion`.

    The beam (subsystem ``"beam"``) lies along the hub frame's x axis; v (in the direction
    of rotation, the x–y plane) and w (vertical, z) use ``n_shapes`` Ritz functions each;
    ``n_axial`` > 0 adds axial deformation with stiffness EA (default: inextensible).
    Units: m, N m², N, kg/m, rad/s, s. ``gravity`` (m/s², along −z) is off by default.
    The first bending frequency at rest is 3.516 √(EI/(ρA L⁴)) = 3.80 rad/s for the
    defaults, below Ωs = 6 rad/s: without ``stiffening`` the in-plane deflection then
    grows without bound. ``precomputed_integrals`` selects the precomputed-moment mode
    (:mod:`projeq.subsystems.beam.integrals`: exact for this model, since the slice position
    is quadratic in q; faster per call up to ~5 functions per plane).
    """
    n_shapes, n_axial = count("n_shapes", n_shapes), count("n_axial", n_axial, minimum=0)
    length, EI, EA, rho_A = positives(length=length, EI=EI, EA=EA, rho_A=rho_A)
    beam = RitzBeam(
        length, rho_A, EI, EA=EA if n_axial else None, n_v=n_shapes, n_w=n_shapes, n_u=n_axial,
        family=family, stiffening=stiffening, precomputed_integrals=precomputed_integrals,
    )
    hub = Prescribed(Revolute(axis="z"), spin_up_motion(omega_s, t_s))
    return System({"beam": beam}, {"beam": hub}, gravity=(0.0, 0.0, -gravity))


def elastic_arm(
    l1: float = 0.5,
    m1: float = 1.0,
    length: float = 1.0,
    rho_A: float = 2.0,
    EI: float = 50.0,
    tip_mass: float = 0.5,
    n_shapes: int = 3,
    stiffening: bool = True,
    gravity: float = 0.0,
    omega0: float = 2.0,
) -> System:
    """A two-link arm turning about z: a rigid first link (length l1, mass m1, a slender
    rod) and an elastic second link (a RitzBeam of ``length``, ρA, EI, ``n_shapes``
    functions per plane) carrying a tip mass at its end. The tip mass hangs on a station
    of the beam (``Fixed(parent="beam", r_pn=(length, 0, 0))``), so its chain matrix T
    depends on the beam's elastic coordinates (docs/theory.md §10). Units SI; ``gravity`` along −z
    is off by default. Initial state: the first joint spinning at ``omega0`` rad/s, the
    beam slightly bent (1 cm tip deflection in the plane)."""
    n_shapes = count("n_shapes", n_shapes)
    l1, m1, length, rho_A, EI, tip_mass = positives(l1=l1, m1=m1, length=length, rho_A=rho_A, EI=EI, tip_mass=tip_mass)
    beam = RitzBeam(length, rho_A, EI, n_v=n_shapes, n_w=n_shapes, stiffening=stiffening)
    system = System(
        {
            "link1": RigidBody(m1, (0.5 * l1, 0.0, 0.0), inertia.cylinder(m1, 0.01, l1, axis="x")),
            "beam": beam,
            "tip": PointMass(tip_mass),
        },
        {
            "link1": Revolute(axis="z"),
            "beam": Revolute(parent="link1", axis="z", r_pn=(l1, 0.0, 0.0)),
            "tip": Fixed(parent="beam", r_pn=(length, 0.0, 0.0)),
        },
        gravity=(0.0, 0.0, -gravity),
    )
    q0 = np.zeros(system.n_q)
    q0[system.e_q_slice[system.index("beam")].start] = 0.01  # first v function: v(L) = 1 cm
    s_dot0 = np.zeros(system.n_s)
    s_dot0[0] = omega0
    return System(
        dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
        gravity=system.gravity, q0=q0, s_dot0=s_dot0,
    )


def flexible_arm(rigid_last_link: bool = False, n_v: int = 4) -> System:
    """Three links turning about z under gravity along −y, hanging from the origin: links of
    0.6 m, 2.0 kg and 0.5 m, 1.5 kg (slender rods), and a last link of 0.8 m that is a RitzBeam
    (ρA = 0.8 kg/m, EI_z = 40 N m², ``n_v`` polynomial bending functions in the plane, n_w = 0)
    or with ``rigid_last_link`` its rigid twin (a rod of the beam's 0.64 kg); a 0.3 kg point
    mass at its end (on the beam's end station). Initial state: q = (0.3, −0.4, 0.2, 0, …)
    from rest. The stiff elastic model of the compiled-by-default benchmark
    (benchmarks/flexible_arm.py: its default simulation against its rigid twin's)."""
    n_v = count("n_v", n_v)
    rod = RigidBody(0.64, (0.4, 0.0, 0.0), inertia.cylinder(0.64, 0.01, 0.8, axis="x"))
    last = rod if rigid_last_link else RitzBeam(0.8, rho_A=0.8, EI_z=40.0, n_v=n_v, n_w=0)
    subsystems = {
        "upper": RigidBody(2.0, (0.3, 0.0, 0.0), inertia.cylinder(2.0, 0.02, 0.6, axis="x")),
        "fore": RigidBody(1.5, (0.25, 0.0, 0.0), inertia.cylinder(1.5, 0.02, 0.5, axis="x")),
        "last": last,
        "tip": PointMass(0.3),
    }
    joints = {
        "upper": Revolute(axis="z"),
        "fore": Revolute(parent="upper", axis="z", r_pn=(0.6, 0.0, 0.0)),
        "last": Revolute(parent="fore", axis="z", r_pn=(0.5, 0.0, 0.0)),
        "tip": Fixed(parent="last", r_pn=(0.8, 0.0, 0.0)),
    }
    q0 = np.zeros(3 + (0 if rigid_last_link else n_v))
    q0[:3] = (0.3, -0.4, 0.2)
    return System(subsystems, joints, gravity=(0.0, -9.81, 0.0), q0=q0, s_dot0=np.zeros(len(q0)))


def spinning_beam(
    omega: float = 2.0,
    length: float = 1.0,
    EI: float = 1.0,
    rho_A: float = 1.0,
    rho_I: float | None = None,
    n_shapes: int = 4,
    family: str = "clamped_free",
) -> System:
    """A cantilever spinning about its own axis x at the constant rate ``omega`` (the
    beam of B(16)–(23), docs/theory.md §9): the root turns by α = Ω t (prescribed); v, w bend in
    the co-rotating frame with ``n_shapes`` functions each; ``rho_I`` (per length, kg m)
    adds the rotary inertia ρI of both bending axes (polar 2ρI, circular section)."""
    n_shapes, omega = count("n_shapes", n_shapes), float(finite_array("omega", omega, ()))
    length, EI, rho_A = positives(length=length, EI=EI, rho_A=rho_A)
    rho_I = None if rho_I is None else positive("rho_I", rho_I)
    beam = RitzBeam(
        length, rho_A, EI, n_v=n_shapes, n_w=n_shapes, family=family,
        rho_I=None if rho_I is None else (rho_I, rho_I),
    )
    spin = Prescribed(Revolute(axis="x"), lambda t: (omega * t, omega, 0.0))
    return System({"beam": beam}, {"beam": spin})


def rotating_blade(
    omega: float = 3.0,
    hub_radius: float = 0.0,
    length: float = 1.0,
    EI: float = 1.0,
    rho_A: float = 1.0,
    n_shapes: int = 4,
    family: str = "clamped_free",
) -> System:
    """A cantilever blade on a hub turning at the constant rate ``omega`` about the transverse
    axis z: the massless hub (subsystem ``"hub"``, :class:`projeq.Frame`) turns by α = Ω t
    (prescribed), the beam (``"beam"``) is clamped to it at ``hub_radius`` along the hub's x
    axis and lies along x. Lead-lag v (in the plane of rotation, y) and flapwise w (along the
    axis z) use ``n_shapes`` functions each; inextensible, with dynamic stiffening.

    Centrifugal stiffening raises both bending frequencies; in the plane of rotation the
    centrifugal load also softens (−ρA Ω² v), so ω_lag² = ω_flap² − Ω² (Wright, Smith, Thresher
    & Wang (1982), "Vibration modes of centrifugally stiffened beams", J. Appl. Mech. 49:197–202).
    The defaults are nondimensional (L = EI = ρA = 1: Ω is their η, ``hub_radius`` their R/L);
    the Campbell diagram is ``projeq campbell rotating_blade`` (:mod:`projeq.analysis.campbell`).
    """
    n_shapes, omega = count("n_shapes", n_shapes), float(finite_array("omega", omega, ()))
    length, EI, rho_A = positives(length=length, EI=EI, rho_A=rho_A)
    hub_radius = non_negative("hub_radius", hub_radius)
    beam = RitzBeam(length, rho_A, EI, n_v=n_shapes, n_w=n_shapes, family=family)
    hub = Prescribed(Revolute(axis="z"), lambda t: (omega * t, omega, 0.0))
    return System({"hub": Frame(), "beam": beam},
                  {"hub": hub, "beam": Fixed(parent="hub", r_pn=(hub_radius, 0.0, 0.0))})


def _cardan_joint(parent: str, r_pn) -> "UserJoint":
    """Two revolute joints in one: about y by β, then about z by γ (q = ṡ-integrable,
    q̇ = ṡ), the relative angular velocity R_zᵀ e_y β̇ + e_z γ̇ in child coordinates."""
    import sympy as sp

    from projeq.joints.user import UserJoint

    b, g, b_dot, g_dot = sp.symbols("beta gamma beta_dot gamma_dot")
    R_y = sp.Matrix([[sp.cos(b), 0, sp.sin(b)], [0, 1, 0], [-sp.sin(b), 0, sp.cos(b)]])
    R_z = sp.Matrix([[sp.cos(g), -sp.sin(g), 0], [sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    F = sp.zeros(6, 2)
    F[3:, 0] = R_z.T * sp.Matrix([0, 1, 0])
    F[5, 1] = 1
    return UserJoint.from_sympy([b, g], [b_dot, g_dot], R_y * R_z, sp.zeros(3, 1), F, sp.eye(2), parent=parent, r_pn=r_pn)


def rigid_slice_chain(n_slices: int, motion, length: float = 1.0, rho_A: float = 1.0, EI: float = 1.0,
                      rho_I: float = 0.01, initial_deflection=None) -> tuple[System, np.ndarray]:
    """The beam of B(16)–(23) as ``n_slices`` rigid slices (an independent model of
    ``spinning_beam``): a hub turned about x by ``motion(t) -> (α, α̇, α̈)``, then slices of
    length Δx, mass ρA Δx, inertia about their centres diag(2ρI, ρI, ρI) Δx + ρA Δx³/12 on
    y, z, joined at their ends by Cardan joints (about y, then z) with JointSprings EI/Δx
    (2EI/Δx at the root, which stands for the half cell [0, Δx/2]). Without torsional
    strain as Δx → 0 (docs/theory.md, "The spinning beam's rotary inertia").

    Returns ``(system, q0)``: q0 bends the chain in the x–y plane along
    ``initial_deflection(x) -> v`` (slice slopes = chord slopes), or straight.
    """
    n_slices = count("n_slices", n_slices)
    length, rho_A, EI, rho_I = (positive(name, value) for name, value in
                                (("length", length), ("rho_A", rho_A), ("EI", EI), ("rho_I", rho_I)))
    dx = length / n_slices
    transverse = rho_I * dx + rho_A * dx**3 / 12
    slice_body = RigidBody(rho_A * dx, (dx / 2, 0.0, 0.0), np.diag([2 * rho_I * dx, transverse, transverse]))
    subsystems = {"hub": RigidBody(1.0, (0.0, 0.0, 0.0), np.eye(3))}  # prescribed: its inertia does not enter
    joints = {"hub": Prescribed(Revolute(axis="x"), motion)}
    springs, parent = [], "hub"
    for i in range(n_slices):
        name = f"slice{i}"
        subsystems[name] = slice_body
        joints[name] = _cardan_joint(parent, (0.0 if i == 0 else dx, 0.0, 0.0))
        springs.append(JointSpring(name, (2.0 if i == 0 else 1.0) * EI / dx))
        parent = name
    q0 = np.zeros(2 * n_slices)
    if initial_deflection is not None:
        edges = np.linspace(0.0, length, n_slices + 1)
        slopes = np.arctan(np.diff(initial_deflection(edges)) / dx)
        q0[1::2] = np.diff(np.r_[0.0, slopes])  # γ: relative turns about z
    return System(subsystems, joints, forces=springs), q0


def rigid_slice_chain_tip(q: np.ndarray, length: float = 1.0) -> np.ndarray:
    """The tip of :func:`rigid_slice_chain` in the hub frame R, (x, v, w)(L), from the joint
    angles q = (β₀, γ₀, β₁, γ₁, …)."""
    n_slices = len(q) // 2
    dx = length / n_slices
    A, tip = np.eye(3), np.zeros(3)
    for beta, gamma in q.reshape(n_slices, 2):
        A = A @ rotation_y(beta) @ rotation_z(gamma)
        tip += A[:, 0] * dx
    return tip
