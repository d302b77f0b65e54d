"""Recursive (THEORY §6) = dense (THEORY §5) on random trees, the core issue's acceptance test.

Random topology up to 30 bodies (each body hangs on a random earlier one or the ground),
random joint types (revolute, prismatic, planar, free, fixed, prescribed, a user joint
from callables), random masses over four decades, random inertias that satisfy the
triangle inequality, random offsets, gravity, forces and states. The two evaluators are
independent algorithms over the same kinematics; they agree to round-off: 1e-10 relative
to the largest acceleration (the trees are small and mildly conditioned, so cond(M)·ε
stays far below that).
"""

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

import projeq as pq
from projeq.spatial import rotation

JOINTS = ("revolute", "prismatic", "planar", "free", "fixed", "prescribed", "spherical")


def _random_inertia(rng):
    """R diag(A, B, C) Rᵀ with A + B ≥ C for every ordering (a real mass distribution)."""
    moments = np.sort(rng.uniform(0.2, 1.0, 3))
    moments[2] = min(moments[2], moments[0] + moments[1])  # the largest ≤ the sum of the others
    axis = rng.standard_normal(3)
    R = rotation(axis / np.linalg.norm(axis), rng.uniform(0, np.pi))
    return R @ np.diag(moments) @ R.T


def _spherical(rng):
    """A ball joint as a user joint from callables: q = rotation vector... kept simple as
    two Cardan angles and a spin, A = R_z(a) R_y(b) R_x(c), ω in child coordinates."""

    def pose(q, t):
        a, b, c = q
        ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
        z = 0 * a
        Rz = np.array([[ca, -sa, z], [sa, ca, z], [z, z, 1 + z]])
        Ry = np.array([[cb, z, sb], [z, 1 + z, z], [-sb, z, cb]])
        Rx = np.array([[1 + z, z, z], [z, cc, -sc], [z, sc, cc]])
        return Rz @ Ry @ Rx, np.zeros(3)

    def F(q, t):
        a, b, c = q
        cb, sb, cc, sc = np.cos(b), np.sin(b), np.cos(c), np.sin(c)
        z = 0 * a
        # ω = ȧ Rxᵀ Ryᵀ e_z + ḃ Rxᵀ e_y + ċ e_x, in child coordinates
        w_a = np.array([-sb + z, cb * sc, cb * cc])
        w_b = np.array([z, cc, -sc])
        w_c = np.array([1 + z, z, z])
        F6 = np.zeros((6, 3), dtype=np.result_type(q, float))
        F6[3:, 0], F6[3:, 1], F6[3:, 2] = w_a, w_b, w_c
        return F6

    return pq.UserJoint.from_functions(3, 3, pose, F, lambda q, t: np.eye(3))


def _joint(kind, parent, rng):
    r_pn = rng.uniform(-1, 1, 3)
    axis = rng.standard_normal(3)
    if kind == "revolute":
        return pq.Revolute(parent, axis, r_pn)
    if kind == "prismatic":
        return pq.Prismatic(parent, axis, r_pn)
    if kind == "planar":
        return pq.Planar(parent, plane=("xy", "yz", "zx")[rng.integers(3)], r_pn=r_pn)
    if kind == "free":
        return pq.Free(parent, r_pn)
    if kind == "fixed":
        return pq.Fixed(parent, r_pn, orientation=rotation(axis / np.linalg.norm(axis), 0.7))
    if kind == "prescribed":
        w = rng.uniform(0.5, 2)
        return pq.Prescribed(pq.Revolute(parent, axis, r_pn), lambda t: (np.sin(w * t), w * np.cos(w * t), -w * w * np.sin(w * t)))
    joint = _spherical(rng)
    joint.parent, joint.r_pn = parent, r_pn
    return joint


