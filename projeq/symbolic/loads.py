"""The force laws of a System in sympy: each law's own symbolic form (:class:`projeq.forces.ForceLaw`).

A body load is a wrench (f, M_O) about the body's origin in body coordinates, added to
h_n = Q_n − G_n ẏ_n (``symbolic_wrenches``); a joint force τ acts directly on the joint's
minimal velocities (``symbolic_joint_forces``; B(14): its projection Σ J_nᵀ h_n is τ).
A law without a symbolic form (a load given as a callable: its values are numbers, not
expressions) is refused by name before any derivation.
"""

from __future__ import annotations

import sympy as sp

from ..forces import ForceLaw

__all__ = ["check_loads", "body_wrenches", "joint_forces"]


def check_loads(system) -> None:
    """Refuse, before any derivation, the force laws without a symbolic form, naming ``forces[i]``."""
    for i, law in enumerate(system.forces):
        reason = law.symbolic_unsupported() if isinstance(law, ForceLaw) else "is not supported symbolically"
        if reason is not None:
            raise ValueError(f"system: forces[{i}] ({type(law).__name__}) {reason}")


def body_wrenches(system, links) -> dict:
    """{n: the sum of the laws' wrenches (f; M_O) on body n, in its coordinates}."""
    return _sum(law.symbolic_wrenches(links) for law in system.forces)


def joint_forces(system, q_joint, s_joint) -> dict:
    """{n: the sum of the laws' τ on joint n's minimal velocities}; ``q_joint[n]``,
    ``s_joint[n]`` are the joint's coordinates and velocities (symbols or the coupling's
    combinations)."""
    return _sum(law.symbolic_joint_forces(q_joint, s_joint) for law in system.forces)


def _sum(contributions) -> dict:
    total: dict = {}
    for contribution in contributions:
        for n, value in contribution.items():
            total[n] = total[n] + value if n in total else sp.Matrix(value)
    return total
