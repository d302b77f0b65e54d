"""The Whipple bicycle: four rigid bodies, two knife-edge wheels rolling on flat ground.

Model and parameters of Meijaard, Papadopoulos, Ruina & Schwab (2007, Proc. R. Soc. A
463:1955–1982, Table 1; "MJPR" below): rear wheel R, rear frame with rider B, front
fork with handlebar H, front wheel F; axes x forward, z *down*, origin at the rear contact
in the upright reference configuration (the table's coordinates are used as given).

Design: a tree plus constraint equations (:class:`~projeq.constraints.partitioned.ConstrainedSystem`,
docs/theory.md §7). The rolling constraints couple the speeds of all four bodies (the yaw rate
follows from steer, roll and the rear wheel's speed; the front wheel's spin from all of
them), so no choice of minimal velocities fits the tree's one-joint-one-slice layout that
:class:`~projeq.joints.UserJoint` scenes (car, rolling disk) use. Instead the tree is

- ``rear_frame`` (body B): a :class:`UserJoint` with q = (x, y, ψ, φ, θ) — the rear contact
  point in the ground plane, yaw ψ about z, roll φ about the yawed x, pitch θ about the
  rolled y (A = R_z(ψ) R_x(φ) R_y(θ)); its origin is the rear wheel's centre, which the
  joint keeps at height r_R above the contact (the rear contact's holonomic constraint is
  in the coordinates); ṡ = q̇;
- ``rear_wheel`` (R): :class:`Revolute` about the frame's y-axis (angle θ_R);
- ``fork`` (H): :class:`Revolute` about the steer axis (angle δ, right-handed about the
  axis pointing *down*, tilted forward by λ), its origin where the axis meets the ground;
- ``front_wheel`` (F): :class:`Revolute` about the fork's y-axis (angle θ_F),

with q = (x, y, ψ, φ, θ, θ_R, δ, θ_F), eight tree velocities ṡ_tree = q̇, and five
constraints: the front contact on the ground, Φ(q) = z_Q = 0 (holonomic: it fixes the
pitch θ), and no slip at both contacts, A(q) q̇ = 0 (the horizontal velocity of each
wheel's material contact point; the vertical one vanishes with Φ̇ and the coordinates).
The minimal velocities are ṡ = (φ̇, θ̇_R, δ̇): roll rate, rear-wheel rate (forward speed
v = −r_R θ̇_R) and steer rate. Φ and A are stated once in sympy from the geometry and
printed as scalar numpy code (:func:`projeq.symbolic.codegen.numeric_function`); the dynamics
are projeq's Projection Equation of the tree with the constraints inserted by coordinate
partitioning. Φ, A and the rear frame's relative motion compile with numba, so that s̈ is one
compiled call (:mod:`projeq.constraints.compiled`: the tree's compiled Gauss form, Φ's and A's
complex-step derivatives, the partition and the projection).

Linearisation (:func:`whipple_eigenvalues`): about upright straight running at speed v,
x, y, ψ, θ_R, θ_F are ignorable and dropped; the longitudinal states (θ, θ̇_R) decouple
from the lateral ones by the left–right symmetry, which leaves (φ, δ, φ̇, δ̇) and four
eigenvalues (MJPR §4: the weave and capsize modes and the castering mode).

Letters: ``c`` is MJPR's trail (not a constraint), ``w`` the wheelbase, ``lam`` the steer
axis tilt λ; θ is the rear frame's pitch and θ_R, θ_F the wheels' rotation angles.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import scipy.optimize
import sympy as sp
from numpy.typing import NDArray

from projeq.checks import finite_array
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.joints import Revolute, UserJoint
from projeq.analysis.linearize import linearize, sorted_eigenvalues
from projeq.spatial import axis_spin, rodrigues, rotation_x, rotation_y, rotation_z
from projeq.subsystems import RigidBody
from projeq.symbolic import algebra, codegen
from projeq.system import System

BENCHMARK = {  # MJPR Table 1 (SI units; x forward, z down, from the rear contact)
    "w": 1.02, "c": 0.08, "lam": np.pi / 10, "g": 9.81,
    "r_R": 0.3, "m_R": 2.0, "I_Rxx": 0.0603, "I_Ryy": 0.12,
    "x_B": 0.3, "z_B": -0.9, "m_B": 85.0, "I_Bxx": 9.2, "I_Byy": 11.0, "I_Bzz": 2.8, "I_Bxz": 2.4,
    "x_H": 0.9, "z_H": -0.7, "m_H": 4.0, "I_Hxx": 0.05892, "I_Hyy": 0.06, "I_Hzz": 0.00708, "I_Hxz": -0.00756,
    "r_F": 0.35, "m_F": 3.0, "I_Fxx": 0.1405, "I_Fyy": 0.28,
}
INDEPENDENT = (3, 5, 6)  # ṡ = (φ̇, θ̇_R, δ̇) among ṡ_tree = q̇
IGNORABLE = ("rear_frame.q[0]", "rear_frame.q[1]", "rear_frame.q[2]", "rear_wheel.q[0]", "front_wheel.q[0]")
LATERAL = ("rear_frame.q[3]", "fork.q[0]", "rear_frame.s_dot[3]", "fork.s_dot[0]")  # φ, δ, φ̇, δ̇


def bicycle_parameters(params: dict | None = None) -> dict:
    """MJPR's benchmark parameters (``BENCHMARK``) updated by ``params``; checked."""
    params = dict(params or {})
    unknown = sorted(set(params) - set(BENCHMARK))
    if unknown:
        raise ValueError(f"params: unknown parameters {unknown}; known: {sorted(BENCHMARK)}")
    values = {**BENCHMARK, **{k: float(finite_array(f"params[{k!r}]", v, ())) for k, v in params.items()}}
    for name in ("w", "r_R", "r_F", "g", "m_R", "m_B", "m_H", "m_F"):
        if not values[name] > 0:
            raise ValueError(f"params: {name} must be positive, got {values[name]}")
    if not abs(values["lam"]) < np.pi / 2:
        raise ValueError(f"params: lam (steer-axis tilt) must lie in (−π/2, π/2), got {values['lam']}")
    return values


