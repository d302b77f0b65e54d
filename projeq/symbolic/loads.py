"""The force laws of :mod:`projeq.forces` in sympy: body wrenches and joint forces.

A body load is a wrench (f, M_O) about the body's origin in body coordinates, added to
h_n = Q_n − G_n ẏ_n; a joint force τ acts directly on the joint's minimal velocities
(B(14): its projection Σ J_nᵀ h_n is τ). Loads given as callables are refused by name:
their values are numbers, not expressions.
"""

from __future__ import annotations

import sympy as sp

from ..forces import Force, JointForce, JointSpring, SpringDamper, Torque
from .algebra import cross, exact, mul

__all__ = ["check_loads", "body_wrenches", "joint_forces"]


def _load(i: int, law, attribute: str):
    """The constant of a load; a callable one is refused, naming ``forces[i]``
    (:func:`projeq.forces._load` marks a constant load with its value, ``load.constant``)."""
    constant = getattr(getattr(law, attribute), "constant", None)
    if constant is None:
        raise ValueError(f"system: forces[{i}] ({type(law).__name__}) has a callable {attribute.strip('_')}, "
                         "which is not supported symbolically; give a constant or use projection_equation")
    return exact(constant)


def check_loads(system) -> None:
    """Refuse, before any derivation, the force laws and callable loads not covered here."""
    for i, law in enumerate(system.forces):
        if not isinstance(law, (Force, Torque, SpringDamper, JointForce)):
            raise ValueError(f"system: forces[{i}] ({type(law).__name__}) is not supported symbolically")
        attribute = {Force: "force", Torque: "torque", JointForce: "_tau"}.get(type(law))
        if attribute:
            _load(i, law, attribute)


def body_wrenches(system, links) -> dict:
    """{n: wrench (f; M_O) in body n's coordinates} of the Force, Torque and SpringDamper laws."""
    wrenches = {}

    def add(n, wrench):
        wrenches[n] = wrenches.get(n, sp.zeros(6, 1)) + wrench

    for i, law in enumerate(system.forces):
        if isinstance(law, Force):
            f = _load(i, law, "force")
            f = mul(links[law.index].R.T, f) if law.frame == "world" else f
            add(law.index, sp.Matrix.vstack(f, cross(exact(law.point), f)))
        elif isinstance(law, Torque):
            tau = _load(i, law, "torque")
            tau = mul(links[law.index].R.T, tau) if law.frame == "world" else tau
            add(law.index, sp.Matrix.vstack(sp.zeros(3, 1), tau))
        elif isinstance(law, SpringDamper):
            for n, wrench in _spring_damper(law, links):
                add(n, wrench)
    return wrenches


def _spring_damper(law, links) -> list:
    """Wrenches of a linear spring-damper: tension k (ℓ − ℓ₀) + d ℓ̇ along the line a → b."""
    ends = []
    for n, point in zip(law.index, law.points):
        point = exact(point)
        if n < 0:
            ends.append((point, sp.zeros(3, 1)))
            continue
        link = links[n]
        v_O, omega = link.twist[:3, :], link.twist[3:, :]
        ends.append((link.r + mul(link.R, point), mul(link.R, v_O + cross(omega, point))))
    (x_a, v_a), (x_b, v_b) = ends
    d = x_b - x_a
    length = sp.sqrt(d.dot(d))
    e = d / length
    tension = law.stiffness * (length - law.length) + law.damping * e.dot(v_b - v_a)
    out = []
    for n, point, sign in zip(law.index, law.points, (1, -1)):
        if n >= 0:
            f = mul(links[n].R.T, sign * tension * e)  # pulls a towards b and b towards a
            out.append((n, sp.Matrix.vstack(f, cross(exact(point), f))))
    return out


def joint_forces(system, q_joint, s_joint) -> dict:
    """{n: τ on joint n's minimal velocities} of the JointForce and JointSpring laws;
    ``q_joint[n]``, ``s_joint[n]`` are the joint's coordinates and velocities (symbols or
    the coupling's combinations)."""
    forces = {}
    for i, law in enumerate(system.forces):
        if isinstance(law, JointSpring):
            q_ref = exact([law._q_ref[k] for k in range(law.n_s)])
            q_n, s_n = sp.Matrix(q_joint[law.index]), sp.Matrix(s_joint[law.index])
            tau = -law.stiffness * (q_n - q_ref) - law.damping * s_n
        elif isinstance(law, JointForce):
            tau = _load(i, law, "_tau")
        else:
            continue
        forces[law.index] = forces.get(law.index, sp.zeros(law.n_s, 1)) + sp.Matrix(tau)
    return forces
