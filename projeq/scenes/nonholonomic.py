"""Non-holonomic scenes: velocity constraints in *before* the derivation, through F.

Every system here is one or two bodies on a :class:`projeq.UserJoint` whose minimal
velocities ṡ already satisfy the non-holonomic constraint (docs/theory.md §2, §7;
Bremer (2009) §2 and conclusions): the constrained direction is simply left out
of F, and the same order-n assembler (and the dense Gauss form) handles the system. The
original constraints are declared on the joint, so every simulated ``Result`` reports
their residual (``result.constraint_residual``).

- :func:`car`: Bremer's car, B(5)–(12);
- :func:`knife_edge_disc`: the knife-edge disc of Orsino (2020) (slides 28–37);
- :func:`rolling_disk`: Barhorst's thin rolling disk with an eccentric mass (Barhorst §3.2);
- :func:`barhorst_particle`: Barhorst's planar particle with ẏ − y²ẋ = 0 (§3.1);
- :func:`nonholonomic_particle`: the particle in space with ẏ + z ẋ = 0 (§3.1, footnote 6).

Helpers return the closed forms the tests and the benchmark need:
:func:`knife_edge_circle` (slide 36) and :func:`rolling_disk_critical_speed`.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as sp

from projeq.checks import finite_array, non_negative, positives
from projeq.constraints.nonholonomic import check_configuration, initial_speeds
from projeq.forces import Force, Torque
from projeq.joints import Fixed, UserJoint
from projeq.subsystems import PlanarBody, PointMass, RigidBody
from projeq.symbolic.algebra import rotation_x, rotation_y, rotation_z, skew, trig_normal
from projeq.system import System


# -- small sympy helpers ---------------------------------------------------------------
def _twist_F(A: sp.Matrix, r: sp.Matrix, q, K: sp.Matrix, s) -> sp.Matrix:
    """F = ∂(v, ω)/∂ṡ in child coordinates from the pose (A, r) and q̇ = K ṡ:
    v = Aᵀ ṙ, ω̃ = Aᵀ Ȧ (exact symbolic differentiation, then each entry in the sin² + cos² = 1
    normal form of :func:`~projeq.symbolic.algebra.trig_normal`: the knife-edge disc's F as
    trigsimp gives it, in a tenth of trigsimp's time)."""
    s_vec = sp.Matrix(s)
    q_dot = K * s_vec
    r_dot = r.jacobian(q) * q_dot
    A_dot = sum((A.diff(qi) * q_dot[i] for i, qi in enumerate(q)), sp.zeros(3, 3))
    W = A.T * A_dot
    twist = sp.Matrix.vstack(A.T * r_dot, sp.Matrix([W[2, 1], W[0, 2], W[1, 0]]))
    return twist.jacobian(s_vec).applyfunc(lambda e: trig_normal(e, q))


# -- Bremer's car ------------------------------------------------------------------------
def car(m: float = 1200.0, C0: float = 3228.0, c: float = 1.2, f_x=0.0, M_z=0.0, f_y=0.0,
        q0=(0.0, 0.0, 0.0), s_dot0=(10.0, 0.2)) -> System:
    """Bremer's car (Bremer (2009) §2.1–2.2, B(5)–(12)): a rigid body in the x–y plane
    whose rear axle does not slide sideways, v_y = 0 in the body frame B.

    q = (x, y, γ) of the body frame's origin O (the rear-axle point) and its heading;
    ṡ = (v_x, ω_z), the velocity of O along the body's x-axis and the yaw rate — the
    non-holonomic constraint −sin γ ẋ + cos γ ẏ = 0 is inserted up front by leaving v_y
    out of F (B(11)); q̇ = K ṡ with K = [[cos γ, 0], [sin γ, 0], [0, 1]] (B(6)).

    Expected (B(9)): m v̇_x − m c ω_z² = f_x,  C° ω̇_z + m c v_x ω_z = M_z + c f_y.

    Parameters
    ----------
    m : float
        Mass of the car (kg).
    C0 : float
        C°, the moment of inertia about the rear-axle point O (kg m²).
    c : float
        Distance O → mass centre along the body x-axis (m).
    f_x : float or callable
        Driving force along the body x-axis at O (N): a constant or ``(t, q, s_dot)``.
    M_z : float or callable
        Torque about z (N m): a constant or ``(t, q, s_dot)``.
    f_y : float or callable
        Lateral force at the mass centre (N; B(12) projects it to c f_y on ω_z).
    q0 : 3-tuple
        Initial (x, y, γ): position of O (m) and heading (rad).
    s_dot0 : 2-tuple
        Initial (v_x, ω_z): forward speed of O (m/s) and yaw rate (rad/s).
    """
    x, y, g = sp.symbols("x y gamma")
    vx, wz = sp.symbols("v_x omega_z")
    xd, yd, gd = sp.symbols("xd yd gd")
    A = rotation_z(g)
    F = sp.Matrix([[1, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 1]])
    K = sp.Matrix([[sp.cos(g), 0], [sp.sin(g), 0], [0, 1]])
    joint = UserJoint.from_sympy(
        [x, y, g], [vx, wz], A, [x, y, 0], F, K,
        constraints=[-sp.sin(g) * xd + sp.cos(g) * yd], q_dot=[xd, yd, gd],
    )
    m, C0, c = *positives(m=m, C0=C0), float(finite_array("c", c, ()))
    C_c = C0 - m * c * c
    if not C_c > 0:
        raise ValueError(f"C0: the moment of inertia about O must exceed m c² = {m * c * c}, got {C0}")
    body = PlanarBody(m, (c, 0.0, 0.0), C_c, plane="xy")
    forces = [Force("car", _vec3(f_x, 0), frame="body"), Torque("car", _vec3(M_z, 2), frame="body")]
    forces.append(Force("car", _vec3(f_y, 1), point=(c, 0.0, 0.0), frame="body"))
    return System({"car": body}, {"car": joint}, forces=forces, q0=q0, s_dot0=s_dot0)


def _vec3(value, index: int):
    """A scalar (or callable returning one) as a 3-vector along axis ``index``."""
    e = np.eye(3)[index]
    if callable(value):
        return lambda t, q, s_dot: e * float(value(t, q, s_dot))
    return e * float(value)


# -- the knife-edge disc (Orsino (2020)) -------------------------------------------
@cache
def _disc_joint_lecture():
    """The knife-edge disc's joint in the lecture's coordinates (slides 28–30).

    q = (x, y, ψ, ϕ, θ): (x, y) of the centre G, heading ψ about n̂z, tilt ϕ about ê1,
    spin θ about the disc axis ê2; z = −r cos ϕ (the integrable third constraint of
    slide 30), n̂z pointing *down* (gravity +g n̂z, L = T + m g z on slide 31).
    The body frame B = E turned by θ about ê2: A = R_z(ψ) R_x(ϕ) R_y(θ), which gives
    ω = ϕ̇ ê1 + (θ̇ + sin ϕ ψ̇) ê2 + cos ϕ ψ̇ ê3 (slide 29). ṡ = (ψ̇, ϕ̇, θ̇); ẋ, ẏ follow
    from rolling without slip (slide 30, rows 1–2 of A q̇ = 0).
    """
    r = sp.Symbol("r", positive=True)
    x, y, psi, phi, th = sp.symbols("x y psi phi theta")
    s = sp.symbols("psi_d phi_d theta_d")
    qd = sp.symbols("xd yd psid phid thetad")
    q = [x, y, psi, phi, th]
    cps, sps, cph, sph = sp.cos(psi), sp.sin(psi), sp.cos(phi), sp.sin(phi)
    # slide 30: ẋ + r cψ sϕ ψ̇ + r cϕ sψ ϕ̇ + r cψ θ̇ = 0,  ẏ + r sψ sϕ ψ̇ − r cψ cϕ ϕ̇ + r sψ θ̇ = 0
    K = sp.Matrix([
        [-r * cps * sph, -r * cph * sps, -r * cps],
        [-r * sps * sph, r * cps * cph, -r * sps],
        [1, 0, 0], [0, 1, 0], [0, 0, 1],
    ])
    A = rotation_z(psi) * rotation_x(phi) * rotation_y(th)
    pos = sp.Matrix([x, y, -r * cph])
    F = _twist_F(A, pos, q, K, s)
    constraints = [
        qd[0] + r * cps * sph * qd[2] + r * cph * sps * qd[3] + r * cps * qd[4],
        qd[1] + r * sps * sph * qd[2] - r * cps * cph * qd[3] + r * sps * qd[4],
    ]
    return q, s, A, pos, F, K, constraints, qd, r


def knife_edge_disc(m: float = 1.0, r: float = 1.0, I: float = 0.25, J: float = 0.5, g: float = 1.0,
                    q0=(0.0, 0.0, 0.0, 0.2, 0.0), s_dot0=(0.0, 0.0, -3.0), q_dot0=None) -> System:
    """The knife-edge disc of Orsino (2020) (slides 28–37): a rigid disc of
    radius ``r`` and mass ``m`` rolling without slipping on a plane; ``I`` its moment of
    inertia about a diameter, ``J`` about its axis (kg m²), gravity ``g``.

    Coordinates as in the lecture: q = (x, y, ψ, ϕ, θ), (x, y) of the centre G in the
    plane, heading ψ, tilt ϕ, spin θ; the plane's normal n̂z points down (gravity is
    +g n̂z) and G is at z = −r cos ϕ. Minimal velocities ṡ = (ψ̇, ϕ̇, θ̇): the two
    rolling constraints (slide 30) are in K, not in the equations. Defaults are the
    lecture's non-dimensional units (m = g = r = 1) with a uniform thin disc,
    μ = I/(m r²) = 1/4, ν = J/(m r²) = 1/2.

    Instead of ``s_dot0`` one may give all five rates ``q_dot0``; they must satisfy the
    rolling constraints (else ValueError with the residual).

    The tilt ϕ = ±π/2 (disc flat on the plane) is where the Euler angles degenerate: the
    ψ̇- and θ̇-columns of F coincide and the mass matrix is singular. Quaternions would
    remove the coordinate singularity, but for the knife edge ϕ = ±π/2 is also the end of
    the rolling contact.
    """
    m, r, I, J = positives(m=m, r=r, I=I, J=J)
    q, s, A, pos, F, K, constraints, qd, r_sym = _disc_joint_lecture()
    joint = UserJoint.from_sympy(q, s, A, pos, F, K, constraints=constraints, q_dot=qd,
                                 parameters={r_sym: r}, q0=np.asarray(q0, dtype=float))
    body = RigidBody(m, (0.0, 0.0, 0.0), np.diag([I, J, I]))
    system = System({"disc": body}, {"disc": joint}, gravity=(0.0, 0.0, g), q0=q0, s_dot0=s_dot0)
    check_configuration(system, system.q0)
    if q_dot0 is not None:
        s0 = initial_speeds(system, system.q0, q_dot0)
        system = System({"disc": body}, {"disc": joint}, gravity=(0.0, 0.0, g), q0=q0, s_dot0=s0)
    return system


def knife_edge_circle(kappa: float, phi0: float, m: float = 1.0, r: float = 1.0, I: float = 0.25,
                      J: float = 0.5, g: float = 1.0, v: float | None = None):
    """The steady circular motion of slide 36, made dimensional.

    G moves on a circle of radius 1/κ with speed v, x = sin(κ v t)/κ, y = −cos(κ v t)/κ,
    tilt ϕ₀: ψ̇ = κ v, ϕ̇ = 0, θ̇ = −(v/r)(1 + κ r sin ϕ₀). With μ = I/(m r²),
    ν = J/(m r²), lengths in r and time in √(r/g), it exists iff

        v² / (g r) = tan ϕ₀ / (κ r (κ r μ sin ϕ₀ + ν + 1)).

    Returns (v, q0, s_dot0) at t = 0 (G at (0, −1/κ), heading ψ = 0); ``v`` overrides the
    speed (to start *off* the steady motion).
    """
    m, r, I, J = positives(m=m, r=r, I=I, J=J)
    mu, nu = I / (m * r * r), J / (m * r * r)
    k = kappa * r
    v2 = g * r * np.tan(phi0) / (k * (k * mu * np.sin(phi0) + nu + 1.0))
    if v is None:
        if not v2 > 0:
            raise ValueError(f"no steady circle for κ = {kappa}, ϕ₀ = {phi0}: v² = {v2:.4g} ≤ 0")
        v = float(np.sqrt(v2))
    q0 = np.array([0.0, -1.0 / kappa, 0.0, phi0, 0.0])
    s_dot0 = np.array([kappa * v, 0.0, -(v / r) * (1.0 + k * np.sin(phi0))])
    return v, q0, s_dot0


# -- Barhorst's rolling disk with an eccentric mass ---------------------------------------
@cache
def _rolling_disk_joint():
    """Barhorst's coordinates (§3.2, eqs. 88–98): q = (q1 heading about n̂3, q2 tilt about
    b̂1, q3 roll about ĉ2, q4, q5 the contact point), C = R_z(q1) R_x(q2) R_y(q3),
    ṡ = (u1, u2, u3) the body-fixed angular velocity in C (eq. 92–93); the body frame's
    origin is the disk centre q4 n̂1 + q5 n̂2 + R b̂3, whose velocity is ω × R b̂3 (no slip)."""
    R = sp.Symbol("R", positive=True)
    q = list(sp.symbols("q1:6"))
    s = list(sp.symbols("u1:4"))
    qd = list(sp.symbols("qd1:6"))
    q1, q2, q3 = q[:3]
    c2, s3, c3, t2 = sp.cos(q2), sp.sin(q3), sp.cos(q3), sp.tan(q2)
    K_ang = sp.Matrix([  # eq. (95)/(96)
        [-s3 / c2, 0, c3 / c2],
        [c3, 0, s3],
        [s3 * t2, 1, -c3 * t2],
    ])
    K = sp.Matrix.vstack(K_ang, R * sp.cos(q1) * K_ang[2, :], R * sp.sin(q1) * K_ang[2, :])  # eq. (97)
    A_B = rotation_z(q1) * rotation_x(q2)
    A = A_B * rotation_y(q3)
    pos = sp.Matrix([q[3], q[4], 0]) + R * A_B[:, 2]
    b3_C = rotation_y(q3).T * sp.Matrix([0, 0, 1])
    F = sp.Matrix.vstack(-R * skew(b3_C), sp.eye(3))  # v = ω × R b̂3, ω = u
    constraints = [qd[3] - R * sp.cos(q1) * qd[2], qd[4] - R * sp.sin(q1) * qd[2]]  # eq. (97)
    return q, s, A, pos, F, K, constraints, qd, R


#: (I, J) / (m R²) of the named shapes: the uniform thin disk and the thin ring (hoop)
DISK_SHAPES = {"disk": (0.25, 0.5), "hoop": (0.5, 1.0)}


def rolling_disk_inertia(inertia, m: float, R: float) -> tuple[float, float]:
    """(I, J): the moments of inertia of the rolling disk about a diameter and about its axis.

    ``inertia``: ``"disk"`` (uniform thin disk, I = m R²/4, J = m R²/2), ``"hoop"`` (thin ring,
    I = m R²/2, J = m R²) or a pair (I, J) in kg m², with 0 < J ≤ 2 I (the triangle inequality of
    a body symmetric about its axis; a flat body has J = 2 I).
    """
    if isinstance(inertia, str):
        if inertia not in DISK_SHAPES:
            raise ValueError(f"inertia: expected 'disk', 'hoop' or a pair (I, J) in kg m², got {inertia!r}")
        return tuple(factor * m * R * R for factor in DISK_SHAPES[inertia])
    try:
        I, J = (float(x) for x in inertia)
    except (TypeError, ValueError):
        raise ValueError(f"inertia: expected 'disk', 'hoop' or a pair (I, J) in kg m², got {inertia!r}") from None
    if not (I > 0 and J > 0):
        raise ValueError(f"inertia: I and J must be positive, got I = {I}, J = {J}")
    if J > 2 * I:
        raise ValueError(f"inertia: J = {J} exceeds 2 I = {2 * I}; no body symmetric about its axis has these "
                         "moments (triangle inequality)")
    return I, J


def rolling_disk(m_disk: float = 0.030, R: float = 0.015, m_ecc: float = 0.001, ecc=None,
                 g: float = 9.81, drag: float = 0.0, inertia="disk",
                 q0=(0.0, 0.15, 0.0, 0.0, 0.0), s_dot0=(0.0, 20.0, 0.0), q_dot0=None) -> System:
    """Barhorst's thin disk rolling without slip, with an optional eccentric point mass
    (Barhorst §3.2; his parameters converted to SI are the defaults: m_r = 30 g,
    R = 1.5 cm, m_s = 1 g at r = 0.95 R in the disk plane, g = 981 cm/s², tilt
    q2(0) = 0.15 rad, q̇3(0) = 20 rad/s).

    q = (q1, q2, q3, q4, q5): heading, tilt, roll (Euler 3-1-2), and the contact point in
    the plane (z up, gravity −g). ṡ = (u1, u2, u3), the angular velocity in the
    body-fixed frame C (eq. 92–93); q̇ = K ṡ with K of eq. (96) and the rolling
    constraints q̇4 = R cos q1 q̇3, q̇5 = R sin q1 q̇3 (eq. 97) as its last rows.

    ``ecc`` = (h, e, r) the eccentric mass's position from the centre in C (default
    (0, 0, 0.95 R)); ``m_ecc = 0`` gives the symmetric disk. ``inertia``: the disk's moments
    about a diameter and its axis (:func:`rolling_disk_inertia`): ``"disk"`` (uniform thin
    disk, the default), ``"hoop"`` or a pair (I, J) in kg m². ``drag`` ≥ 0 adds Barhorst's
    air-drag torque −drag · u_i |u_i| about each body axis (eq. 104).

    Which inertia did Barhorst use? He writes of "the disk" and its central inertia; his
    figures do not say. At the start (q3 = q̇1 = q̇2 = 0, q̇3 = Ω) the energy is, with the
    eccentric mass at r on ĉ3,

        E0 = ½ m_r (ΩR)² + ½ J Ω² + ½ m_s Ω² (R + r)² + g cos q2 (m_r R + m_s (R + r)),

    68447.6 g cm²/s² for the uniform disk (J = m_r R²/2) and 75197.6 for the hoop (J = m_r R²).
    His Fig. 8 (the run that conserves energy) shows E ≈ 75197, and his p₂ axes (Figs. 6, 8,
    from about 2850 g cm²/s) fit p₂(0) = (J + m_r R² + m_s (R + r)²) Ω = 2871 of the hoop, not
    2196 of the disk: both point to J = m_r R². His trajectories fit the uniform disk better:
    over his 10 s the heading q1 reaches −56.5 rad, the roll q3 239 rad, q4 stays within ±7 cm
    and q5 reaches −13.1 cm for the disk (his axes: about −60 rad, 250 rad, ±6 cm, −12 cm), but
    −36.5 rad, 220 rad, ±9 cm and −18 cm for the hoop (``benchmarks/rolling_disk_inertia.py``).
    No single body reproduces both his energy level and his trajectories; the uniform disk
    stays the default.

    K(q) contains sec q2: at the tilt q2 = ±π/2 (disk flat) these Euler angles
    degenerate (Barhorst notes the singularity near q2 = π/2); a construction there
    raises a ValueError naming the coordinate.
    """
    m_disk, R = positives(m_disk=m_disk, R=R)
    m_ecc, drag = non_negative("m_ecc", m_ecc), non_negative("drag", drag)
    if ecc is not None and m_ecc == 0:
        raise ValueError(f"ecc: the eccentric mass's position {ecc!r} is given, but m_ecc = 0 places no mass there")
    q, s, A, pos, F, K, constraints, qd, R_sym = _rolling_disk_joint()
    joint = UserJoint.from_sympy(q, s, A, pos, F, K, constraints=constraints, q_dot=qd,
                                 parameters={R_sym: R}, q0=np.asarray(q0, dtype=float))
    I, J = rolling_disk_inertia(inertia, m_disk, R)
    I_d = np.diag([I, J, I])
    subsystems = {"disk": RigidBody(m_disk, (0.0, 0.0, 0.0), I_d)}
    joints = {"disk": joint}
    if m_ecc > 0:
        ecc = (0.0, 0.0, 0.95 * R) if ecc is None else ecc
        subsystems["mass"] = PointMass(m_ecc)
        joints["mass"] = Fixed(parent="disk", r_pn=ecc)
    forces = []
    if drag > 0:
        forces.append(Torque("disk", lambda t, q_, s_: -drag * s_[:3] * np.abs(s_[:3]), frame="body"))

    def build(s0):
        return System(subsystems, joints, gravity=(0.0, 0.0, -g), forces=forces, q0=q0, s_dot0=s0)

    system = build(s_dot0)
    check_configuration(system, system.q0)
    if q_dot0 is not None:
        system = build(initial_speeds(system, system.q0, q_dot0))
    return system


def rolling_disk_critical_speed(m: float, R: float, I: float, J: float, g: float) -> float:
    """Critical forward speed of the upright, straight rolling of a symmetric disk.

    Linearising the angular-momentum equations of slide 37 (Orsino (2020)) about ϕ = 0,
    ψ̇ = ϕ̇ = 0, θ̇ = −Ω gives ψ̈ = (J/I) Ω ϕ̇ and
    (I + m R²) ϕ̈ = −Ω (J + m R²) ψ̇ + m g R ϕ; eliminating ψ̇ = (J/I) Ω ϕ (+ const):

        ϕ̈ + [Ω² J (J + m R²)/I − m g R]/(I + m R²) ϕ = 0,

    so the motion is (neutrally) stable iff Ω² > m g R I / (J (J + m R²)); with v = R Ω,
    v_c = √(m g R³ I / (J (J + m R²))) — for a uniform thin disk v_c = √(g R / 3).
    """
    return float(np.sqrt(m * g * R**3 * I / (J * (J + m * R * R))))


# -- Barhorst's particles -------------------------------------------------------------------
def barhorst_particle(m: float = 1.0, g: float = 10.0, q0=(2.0, 2.0), s_dot0=(0.0,), q_dot0=None) -> System:
    """Barhorst's particle in the x–y plane with ẏ − y² ẋ = 0 (Barhorst §3.1),
    gravity −g n̂2 (so E = m g y, 20 units at the start (2, 2) at rest).

    q = (x, y), ṡ = (ẋ,): ẏ = y² ẋ goes into F and K. (Barhorst takes ẏ independent,
    A12 = 1/y², and notes that choosing ẋ avoids the singularity at y → 0: done here.)
    The constraint integrates to y = 1/(x₀ + 1/y₀ − x) (his footnote 6 gives −1/x + c),
    so the particle slides down that curve.
    """
    x, y = sp.symbols("x y")
    (u,) = sp.symbols("u:1")
    xd, yd = sp.symbols("xd yd")
    F = sp.Matrix([[1], [y**2], [0], [0], [0], [0]])
    K = sp.Matrix([[1], [y**2]])
    joint = UserJoint.from_sympy([x, y], [u], sp.eye(3), [x, y, 0], F, K,
                                 constraints=[yd - y**2 * xd], q_dot=[xd, yd])
    system = System({"particle": PointMass(m)}, {"particle": joint}, gravity=(0.0, -g, 0.0), q0=q0, s_dot0=s_dot0)
    if q_dot0 is not None:
        system = System({"particle": PointMass(m)}, {"particle": joint}, gravity=(0.0, -g, 0.0), q0=q0,
                        s_dot0=initial_speeds(system, system.q0, q_dot0))
    return system


def nonholonomic_particle(m: float = 1.0, g: float = 10.0, q0=(0.0, 0.0, 1.0), s_dot0=(1.0, 2.0),
                          q_dot0=None) -> System:
    """The truly non-holonomic particle in space with ẏ + z ẋ = 0 (Barhorst
    §3.1, footnote 6), gravity −g n̂3.

    q = (x, y, z), ṡ = (ẋ, ż); ẏ = −z ẋ. The constraint is not integrable (its
    distribution is the contact structure dy + z dx), so a closed loop in (x, z) shifts y.
    Kane's equations in these speeds: (1 + z²) ẍ + z ż ẋ = 0, z̈ = −g, hence
    ẋ √(1 + z²) is conserved.
    """
    x, y, z = sp.symbols("x y z")
    u = sp.symbols("u_x u_z")
    xd, yd, zd = sp.symbols("xd yd zd")
    F = sp.Matrix([[1, 0], [-z, 0], [0, 1], [0, 0], [0, 0], [0, 0]])
    K = sp.Matrix([[1, 0], [-z, 0], [0, 1]])
    joint = UserJoint.from_sympy([x, y, z], list(u), sp.eye(3), [x, y, z], F, K,
                                 constraints=[yd + z * xd], q_dot=[xd, yd, zd])

    def build(s0):
        return System({"particle": PointMass(m)}, {"particle": joint}, gravity=(0.0, 0.0, -g), q0=q0, s_dot0=s0)

    system = build(s_dot0)
    if q_dot0 is not None:
        system = build(initial_speeds(system, system.q0, q_dot0))
    return system


__all__ = [
    "barhorst_particle",
    "car",
    "knife_edge_circle",
    "knife_edge_disc",
    "nonholonomic_particle",
    "rolling_disk",
    "rolling_disk_critical_speed",
    "rolling_disk_inertia",
]
