"""Symbolic derivations (sympy): the Projection Equation, Hamel, Lagrange/Hamilton, program constraints.

- :mod:`.algebra`: spin matrices, cross products, rotations in sympy (the twin of
  :mod:`projeq.spatial`), used by every derivation;
- :mod:`.projection`, :mod:`.system`: the Projection Equation from velocity expressions
  (B(10)–(12)) and from a numeric :class:`projeq.System` (``gauss_form``);
- :mod:`.hamel`: Hamel's coefficients and equations (B(3)–(4));
- :mod:`.lagrange`, :mod:`.canonical`: Lagrange/Hamilton with multipliers, the canonical
  momentum forms of A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems";
- :mod:`.program`: high-order program constraints (the generalized program motion
  equations of "On derivation of motion equations for systems with non-holonomic
  high-order program constraints", eqs. 6.30–6.33);
- :mod:`.spinning_beam`: Hamilton vs Projection Equation for the spinning beam (B(16)–(23)), and
  the beam without torsional strain that both miss under spin-up.

The names below load their module on first use, so that importing one module of this
package (e.g. :mod:`.algebra` from the numeric scenes) does not import the others.
"""

_LAZY = {
    "Body": ".projection", "GaussForm": ".projection", "SymbolicEvaluator": ".projection",
    "projection_equation": ".projection", "t": ".projection",
    "gauss_form": ".system",
    "check_regular": ".hamel", "hamel_coefficients": ".hamel", "hamel_equations": ".hamel",
    "MultiplierSystem": ".lagrange", "multiplier_system": ".lagrange",
    "CanonicalForm": ".canonical", "lagrangian_canonical": ".canonical", "projective_canonical": ".canonical",
    "ProgramEquations": ".program", "program_motion_equations": ".program",
}

__all__ = list(_LAZY)


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
