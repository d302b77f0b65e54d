"""Generate docs/api.md from the docstrings: ``python docs/gen_api.py``.

Every name of ``projeq.__all__`` gets a heading, its signature and its docstring rendered as
plain Markdown (numpydoc sections as bold titles and lists, doctest examples as code, Sphinx
roles and double backticks as code spans), so that the page reads the same on any Markdown
viewer. Classes list their own public methods and properties (a method that implements a base
class's, documented there, and the evaluators' methods of :data:`INTERNAL` are named in one line,
not documented again); modules their public names; :data:`MODULES` adds functions of submodules.
tests/test_api_doc.py checks that docs/api.md is what this script writes now.
"""

from __future__ import annotations

import inspect
import re
import sys
from collections.abc import Mapping
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import projeq  # noqa: E402  (after the path: projeq need not be installed)

TARGET = ROOT / "docs" / "api.md"
GROUPS = (
    ("Building a system", ("GROUND", "System", "SystemBuilder")),
    ("Subsystems", ("Subsystem", "RigidBody", "PlanarBody", "PointMass", "Frame", "RitzBeam", "inertia")),
    ("Joints", ("Joint", "Revolute", "Prismatic", "Fixed", "Planar", "Free", "Prescribed", "UserJoint")),
    ("Forces", ("ForceLaw", "Force", "Torque", "JointForce", "JointSpring", "SpringDamper")),
    ("Constraint equations and reactions",
     ("ConstrainedSystem", "PinClosure", "reactions", "joint_reactions", "contact_event")),
    ("Simulation", ("simulate", "Result", "SimulationError", "StiffnessWarning", "SingularMassError",
                    "sweep", "SweepTable", "plots")),
    ("Analysis and comparisons", ("linearize", "Linearization", "NotSteadyError", "eigenvalue_sweep",
                                  "modes", "Modes", "campbell", "CampbellDiagram", "compare", "ComparisonTable")),
    ("Scenes and symbolic derivations", ("scenes", "symbolic")),
)
#: Hand-written introductions of groups (Markdown), placed under the group's heading.
INTROS = {
    "Building a system": """Coordinates by name. Every joint and subsystem declares the (name, unit) of its
coordinates (`Joint.coordinates`, `Joint.velocities`, `Subsystem.coordinates`; defaults
`q[i]`, `s_dot[i]`, `e[i]` with unknown units, so user plug-ins work unchanged), and every
model lists them as `"subsystem.coordinate"` in the order of q and ṡ
(`Model.coordinates()`, `Model.velocities()`; a Result carries them, and its
`column_names()`). The tree keeps the order in which the subsystems were declared whenever
each parent comes before its children (else a warning names the order q follows), and
`Model.state`, `Model.q_index` address entries by name:

```python
import projeq as pq
system = pq.scenes.chain(3)
q0, s_dot0 = system.state(link2=0.2, s_dot={"link1.angle_dot": 1.5})
result = pq.simulate(system, 1.0, q0=q0, s_dot0=s_dot0)
i = system.q_index("link2.angle")   # 1: for functions of q such as constraints Φ(q)
```
""",
}
#: Names of submodules documented in a group besides projeq.__all__'s: {group: ((module, name), ...)}.
MODULES = {"Subsystems": (("projeq.subsystems", "Visual"),),
           "Simulation": (("projeq.simulation.export", "write_vtu_series"),)}
#: Public methods that the evaluators, the integrators and the command line call, not a user building
#: or running a model: named in one line under their class.
INTERNAL = {
    "System": ("joint_q_getter", "joint_s_dot_getter", "joint_s_columns", "evaluator", "accelerations_tree",
               "tree_velocities", "gauss_form", "output_row"),
    "ConstrainedSystem": ("row_models", "F", "particular", "tree_velocities", "project", "gamma",
                          "tree_gauss_form", "compiled_tree", "gauss_form", "accelerations_tree",
                          "compiled_kernel", "evaluator", "output_row", "after_event", "with_independent",
                          "check_closed"),
}
#: Plug-in contracts documented besides projeq.__all__ (module, name); name None: the module.
CONTRACTS = (("projeq.system", "Model"), ("projeq.joints.base", "Relative"),
             ("projeq.joints.base", "SymbolicRelative"), ("projeq.simulation.integrators", None))
SECTIONS = ("Parameters", "Other Parameters", "Returns", "Yields", "Raises", "Warns", "Attributes",
            "Examples", "Notes", "See Also", "References")
ROLE = re.compile(r":(?:py:)?(?:mod|class|func|meth|attr|data|obj|exc|const|ref):`~?([^`]+)`")


# -- docstrings to Markdown -------------------------------------------------------------------

def inline(text: str) -> str:
    """Sphinx roles and ``double backticks`` as Markdown code spans."""
    text = ROLE.sub(lambda m: f"`{m.group(1)}`", text)
    return re.sub(r"``([^`]+?)``", r"`\1`", text)


def is_underline(line: str, title: str) -> bool:
    return len(line.strip()) >= 3 and set(line.strip()) == {"-"} and title.strip() in SECTIONS


