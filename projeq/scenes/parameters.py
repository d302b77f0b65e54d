"""Scene parameters as data: names, defaults and units, overridable by name.

A scene's parameters are its build function's keyword arguments; their defaults come from
the signature, their units from :data:`UNITS` (SI; a scene may override entries) and their
descriptions from the numpydoc ``Parameters`` section of its docstring (else :data:`DESCRIPTIONS`).
``--set name=value`` strings are parsed against the type of the default.

>>> from projeq.scenes import SCENES
>>> print(scene_parameters(SCENES["atwood"])[0])
m1 = 2.0 kg
>>> parse_value(SCENES["atwood"], "m1", "3")
3.0
"""

from __future__ import annotations

import ast
import inspect
from typing import NamedTuple

from projeq.checks import closest

#: SI unit of each parameter name used by the built-in scenes ("-": dimensionless or a count).
UNITS = {
    "m": "kg", "m1": "kg", "m2": "kg", "m_disk": "kg", "m_ecc": "kg", "pulley_mass": "kg", "tip_mass": "kg",
    "l1": "m", "l2": "m", "length": "m", "radius": "m", "r": "m", "R": "m", "ecc": "m", "c": "m",
    "g": "m/s²", "gravity": "m/s²",
    "I": "kg m²", "J": "kg m²", "C0": "kg m²",
    "EI": "N m²", "EA": "N", "rho_A": "kg/m", "rho_I": "kg m",
    "omega": "rad/s", "omega_s": "rad/s", "omega0": "rad/s", "t_s": "s",
    "f_x": "N", "f_y": "N", "M_z": "N m", "drag": "N m s²",
    "q0": "rad or m (per coordinate)", "s_dot0": "rad/s or m/s (per velocity)",
    "q_dot0": "rad/s or m/s (per coordinate)",
    "n": "-", "n_shapes": "-", "n_axial": "-", "family": "-", "stiffening": "-", "planar": "-",
    "precomputed_integrals": "-", "params": "- (see the scene's docstring)",
    "a": "m", "b": "m", "d": "m", "l": "m", "A": "m", "H": "m", "m_a": "kg", "m_b": "kg",
    "theta0": "rad", "theta1": "rad", "roll": "rad", "steer": "rad",
    "omega1": "rad/s", "roll_rate": "rad/s", "steer_rate": "rad/s", "speed": "m/s",
    "L": "m", "side": "m", "hub_radius": "m",
}


#: What a parameter common to many scenes is, where the scene's docstring does not say.
DESCRIPTIONS = {
    "g": "gravitational acceleration", "gravity": "gravitational acceleration",
    "q0": "initial coordinates q", "s_dot0": "initial minimal velocities ṡ",
    "q_dot0": "initial coordinate rates q̇", "n_shapes": "shape functions per bending plane",
}


class Parameter(NamedTuple):
    """One keyword parameter of a scene: its name, default value, SI unit and what it is."""

    name: str
    default: object
    unit: str
    description: str = ""

    def __str__(self) -> str:
        unit = "" if self.unit == "-" else f" {self.unit}"
        return f"{self.name} = {self.default!r}{unit}"


def scene_parameters(scene) -> list[Parameter]:
    """The keyword parameters of ``scene.build`` with defaults, units and descriptions."""
    units = {**UNITS, **(scene.units or {})}
    described = DESCRIPTIONS | documented(scene.build)
    return [
        Parameter(p.name, p.default, units.get(p.name, "-"), described.get(p.name, ""))
        for p in inspect.signature(scene.build).parameters.values()
        if p.default is not inspect.Parameter.empty
    ]


def documented(function) -> dict[str, str]:
    """{name: description} from the numpydoc ``Parameters`` section of ``function``'s docstring
    (an entry ``a, b : type`` describes each name; its indented lines joined)."""
    lines = (inspect.getdoc(function) or "").splitlines()
    if "Parameters" not in lines or lines.index("Parameters") + 1 >= len(lines):
        return {}
    found, names = {}, []
    body = lines[lines.index("Parameters") + 2:]
    for k, line in enumerate(body):
        if line and not line.startswith(" "):
            if body[k + 1: k + 2] and body[k + 1].strip() and not body[k + 1].strip("-"):
                break  # the next section's title, underlined
            names = [name.strip() for name in line.split(" : ")[0].split(",")]
            found.update(dict.fromkeys(names, ""))
        elif line.strip():
            found.update({name: (found[name] + " " + line.strip()).strip() for name in names})
    return found


def check_names(scene, overrides: dict) -> None:
    """ValueError naming an unknown parameter, the valid ones and the closest match."""
    known = [p.name for p in scene_parameters(scene)]
    for name in overrides:
        if name not in known:
            raise ValueError(
                f"{name}: unknown parameter{closest(name, known)}; valid parameters: {', '.join(known)}"
            )


def _as_bool(name: str, text: str) -> bool:
    words = {"true": True, "1": True, "yes": True, "on": True, "false": False, "0": False, "no": False, "off": False}
    if text.strip().lower() not in words:
        raise ValueError(f"{name}: expected a bool (true/false), got {text!r}")
    return words[text.strip().lower()]


def parse_value(scene, name: str, text: str):
    """The value of ``name=text`` for ``scene``, of the type of the parameter's default.

    bool: true/false/yes/no/1/0; int and float: a number; str: the text, or a tuple when the
    text is a tuple literal (for parameters that take a name or numbers, such as the rolling
    disk's ``inertia=hoop`` or ``inertia=(2e-6,4e-6)``); a tuple or None default: a Python
    literal (``0.1,0.2`` or ``(0.1, 0.2)`` or ``None``).
    """
    check_names(scene, {name: text})
    default = {p.name: p.default for p in scene_parameters(scene)}[name]
    kinds = {bool: ("a bool", lambda s: _as_bool(name, s)), int: ("an integer", int), float: ("a number", float)}
    if type(default) in kinds:
        expected, convert = kinds[type(default)]
        try:
            return convert(text)
        except ValueError:
            raise ValueError(f"{name}: expected {expected}, got {text!r}") from None
    if isinstance(default, str):
        try:
            value = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            return text
        return tuple(value) if isinstance(value, (list, tuple)) else text
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError):
        raise ValueError(f"{name}: expected a number, a tuple of numbers or None, got {text!r}") from None
    return tuple(value) if isinstance(value, list) else value


def parse_settings(scene, settings) -> dict:
    """``{"m": 2.0}`` from ``["m=2.0"]``; ValueError naming a malformed setting or a name set
    twice (which of the two values was meant, the command line does not say)."""
    overrides, given = {}, {}
    for setting in settings or ():
        name, sep, text = setting.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(f"--set: expected name=value, got {setting!r}")
        if name in given:
            raise ValueError(f"--set: {name} is set twice ({given[name]!r} and {setting!r}); set it once")
        given[name] = setting
        overrides[name] = parse_value(scene, name, text.strip())
    return overrides
