"""One forward pass over the tree: poses, describing velocities and chain terms (docs/theory.md §4).

:func:`forward` gives all of them (:class:`Kinematics`, what the evaluators need);
:func:`poses` only the poses, twists and ẏ_n (:class:`Poses`, what energies, exports and
constraint positions need, at about half the cost).

For each subsystem n with predecessor p and joint frame J (fixed in p):

    A_pn = A_pJ A_Jn,  r_pn = r_pJ + A_pJ r_Jn,  T⁶_np = [[A_np, −A_np r̃_pn], [0, A_np]]
    u = T⁶_np Sₚᵀ ẏ_p            (p's twist carried to n)
    ẏ_n = Sₙ (u + F⁶ ṡ_n + f⁶),  T_np = Sₙ T⁶_np Sₚᵀ,  F_n = Sₙ F⁶
    ζ_n = Sₙ (u × w + Ḟ⁶ ṡ_n + ḟ⁶),  w = F⁶ ṡ_n + f⁶

where u × w is the motion cross product (``spatial.cross_motion``): it is Ṫ_np ẏ_p, since
Ȧ_np = −ω̃_rel A_np and ṙ_pn = A_pn v_rel. The lists have one extra entry at index −1 for
the ground (n_y = 0, at rest in the inertial frame), so ``parent = -1`` needs no branch.

Only poses and twists need the root-to-leaves loop; T_np, ζ_n and the Gauss terms of
rigid bodies are then computed for all subsystems at once on stacked arrays (the
formulas are the same functions, applied row-wise), which is what makes a pass cheap in
numpy. A :class:`Plan` holds what this needs and is built once per System.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from projeq.spatial import chain_matrix, cross, cross_motion
from projeq.subsystems.rigid import RigidGroup


class Plan:
    """Per-System preparation of the forward pass (built once, by the System's constructor).

    - ``groups``: subsystems whose terms are the rigid-body terms of docs/theory.md §3
      (``rigid_inertia``), one :class:`RigidGroup` per selection S, as (indices, group);
      ``singles``: the others, whose own ``gauss_terms`` are called one by one;
    - ``S_aug[n]`` = blockdiag(S_n, 1), and [0 … 0 1] for the ground, so that
      T̃_np = S̃_n T̃⁶_np S̃_pᵀ; ``plain[n]`` marks the common case S̃ = E on both sides;
    - ``internal``: subsystems with internal coordinates q_e (ṡ_e = q̇_e), whose last n_e
      rows of ẏ_n are ṡ_e (S_n has zero rows there);
    - ``port[n]``: joint n sits on a deforming parent (``has_ports``, a beam), at the
      station its ``r_pn`` names; ``stations[n]``: that frame of the parent, built here
      once (``parent.port_at(r_pn)``).
    """

    def __init__(self, system):
        N = len(system.joints)
        by_selection: dict = {}
        self.singles = []
        for n, sub in enumerate(system.subsystems):
            if sub.rigid_inertia is None:
                self.singles.append(n)
            else:
                selection = None if sub.S is None else (sub.S.shape, sub.S.tobytes())
                by_selection.setdefault(selection, []).append(n)
        self.groups = [
            (np.array(idx), RigidGroup([system.subsystems[n] for n in idx])) for idx in by_selection.values()
        ]
        ground = np.zeros((1, 7))
        ground[0, 6] = 1.0
        self.S_aug = [_augmented_selection(system.S[n]) for n in range(N)] + [ground]
        self.plain = [
            system.S[n] is None and system.parent[n] >= 0 and system.S[system.parent[n]] is None for n in range(N)
        ]
        self.internal = [n for n in range(N) if system.subsystems[n].n_e]
        self.port = [system.parent[n] >= 0 and system.subsystems[system.parent[n]].has_ports for n in range(N)]
        self.plain = [plain and not port for plain, port in zip(self.plain, self.port)]
        self.stations = {
            n: system.subsystems[system.parent[n]].port_at(system.joints[n].r_pn) for n in range(N) if self.port[n]
        }


def _augmented_selection(S: NDArray | None) -> NDArray:
    """S̃ = blockdiag(S, 1) (E₇ for S = None)."""
    if S is None:
        return np.eye(7)
    S_aug = np.zeros((S.shape[0] + 1, 7))
    S_aug[:-1, :6] = S
    S_aug[-1, 6] = 1.0
    return S_aug


def plan(system) -> Plan:
    """The System's :class:`Plan` (built by its constructor)."""
    return system.plan


@dataclass
class Poses:
    """Poses and velocities of every subsystem; index −1 is the ground."""

    R: list  # body → inertial rotation of frame n
    r: list  # origin of frame n, inertial coordinates
    twist: list  # (v_O, ω) of frame n in its own coordinates
    y_dot: list  # ẏ_n = S_n twist


@dataclass
class Kinematics(Poses):
    """Poses, velocities and chain terms of every subsystem; index −1 is the ground.

    ``T_aug[n]`` is T̃_np = [[T_np, ζ_n], [0, 1]], the affine map (ÿ_p; 1) ↦ (ÿ_n − F_n s̈_n; 1)
    that both evaluators use; ``T[n]`` and ``zeta[n]`` are views into it.
    """

    T_aug: list  # T̃_np
    F: list  # F_n (n_y × n_s_n)

    @property
    def T(self) -> list:
        """T_np (n_y × n_y_p) of every subsystem."""
        return [T[:-1, :-1] for T in self.T_aug[:-1]]

    @property
    def zeta(self) -> list:
        """ζ_n = Ṫ_np ẏ_p + Ḟ_n ṡ_n (+ ḟ_n) of every subsystem."""
        return [T[:-1, -1] for T in self.T_aug[:-1]]


def poses(system, q: NDArray, s_dot: NDArray, t: float) -> Poses:
    """Poses, twists and ẏ_n of every subsystem at (q, ṡ, t), without the chain terms."""
    prep = plan(system)
    R, r, twist = _poses_and_twists(system, prep, q, s_dot, t)[:3]
    return Poses(R, r, twist, describing_velocities(system, prep, twist, s_dot))


def forward(system, q: NDArray, s_dot: NDArray, t: float) -> Kinematics:
    """Poses, ẏ_n, T̃_np (T_np and ζ_n) and F_n of every subsystem at (q, ṡ, t)."""
    prep = plan(system)
    R, r, twist, rels, A_np, r_pn, u, P_aug = _poses_and_twists(system, prep, q, s_dot, t)
    y_dot = describing_velocities(system, prep, twist, s_dot)
    w = np.array([rel.w for rel in rels])
    zeta6 = cross_motion(np.array(u), w) + np.array([rel.zeta for rel in rels])  # Ṫ ẏ_p + Ḟ ṡ + ḟ
    chain = chain_matrix(np.array(A_np), np.array(r_pn))
    T_aug6 = np.zeros((len(rels), 7, 7), dtype=np.result_type(chain, zeta6))
    T_aug6[:, :6, :6] = chain
    T_aug6[:, :6, 6] = zeta6
    T_aug6[:, 6, 6] = 1.0
    T_aug, F = selected_chain_terms(system, prep, [rel.F for rel in rels], T_aug6, P_aug)
    return Kinematics(R, r, twist, y_dot, T_aug, F)


def _poses_and_twists(system, prep: Plan, q: NDArray, s_dot: NDArray, t: float) -> tuple:
    """Root → leaves: R_n, r_n, the twists, the joints' relative motions, A_np, r_pn,
    u = T⁶_np twist_p and the port maps P̃ of joints on deforming parents."""
    N = len(system.joints)
    parent, joints = system.parent, system.joints
    R, r, twist = [None] * N + [np.eye(3)], [None] * N + [np.zeros(3)], [None] * N + [np.zeros(6)]
    rels, A_np, r_pn, u, P_aug = [None] * N, [None] * N, [None] * N, [None] * N, [None] * N
    for n, joint in enumerate(joints):
        p = parent[n]
        rels[n] = rel = joint.relative(system._q_get[n](q), system._s_get[n](s_dot), t)
        if prep.port[n]:  # the joint sits at a station of a deforming parent
            base_R, base_r, base_twist, offset, P_aug[n] = _port(system, prep.stations[n], p, q, s_dot, R, r, twist)
        else:
            base_R, base_r, base_twist, offset = R[p], r[p], twist[p], joint.r_pn
        A_pn = joint.orientation @ rel.A
        r_pn[n] = offset + joint.orientation @ rel.r
        A_np[n] = A = A_pn.T
        v_p, omega_p = base_twist[:3], base_twist[3:]
        u[n] = np.concatenate((A @ (v_p + cross(omega_p, r_pn[n])), A @ omega_p))  # T⁶_np twist_p
        R[n], r[n] = base_R @ A_pn, base_r + base_R @ r_pn[n]
        twist[n] = u[n] + rel.w
    return R, r, twist, rels, A_np, r_pn, u, P_aug


def _port(system, station, p, q, s_dot, R, r, twist):
    """The frame ``station`` (``Plan.stations``) of a joint on its deforming parent p: its
    pose, its twist, and P̃ = [[T⁶_port Sₚᵀ + F_port Eₑᵀ, ζ_port], [0, 1]], the map
    (ÿ_p; 1) ↦ (port acceleration; 1) that T̃_np composes with (docs/theory.md §10, last line)."""
    port = station.relative(q[system.e_q_slice[p]], s_dot[system.e_s_slice[p]])
    T6 = chain_matrix(port.A.T, port.r)
    u = T6 @ twist[p]
    n_y = system.subsystems[p].n_y
    n_e = port.F.shape[1]
    P_aug = np.zeros((7, n_y + 1), dtype=np.result_type(T6, port.F, port.zeta))
    P_aug[:6, :n_y] = T6 @ system.S[p].T
    P_aug[:6, n_y - n_e : n_y] += port.F
    P_aug[:6, -1] = cross_motion(u, port.w) + port.zeta
    P_aug[6, -1] = 1.0
    return R[p] @ port.A, r[p] + R[p] @ port.r, u + port.w, np.zeros(3), P_aug


def describing_velocities(system, prep: Plan, twist, s_dot: NDArray) -> list:
    """ẏ_n = S_n twist_n, plus the internal velocities ṡ_e in the last n_e rows of the
    subsystems that have them; the ground's entry (−1) is empty."""
    N = len(system.joints)
    y_dot = [twist[n] if system.S[n] is None else system.S[n] @ twist[n] for n in range(N)] + [np.zeros(0)]
    for n in prep.internal:
        n_e = system.e_s_slice[n].stop - system.e_s_slice[n].start
        y_dot[n] = y_dot[n].astype(np.result_type(y_dot[n], s_dot))
        y_dot[n][-n_e:] += s_dot[system.e_s_slice[n]]
    return y_dot


def selected_chain_terms(system, prep: Plan, F6, T_aug6, P_aug) -> tuple[list, list]:
    """Apply the selections S_n to the spatial F⁶ and T̃⁶_np of every joint: F_n = S_n F⁶
    (with [0; E] columns for internal velocities) and T̃_np = S̃_n T̃⁶ S̃_pᵀ (composed with
    P̃ for joints on a deforming parent)."""
    N = len(F6)
    T_aug, F = [None] * N + [np.ones((1, 1))], [selected_F(system, n, F6[n]) for n in range(N)]
    for n in range(N):
        if prep.plain[n]:
            T_aug[n] = T_aug6[n]
        elif prep.port[n]:
            T_aug[n] = prep.S_aug[n] @ T_aug6[n] @ P_aug[n]
        else:
            T_aug[n] = prep.S_aug[n] @ T_aug6[n] @ prep.S_aug[system.parent[n]].T
    return T_aug, F


def selected_F(system, n: int, F6: NDArray) -> NDArray:
    """F_n = S_n F⁶ of subsystem n from its joint's spatial F⁶, with [0; E] columns for its internal
    velocities ṡ_e (if any)."""
    S, n_e = system.S[n], system.e_s_slice[n].stop - system.e_s_slice[n].start
    F = F6 if S is None else S @ F6
    return np.hstack((F, np.eye(F.shape[0])[:, -n_e:])) if n_e else F


def gauss_terms(system, kin: Kinematics, q: NDArray, s_dot: NDArray, t: float) -> tuple[list, list]:
    """M_n and h_n = Q_n − G_n ẏ_n of every subsystem, forces included (B(14)).

    Grouped subsystems are evaluated together (``Plan.groups``), the others one by one.
    The lists have a ground entry at −1 (empty), where joint forces on the ground land.
    """
    N = len(system.subsystems)
    M, h = [None] * N + [np.zeros((0, 0))], [None] * N + [np.zeros(0)]
    prep = plan(system)
    for idx, group in prep.groups:
        H = group.h(np.array([kin.y_dot[n] for n in idx]), np.array([kin.R[n] for n in idx]), system.gravity)
        for k, n in enumerate(idx):
            M[n], h[n] = group.M[k], H[k]
    for n in prep.singles:
        q_e = q[system.e_q_slice[n]]
        M[n], h[n] = system.subsystems[n].gauss_terms(kin.y_dot[n], kin.R[n], system.gravity, q_e)
    if system.forces and any(np.iscomplexobj(x) for x in (q, s_dot, *h, *kin.T_aug)):  # a complex step: forces add into h
        h = [np.asarray(h_n, dtype=complex) for h_n in h]
    for force in system.forces:
        force.add_to(h, kin, t, q, s_dot)
    return M, h