def split_sections(lines: list[str]) -> list[tuple[str | None, list[str]]]:
    """[(section title or None for the summary, its lines)] of a numpydoc docstring."""
    sections: list[tuple[str | None, list[str]]] = [(None, [])]
    i = 0
    while i < len(lines):
        if i + 1 < len(lines) and is_underline(lines[i + 1], lines[i]):
            sections.append((lines[i].strip(), []))
            i += 2
            continue
        sections[-1][1].append(lines[i])
        i += 1
    return sections


DEFINITION = re.compile(r"([\w.,;* ]+?) : (.*)")


def definitions(lines: list[str]) -> list[str]:
    """Left-margin ``name : text`` lines of free text (and their indented continuation) as
    list items."""
    out: list[str] = []
    for line in lines:
        match = DEFINITION.fullmatch(line)
        if match and not line.startswith(" "):
            out.append(f"- `{match.group(1)}`: {match.group(2)}")
        elif out and out[-1].startswith("- `") and line.startswith(" ") and line.strip():
            out[-1] += " " + line.strip()
        else:
            out.append(line)
    return out


def fence_doctests(lines: list[str]) -> list[str]:
    """Runs of ``>>>`` lines and their output as python code blocks."""
    out: list[str] = []
    in_code = False
    for line in lines:
        starts = line.lstrip().startswith(">>>")
        if starts and not in_code:
            out += ["```python"]
            in_code = True
        elif in_code and not line.strip():
            out += ["```"]
            in_code = False
        out.append(line.strip() if in_code else line)
    return out + (["```"] if in_code else [])


HEAD = re.compile(r"[\w.,*\[\] |]+")


def entries(lines: list[str]) -> list[str]:
    """numpydoc entries ``name : type`` + indented description as a Markdown list; prose at
    the left margin (no entry) stays a paragraph."""
    items: list[tuple[str, list[str]]] = []
    for line in lines:
        if not line.strip():
            continue
        if line.startswith(" ") and items:
            items[-1][1].append(line.strip())
        elif (HEAD.fullmatch(line.strip().partition(" : ")[0]) and " : " in line or HEAD.fullmatch(line.strip())) \
                and len(line) < 100:
            name, sep, kind = line.strip().partition(" : ")
            items.append((f"- `{name}`" + (f" ({kind.strip()})" if sep else ""), []))
        elif items and not items[-1][0].startswith("- "):
            items[-1][1].append(line.strip())
        else:
            items.append(("", [line.strip()]))
    return ["\n" + " ".join(desc) + "\n" if not head else head + (": " + " ".join(desc) if desc else "")
            for head, desc in items]


def markdown(doc: str) -> str:
    """A numpydoc docstring as plain Markdown."""
    parts: list[str] = []
    for title, lines in split_sections(inline(doc).splitlines()):
        if title is None:
            parts.append("\n".join(fence_doctests(definitions(lines))).strip())
        elif title in ("Parameters", "Other Parameters", "Returns", "Yields", "Raises", "Warns", "Attributes"):
            parts.append(f"**{title}**\n\n" + "\n".join(entries(lines)))
        else:
            parts.append(f"**{title}**\n\n" + "\n".join(fence_doctests(lines)).strip())
    return "\n\n".join(part for part in parts if part.strip()) + "\n"


# -- signatures -------------------------------------------------------------------------------

