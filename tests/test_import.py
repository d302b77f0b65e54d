"""``import projeq`` stays light: sympy, scipy's solvers, matplotlib and numba load on first use
(issue: `import projeq` took 0.6–0.9 s because sympy and scipy.optimize loaded eagerly)."""

import subprocess
import sys

HEAVY = ("sympy", "scipy.optimize", "scipy.integrate", "scipy.linalg", "matplotlib", "numba", "meshio")


def test_import_projeq_loads_no_heavy_module():
    code = ("import sys, types, projeq\n"
            "loaded = [m for m in %r if type(sys.modules.get(m)) is types.ModuleType]\n"
            "print(','.join(loaded))" % (HEAVY,))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"import projeq loads {out}"


def test_a_lazily_imported_sympy_works_for_the_user():
    code = ("import projeq, sympy\n"
            "from sympy.physics.mechanics import dynamicsymbols\n"
            "x = sympy.Symbol('x')\n"
            "print(sympy.diff(sympy.sin(x), x), dynamicsymbols('q'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["cos(x)", "q(t)"]
