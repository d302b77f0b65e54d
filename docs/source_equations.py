"""The source documents' numbered equations and worked examples, each with the code and tests that cite it.

Used by ``docs/gen_validation.py`` (the section "Source documents, equation by equation" of
docs/validation.md). The rows are found, not written: every function docstring of projeq/ (code) and
of tests/ (tests) is searched for the citation forms of each document —

* H. Bremer, "Problems in fast moving non-holonomic elastic systems": ``B(n)``, ``B(n)–(m)``;
* the lecture on non-holonomic systems and Lagrange multipliers (Orsino 2020): ``K(n)``;
* A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems": ``eq. n``, ``eqs. n–m``
  in a file or docstring that names Barhorst;
* "On derivation of motion equations for systems with non-holonomic high-order program constraints":
  ``(4.2)``, ``(6.30)–(6.33)`` in a file about program constraints;
* the problem seminars on Lagrange's equations: ``Problem n``, ``Seminar n`` (their equation numbers
  restart with each problem, so the worked problems are the rows; the lecture notes I–VII by section) —

and an equation no docstring cites carries a stated reason (:data:`REASONS`).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

DOCUMENTS = {
    "bremer": 'H. Bremer, "Problems in fast moving non-holonomic elastic systems"',
    "lecture": "lecture on non-holonomic systems and Lagrange multipliers (Orsino 2020)",
    "barhorst": 'A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems"',
    "program": '"On derivation of motion equations for systems with non-holonomic high-order program constraints"',
    "problems": "problem seminars on Lagrange's equations (worked problems)",
}
_DASH = r"\s*[–-]\s*"
PATTERNS = {
    "bremer": re.compile(rf"B\((\d+)\)(?:{_DASH}\(?(\d+)\))?"),
    "lecture": re.compile(rf"K\((\d+)\)(?:{_DASH}\(?(\d+)\))?"),
    "barhorst": re.compile(rf"\beqs?\.\s*\(?(\d+)\)?(?:{_DASH}\(?(\d+)\)?)?"),
    "program": re.compile(rf"(?:\(|eqs?\.\s*)(\d\.\d+a?)\)?(?:{_DASH}\(?(\d\.\d+a?)\)?)?"),
    "problems": re.compile(r"((?:Problem|Seminar) \d+)"),
}
#: Only docstrings in this context cite the document with its (otherwise ambiguous) pattern.
CONTEXT = {"barhorst": "barhorst", "program": "program"}

#: Why an equation has no code or test of its own, by document and equation (ranges "a–b" allowed).
REASONS = {
    "bremer": {
        "1": "the virtual work of the mass elements, the start of the Central Equation B(2): "
             "projeq.symbolic.central_equation (tests/symbolic/test_central.py derives B(8), B(9), B(12) from it)",
        "13": "the subsystem form with F and T: the assembly of every System (tests/subsystems/test_user_subsystem.py, "
              "tests/assembly/test_overrides.py)",
        "19": "the slice velocities of B(19) enter B(23) (tests/symbolic/test_spinning_beam.py)",
        "24": "the Ritz shape functions: RitzBeam's families (tests/subsystems/test_beam.py)",
        "25": "the Ritz integrals of the elastic subsystem: RitzBeam (tests/subsystems/test_beam_integrals.py)",
    },
    "lecture": {
        "1–6": "Pfaffian constraints and virtual displacements: definitions used by multiplier_system",
        "8–22": "the knife-edge disc's kinematics, constraints and T: derived by lecture_disc "
                "(tests/symbolic/test_lagrange.py, the explicit equations)",
        "24–26": "Hamilton's function and canonical equations with multipliers: MultiplierSystem.hamiltonian, "
                 "canonical_equations (tests/symbolic/test_lagrange.py)",
    },
    "barhorst": {
        "0–6": "Hamilton's principle, Lagrange's equations and Pfaffian constraints: restated definitions "
               "(docs/theory.md §11)",
        "7": "Hamilton's canonical equations with multipliers: MultiplierSystem.hamilton_dae "
             "(tests/symbolic/test_barhorst_study.py::test_hamilton_dae_particle_follows_the_integral_curve)",
        "8–14": "general speeds and constraint elimination: lagrangian_canonical(speeds=…) "
                "(tests/symbolic/test_barhorst_study.py)",
        "15–16": "Kane's form with dependent speeds = B(10): projection_equation (tests/nonholonomic/"
                 "test_barhorst_particles.py::test_planar_particle_equals_barhorsts_projective_equation)",
        "17–27": "the projective form's partial velocities and their derivation steps: projective_canonical",
        "28–37": "the projective canonical form: projective_canonical "
                 "(tests/symbolic/test_canonical.py::test_both_momenta_are_dT_du_and_agree_at_random_states)",
        "38–44": "the energy condition and its derivation: energy_rate (tests/symbolic/test_barhorst_study.py)",
        "53–69": "the particle's and the energy's intermediate steps: barhorst_particle",
        "70–72": "the particle with u = ẏ: tests/nonholonomic/test_barhorst_particles.py::"
                 "test_planar_particle_equals_barhorsts_projective_equation",
        "73–78": "the particle's projective momenta, intermediate steps of eqs. 79–80",
        "79–80": "the particle's projective canonical equations: tests/studies/test_compare_barhorst.py::"
                 "test_compare_barhorst_particle_four_formulations_agree",
        "81–85": "the particle's Lagrangian canonical steps, ending in eqs. 86–87",
        "86–87": "the particle's Lagrangian canonical equations: tests/studies/test_compare_barhorst.py::"
                 "test_compare_barhorst_particle_four_formulations_agree",
        "88–92": "the rolling disk's kinematics: rolling_disk, disk_kinematics",
        "94–108": "the rolling disk's and quick return's intermediate steps: barhorst_examples",
        "109": "the quick return's q̇ = K̄ q̇1: tests/studies/test_compare_barhorst.py::test_compare_quick_return",
        "110–111": "the quick return's T and V: quick_return",
        "112": "the quick return's Lagrangian canonical form: tests/studies/test_compare_barhorst.py::"
               "test_compare_quick_return",
        "113–116": "the quick return's Lagrangian canonical steps, ending in eqs. 112–116's ṗ",
    },
    "program": {
        "1": "the constraint classification: definitions",
        "1.1": "constraint classes and their orders: definitions (docs/theory.md)",
        "2": "constraint classes and their orders: definitions (docs/theory.md)",
        "2.1–2.2": "the high-order constraint and its linear form: program_motion_equations checks linearity",
        "2.2a": "the high-order constraint and its linear form: program_motion_equations checks linearity",
        "3.1–3.2": "the virtual displacements of a program constraint: definitions used by program_motion_equations",
        "3.1a": "the virtual displacements of a program constraint: definitions used by program_motion_equations",
        "4.3a": "the precession's rate equation, solved in pseudo_regular_precession",
        "5.3–5.9": "the Nielsen and Tzenoff operators' steps: nielsen_equations, tzenoff_equations",
        "6.1–6.29": "the GPME derivation steps, ending in (6.30)–(6.33): program_motion_equations",
        "6.31–6.32": "the GPME (6.30)–(6.33): tests/symbolic/test_program.py (the curvature example, (6.34a))",
        "6.34": "the example's result, with (6.34a) (tests/symbolic/test_program.py)",
    },
    "problems": {
        "Seminar 1": "Problems 1–4 (their rows)",
        "Seminar 2": "Problems 7–8, pendulums (their rows)",
        "Seminar 3": "Problems 10–12 (their rows)",
        "Seminar 4": "Problems 14–17: not reproduced — the charged particle's velocity-dependent potential "
                     "q(φ − v·A) is outside projeq's force laws (Problem 41's magnetic Hamiltonian is checked)",
        "Problem 14": "see Seminar 4",
        "Problem 15": "see Seminar 4",
        "Problem 16": "see Seminar 4",
        "Problem 17": "the isotropic 3-D oscillator: its invariants are Problem 44's test; the eigenfrequencies "
                      "not separately (see Seminar 4)",
        "Problem 23": "the coupled oscillators of Seminar 6 (its row)",
        "Seminar 7": "Problems 26–27: not reproduced — projeq has no central-force scene (1/r², 1/r³ orbits)",
        "Problem 26": "see Seminar 7",
        "Problem 27": "see Seminar 7",
        "Seminar 10": "Problems 40–41 (their rows)",
        "Seminar 11": "Problems 43–44 (their rows)",
        "Notes I": "the variational approach: Hamilton's principle, hamilton_field_equations "
                   "(tests/symbolic/test_spinning_beam.py::test_hamilton_reproduces_B18)",
        "Notes II": "Lagrange's equations: the rows of Problems 1–12 and lagrange_steps (tests/studies/test_effort_growth.py)",
        "Notes III": "small oscillations: projeq.linearize (tests/analysis/test_linearize.py) and Seminar 6's row",
        "Notes IV": "the central-force problem: not reproduced (see Seminar 7)",
        "Notes V": "the Hamiltonian formulation: MultiplierSystem.hamiltonian, canonical_equations "
                   "(tests/symbolic/test_lagrange.py::test_disc_hamiltonian_and_canonical_equations_match_the_lecture)",
        "Notes VI": "canonical transformations, action-angle variables: canonical_transformation "
                    "(tests/symbolic/test_canonical_transformations.py)",
        "Notes VII": "Hamilton–Jacobi theory, S = W − E t: separate_hamilton_jacobi, principal_function "
                     "(tests/symbolic/test_hamiltonian.py)",
    },
}


def _numbers(first: str, last: str | None) -> list[str]:
    """The equation numbers ``first``…``last`` (integers, or n.k within one n; a suffix letter only alone)."""
    if not last:
        return [first]
    if first.isdigit() and last.isdigit() and int(first) <= int(last):
        return [str(k) for k in range(int(first), int(last) + 1)]
    head, _, a = first.partition(".")
    head2, _, b = last.partition(".")
    if head == head2 and a.isdigit() and b.isdigit() and int(a) <= int(b):
        return [f"{head}.{k}" for k in range(int(a), int(b) + 1)]
    return [first, last]


def _docstrings(folder: str):
    """(file path, name, docstring) of every module (name ``test_module`` for a test file, ``module``
    otherwise: a test module's docstring states what all its tests check), function and class."""
    for path in sorted((ROOT / folder).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        module = "test_module" if path.name.startswith("test_") else "module"
        for node in [tree, *ast.walk(tree)]:
            if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                doc = ast.get_docstring(node)
                if doc:
                    yield path.relative_to(ROOT).as_posix(), getattr(node, "name", module), doc


def citations() -> dict:
    """{document: {equation: {"code": [...], "tests": [...]}}} from the docstrings of projeq/ and tests/."""
    found = {name: {} for name in DOCUMENTS}
    for folder, kind in (("projeq", "code"), ("tests", "tests")):
        for path, name, doc in _docstrings(folder):
            if kind == "tests" and not name.startswith("test"):
                continue
            for document, pattern in PATTERNS.items():
                context = CONTEXT.get(document)
                if context and context not in path.lower() and context not in doc.lower():
                    continue
                for match in pattern.finditer(doc):
                    for number in _numbers(*match.groups()) if document != "problems" else [match.group(1)]:
                        entry = found[document].setdefault(number, {"code": [], "tests": []})
                        where = path if name.endswith("module") else f"{path}::{name}"
                        if where not in entry[kind]:
                            entry[kind].append(where)
    return found


def reason(document: str, number: str) -> str | None:
    """The stated reason of :data:`REASONS` that covers ``number``, if any."""
    for span, text in REASONS[document].items():
        if number in _numbers(*(span.split("–") + [None])[:2]):
            return text
    return None


def _natural(number: str):
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", number)]


def rows() -> list[str]:
    """Markdown rows ``| document | equation | code | tests or reason |``: every equation a docstring cites
    or :data:`REASONS` states a reason for, in the order of the documents and their numbering."""
    found = citations()
    lines = []
    for document in DOCUMENTS:
        stated = {n for span in REASONS[document] for n in _numbers(*(span.split("–") + [None])[:2])}
        for number in sorted(set(found[document]) | stated, key=_natural):
            entry = found[document].get(number, {"code": [], "tests": []})
            code = ", ".join(f"`{c}`" for c in entry["code"][:2]) or "—"
            tests = ", ".join(f"`{c}`" for c in entry["tests"][:2])
            why = (tests or reason(document, number)
                   or "no test cites it" + (" (code only)" if entry["code"] else ""))
            lines.append(f"| {DOCUMENTS[document]} | {number} | {code} | {why} |")
    return lines
