"""Input checks shared by the symbolic derivations: ``ValueError`` naming the argument."""

import sympy as sp


def matrix(name: str, value) -> sp.Matrix:
    """``value`` as a sympy Matrix (a flat sequence becomes a column)."""
    try:
        return sp.Matrix(value)
    except (TypeError, ValueError, sp.SympifyError) as exc:
        raise ValueError(f"{name}: expected a sympy matrix or a sequence of expressions, got {value!r}") from exc


def symbol_vector(name: str, value) -> list:
    """``value`` as a list of distinct sympy symbols (or functions of t, dynamic symbols)."""
    items = list(value)
    for item in items:
        if not isinstance(item, (sp.Symbol, sp.Function, sp.core.function.AppliedUndef)):
            raise ValueError(f"{name}: expected sympy symbols, got {item!r}")
    if len(set(items)) != len(items):
        raise ValueError(f"{name}: symbols must be distinct, got {items}")
    return items


def check_symbols(name: str, expr, declared) -> None:
    """Raise ``ValueError`` naming the symbols of ``expr`` that are not ``declared``."""
    unknown = sp.sympify(expr).free_symbols - set(declared)
    if unknown:
        names = ", ".join(sorted(str(u) for u in unknown))
        raise ValueError(
            f"{name}: depends on undeclared symbols {names}; declare them as coordinates q, "
            "speeds s or parameters"
        )