# -- geometry: body-fixed vectors of the reference configuration ----------------------------
def _steer_axis(p: dict) -> NDArray:
    """Unit vector of the steer axis pointing down (tilted forward by λ), rear-frame axes."""
    return np.array([np.sin(p["lam"]), 0.0, np.cos(p["lam"])])


def _inertia(xx: float, yy: float, zz: float, xz: float = 0.0) -> NDArray:
    return np.array([[xx, 0.0, xz], [0.0, yy, 0.0], [xz, 0.0, zz]])


def _tree(p: dict, q0: NDArray) -> System:
    """The bicycle cut free of its contacts (see the module docstring), gravity +g along z."""
    rear_centre = np.array([0.0, 0.0, -p["r_R"]])  # in MJPR coordinates
    fork_origin = np.array([p["w"] + p["c"], 0.0, 0.0])  # steer axis ∩ ground
    front_centre = np.array([p["w"], 0.0, -p["r_F"]])
    bodies = {
        "rear_frame": RigidBody(p["m_B"], np.array([p["x_B"], 0.0, p["z_B"]]) - rear_centre,
                                _inertia(p["I_Bxx"], p["I_Byy"], p["I_Bzz"], p["I_Bxz"])),
        "rear_wheel": RigidBody(p["m_R"], (0.0, 0.0, 0.0), _inertia(p["I_Rxx"], p["I_Ryy"], p["I_Rxx"])),
        "fork": RigidBody(p["m_H"], np.array([p["x_H"], 0.0, p["z_H"]]) - fork_origin,
                          _inertia(p["I_Hxx"], p["I_Hyy"], p["I_Hzz"], p["I_Hxz"])),
        "front_wheel": RigidBody(p["m_F"], (0.0, 0.0, 0.0), _inertia(p["I_Fxx"], p["I_Fyy"], p["I_Fxx"])),
    }
    joints = {
        "rear_frame": _rear_frame_joint(p["r_R"], q0[:5]),
        "rear_wheel": Revolute(parent="rear_frame", axis="y"),
        "fork": Revolute(parent="rear_frame", axis=_steer_axis(p), r_pn=fork_origin - rear_centre),
        "front_wheel": Revolute(parent="fork", axis="y", r_pn=front_centre - fork_origin),
    }
    return System(bodies, joints, gravity=(0.0, 0.0, p["g"]), q0=q0)


