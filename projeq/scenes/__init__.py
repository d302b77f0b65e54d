"""Ready-made named systems for scripts, the CLI, tests and docs.

Every scene is a function returning a :class:`projeq.System` with sensible default initial
conditions; its keyword parameters (SI units) are documented in its docstring. ``SCENES``
maps the names the CLI knows to these functions.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import MutableMapping
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from projeq.checks import positives
from projeq.subsystems import inertia
from projeq.joints import Prismatic, Revolute
from projeq.subsystems import PlanarBody, PointMass, RigidBody
from projeq.scenes.elastic import elastic_arm, flexible_arm, rotating_blade, spin_up_beam, spinning_beam
from projeq.scenes.iftomm import andrews_squeezer, bricard, flyball_governor, n_four_bar, simple_pendulum
from projeq.scenes.mechanisms import (bar_on_wall, flexible_four_bar, four_bar, quick_return, slider_pendulum,
                                      sphere_on_sphere)
from projeq.scenes.parameters import Parameter, check_names, closest, parse_settings, scene_parameters
from projeq.system import System


def chain(n: int = 5, planar: bool = False, q0=None) -> System:
    """n identical links hanging from the origin, joined by revolute joints about y.

    Each link: length 1 m, mass 1 kg, a solid cylinder of radius 0.01 m along the link, its
    joint at the upper end and its mass centre in the middle; in q = 0 the links hang
    along −z; gravity 9.81 m/s² along −z; q = relative joint angles (right-hand rule
    about +y). ``planar=True`` builds the same system from planar bodies in the x–z
    plane. Default initial state: first joint at 0.5 rad, the rest 0, at rest.
    """
    if int(n) != n or n < 1:
        raise ValueError(f"n: number of links must be a positive integer, got {n!r}")
    n = int(n)
    I_c = inertia.cylinder(m=1.0, radius=0.01, length=1.0, axis="z")
    link = PlanarBody(1.0, (0.0, 0.0, -0.5), I_c, plane="zx") if planar else RigidBody(1.0, (0.0, 0.0, -0.5), I_c)
    names = [f"link{i + 1}" for i in range(n)]
    joints = {
        name: Revolute(parent=None if i == 0 else names[i - 1], axis="y", r_pn=(0.0, 0.0, 0.0 if i == 0 else -1.0))
        for i, name in enumerate(names)
    }
    if q0 is None:
        q0 = np.zeros(n)
        q0[0] = 0.5
    return System(dict.fromkeys(names, link), joints, gravity=(0.0, 0.0, -9.81), q0=q0)


def double_pendulum(m1: float = 1.0, m2: float = 1.0, l1: float = 1.0, l2: float = 1.0, g: float = 9.81, q0=(np.pi / 2, 0.0)) -> System:
    """Two point masses on massless rods, hinged about y, hanging along −z (Problem 8 of
    the Lagrange problem book). q = (θ₁, θ₂), θ₂ relative to the first rod.
    Default: released from rest with the first rod horizontal."""
    m1, m2, l1, l2 = positives(m1=m1, m2=m2, l1=l1, l2=l2)
    return System(
        {"bob1": PointMass(m1, (0.0, 0.0, -l1)), "bob2": PointMass(m2, (0.0, 0.0, -l2))},
        {"bob1": Revolute(axis="y"), "bob2": Revolute(parent="bob1", axis="y", r_pn=(0.0, 0.0, -l1))},
        gravity=(0.0, 0.0, -g),
        q0=q0,
    )


def atwood(m1: float = 2.0, m2: float = 1.0, pulley_mass: float = 0.5, radius: float = 0.1, g: float = 9.81) -> System:
    """Atwood machine: masses m1 (at x = −radius) and m2 (x = +radius) on a rope over a
    pulley (a uniform disk about y at the origin, inertia ½ pulley_mass radius²).

    One minimal coordinate: the pulley angle θ about +y. The rope does not slip, so mass 1
    rises by radius·θ and mass 2 sinks by radius·θ: their prismatic joints are *coupled*
    to the pulley (shared minimal velocity, evaluated by the dense Gauss form).
    Reference: ẍ₁ = (m1 − m2) g / (m1 + m2 + I/a²) downwards for mass 1 (Problem 1).
    """
    m1, m2, pulley_mass, a = positives(m1=m1, m2=m2, pulley_mass=pulley_mass, radius=radius)
    return System(
        {
            "pulley": RigidBody(pulley_mass, I_c=inertia.disk(pulley_mass, a, axis="y")),
            "mass1": PointMass(m1),
            "mass2": PointMass(m2),
        },
        {
            "pulley": Revolute(axis="y"),
            "mass1": Prismatic(axis="z", r_pn=(-a, 0.0, -1.0), coupling={"pulley": a}),
            "mass2": Prismatic(axis="z", r_pn=(a, 0.0, -1.0), coupling={"pulley": -a}),
        },
        gravity=(0.0, 0.0, -g),
    )


class Scene(NamedTuple):
    """A named scene: how to build it, what it is, how long to run it (s).

    ``units`` maps parameter names to SI units where they differ from or are missing in
    :data:`projeq.scenes.parameters.UNITS`; ``plane`` = the indices (i, j) of q that are a
    position in the ground plane, for a trajectory plot; ``events`` = terminal events
    ``event(t, q, s_dot)`` that end a run for a physical reason, each with a ``description``
    (``projeq run`` passes them to ``simulate`` and says which one stopped the run);
    ``settings`` = keywords of :func:`projeq.simulate` (integrator, tolerances) that
    ``projeq run`` and ``projeq sweep`` use for this scene unless told otherwise, where
    ``simulate``'s own defaults would be slow for the accuracy the scene needs (each
    documented with its measured accuracy, as :data:`SPIN_UP_SETTINGS`).
    Registering a scene is one entry in ``SCENES``.
    """

    build: Callable[..., System]
    description: str
    t_end: float
    units: dict | None = None
    plane: tuple | None = None
    events: tuple = ()
    settings: dict | None = None


#: the scenes whose modules import sympy (their joints are derived symbolically, as
#: :meth:`projeq.UserJoint.from_sympy`) or scipy.optimize: imported on first use, so that
#: ``projeq run`` of another scene does not pay for them
_SYMBOLIC = dict.fromkeys(("car", "knife_edge_disc", "knife_edge_circle", "rolling_disk", "rolling_disk_critical_speed",
                           "rolling_disk_inertia", "barhorst_particle", "nonholonomic_particle"),
                          "projeq.scenes.nonholonomic") | dict.fromkeys(
    ("fallen_over", "whipple_bicycle", "whipple_eigenvalues"), "projeq.scenes.bicycle")


def _symbolic(name: str):
    """The function ``name`` of the module :data:`_SYMBOLIC` names, imported now."""
    return getattr(importlib.import_module(_SYMBOLIC[name]), name)


def __getattr__(name: str):
    if name in _SYMBOLIC:
        return _symbolic(name)
    raise AttributeError(f"module 'projeq.scenes' has no attribute {name!r}")


class _Later(NamedTuple):
    """A registered scene made on first use (:class:`Registry`)."""

    make: Callable[[], Scene]


class Registry(MutableMapping):
    """name → :class:`Scene`, in the order registered (``SCENES[name] = Scene(...)`` registers
    one); an entry given as :class:`_Later` is made when first looked up (and kept), so that
    listing the names imports nothing."""

    def __init__(self, entries: dict) -> None:
        self._entries = dict(entries)

    def __getitem__(self, name: str) -> Scene:
        entry = self._entries[name]
        if isinstance(entry, _Later):
            entry = self._entries[name] = entry.make()
        return entry

    def __setitem__(self, name: str, scene: Scene) -> None:
        self._entries[name] = scene

    def __delitem__(self, name: str) -> None:
        del self._entries[name]

    def __iter__(self):
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)


#: the spin-up beam's integrator for ``projeq run``: its elastic modes are stiff (an explicit
#: method crawls at its stability limit: RK45 at simulate's rtol 1e-8 needs about 45,000 evaluations
#: over the 20 s, Radau at rtol 1e-4 2,500), and at rtol 1e-4 the tip deflection at 5, 10, 15,
#: 20 s is within 4.2e-5 m of the converged reference of benchmarks/beam_convergence.py (8
#: clamped–free functions per plane, DOP853 at rtol 1e-10), the same as RK45 at 1e-8 or DOP853
#: at 1e-9 (all 4.2e-5 m: the error of the scene's 4 polynomial functions, not the integrator's)
SPIN_UP_SETTINGS = {"method": "Radau", "rtol": 1e-4, "atol": 1e-6}

SCENES = Registry({
    "spin_up_beam": Scene(spin_up_beam, "a cantilever spun up to Ωs = 6 rad/s, with dynamic stiffening", 20.0,
                          settings=SPIN_UP_SETTINGS),
    "spinning_beam": Scene(spinning_beam, "a cantilever spinning about its own axis (B(16)-(23))", 10.0),
    "rotating_blade": Scene(rotating_blade, "a cantilever blade on a hub turning about a transverse axis "
                            "(flapwise stiffening, lead-lag softening)", 10.0),
    "elastic_arm": Scene(elastic_arm, "rigid link + elastic link with a tip mass, turning freely", 5.0),
    "chain": Scene(chain, "n links on revolute joints hanging from the origin (default n = 5)", 10.0),
    "double_pendulum": Scene(double_pendulum, "two point masses on massless rods, released horizontally", 10.0),
    "atwood": Scene(atwood, "two masses on a rope over a pulley with inertia (coupled joints)", 2.0),
    "car": _Later(lambda: Scene(_symbolic("car"), "Bremer's car: a planar body whose rear axle cannot slide (B(5)-(12))",
                                10.0, plane=(0, 1))),
    "knife_edge_disc": _Later(lambda: Scene(_symbolic("knife_edge_disc"), "a knife-edge disc rolling without slip "
                                            "(Orsino (2020), slides 28-37)", 20.0, plane=(0, 1))),
    "rolling_disk": _Later(lambda: Scene(_symbolic("rolling_disk"), "Barhorst's rolling disk with an eccentric mass "
                                         "(Barhorst §3.2)", 10.0, units={"inertia": "(or 'hoop', or (I, J) in kg m²)"},
                                         plane=(3, 4))),
    "barhorst_particle": _Later(lambda: Scene(_symbolic("barhorst_particle"), "a particle with the constraint "
                                              "y' - y^2 x' = 0 (Barhorst §3.1)", 10.0)),
    "nonholonomic_particle": _Later(lambda: Scene(_symbolic("nonholonomic_particle"), "a particle in space with "
                                                  "y' + z x' = 0 (Barhorst §3.1)", 2.0)),
    "whipple_bicycle": _Later(lambda: Scene(_symbolic("whipple_bicycle"), "the Whipple bicycle of Meijaard et al. "
                                            "(2007), constraint equations", 5.0, plane=(0, 1),
                                            events=(_symbolic("fallen_over"),))),
    "quick_return": Scene(quick_return, "Barhorst's quick-return mechanism, a closed loop (Barhorst §3.3)", 5.0),
    "four_bar": Scene(four_bar, "a four-bar linkage closed by a constraint equation", 5.0),
    "simple_pendulum": Scene(simple_pendulum, "IFToMM benchmark A01: a pendulum in natural coordinates",
                             10.0),
    "n_four_bar": Scene(n_four_bar, "IFToMM benchmark A02: n four-bars in a row, through singular positions",
                        20.0),
    "bricard": Scene(bricard, "IFToMM benchmark A04: Bricard's overconstrained mechanism (a redundant row)",
                     10.0),
    "andrews_squeezer": Scene(andrews_squeezer, "IFToMM benchmark A03: Andrews' squeezing mechanism, seven bodies "
                              "in one loop (Hairer & Wanner 1996, §VII.7)", 0.05),
    "flyball_governor": Scene(flyball_governor, "IFToMM benchmark A05: the stiff flyball governor, coupler rods "
                              "replaced by stiff spring-dampers", 10.0,
                              units={"K": "N/m", "C": "N s/m", "s0": "m", "alpha0": "rad"}),
})
DEFAULT_SCENE = "spin_up_beam"


def get_scene(name: str) -> Scene:
    """The registered scene ``name``; ValueError listing the scenes and the closest name."""
    if name not in SCENES:
        raise ValueError(f"scene: unknown scene {name!r}{closest(name, SCENES)}; known scenes: {', '.join(SCENES)}")
    return SCENES[name]


def resolve_scene(text: str) -> Scene:
    """The scene ``text`` names: a registered scene (:func:`get_scene`), or ``FILE.py:FUNCTION``,
    a function in the user's file returning a System or ConstrainedSystem, whose keyword
    parameters (with defaults) are the scene's parameters, its docstring's first line the
    description and its attribute ``t_end`` (default 10) the end time in s. ValueError
    naming what is missing."""
    path, sep, function = text.rpartition(":")
    if not sep or not path.endswith(".py"):
        return get_scene(text)
    module = _load_file(Path(path))
    build = getattr(module, function, None)
    if not callable(build):
        found = [n for n, f in vars(module).items() if callable(f) and getattr(f, "__module__", None) == module.__name__]
        raise ValueError(f"scene: {path} has no function {function!r}; its functions: {', '.join(found) or 'none'}")
    description = (build.__doc__ or f"{function} from {path}").strip().splitlines()[0]
    return Scene(build, description, float(getattr(build, "t_end", 10.0)))


def _load_file(path: Path):
    """The module of the Python file ``path``, loaded once (registered in sys.modules under
    a name of its own, so that worker processes and pickles find its functions)."""
    if not path.is_file():
        raise ValueError(f"scene: no file {str(path)!r}")
    name = "projeq_user_scene_" + "".join(c if c.isalnum() else "_" for c in str(path.resolve()))
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except (SyntaxError, ImportError) as exc:  # the file cannot be read as Python: a bad argument
            del sys.modules[name]
            raise ValueError(f"scene: {path} cannot be imported: {_import_error(exc)}") from None
        except Exception:
            del sys.modules[name]
            raise
    return sys.modules[name]


def _import_error(exc: SyntaxError | ImportError) -> str:
    """What is wrong with a file that cannot be imported: the line of a syntax error, the
    module missing, in one line."""
    if isinstance(exc, SyntaxError):
        return f"{type(exc).__name__} at line {exc.lineno}: {exc.msg}: {(exc.text or '').strip()!r}"
    return f"{type(exc).__name__}: {exc}"


def build_scene(name: str, **overrides) -> System:
    """Build the registered scene ``name`` with parameters overridden by keyword.

    >>> build_scene("chain", n=2).n_q
    2
    """
    scene = get_scene(name)
    check_names(scene, overrides)
    return scene.build(**overrides)

__all__ = [
    "chain", "double_pendulum", "atwood", "spin_up_beam", "spinning_beam", "rotating_blade", "elastic_arm", "flexible_arm",
    "car", "knife_edge_disc", "knife_edge_circle", "rolling_disk", "rolling_disk_critical_speed", "rolling_disk_inertia",
    "barhorst_particle", "nonholonomic_particle", "whipple_bicycle", "whipple_eigenvalues",
    "quick_return", "four_bar", "flexible_four_bar", "sphere_on_sphere", "bar_on_wall", "slider_pendulum",
    "simple_pendulum", "n_four_bar", "bricard", "andrews_squeezer", "flyball_governor",
    "Scene", "SCENES", "DEFAULT_SCENE", "get_scene", "resolve_scene", "build_scene", "scene_parameters", "parse_settings", "Parameter",
]
