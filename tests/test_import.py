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


def test_import_projeq_scenes_loads_no_solver_of_scipy():
    """The scenes' references (the pendulum's elliptic functions, the parallelogram's solve_ivp,
    the flyball's Brent roots) import scipy's solvers where they are called: ``import
    projeq.scenes`` (and the parser of ``projeq run``) costs numpy and scipy.linalg, not
    scipy.integrate's import of scipy.special, scipy.optimize and scipy.sparse (0.70 s instead
    of 1.31 s CPU, benchmarks/results/2026-11-28)."""
    code = ("import sys, types, projeq.scenes\n"
            "loaded = [m for m in %r if type(sys.modules.get(m)) is types.ModuleType]\n"
            "print(','.join(loaded))" % (tuple(m for m in HEAVY if m != "scipy.linalg") + ("scipy.special", "scipy.sparse"),))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"import projeq.scenes loads {out}"


def test_a_lazily_imported_sympy_works_for_the_user():
    code = ("import projeq, sympy\n"
            "from sympy.physics.mechanics import dynamicsymbols\n"
            "x = sympy.Symbol('x')\n"
            "print(sympy.diff(sympy.sin(x), x), dynamicsymbols('q'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["cos(x)", "q(t)"]


def test_projeq_run_imports_no_sympy_matplotlib_or_meshio(tmp_path):
    """``projeq run`` (issue 15: as fast as it can with no arguments) loads only what it runs: not
    sympy (the symbolic scenes register lazily), matplotlib (plots only with --plots), meshio
    (the VTU files are written directly) nor the benchmark and study modules."""
    code = ("import sys, types\nfrom projeq.cli import main\n"
            f"assert main(['run', '--t-end', '0.05', '--out', {str(tmp_path)!r}, '--quiet']) == 0\n"
            "heavy = ('sympy', 'matplotlib', 'meshio', 'projeq.studies.bench', 'projeq.studies.compare', 'projeq.cli.bench', 'projeq.scenes.bicycle')\n"
            "print(','.join(m for m in heavy if type(sys.modules.get(m)) is types.ModuleType))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"projeq run loads {out}"
    assert len(list(tmp_path.glob("*/paraview/*.vtu"))) > 1
