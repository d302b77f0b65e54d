"""The API reference (issue 19, item 2): docs/api.md is what docs/gen_api.py writes from the
current docstrings, documents every name of projeq.__all__ with its signature, and reads as
plain Markdown (no Sphinx roles, no double backticks outside code blocks)."""
import importlib.util
import re
from pathlib import Path

import projeq

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "api.md"


def generator():
    spec = importlib.util.spec_from_file_location("gen_api", ROOT / "docs" / "gen_api.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def prose(text):
    """The page without its fenced code blocks."""
    return re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)


def test_api_md_is_up_to_date():
    assert API.read_text(encoding="utf-8") == generator().page(), \
        "docs/api.md is stale: run `python docs/gen_api.py`"


def test_every_public_name_has_a_heading_and_a_signature():
    text = API.read_text(encoding="utf-8")
    missing = [name for name in projeq.__all__ if not re.search(rf"^### projeq\.{name}\b", text, re.M)]
    assert missing == []
    for name in ("simulate", "RigidBody", "Revolute", "RitzBeam", "UserJoint", "ConstrainedSystem"):
        section = text.split(f"### projeq.{name}\n", 1)[1]
        assert section.lstrip().startswith(f"```python\nprojeq.{name}("), name


def test_user_methods_are_documented_once_and_internal_ones_named_only():
    """A class documents its own user methods; a method implementing a documented base class's
    (Revolute.relative: Joint's) and the evaluators' methods (System.evaluator) are named in a
    line, without a heading; write_vtu_series and Visual (submodules) have their headings."""
    text = API.read_text(encoding="utf-8")
    assert re.search(r"^#### System\.mass_matrix$", text, re.M)
    assert re.search(r"^#### Joint\.relative$", text, re.M)
    internal = ("System.evaluator", "System.joint_q_getter", "ConstrainedSystem.compiled_kernel")
    for heading in ("Revolute.relative",) + internal:
        assert not re.search(rf"^#### {re.escape(heading)}\b", text, re.M), heading
    revolute = text.split("### projeq.Revolute\n")[1].split("###")[0]
    assert "Implements `coordinates`, `velocities`, `relative`" in revolute
    assert "`evaluator`" in text.split("### projeq.System\n")[1].split("\n### ")[0]
    assert re.search(r"^### projeq\.simulation\.export\.write_vtu_series$", text, re.M)
    assert re.search(r"^### projeq\.subsystems\.Visual$", text, re.M)


def test_docstrings_are_rendered_as_plain_markdown():
    text = prose(API.read_text(encoding="utf-8"))
    assert not re.search(r":(mod|class|func|meth|attr|data|obj|exc):`", text)
    assert "``" not in text
    assert not re.search(r"^-{3,}$", text, re.M)  # numpydoc underlines became bold titles


def test_the_renderer_turns_numpydoc_into_markdown():
    """The conversion on a small docstring, so that a broken renderer fails here too."""
    doc = ("Summary with :class:`projeq.System` and ``code``.\n\nParameters\n----------\n"
           "m : float\n    Mass in kg.\n\nExamples\n--------\n>>> 1 + 1\n2\n")
    assert generator().markdown(doc) == (
        "Summary with `projeq.System` and `code`.\n\n**Parameters**\n\n- `m` (float): Mass in kg.\n\n"
        "**Examples**\n\n```python\n>>> 1 + 1\n2\n```\n")
