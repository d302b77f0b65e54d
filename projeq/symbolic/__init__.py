"""Symbolic derivations (sympy): the Projection Equation, Hamel, Lagrange/Hamilton, program constraints.

- :mod:`.algebra`: spin matrices, cross products, rotations in sympy (the twin of
  :mod:`projeq.spatial`), used by every derivation;
- :mod:`.projection`, :mod:`.system`: the Projection Equation from velocity expressions
  (B(10)–(12)) and from a numeric :class:`projeq.System` (``gauss_form``);
- :mod:`.hamel`: Hamel's coefficients and equations (B(3)–(4));
- :mod:`.central`: Bremer's Central Equation B(2) as code — Hamel's, the Projection Equation's, Kane's
  and Lagrange's (with multipliers) equations derived from one description;
- :mod:`.lagrange`, :mod:`.canonical`: Lagrange/Hamilton with multipliers, the canonical
  momentum forms of A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems";
- :mod:`.hamiltonian`: Poisson brackets, constants of motion, Hamilton–Jacobi separation, the
  principal function, canonical transformations from generating functions, action-angle variables,
  Routh's elimination of cyclic coordinates (the problem-seminar book on Lagrange's equations,
  lecture notes §II.7, §§VI–VII, Seminars 10–11);
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
    "energy_rate": ".canonical",
    "poisson_bracket": ".hamiltonian", "constant_of_motion_rate": ".hamiltonian",
    "is_constant_of_motion": ".hamiltonian", "Separation": ".hamiltonian",
    "separate_hamilton_jacobi": ".hamiltonian",
    "principal_function": ".hamiltonian", "CanonicalTransformation": ".hamiltonian",
    "canonical_transformation": ".hamiltonian", "Libration": ".hamiltonian", "Routhian": ".hamiltonian",
    "routhian": ".hamiltonian",
    "CentralEquation": ".central", "central_equation": ".central",
    "ProgramEquations": ".program", "program_motion_equations": ".program", "nielsen_equations": ".program",
    "tzenoff_equations": ".program", "pseudo_regular_precession": ".program",
}

__all__ = list(_LAZY)


def lazy_import(name: str):
    """The module ``name``, loaded at its first attribute access (the standard library's
    ``importlib.util.LazyLoader`` recipe): the numeric joints and force laws keep their sympy
    forms next to their numeric ones without ``import projeq`` paying for sympy."""
    import importlib.util
    import sys

    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
