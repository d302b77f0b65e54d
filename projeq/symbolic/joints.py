"""The joints of a System in sympy: each joint's own ``symbolic_relative`` (docs/theory.md §4).

Every joint class states its relative kinematics in sympy next to the numeric ones
(:meth:`projeq.joints.Joint.symbolic_relative`, a :class:`SymbolicRelative`: ``A``, ``r``,
``F``, ``f``, ``K``, ``k``); here they are called with the parameters the joint declares
(``symbolic_parameters``, e.g. a Prescribed joint's ``motion``), and a joint without a
symbolic form is refused by name.
"""

from __future__ import annotations

from ..joints import SymbolicRelative

__all__ = ["SymbolicRelative", "relative"]


def relative(joint, name: str, q_n, s_n, t, parameters: dict) -> SymbolicRelative:
    """Relative kinematics of ``joint`` (named ``name``) at the symbols or expressions
    q_n, s_n and time t; ``parameters`` are gauss_form's (``"<name>.<field>"`` keys)."""
    given = {}
    for field, meaning in joint.symbolic_parameters.items():
        key = f"{name}.{field}"
        if key not in parameters:
            raise ValueError(f"parameters: joint {name!r} ({type(joint).__name__}) needs {meaning}: "
                             f"parameters={{'{key}': ...}}")
        given[field] = parameters[key]
    try:
        return joint.symbolic_relative(q_n, s_n, t, **given)
    except NotImplementedError as reason:
        raise ValueError(f"system: joint {name!r} {reason}") from None