def _random_system(seed, n_bodies, kinds):
    rng = np.random.default_rng(seed)
    names = [f"b{i}" for i in range(n_bodies)]
    subsystems, joints = {}, {}
    for i, name in enumerate(names):
        parent = None if i == 0 or rng.random() < 0.15 else names[rng.integers(i)]
        subsystems[name] = pq.RigidBody(10 ** rng.uniform(-2, 2), rng.uniform(-0.5, 0.5, 3), _random_inertia(rng) * 10 ** rng.uniform(-2, 1))
        joints[name] = _joint(kinds[i % len(kinds)], parent, rng)
    forces = [
        pq.Force(names[-1], lambda t, q, s_dot: np.array([np.sin(t), 1.0, np.sum(q)]), point=(0.1, 0.2, 0.3)),
        pq.Torque(names[0], (0.3, -0.2, 0.5), frame="body"),
    ]
    springs = [pq.JointSpring(name, 5.0, 0.3) for name, kind in zip(names, kinds * n_bodies) if kind in ("revolute", "prismatic")]
    return pq.System(subsystems, joints, gravity=rng.uniform(-10, 10, 3), forces=forces + springs[:2]), rng


@given(
    seed=st.integers(0, 2**31 - 1),
    n_bodies=st.integers(1, 30),
    kinds=st.lists(st.sampled_from(JOINTS), min_size=1, max_size=6),
)
@example(seed=1, n_bodies=30, kinds=list(JOINTS))  # always the largest tree with every joint
def test_recursive_equals_dense_on_random_trees(seed, n_bodies, kinds):
    system, rng = _random_system(seed, n_bodies, kinds)
    q = system.normalized(rng.uniform(-1, 1, system.n_q))
    s_dot = rng.uniform(-1, 1, system.n_s)
    t = rng.uniform(0, 3)
    a = system.accelerations(q, s_dot, t, method="recursive")
    b = system.accelerations(q, s_dot, t, method="dense")
    assert np.abs(a - b).max(initial=0.0) <= 1e-10 * max(1.0, np.abs(b).max(initial=0.0))  # n_s = 0 allowed


@given(seed=st.integers(0, 2**31 - 1), n_bodies=st.integers(1, 12))
def test_planar_trees_agree_with_their_spatial_twins(seed, n_bodies):
    """Planar bodies in the x–y plane on revolute (z) and prismatic (in-plane) joints: the
    recursive and dense evaluators agree, and both equal the same tree built from spatial
    bodies (the planar body is the spatial one restricted to the plane, THEORY §3)."""
    rng = np.random.default_rng(seed)
    planar, spatial, joints = {}, {}, {}
    for i in range(n_bodies):
        name = f"b{i}"
        m, r_c = 10 ** rng.uniform(-1, 1), np.append(rng.uniform(-0.5, 0.5, 2), 0.0)
        I_c = _random_inertia(rng)
        planar[name] = pq.PlanarBody(m, r_c, I_c, plane="xy")
        spatial[name] = pq.RigidBody(m, r_c, I_c)
        parent = None if i == 0 else f"b{rng.integers(i)}"
        r_pn = np.append(rng.uniform(-1, 1, 2), 0.0)
        joints[name] = pq.Revolute(parent, "z", r_pn) if rng.random() < 0.6 else pq.Prismatic(parent, np.append(rng.standard_normal(2), 0.0), r_pn)
    gravity = np.append(rng.uniform(-10, 10, 2), 0.0)
    P, S = pq.System(planar, joints, gravity), pq.System(spatial, joints, gravity)
    q, s_dot = rng.uniform(-1, 1, n_bodies), rng.uniform(-1, 1, n_bodies)
    a = P.accelerations(q, s_dot, method="recursive")
    scale = max(1.0, np.abs(a).max())
    assert np.abs(a - P.accelerations(q, s_dot, method="dense")).max() <= 1e-10 * scale
    assert np.abs(a - S.accelerations(q, s_dot, method="recursive")).max() <= 1e-10 * scale