def signature(name: str, obj) -> str:
    """``name(parameters) -> return``, string annotations unquoted, one parameter a line when long."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return f"{name}(...)"
    params = []
    for p in sig.parameters.values():
        if p.name in ("self", "cls"):
            continue
        if p.kind is p.KEYWORD_ONLY and not any(x.startswith("*") for x in params):
            params.append("*")
        params.append(re.sub(r": '([^']*)'", r": \1", str(p)))
    ret = "" if sig.return_annotation in (inspect.Signature.empty, None, "None") else \
        " -> " + (sig.return_annotation if isinstance(sig.return_annotation, str)
                  else getattr(sig.return_annotation, "__name__", str(sig.return_annotation)))
    ret = ret.replace("'", "")
    one_line = f"{name}({', '.join(params)}){ret}"
    if len(one_line) <= 96:
        return one_line
    return f"{name}(\n" + "".join(f"    {p},\n" for p in params) + f"){ret}"


def code(text: str) -> str:
    return f"```python\n{text}\n```\n"


# -- objects ----------------------------------------------------------------------------------

def own_members(cls) -> list[tuple[str, object]]:
    """Public methods and properties defined in ``cls`` itself, in source order."""
    members = []
    for name, value in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(value, (staticmethod, classmethod)):
            value = value.__func__
        if isinstance(value, property) or inspect.isfunction(value):
            members.append((name, value))
    return members


def documented_classes() -> set:
    """The classes this page documents: those of projeq.__all__ and of :data:`CONTRACTS`."""
    named = [getattr(projeq, name) for name in projeq.__all__]
    named += [getattr(__import__(module, fromlist=["_"]), name) for module, name in CONTRACTS if name]
    return {value for value in named if inspect.isclass(value)}


def implemented(cls, name: str) -> str | None:
    """The name of the nearest documented base class of ``cls`` that defines ``name`` (where the
    method is documented), or None."""
    return next((base.__name__ for base in cls.__mro__[1:-1] if name in vars(base)
                 and base in documented_classes()), None)


def document_class(qualified: str, cls, level: int = 3) -> str:
    bases = [b.__name__ for b in cls.__bases__ if b is not object]
    text = [f"{'#' * level} {qualified}\n", code(signature(qualified, cls))]
    if bases:
        text.append(f"Bases: {', '.join(f'`{b}`' for b in bases)}\n")
    text.append(markdown(inspect.getdoc(cls) or "(no docstring)"))
    members = own_members(cls)
    overrides: dict[str, list[str]] = {}
    for name, _ in members:
        if implemented(cls, name) and name not in INTERNAL.get(cls.__name__, ()):
            overrides.setdefault(implemented(cls, name), []).append(f"`{name}`")
    for base, names in overrides.items():
        text.append(f"Implements {', '.join(names)} of `{base}` (documented there).\n")
    internal = [f"`{name}`" for name, _ in members if name in INTERNAL.get(cls.__name__, ())]
    if internal:
        text.append(f"For the evaluators and integrators (not needed to build or run a model): "
                    f"{', '.join(internal)}.\n")
    for name, member in members:
        doc = inspect.getdoc(member)
        if not doc or implemented(cls, name) or name in INTERNAL.get(cls.__name__, ()):
            continue
        if isinstance(member, property):
            text.append(f"{'#' * (level + 1)} {cls.__name__}.{name} (property)\n\n" + markdown(doc))
        else:
            text.append(f"{'#' * (level + 1)} {cls.__name__}.{name}\n\n" + code(signature(name, member))
                        + "\n" + markdown(doc))
    return "\n".join(text)


def document_function(qualified: str, func, level: int = 3) -> str:
    return f"{'#' * level} {qualified}\n\n" + code(signature(qualified, func)) + "\n" + markdown(inspect.getdoc(func) or "")


def module_names(module) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items() if not n.startswith("_")
                 and (inspect.isfunction(v) or inspect.isclass(v)) and v.__module__ == module.__name__]
    return list(names)


def document_module(qualified: str, module) -> str:
    text = [f"### {qualified} (module)\n", markdown(inspect.getdoc(module) or "")]
    for name in module_names(module):
        value = getattr(module, name)
        if inspect.isclass(value):
            text.append(document_class(f"{qualified}.{name}", value, level=4))
        elif callable(value):
            text.append(document_function(f"{qualified}.{name}", value, level=4))
        else:
            text.append(f"#### {qualified}.{name}\n\n{constant(value)}\n")
    return "\n".join(text)


def constant(value) -> str:
    if isinstance(value, Mapping):
        kind = "dict" if isinstance(value, dict) else f"mapping ({type(value).__name__})"
        return f"A {kind} with the keys {', '.join(f'`{k}`' for k in value)}."
    return f"`{value!r}`"


def document(qualified: str, obj) -> str:
    if inspect.ismodule(obj):
        return document_module(qualified, obj)
    if inspect.isclass(obj):
        return document_class(qualified, obj)
    if callable(obj):
        return document_function(qualified, obj)
    return f"### {qualified}\n\n{constant(obj)}: " + {
        "GROUND": "the parent index of a subsystem attached to the inertial frame "
                  "(subsystems are numbered in topological order, parent[n] < n).",
    }.get(qualified.split(".")[-1], "a constant.") + "\n"


def page() -> str:
    grouped = [name for _, names in GROUPS for name in names]
    others = tuple(name for name in projeq.__all__ if name not in grouped)
    text = ["# API reference\n",
            "Generated by `python docs/gen_api.py` from the docstrings of everything in "
            "`projeq.__all__` (`import projeq as pq`, then `pq.RigidBody`, `pq.simulate`, ...). "
            "Equation numbers B(n) and K(n) and the short literature keys are explained in "
            "[the theory page](theory.md), whose numbered sections the docstrings cite as "
            "\"docs/theory.md §n\".\n"]
    for title, names in GROUPS + ((("Other names", others),) if others else ()):
        present = [n for n in names if n in projeq.__all__]
        if present:
            text.append(f"## {title}\n")
            if title in INTROS:
                text.append(INTROS[title])
            text += [document(f"projeq.{name}", getattr(projeq, name)) for name in present]
            for module_name, name in MODULES.get(title, ()):
                module = __import__(module_name, fromlist=["_"])
                text.append(document(f"{module_name}.{name}", getattr(module, name)))
    text.append("## Plug-in contracts\n\nSee [the architecture](architecture.md) for how to add a joint, "
                "a subsystem or a force law.\n")
    for module_name, name in CONTRACTS:
        module = __import__(module_name, fromlist=["_"])
        text.append(document(module_name if name is None else f"{module_name}.{name}",
                             module if name is None else getattr(module, name)))
    return "\n".join(text).rstrip() + "\n"


def main():
    TARGET.write_text(page(), encoding="utf-8")
    print(f"wrote {TARGET.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