@cache
def _rear_frame_symbols():
    """Pose and twist of the rear frame (origin: rear wheel centre) in q = (x, y, ψ, φ, θ).

    With the lean frame L = R_z(ψ) R_x(φ) and u = Lᵀ ω_L = (φ̇, sin φ ψ̇, cos φ ψ̇): the
    frame's ω = R_y(θ)ᵀ u + θ̇ e_y, and the velocity of r = (x, y, 0) − r_R L e_z is
    R_y(θ)ᵀ (Lᵀ (ẋ, ẏ, 0) − r_R u × e_z), in frame coordinates (from_sympy checks F
    against the pose)."""
    r_R = sp.Symbol("r_R", positive=True)
    q = list(sp.symbols("x y psi phi theta"))
    s = list(sp.symbols("xd yd psid phid thetad"))
    lean = algebra.rotation_z(q[2]) * algebra.rotation_x(q[3])
    A = lean * algebra.rotation_y(q[4])
    r = sp.Matrix([q[0], q[1], 0]) + lean * sp.Matrix([0, 0, -r_R])
    u = sp.Matrix([s[3], sp.sin(q[3]) * s[2], sp.cos(q[3]) * s[2]])
    v_lean = lean.T * sp.Matrix([s[0], s[1], 0]) - r_R * u.cross(sp.Matrix([0, 0, 1]))
    pitch = algebra.rotation_y(q[4]).T
    twist = sp.Matrix.vstack(pitch * v_lean, pitch * u + sp.Matrix([0, s[4], 0]))
    return q, s, A, r, twist.jacobian(sp.Matrix(s)), r_R


def _rear_frame_joint(r_R: float, q0: NDArray) -> UserJoint:
    q, s, A, r, F, r_sym = _rear_frame_symbols()
    return UserJoint.from_sympy(q, s, A, r, F, sp.eye(5), parameters={r_sym: r_R}, q0=q0)


# -- the contact constraints Φ(q) = 0 and A(q) q̇ = 0 ----------------------------------------
@cache
def _contact_expressions():
    """(q, constants, Φ, A): the front-contact height and the no-slip rows in sympy (the
    kinematics of :class:`Contacts`), in the coordinates q and the geometry's constants
    r_R, r_F, the steer axis e_s = (s_x, 0, s_z) and the offsets d_fork = (f_x, 0, f_z) (frame
    axes), d_front = (h_x, 0, h_z) (fork axes)."""
    q = sp.symbols("x y psi phi theta theta_R delta theta_F")
    constants = sp.symbols("r_R r_F s_x s_z f_x f_z h_x h_z")
    r_R, r_F, s_x, s_z, f_x, f_z, h_x, h_z = constants
    e_z = sp.Matrix([0, 0, 1])
    lean = algebra.rotation_z(q[2]) * algebra.rotation_x(q[3])
    frame = lean * algebra.rotation_y(q[4])
    e_s = sp.Matrix([s_x, 0, s_z])
    fork = algebra.mul(frame, algebra.rotation(e_s, q[6]))
    d_fork, d_front = frame * sp.Matrix([f_x, 0, f_z]), fork * sp.Matrix([h_x, 0, h_z])
    a = fork[:, 1]
    n_z = sp.sqrt(1 - a[2] ** 2)
    n = (e_z - a[2] * a) / n_z
    phi = sp.Matrix([-r_R * lean[2, 2] + d_fork[2] + d_front[2] + r_F * n_z])
    J_frame = sp.zeros(3, 8)
    J_frame[:, 2], J_frame[:, 3], J_frame[:, 4] = e_z, lean[:, 0], lean[:, 1]
    J_v = sp.zeros(3, 8)  # rear centre: (ẋ, ẏ, 0) − r_R ω_L × L e_z
    J_v[0, 0] = J_v[1, 1] = 1
    J_v[:, 2] = -r_R * algebra.cross(e_z, lean[:, 2])
    J_v[:, 3] = -r_R * algebra.cross(lean[:, 0], lean[:, 2])
    J_rear, J_fork = J_frame.copy(), J_frame.copy()
    J_rear[:, 5], J_fork[:, 6] = lean[:, 1], frame * e_s
    J_front = J_fork.copy()
    J_front[:, 7] = fork[:, 1]
    v_P = J_v - algebra.skew(r_R * lean[:, 2]) * J_rear
    v_Q = J_v - algebra.skew(d_fork) * J_frame - algebra.skew(d_front) * J_fork - algebra.skew(r_F * n) * J_front
    return q, constants, phi, sp.Matrix.vstack(v_P[:2, :], v_Q[:2, :])


