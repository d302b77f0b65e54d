"""The subsystem contract: one term of the sum in B(14).

A subsystem n has describing velocities ẏ_n and contributes M_n ÿ_n + G_n ẏ_n − Q_n to
the Projection Equation. :class:`Subsystem` lists every member that an evaluator, the
command line or the exporter uses; the optional ones have defaults there, and what a
subsystem can do (carry joints at stations, deform) is an attribute set once, when its
class is defined, never probed during evaluation. So a new kind of subsystem (an elastic
beam, a user-defined one) plugs in by subclassing :class:`Subsystem` without changing the
evaluators.

Letters in this module: ``M`` is the subsystem mass matrix (never a torque), ``h`` is
h_n = Q_n − G_n ẏ_n.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MethodType

import numpy as np
from numpy.typing import NDArray

from projeq.checks import drop_inherited_twins

REQUIRED = ("n_y", "gauss_terms", "kinetic_energy", "potential_energy")  # no default
DEFAULTS = ("S", "n_e", "rigid_inertia", "elastic_terms", "port_at", "coordinates", "out_of_range")  # optional members with a default
_ABSENT = object()
DERIVED = ("rigid_inertia", "elastic_terms")  # derived from gauss_terms: reset where it is restated
CAPABILITIES = {"has_ports": ("port",), "deforms": ("centre_line", "deflection")}  # flag: its methods


class Subsystem:
    """Something that moves: the Gauss-form terms of one subsystem (B(13)–(14)).

    Required: ``n_y``, :meth:`gauss_terms`, :meth:`kinetic_energy`, :meth:`potential_energy`.

    Attributes
    ----------
    n_y : int
        Number of describing velocities ẏ_n.
    S : ndarray of shape (n_y, 6), or None (default)
        Selection of ẏ_n from the twist (v_O, ω) of the subsystem's reference frame R_n,
        ẏ_n = S · twist + [0; ṡ_e] (``None`` means ẏ_n *is* the twist). Joints act through
        it: F_n = [S F⁶, [0; E]], T_np = S T⁶_np Sₚᵀ (docs/theory.md §4). Planar bodies select
        three rows; a subsystem with internal coordinates has zero rows for them.
    n_e : int (default 0)
        Internal coordinates q_e (elastic coordinates of a beam, an absorber's travel),
        owned by the subsystem, with minimal velocities ṡ_e = q̇_e: the last n_e entries
        of ẏ_n. They follow the joint's coordinates in q and ṡ.
    rigid_inertia : (m, r_c, I_c) or None (default)
        Set when :meth:`gauss_terms` are the rigid-body terms of B(13) (the formula table of
        docs/theory.md) of this mass, mass centre and inertia tensor, selected by ``S``: then
        the evaluators may compute them in batches, compiled or in sympy from these three.
    has_ports : bool
        The class implements :meth:`port`: joints of children sit at stations of this
        deforming subsystem (set when the class is defined).
    deforms : bool
        The class implements :meth:`centre_line` and :meth:`deflection` of a deforming
        centre line of length ``length`` (export, command line; set when the class is defined).
    length : float
        (``deforms``) Length of the centre line, in m.
    visuals : tuple of Visual (default empty)
        Solids that draw the subsystem in the viewer (``Result.animate``, ``projeq view``), in
        its reference frame; :func:`projeq.from_urdf` sets a link's URDF primitives here. Empty:
        a rigid body is drawn as the solid of its inertia. Drawing only: the equations of
        motion never read it.

    Overrides are never bypassed: the members derived from :meth:`gauss_terms`
    (``rigid_inertia``, :meth:`elastic_terms`) are stated for the class that defines them;
    a subclass that restates ``gauss_terms`` gets the defaults back (no rigid_inertia,
    elastic_terms as rows of its gauss_terms) unless it restates them too.
    """

    n_y: int
    S: NDArray | None = None
    n_e: int = 0
    rigid_inertia: tuple | None = None
    has_ports: bool = False
    deforms: bool = False
    length: float
    visuals: tuple = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        drop_inherited_twins(cls, Subsystem, ("gauss_terms",), DERIVED)
        for flag, methods in CAPABILITIES.items():
            setattr(cls, flag, all(getattr(cls, m) is not getattr(Subsystem, m) for m in methods))

    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """Return (M_n, h_n), h_n = Q_n − G_n ẏ_n with gravity included in Q_n.

        ``R`` rotates the reference frame's coordinates into inertial ones; ``gravity`` is
        the gravitational acceleration in inertial coordinates; ``q_e`` the internal
        coordinates (empty for rigid bodies).
        """
        raise NotImplementedError

    def kinetic_energy(self, y_dot: NDArray, q_e: NDArray) -> float:
        """½ ẏ_nᵀ M_n ẏ_n."""
        raise NotImplementedError

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e: NDArray) -> float:
        """Potential of the subsystem (gravity, internal springs) with frame pose (R, r)."""
        raise NotImplementedError

    def elastic_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """The last n_e rows (M_e, h_e) of :meth:`gauss_terms`: what the internal
        coordinates of a subsystem on a hub of given motion need (M_ee q̈_e = h_e − M_eR ζ)."""
        M, h = self.gauss_terms(y_dot, R, gravity, q_e)
        return M[-self.n_e :], h[-self.n_e :]

    def coordinates(self) -> tuple:
        """(name, unit) of each internal coordinate q_e, in order (results, tables and plots
        call them ``"<subsystem>.<name>"``; their velocities ṡ_e = q̇_e ``"<name>_dot"``).
        Default ``("e[i]", "")``, unit unknown; a beam states its Ritz amplitudes."""
        return tuple((f"e[{i}]", "") for i in range(self.n_e))

    def port(self, point: NDArray, q_e: NDArray, q_e_dot: NDArray):
        """(``has_ports``) The frame at the station ``point`` (reference-frame coordinates of
        the undeformed subsystem) as a :class:`projeq.joints.Relative` of the reference
        frame: its pose, twist F q̇_e and ζ = Ḟ q̇_e (docs/theory.md §10)."""
        raise NotImplementedError(f"{type(self).__name__} has no ports (has_ports is False)")

    def port_at(self, point: NDArray) -> "Port":
        """(``has_ports``) The frame at ``point``, built once per joint by the kinematic plan:
        an object whose ``relative(q_e, q_e_dot)`` is :meth:`port` there. The default calls
        :meth:`port`; a subsystem overrides it to prepare what the station needs once (a
        beam: its shape functions there)."""
        return Port(self, point)

    def centre_line(self, q_e: NDArray, y_dot: NDArray, stations: int = 21) -> tuple[NDArray, NDArray]:
        """(``deforms``) Positions and velocities of ``stations`` points of the centre line
        in the reference frame (for drawing and export)."""
        raise NotImplementedError(f"{type(self).__name__} does not deform (deforms is False)")

    def out_of_range(self, q_e: NDArray) -> str | None:
        """Where the rows of internal coordinates ``q_e`` leave the range the subsystem's
        model describes (a beam's moderate deflections), and what to do; None inside it (a
        rigid body: always)."""
        return None

    def deflection(self, result, x: float) -> NDArray:
        """(``deforms``) Displacement (u, v, w) of the centre line at station x, one row per
        time point of a simulated ``result``."""
        raise NotImplementedError(f"{type(self).__name__} does not deform (deforms is False)")


VISUAL_SIZES = {"box": 3, "cylinder": 2, "sphere": 1}  # kind: number of sizes


@dataclass(frozen=True)
class Visual:
    """A solid that draws a subsystem (:attr:`Subsystem.visuals`), URDF's primitives (ROS, "URDF
    XML specification: link/visual/geometry").

    Attributes
    ----------
    kind : str
        ``"box"`` (``size``: edges along the solid's x, y, z), ``"cylinder"`` (radius, length
        along the solid's z) or ``"sphere"`` (radius); sizes in m, positive.
    size : tuple of float
    origin : (4, 4) array
        Pose of the solid's frame (its centre and axes) in the subsystem's reference frame, a
        homogeneous transform; default identity.
    """

    kind: str
    size: tuple
    origin: NDArray = field(default_factory=lambda: np.eye(4))

    def __post_init__(self):
        if self.kind not in VISUAL_SIZES:
            raise ValueError(f"kind: expected one of {sorted(VISUAL_SIZES)}, got {self.kind!r}")
        size = np.asarray(self.size, dtype=float)
        if size.shape != (VISUAL_SIZES[self.kind],) or not np.all(np.isfinite(size) & (size > 0)):
            raise ValueError(f"size: a {self.kind} takes {VISUAL_SIZES[self.kind]} positive sizes, "
                             f"got {self.size!r}")
        origin = np.asarray(self.origin, dtype=float)
        rotation = origin[:3, :3] if origin.shape == (4, 4) else None
        if rotation is None or not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9) \
                or not np.all(np.isfinite(origin)) or np.linalg.det(rotation) <= 0:
            raise ValueError(f"origin: expected a 4 x 4 homogeneous transform with a rotation, "
                             f"got {self.origin!r}")
        object.__setattr__(self, "size", tuple(float(x) for x in size))
        object.__setattr__(self, "origin", origin)


class Port:
    """The frame at ``point`` of ``subsystem`` (the default of :meth:`Subsystem.port_at`)."""

    def __init__(self, subsystem, point: NDArray):
        self.subsystem, self.point = subsystem, point

    def relative(self, q_e: NDArray, q_e_dot: NDArray):
        """:meth:`Subsystem.port` at this point."""
        return self.subsystem.port(self.point, q_e, q_e_dot)

    def position(self, q_e: NDArray) -> NDArray:
        """The frame's origin in the reference frame at q_e (real or complex)."""
        return self.relative(q_e, np.zeros_like(q_e)).r


def conform(name: str, sub) -> None:
    """Check that ``sub`` (added under ``name``) is a subsystem; called where a System is built.

    A missing required member (or a required method left to the base class) is a ValueError
    naming it. An object that does not subclass :class:`Subsystem` (duck-typed) is given the
    defaults of the members it lacks (``S``, ``n_e``, ``rigid_inertia``, :meth:`elastic_terms`
    from its own ``gauss_terms``, :meth:`port_at` from its own ``port``) and its capabilities (``has_ports`` if it has ``port``, ...),
    so that the evaluators read declared members only.
    """
    missing = [m for m in REQUIRED if not hasattr(sub, m) or getattr(type(sub), m, None) is getattr(Subsystem, m, _ABSENT)]
    if missing:
        raise ValueError(
            f"subsystems[{name!r}]: {sub!r} is not a subsystem (it lacks {', '.join(missing)}; "
            "subclass projeq.Subsystem, which lists the members)"
        )
    if not isinstance(sub, Subsystem):
        for member in DEFAULTS:
            if not hasattr(sub, member):
                default = getattr(Subsystem, member)
                _give(name, sub, member, MethodType(default, sub) if callable(default) else default)
        for flag, methods in CAPABILITIES.items():
            _give(name, sub, flag, all(hasattr(sub, m) for m in methods))
    _check_shapes(name, sub)


def _check_shapes(name: str, sub) -> None:
    """``n_y``, ``S`` and the shapes of (M_n, h_n) from ``gauss_terms`` at rest (ẏ = 0, q_e = 0,
    no gravity): a wrong shape is named here, not by numpy inside an evaluator."""
    n_y, n_e = sub.n_y, sub.n_e
    if isinstance(n_y, bool) or not isinstance(n_y, (int, np.integer)) or n_y < 1 or not 0 <= n_e <= n_y:
        raise ValueError(f"subsystems[{name!r}]: n_y = {n_y!r}, n_e = {n_e!r}; expected integers "
                         "1 <= n_y and 0 <= n_e <= n_y")
    if sub.S is not None and np.shape(sub.S) != (n_y, 6):
        raise ValueError(f"subsystems[{name!r}]: S has shape {np.shape(sub.S)}, expected (n_y, 6) = ({n_y}, 6)")
    M, h = sub.gauss_terms(np.zeros(n_y), np.eye(3), np.zeros(3), np.zeros(n_e))
    if np.shape(M) != (n_y, n_y) or np.shape(h) != (n_y,):
        raise ValueError(f"subsystems[{name!r}]: gauss_terms returned M of shape {np.shape(M)} and h of shape "
                         f"{np.shape(h)}; with n_y = {n_y} they must be ({n_y}, {n_y}) and ({n_y},)")


def _give(name: str, sub, member: str, value) -> None:
    try:
        setattr(sub, member, value)
    except AttributeError:
        raise ValueError(
            f"subsystems[{name!r}]: {sub!r} does not take the member {member}; subclass projeq.Subsystem"
        ) from None
