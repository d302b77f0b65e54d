"""``gauss_form(system)``: the symbolic Projection Equation of a numeric :class:`projeq.System`.

The joint chain of THEORY §4 (R_n = R_p Ā A_rel(q), r_n = r_p + R_p (r_pn + Ā r_rel), Ā the
joint's ``orientation``) is written out in sympy in the inertial frame; each body's
mass-centre velocity, angular velocity, inertia R_n I_c R_nᵀ and weight go into B(10) via
:func:`projection_equation`.

Supported (so far): trees of ``Revolute``, ``Prismatic`` and ``Fixed`` joints (no
coupling) carrying ``RigidBody`` or ``PointMass`` subsystems, gravity as the only load.
Anything else raises ``ValueError`` naming the joint, body or force.

Parameters are made symbolic with ``parameters={"link1.m": m1, "link1.r_c": ..., "link1.I_c":
..., "link2.r_pn": ..., "gravity": ...}``: the sympy value replaces the number the
system was built with (the numeric constructors stay strict); every free symbol of
these values is a parameter of the resulting :class:`GaussForm`.
"""

import sympy as sp

from ..joints import Fixed, Prismatic, Revolute
from ..subsystems.rigid import PlanarBody, RigidBody
from .projection import Body, GaussForm, projection_equation

__all__ = ["gauss_form"]

_JOINTS = (Revolute, Prismatic, Fixed)


def gauss_form(system, parameters=None) -> GaussForm:
    """M(q) s̈ = rhs(q, ṡ, t) of ``system`` in sympy (B(10), THEORY §2–4), nothing inverted.

    ``.q`` = (q_1, …), ``.s`` = (s_1, …) in the system's order of coordinates and minimal
    velocities; time is ``.t``. See the module docstring for ``parameters``.

    >>> import projeq as pq
    >>> gf = gauss_form(pq.scenes.double_pendulum(), {"bob1.m": sp.Symbol("m_1")})
    >>> gf.parameters
    (m_1,)
    """
    parameters = _check_parameters(system, dict(parameters or {}))
    q = sp.symbols(f"q_1:{system.n_q + 1}")
    s = sp.symbols(f"s_1:{system.n_s + 1}")
    gravity = parameters.get("gravity", sp.Matrix(system.gravity))
    R, r, omega = {}, {}, {}
    bodies = {}
    for n, (name, joint, body) in enumerate(zip(system.names, system.joints, system.subsystems)):
        p = system.parent[n]
        R_p, r_p, omega_p = (sp.eye(3), sp.zeros(3, 1), sp.zeros(3, 1)) if p not in R else (R[p], r[p], omega[p])
        A_rel, r_rel, w_rel = _relative(joint, q[system.q_slice[n]], s[system.s_slice[n]])
        orientation = sp.Matrix(joint.orientation)
        r_pn = parameters.get(f"{name}.r_pn", sp.Matrix(joint.r_pn))
        R[n] = R_p * orientation * A_rel
        r[n] = r_p + R_p * (r_pn + orientation * r_rel)
        omega[n] = omega_p + R_p * orientation * w_rel
        m = parameters.get(f"{name}.m", sp.Float(body.m))
        r_c = r[n] + R[n] * parameters.get(f"{name}.r_c", sp.Matrix(body.r_c))
        I_c = parameters.get(f"{name}.I_c", sp.Matrix(body.I_c))
        bodies[name] = Body(v_c=r_c.jacobian(q) * sp.Matrix(s), omega=omega[n], m=m,
                            I_c=R[n] * I_c * R[n].T, f=m * gravity)
    symbols = sorted(set().union(*(sp.sympify(v).free_symbols for v in parameters.values())), key=str)
    return projection_equation(bodies, q, s, parameters=symbols)


def _relative(joint, q_n, s_n):
    """Relative rotation, translation and angular velocity of a joint (joint-frame coordinates)."""
    if isinstance(joint, Revolute):
        e = sp.Matrix(joint.axis)
        E = sp.Matrix([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])  # ẽ
        return sp.eye(3) + sp.sin(q_n[0]) * E + (1 - sp.cos(q_n[0])) * E * E, sp.zeros(3, 1), e * s_n[0]
    if isinstance(joint, Prismatic):
        return sp.eye(3), sp.Matrix(joint.axis) * q_n[0], sp.zeros(3, 1)
    return sp.eye(3), sp.zeros(3, 1), sp.zeros(3, 1)


def _check_parameters(system, parameters) -> dict:
    """Refuse what the symbolic chain does not cover, by name; parameters as sympy values."""
    for name, joint, body in zip(system.names, system.joints, system.subsystems):
        if type(joint) not in _JOINTS or joint.coupling:
            raise ValueError(f"system: joint {name!r} ({type(joint).__name__}) is not supported symbolically; "
                             "use projection_equation with its velocity expressions")
        if not isinstance(body, RigidBody) or isinstance(body, PlanarBody):
            raise ValueError(f"system: subsystem {name!r} ({type(body).__name__}) is not supported symbolically")
    if system.forces:
        raise ValueError(f"system: force laws ({type(system.forces[0]).__name__}) are not supported symbolically")
    shapes = {"m": (), "r_c": (3, 1), "I_c": (3, 3), "r_pn": (3, 1)}
    out = {}
    for key, value in parameters.items():
        name, _, field = key.rpartition(".")
        shape = (3, 1) if key == "gravity" else shapes.get(field)
        if key != "gravity" and (name not in system.names or shape is None):
            raise ValueError(f"parameters: unknown key {key!r}; use 'gravity' or '<name>.m', '.r_c', '.I_c', '.r_pn'")
        value = sp.sympify(value) if shape == () else sp.Matrix(value)
        if shape and value.shape != shape:
            raise ValueError(f"parameters: {key!r} must have shape {shape}, got {value.shape}")
        out[key] = value
    return out

