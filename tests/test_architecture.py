"""The layout keeps its promises (docs/architecture.md): a short top level, no import cycles,
no private name imported across modules, and nothing in the package reading the repository
checkout. Each check reads the source with :mod:`ast`, so it fails on the line that breaks it."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "projeq"


def _modules() -> dict[str, Path]:
    """Dotted module name → file, for every module of the package."""
    modules = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    return modules


def _imports(name: str, path: Path, modules: dict) -> list[tuple[str, str, int]]:
    """(imported module, imported name or '', line) of every import of the module, those
    inside functions included (a deferred import is still a dependency), those under
    ``if TYPE_CHECKING`` not."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
            node.body = []
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, "", node.lineno) for alias in node.names if alias.name.startswith("projeq")]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            if not base.startswith("projeq"):
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found.append((sub, "", node.lineno) if sub in modules else (base, alias.name, node.lineno))
    return found


def test_the_top_level_has_at_most_16_entries():
    """At most 16 modules and packages at the top of projeq/; the PEP 561 marker py.typed is data, not code."""
    entries = sorted(p.name for p in PACKAGE.iterdir() if p.name not in ("__pycache__", "py.typed"))
    assert len(entries) <= 16, entries
    assert (PACKAGE / "py.typed").is_file()


def test_no_import_cycles():
    """Depth-first search over the imports; importing a module also loads its packages' __init__."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        edges = set()
        for target, _, _ in _imports(name, path, modules):
            parts = target.split(".")
            edges |= {".".join(parts[:k]) for k in range(1, len(parts) + 1)} & modules.keys()
        graph[name] = edges - {name}
    state: dict[str, int] = {}
    cycles = []

    def visit(node, stack):
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    # a package's __init__ importing its own submodules is not a cycle of concepts
    real = [c for c in cycles if not all(m.startswith(c[0] + ".") or m == c[0] for m in c)]
    assert not real, "\n".join(" -> ".join(c) for c in real)


def _private(name: str) -> bool:
    """``_name`` is private; a dunder (``__version__``) is public."""
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_no_private_name_is_imported_across_modules():
    modules = _modules()
    offenders = [
        f"{name}:{line} imports {what} from {source}"
        for name, path in modules.items()
        for source, what, line in _imports(name, path, modules)
        if _private(what) or _private(source.rpartition(".")[2])
    ]
    assert not offenders, "\n".join(offenders)


def test_the_installed_package_does_not_read_the_repository_checkout():
    """No module looks for ``benchmarks/``, ``examples/`` or ``tests/`` next to the package."""
    offenders = [
        str(path.relative_to(PACKAGE.parent))
        for path in PACKAGE.rglob("*.py")
        for word in ('"benchmarks"', "'benchmarks'", '"examples"', '"tests"', "parents[1]")
        if word in path.read_text()
    ]
    assert not offenders, offenders
