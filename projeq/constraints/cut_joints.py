"""Cut joints of closed loops: a point of one body held on a point of another (docs/theory.md §7).

A loop is cut open at a joint that pins point P_a of subsystem a to point P_b of subsystem
b (or of the ground): a revolute joint of a planar loop, a spherical joint in space. Its
closure, given to :class:`~projeq.constraints.partitioned.ConstrainedSystem` as ``phi``, is

    Φ(q) = (r_a + R_a ρ_a − r_b − R_b ρ_b)[axes]

(r_n, R_n: origin O_n and orientation of frame n; ρ: the point in body axes; on a deforming
subsystem with ports, such as a RitzBeam, R_n ρ is replaced by R_n r_P(q_e), the origin of the frame
at the station ρ — x along the beam, (0, y, z) the cross-section offset —, which bends and turns
with the beam, docs/theory.md §10). With the
constraint inserted before the projection, M s̈_tree + b = A_sᵀ λ = (J_a − J_b)ᵀ λ, where
J is the Jacobian of the point's inertial velocity by ṡ_tree: the multipliers λ are the
joint's force on a at P_a (and −λ on b at P_b), in inertial axes, one per row of ``axes``.
In the coordinates ẏ_n of a rigid subsystem (velocity of O_n and angular velocity, body
axes, selected by S_n) a force f at ρ is the wrench w_n = S_n (R_nᵀ f; ρ × R_nᵀ f), so that
w_nᵀ ẏ_n is its power; at a station of a beam it gains the generalised forces (A F_v)ᵀ R_nᵀ f on
the amplitudes q_e (ṙ_P = A F_v q̇_e, the station's ``relative``).

Φ takes complex q (the complex step gives the numpy path exact derivatives), and the compiled
closure kernels evaluate cut joints themselves (:mod:`projeq.constraints.compiled`): A_s and γ
from the chain's own terms, without differences. Several cut joints are ``phi=[pin_1, pin_2]``
(:class:`CutJoints`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import finite_array
from projeq.assembly.kinematics import poses
from projeq.spatial import cross

_AXES = "xyz"


class PinClosure:
    """Φ(q, t) of a cut joint that keeps point ``rho_a`` of subsystem ``a`` on point
    ``rho_b`` of subsystem ``b`` (``b=None``: the inertial point ``rho_b``), along ``axes``.

    Examples
    --------
    A rod on x and y sliders pinned at its end to the origin is a physical pendulum:

    >>> import numpy as np, projeq as pq
    >>> from projeq.constraints.partitioned import ConstrainedSystem
    >>> tree = pq.System({"x": pq.Frame(), "y": pq.Frame(), "rod": pq.PlanarBody(1.0, (0.5, 0, 0), 1 / 12)},
    ...     {"x": pq.Prismatic(axis="x"), "y": pq.Prismatic(parent="x", axis="y"),
    ...      "rod": pq.Revolute(parent="y", axis="z")}, gravity=(0, -9.81, 0))
    >>> pin = PinClosure(tree, "rod", (0, 0, 0), None, (0, 0, 0), axes="xy")
    >>> pin([0.0, 0.0, -np.pi / 2]).tolist()
    [0.0, 0.0]
    >>> ConstrainedSystem(tree, phi=pin, q0=[0.0, 0.0, -np.pi / 2]).independent.tolist()
    [2]
    """

    def __init__(self, tree, a: str, rho_a, b: str | None, rho_b, axes: str = "xyz"):
        self.tree = tree
        self.a, self.b = tree.index(a), None if b is None else tree.index(b)
        if self.a == self.b:
            raise ValueError(f"b: the cut joint must join two subsystems, got a = b = {a!r}")
        self.rho_a, self.rho_b = finite_array("rho_a", rho_a, (3,)), finite_array("rho_b", rho_b, (3,))
        self.ports = {n: _port(tree, name, n, rho) for name, n, rho in (("a", self.a, self.rho_a),
                                                                     ("b", self.b, self.rho_b)) if _deforms(tree, n)}
        if not axes or len(set(axes)) != len(axes) or set(axes) - set(_AXES):
            raise ValueError(f"axes: expected distinct letters of 'xyz' (the inertial directions held), got {axes!r}")
        self.rows = [_AXES.index(axis) for axis in axes]
        self.names = (tree.names[self.a], None if b is None else tree.names[self.b])

    def _point(self, kin, n, rho, q) -> NDArray:
        """P = r_n + R_n ρ (rigid n), r_n + R_n r_port(q_e) (the frame at the station ρ of a
        deforming n), or ρ itself (the ground)."""
        if n is None:
            return rho
        local = self.ports[n].position(q[self.tree.e_q_slice[n]]) if n in self.ports else rho
        return kin.r[n] + kin.R[n] @ local

    def __call__(self, q, t: float = 0.0) -> NDArray:
        """Φ = (P_a − P_b)[axes] in inertial coordinates; complex q gives complex Φ (the
        complex step's exact derivatives, Martins, Sturdza & Alonso 2003)."""
        q = _complex_safe(q)
        return self.difference(_poses(self.tree, q, t), q)

    def difference(self, kin, q) -> NDArray:
        """(P_a − P_b)[axes] at the tree's poses ``kin`` and coordinates q."""
        return (self._point(kin, self.a, self.rho_a, q) - self._point(kin, self.b, self.rho_b, q))[self.rows]

    def point_rows(self) -> list:
        """One (a, b, axis, ρ_a, ρ_b, port_a, port_b) per row of Φ (b = −1: the inertial point
        ρ_b; port: the frame at the station of a deforming subsystem, else None), the statement
        the compiled closure kernel evaluates (projeq.constraints.compiled)."""
        b = -1 if self.b is None else self.b
        ports = (self.ports.get(self.a), self.ports.get(self.b))
        return [(self.a, b, axis, self.rho_a, self.rho_b, *ports) for axis in self.rows]

    def wrenches(self, kin, lam: NDArray, q=None) -> dict:
        """{n: w_n}: the joint's force λ (inertial, rows of ``axes``) on a at P_a and −λ on b
        at P_b as wrenches in the subsystems' ẏ coordinates (``kin``: the tree's kinematics at
        q, which a point on a deforming subsystem needs)."""
        f = np.zeros(3)
        f[self.rows] = lam
        loads = {self.a: (f, self.rho_a)} | ({} if self.b is None else {self.b: (-f, self.rho_b)})
        return {n: self._wrench(kin, n, force, rho, q) for n, (force, rho) in loads.items()}

    def _wrench(self, kin, n, force, rho, q) -> NDArray:
        """w_n with w_nᵀ ẏ_n the power of ``force`` at the point: [f; ρ × f] about O_n in body
        axes; at the station of a deforming subsystem [f; r × f; (A F_v)ᵀ f] with the station's
        origin r, orientation A and velocity rows F_v (ṙ = A F_v q̇_e, its ``relative``)."""
        f_body = kin.R[n].T @ force
        if n not in self.ports:
            return self._selected(n, np.concatenate((f_body, cross(rho, f_body))))  # force, moment about O_n
        if q is None:
            raise ValueError(f"q: the wrench of a cut joint on the deforming {self.tree.names[n]!r} needs q")
        q_e = np.asarray(q, dtype=float)[self.tree.e_q_slice[n]]
        port = self.ports[n].relative(q_e, np.zeros_like(q_e))
        w = self._selected(n, np.concatenate((f_body, cross(port.r, f_body))))
        w[-len(q_e):] += (port.A @ port.F[:3]).T @ f_body  # ẏ_n's last n_e rows are q̇_e
        return w

    def _selected(self, n, w: NDArray) -> NDArray:
        """S_n w of a wrench w about O_n in body axes."""
        S = self.tree.S[n]
        return w if S is None else S @ w


class CutJoints:
    """Φ(q, t) of several cut joints of one tree: the :class:`PinClosure` rows stacked in the
    order given (what :class:`~projeq.constraints.partitioned.ConstrainedSystem` makes of
    ``phi=[pin_1, pin_2, …]``)."""

    def __init__(self, pins):
        pins = list(pins)
        if not pins or not all(isinstance(pin, PinClosure) for pin in pins):
            raise ValueError(f"phi: expected a callable or a list of PinClosure, got {pins!r}")
        if any(pin.tree is not pins[0].tree for pin in pins):
            raise ValueError("phi: the cut joints belong to different trees")
        self.pins, self.tree = pins, pins[0].tree

    def __call__(self, q, t: float = 0.0) -> NDArray:
        """Φ = the pins' (P_a − P_b)[axes], stacked; complex q gives complex Φ."""
        q = _complex_safe(q)
        kin = _poses(self.tree, q, t)
        return np.concatenate([pin.difference(kin, q) for pin in self.pins])

    def point_rows(self) -> list:
        """The pins' :meth:`PinClosure.point_rows`, stacked."""
        return [row for pin in self.pins for row in pin.point_rows()]


def cut_joints(phi):
    """``phi`` as ConstrainedSystem keeps it: a list or tuple of :class:`PinClosure` as one
    :class:`CutJoints`, anything else as it is."""
    return CutJoints(phi) if isinstance(phi, (list, tuple)) else phi


def _complex_safe(q) -> NDArray:
    """q as an array of floats, or of complex numbers under the complex step."""
    q = np.asarray(q)
    return q.astype(np.result_type(q, float))


def _poses(tree, q, t):
    """The tree's poses at q and t (real or complex: the complex step), at rest."""
    return poses(tree, q, np.zeros(tree.n_s), t)


def _deforms(tree, n) -> bool:
    """Subsystem n (None: the ground) has internal coordinates."""
    return n is not None and tree.e_s_slice[n].stop > tree.e_s_slice[n].start


def _port(tree, name: str, n: int, rho):
    """The frame at the station ``rho`` of the deforming subsystem n (its ``port_at``)."""
    body = tree.subsystems[n]
    if not body.has_ports:
        raise ValueError(f"{name}: {tree.names[n]!r} deforms and has no ports (stations where a cut joint can "
                         "hold a point); a cut joint needs a rigid subsystem or one with ports, such as a RitzBeam")
    try:
        return body.port_at(rho)
    except ValueError as error:
        raise ValueError(f"rho_{name}: {str(error).split(': ', 1)[-1]}") from None


def point_rows(phi) -> list | None:
    """The rows (a, b, axis, ρ_a, ρ_b, port_a, port_b) of ``phi`` (:meth:`PinClosure.point_rows`) if it
    is made of cut joints (:class:`PinClosure`, :class:`CutJoints`), else None."""
    return phi.point_rows() if isinstance(phi, (PinClosure, CutJoints)) else None
