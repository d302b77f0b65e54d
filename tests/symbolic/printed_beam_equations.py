"""The spinning beam's field equations as printed in H. Bremer, "Problems in Fast Moving
Non-Holonomic Elastic Systems": B(18) (Hamilton's principle) and B(23) (the Projection
Equation). Test oracles: the derivations of :mod:`projeq.symbolic.spinning_beam` are checked
against them (tests/symbolic/test_spinning_beam.py, tests/studies/test_compare.py)."""

import sympy as sp

from projeq.symbolic.spinning_beam import EI, alpha, rho_A, rho_I, t, v, w, x


def _field_expected(rho_I_coupling: tuple[int, int]):
    """The two linear field equations with signs (s_v, s_w) of the ρI α̈ terms."""
    ad, add = alpha.diff(t), alpha.diff(t, 2)
    sv, sw = rho_I_coupling
    eq_v = (rho_A * (v.diff(t, 2) - 2 * ad * w.diff(t) - add * w - ad**2 * v)
            - rho_I * (v.diff(x, 2, t, 2) + ad**2 * v.diff(x, 2) + sv * add * w.diff(x, 2)) + EI * v.diff(x, 4))
    eq_w = (rho_A * (w.diff(t, 2) + 2 * ad * v.diff(t) + add * v - ad**2 * w)
            - rho_I * (w.diff(x, 2, t, 2) + ad**2 * w.diff(x, 2) + sw * add * v.diff(x, 2)) + EI * w.diff(x, 4))
    return sp.expand(eq_v), sp.expand(eq_w)


def expected_B18():
    """B(18) as printed (circular section, EI constant), with ρA α̈ v (not α̈ v/2, a slip of
    the text's transcription): ρI α̈ coupling −ρI(… − α̈w″), −ρI(… − α̈v″), symmetric."""
    return _field_expected((-1, -1))


def expected_B23():
    """B(23) as printed, with the signs of docs/theory.md: −ρI(… + α̈w″), −ρI(… − α̈v″), skew-symmetric."""
    return _field_expected((1, -1))