@cache
def _contact_functions():
    """Factories of Φ(q, t) and A(q, t) from :func:`_contact_expressions` (scalar numpy code
    that numba compiles, :func:`projeq.symbolic.codegen.numeric_function`)."""
    q, constants, phi, A = _contact_expressions()
    arguments = [("q", list(q)), ("t", sp.Symbol("t"))]
    return (codegen.numeric_function("phi", arguments, phi, constants),
            codegen.numeric_function("A", arguments, A, constants))


class Contacts:
    """Front-contact height Φ(q) and no-slip rows A(q) of the bicycle with parameters ``p``.

    Rigid-body kinematics in inertial coordinates (z down), all linear in q̇ through the
    Jacobians J_ω (3×8) of the bodies' angular velocities and J_v of the rear wheel
    centre's velocity: the frame turns with ω = ψ̇ e_z + φ̇ R_z e_x + θ̇ L e_y
    (L = R_z(ψ) R_x(φ), frame A = L R_y(θ)), the fork adds δ̇ A e_s, the wheels θ̇_R L e_y
    and θ̇_F a (a = the front axle). A wheel's material point at P has velocity
    v_c + ω × (P − c); the front contact is Q = c_F + r_F n with
    n = (e_z − a_z a)/√(1 − a_z²), the wheel plane's most downward unit vector.

    ``phi(q, t)`` (Φ = z_Q, zero on the ground; the rows q[i] may be arrays, a batch of
    states) and ``A(q, t)`` (rows of A q̇ = 0: the horizontal velocities of the rear and the
    front wheel's material contact points) are these expressions stated once in sympy
    (:func:`_contact_expressions`) and printed as scalar code that numba compiles, so that the
    constrained s̈ is one compiled call (:mod:`projeq.constraints.compiled`); ``_poses`` gives
    the same poses in numpy."""

    def __init__(self, p: dict):
        self.r_R, self.r_F = p["r_R"], p["r_F"]
        self.e_s = _steer_axis(p)
        self.spin_s = axis_spin(self.e_s)
        self.d_fork = np.array([p["w"] + p["c"], 0.0, p["r_R"]])  # rear centre → fork origin, frame axes
        self.d_front = np.array([-p["c"], 0.0, -p["r_F"]])  # fork origin → front centre, fork axes
        constants = (self.r_R, self.r_F, *self.e_s[[0, 2]], *self.d_fork[[0, 2]], *self.d_front[[0, 2]])
        make_phi, make_A = _contact_functions()
        self.phi, self.A = make_phi(*map(float, constants)), make_A(*map(float, constants))

    def _poses(self, q):
        lean = rotation_z(q[2]) @ rotation_x(q[3])
        frame = lean @ rotation_y(q[4])
        fork = frame @ rodrigues(self.spin_s, q[6])
        rear_centre = np.array([q[0], q[1], 0.0]) - self.r_R * lean[:, 2]
        front_centre = rear_centre + frame @ self.d_fork + fork @ self.d_front
        a = fork[:, 1]
        n = (_E[2] - a[2] * a) / np.sqrt(1.0 - a[2] ** 2)
        return lean, frame, fork, rear_centre, front_centre, n


_E = np.eye(3)


FALLEN_ROLL = np.pi / 3  # rad: |roll| at which the bicycle counts as fallen over


def fallen_over(t: float, q, s_dot) -> float:
    """Terminal event of the bicycle falling over: zero where the roll φ = q[3] reaches
    ±60° (:data:`FALLEN_ROLL`). Beyond it the model's knife-edge wheels approach lying flat on
    the ground, where the rolling constraints cannot be solved for the dependent speeds."""
    return FALLEN_ROLL - abs(q[3])


fallen_over.terminal = True
fallen_over.description = f"the bicycle fell over (|roll| reached {np.degrees(FALLEN_ROLL):.0f}°)"


def upright_pitch(roll: float, steer: float, params: dict | None = None) -> float:
    """The pitch θ that puts the front wheel on the ground at the given roll and steer
    (Φ = 0 solved by Brent's method within ±0.5 rad; 0 for the upright, straight bicycle)."""
    contacts = Contacts(bicycle_parameters(params))

    def height(pitch):
        return contacts.phi(np.array([0.0, 0.0, 0.0, roll, pitch, 0.0, steer, 0.0]), 0.0)[0]

    try:
        return float(scipy.optimize.brentq(height, -0.5, 0.5, xtol=1e-15))
    except ValueError as exc:
        raise ValueError(f"roll, steer: no pitch puts the front wheel on the ground at roll = {roll}, "
                         f"steer = {steer} (the bicycle lies on the ground or folds)") from exc


