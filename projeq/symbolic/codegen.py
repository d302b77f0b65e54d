"""Sympy expressions as scalar numpy code that numba compiles.

:func:`numeric_function` prints expressions in symbols that stand for the entries of array
arguments (``q[i]``) as one Python function of those arrays, with sympy's common
subexpressions (``cse``) as temporaries and numpy's elementary functions: the same source runs
in numpy (real or complex arguments — the complex step — and, for a column of expressions, on
arrays of rows q[i], a batch of points) and compiles with ``numba.njit``, also as a C callback
(:mod:`projeq.constraints.compiled`). Numbers are printed to full precision (``repr`` of the
float), so the code evaluates the expressions as given.

>>> import numpy as np, sympy as sp
>>> q = sp.symbols("a b")
>>> make = numeric_function("height", [("q", q)], sp.Matrix([sp.Symbol("r") * sp.cos(q[0]) + q[1]]),
...                         constants=[sp.Symbol("r")])
>>> height = make(2.0)
>>> height(np.array([0.0, 0.5])).tolist()
[2.5]
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

__all__ = ["numeric_function"]


class _Printer(NumPyPrinter):
    """numpy code with floats to full precision (sympy prints 15 digits) and small integer powers
    as products: numba's complex power goes through exp(n log z), whose round-off leaves an
    imaginary part of order ε |z|ⁿ at a negative real z — (−0.566 + 10⁻²⁰ i)³ has 7e-17 i instead
    of 1e-20 i —, which a complex step reads as a derivative of order 10⁴."""

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):
        exponent = expr.exp
        if exponent.is_number and float(exponent).is_integer() and 1 <= abs(int(exponent)) <= 4:
            base = self._print(expr.base) if expr.base.is_Symbol else f"({self._print(expr.base)})"
            product = "*".join([base] * abs(int(exponent)))
            return f"({product})" if exponent > 0 else f"(1/({product}))"
        return super()._print_Pow(expr, rational)


def numeric_function(name: str, arguments, expressions, constants=()):
    """A factory ``make(*values)`` of the function ``name(*argument names)`` that returns the
    sympy ``expressions`` as a numpy array: 1-D for a column (or a list), 2-D for a matrix.

    ``arguments``: (name, symbols) pairs — a list of symbols are the entries ``name[i]`` of an
    array argument, a single symbol a scalar argument; ``constants``: symbols whose values
    ``make`` takes (captured by the function, constants to numba). The function's ``source``
    attribute is its own source (in the names of ``constants``, its ``constants`` attribute), to
    be compiled where the constants are module globals or the entries of an array argument
    (:func:`projeq.assembly.generated.generated_module`), ``values`` the values ``make`` was given."""
    rename = {}
    for argument, symbols in arguments:
        if isinstance(symbols, sp.Symbol):
            rename[symbols] = sp.Symbol(argument)
        else:
            rename.update({s: sp.Symbol(f"{argument}[{i}]") for i, s in enumerate(symbols)})
    matrix = sp.Matrix(expressions)
    temporaries, reduced = sp.cse([e.xreplace(rename) for e in matrix], symbols=sp.numbered_symbols("_c"))
    printer = _Printer()

    def entry(e):
        return repr(float(e)) if e.is_number else printer.doprint(e)

    entries = [entry(e) for e in reduced]
    if matrix.cols == 1:
        body = ", ".join(entries)
    else:
        body = ", ".join("[" + ", ".join(entries[r * matrix.cols:(r + 1) * matrix.cols]) + "]"
                         for r in range(matrix.rows))
    names = [str(c) for c in constants]
    signature = f"def {name}({', '.join(a for a, _ in arguments)}):"
    body = [f"    {s} = {printer.doprint(e)}" for s, e in temporaries] + [f"    return numpy.array([{body}])"]
    lines = [f"def make({', '.join(names)}):", "    " + signature, *("    " + line for line in body),
             f"    {name}.source = source", f"    {name}.constants = {tuple(names)!r}",
             f"    {name}.values = ({''.join(n + ', ' for n in names)})", f"    return {name}"]
    source = "\n".join(lines) + "\n"
    namespace = {"numpy": np, "source": "\n".join([signature, *body]) + "\n"}
    exec(compile(source, f"<projeq.symbolic.codegen {name}>", "exec"), namespace)  # noqa: S102 — our own printout
    return namespace["make"]
