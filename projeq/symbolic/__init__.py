"""Symbolic derivations (sympy): the Projection Equation, Hamel, Lagrange/Hamilton, program constraints.

- :mod:`.projection`, :mod:`.system`: the Projection Equation from velocity expressions
  (B(10)–(12)) and from a numeric :class:`projeq.System` (``gauss_form``);
- :mod:`.hamel`: Hamel's coefficients and equations (B(3)–(4));
- :mod:`.lagrange`, :mod:`.canonical`: Lagrange/Hamilton with multipliers, Barhorst's
  canonical momentum forms (seed 001 K(1)–(26), seed 000);
- :mod:`.hamiltonian`: Poisson brackets, constants of motion, Hamilton–Jacobi separation (the
  problem-seminar book on Lagrange's equations, Seminars 10–11);
- :mod:`.program`: high-order program constraints (GPME, seed 002 eqs. 6.30–6.33);
- :mod:`.spinning_beam`: Hamilton vs Projection Equation for the spinning beam (B(16)–(23)).
"""

from .canonical import CanonicalForm, energy_rate, lagrangian_canonical, projective_canonical
from .hamiltonian import (Separation, constant_of_motion_rate, is_constant_of_motion, poisson_bracket,
                          separate_hamilton_jacobi)
from .hamel import check_regular, hamel_coefficients, hamel_equations
from .lagrange import MultiplierSystem, multiplier_system
from .program import ProgramEquations, program_motion_equations
from .projection import Body, GaussForm, SymbolicEvaluator, projection_equation, t
from .system import gauss_form

__all__ = [
    "Body", "GaussForm", "SymbolicEvaluator", "gauss_form", "projection_equation", "t",
    "check_regular", "hamel_coefficients", "hamel_equations",
    "MultiplierSystem", "multiplier_system", "CanonicalForm", "energy_rate", "lagrangian_canonical",
    "projective_canonical",
    "ProgramEquations", "program_motion_equations",
    "poisson_bracket", "constant_of_motion_rate", "is_constant_of_motion", "Separation", "separate_hamilton_jacobi",
]