def whipple_bicycle(params: dict | None = None, speed: float = 4.0, roll: float = 0.0, steer: float = 0.0,
                    roll_rate: float = 0.0, steer_rate: float = 0.0, **options) -> ConstrainedSystem:
    """The Whipple bicycle of MJPR (2007), see the module docstring.

    Parameters
    ----------
    params : dict, optional
        Overrides of MJPR's benchmark parameters (``BENCHMARK``, Table 1; names ``w, c, lam,
        g, r_R, m_R, I_Rxx, I_Ryy, x_B, z_B, m_B, I_Bxx, I_Byy, I_Bzz, I_Bxz, x_H, z_H, m_H,
        I_Hxx, I_Hyy, I_Hzz, I_Hxz, r_F, m_F, I_Fxx, I_Fyy``; SI units, z down).
    speed : float
        Initial forward speed v (m/s) of the rear wheel centre: θ̇_R = −v/r_R.
    roll, steer, roll_rate, steer_rate : float
        Initial roll φ, steer δ (rad) and their rates (rad/s); the pitch is solved from Φ = 0.
    **options
        Passed to :class:`~projeq.constraints.partitioned.ConstrainedSystem` (``correction``,
        ``beta``, ``repivot``). ``repivot`` defaults to True: the run starts with ṡ = (φ̇, θ̇_R, δ̇)
        and re-partitions where those stop determining the others (a steep roll), so a falling
        bicycle runs until it has fallen (:func:`fallen_over`).

    Returns
    -------
    ConstrainedSystem
        q = (x, y, ψ, φ, θ, θ_R, δ, θ_F), ṡ = (φ̇, θ̇_R, δ̇).

    Examples
    --------
    >>> bike = whipple_bicycle(speed=5.0)
    >>> bike.n_q, bike.n_s, bike.s_dot0.tolist()
    (8, 3, [0.0, -16.666666666666668, 0.0])
    """
    p = bicycle_parameters(params)
    speed, roll, steer, roll_rate, steer_rate = (
        float(finite_array(name, value, ())) for name, value in
        (("speed", speed), ("roll", roll), ("steer", steer), ("roll_rate", roll_rate), ("steer_rate", steer_rate))
    )
    q0 = np.array([0.0, 0.0, 0.0, roll, upright_pitch(roll, steer, p), 0.0, steer, 0.0])
    contacts = Contacts(p)
    s_dot0 = np.array([roll_rate, -speed / p["r_R"], steer_rate])
    return ConstrainedSystem(
        _tree(p, q0), phi=contacts.phi, A=contacts.A,
        independent=INDEPENDENT, q0=q0, s_dot0=s_dot0, **{"repivot": True, **options},
    )


def whipple_eigenvalues(speed: float, params: dict | None = None) -> NDArray:
    """Eigenvalues (four, complex, by decreasing real part) of the linearised roll/steer
    dynamics of upright straight running at forward speed ``speed`` (m/s).

    :func:`projeq.linearize` about q = 0, ṡ = (0, −v/r_R, 0) drops the ignorable x, y, ψ,
    θ_R, θ_F; of the remaining states the lateral (φ, δ, φ̇, δ̇) are kept. Their coupling
    to the longitudinal (θ, θ̇_R) vanishes by symmetry (checked: a ValueError reports it
    otherwise), so these are the eigenvalues of MJPR's linearised roll/steer equations.

    >>> lam = whipple_eigenvalues(5.0)
    >>> lam.shape, bool(lam.real.max() < 0)   # self-stable at 5 m/s (MJPR: 4.3 … 6.0 m/s)
    ((4,), True)
    """
    v = float(finite_array("speed", speed, ()))
    lin = linearize(whipple_bicycle(params, speed=v), ignore=IGNORABLE)
    lateral = [lin.states.index(name) for name in LATERAL]
    others = [i for i in range(len(lin.states)) if i not in lateral]
    coupling = max(np.abs(lin.A[np.ix_(lateral, others)]).max(), np.abs(lin.A[np.ix_(others, lateral)]).max())
    if coupling > 1e-6 * np.abs(lin.A).max():  # 1e-6: far above the Jacobian's error (~1e-9 here)
        raise ValueError(f"params: the lateral and longitudinal motions are coupled ({coupling:.3g}); "
                         "the bicycle is not left–right symmetric")
    return sorted_eigenvalues(lin.A[np.ix_(lateral, lateral)])
