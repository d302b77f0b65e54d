"""Cut joints (PinClosure) in the compiled closure kernels (projeq.constraints.compiled: A_s rows from
the chain's body Jacobians, γ from the points' accelerations at s̈ = 0), checked against: the numpy path
of the same model (numpy's linear algebra on the dense Gauss form, docs/theory.md §7; a PinClosure's
rows Φ, A_s and γ there are the kernels' own ``cut_joint_rows``, so this checks the kernels' algebra,
not the rows); the rows against independent statements: the four-bar's loop closure differentiated by
sympy and the KKT system [M A_sᵀ; A_s 0] solved by numpy, and the work–energy theorem (the cut joints'
forces do no work, so a conservative mechanism keeps dE/dt = 0); and the refusal of a ``phi`` list that
is not made of one tree's cut joints. The models: planar four-bars (partitioned and tangent, with force
laws, on a sympy UserJoint), a rod pinned to the ground, two loops on one crank, and a spatial loop
on skew axes whose terms the planar ones cannot see (ω̇ at s̈ = 0, ζ̄ carried down a chain, z
components)."""

import warnings
from contextlib import contextmanager

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.analysis.differentiation import DifferencesWarning
from projeq.assembly.auto import InterpretedWarning
from projeq.assembly.kinematics import poses
from projeq.constraints.batched import PointwiseWarning
from projeq.constraints.compiled import CompiledClosure, UncompiledClosureWarning, pin_table
from projeq.constraints.cut_joints import PinClosure
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.constraints.partitioned import TangentSystem
from projeq.constraints.tangent import ACTING
from projeq.scenes.mechanisms import four_bar_angles

G = 9.81
A, B, C, D = 0.3, 1.0, 0.8, 1.0  # crank, coupler, rocker, ground of the four-bar
B2, C2, D2, Z2 = 1.2, 0.7, 1.1, 0.2  # the second loop of the two-loop mechanism, in the plane z = Z2
FALLBACKS = (UncompiledClosureWarning, DifferencesWarning, PointwiseWarning, InterpretedWarning)


@contextmanager
def _strict():
    """Any fallback from the compiled kernel (or from exact derivatives) is an error."""
    with warnings.catch_warnings():
        for category in FALLBACKS:
            warnings.simplefilter("error", category)
        yield


def _rod(m, length):
    return pq.RigidBody(m, (length / 2, 0, 0), np.diag([1e-4, m * length**2 / 12, m * length**2 / 12]))


def _four_bar_tree(g=G, forces=()):
    """The crank–rocker four-bar of tests/test_model.py::_spatial_four_bar: spatial rigid rods on
    revolute joints about z, q = (crank, coupler relative to the crank, rocker)."""
    return pq.System(
        {"crank": _rod(1.0, A), "coupler": _rod(2.0, B), "rocker": _rod(1.5, C)},
        {"crank": pq.Revolute(axis="z"), "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0, 0)),
         "rocker": pq.Revolute(axis="z", r_pn=(D, 0, 0))},
        gravity=(0, -g, 0), forces=forces,
    )


def _four_bar_q0(theta1=0.7):
    theta2, theta3 = four_bar_angles(theta1, A, B, C, D)
    return np.array([theta1, theta2 - theta1, theta3])


def four_bar(g=G, forces=(), kind=ConstrainedSystem, axes="xy", **options):
    """The four-bar with its coupler tip pinned to the rocker tip (PinClosure along ``axes``)."""
    tree = _four_bar_tree(g, forces)
    assert tree.names == ("crank", "coupler", "rocker")
    pin = PinClosure(tree, "coupler", (B, 0, 0), "rocker", (C, 0, 0), axes=axes)
    return kind(tree, phi=pin, q0=_four_bar_q0(), **options)


def pendulum(rho=0.0):
    """tests/constraints/test_cut_joints.py's pendulum: a uniform rod (PlanarBody) on x and y
    sliders, its point (ρ, 0, 0) pinned to the ground (b = None) by a cut revolute joint."""
    m, length = 1.3, 0.9
    tree = pq.System(
        {"x": pq.Frame(), "y": pq.Frame(), "rod": pq.PlanarBody(m, (length / 2, 0, 0), m * length**2 / 12)},
        {"x": pq.Prismatic(axis="x"), "y": pq.Prismatic(parent="x", axis="y"),
         "rod": pq.Revolute(parent="y", axis="z")},
        gravity=(0, -G, 0),
    )
    pin = PinClosure(tree, "rod", (rho, 0, 0), None, (0, 0, 0), axes="xy")
    return ConstrainedSystem(tree, phi=pin, q0=[0.0, rho, -np.pi / 2])  # the rod hanging, P = 0


def two_loops(forces=()):
    """Two crank–rocker four-bars sharing the crank (the second in the plane z = Z2, its coupler on
    the crank tip's offset pin), ``phi=[pin_1, pin_2]``: 5 tree velocities, 4 closure rows, mobility 1."""
    tree = pq.System(
        {"crank": _rod(1.0, A), "coupler": _rod(2.0, B), "rocker": _rod(1.5, C),
         "coupler2": _rod(1.2, B2), "rocker2": _rod(0.9, C2)},
        {"crank": pq.Revolute(axis="z"), "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0, 0)),
         "rocker": pq.Revolute(axis="z", r_pn=(D, 0, 0)),
         "coupler2": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0, Z2)),
         "rocker2": pq.Revolute(axis="z", r_pn=(D2, 0, Z2))},
        gravity=(0, -G, 0), forces=forces,
    )
    pins = [PinClosure(tree, "coupler", (B, 0, 0), "rocker", (C, 0, 0), axes="xy"),
            PinClosure(tree, "coupler2", (B2, 0, 0), "rocker2", (C2, 0, 0), axes="xy")]
    theta1 = 0.7
    t2, t3 = four_bar_angles(theta1, A, B, C, D)
    u2, u3 = four_bar_angles(theta1, A, B2, C2, D2)
    q0, _ = tree.state(crank=theta1, coupler=t2 - theta1, rocker=t3, coupler2=u2 - theta1, rocker2=u3)
    return ConstrainedSystem(tree, phi=pins, q0=q0, independent=[tree.index("crank")])


def cam_four_bar():
    """The four-bar with its coupler on a UserJoint from sympy (a joint of kind GIVEN in the kernels:
    its relative motion by a compiled callback): a revolute about z whose pivot slides along the
    crank with the angle, r = (0.05 sin θ, 0, 0), so that F(q) = [R_zᵀ r′; e_z] varies (Ḟ ≠ 0): the
    only model that sees A_s taken with a GIVEN joint's F left from the previous call."""
    th, w = sp.symbols("theta omega")
    Rz = sp.Matrix([[sp.cos(th), -sp.sin(th), 0], [sp.sin(th), sp.cos(th), 0], [0, 0, 1]])
    r = sp.Matrix([0.05 * sp.sin(th), 0, 0])
    v = Rz.T * r.diff(th)  # the pivot's velocity per θ̇, child axes
    joint = pq.UserJoint.from_sympy([th], [w], Rz, r, sp.Matrix([*v, 0, 0, 1]), sp.eye(1), parent="crank",
                                    r_pn=(A, 0, 0))
    tree = pq.System({"crank": _rod(1.0, A), "coupler": _rod(2.0, B), "rocker": _rod(1.5, C)},
                     {"crank": pq.Revolute(axis="z"), "coupler": joint, "rocker": pq.Revolute(axis="z", r_pn=(D, 0, 0))},
                     gravity=(0, -G, 0))
    pin = PinClosure(tree, "coupler", (B, 0, 0), "rocker", (C, 0, 0), axes="xy")
    return ConstrainedSystem(tree, phi=pin, q0=_four_bar_q0(), independent=[0], project_q0=True)


def _body(m, centre, inertia):
    return pq.RigidBody(m, centre, np.array(inertia, dtype=float))


def spatial_loop(forces=(), g=(1.0, -G, 2.0), kind=ConstrainedSystem):
    """A spatial loop: a branch of three revolutes and one of one, about skew axes, a point of the
    long branch's tip pinned to a point of the other in x, y and z (a spherical cut joint; 4 tree
    velocities, 3 closure rows, mobility 1); bodies with products of inertia and off-axis points:
    every term of the points' velocities and accelerations (ω × ρ, ω̇ × ρ — ω̇ ≠ 0 at s̈ = 0 on skew
    axes —, ω × (ω × ρ), and ζ̄ carried down a chain whose middle body's origin accelerates) in
    all three components."""
    tree = pq.System(
        {"a1": _body(1.1, (0.3, 0.05, 0.02), [[0.02, 0.003, 0.0], [0.003, 0.05, 0.001], [0.0, 0.001, 0.06]]),
         "a2": _body(0.8, (0.2, -0.03, 0.05), [[0.01, 0.0, 0.002], [0.0, 0.03, 0.0], [0.002, 0.0, 0.035]]),
         "a3": _body(0.6, (0.15, 0.02, 0.0), [[0.008, 0.001, 0.0], [0.001, 0.012, 0.0], [0.0, 0.0, 0.014]]),
         "b1": _body(1.4, (0.25, 0.0, -0.04), [[0.03, 0.002, 0.0], [0.002, 0.04, 0.0], [0.0, 0.0, 0.05]])},
        {"a1": pq.Revolute(axis=(0.0, 0.3, 1.0)),
         "a2": pq.Revolute(parent="a1", axis=(1.0, 0.2, 0.1), r_pn=(0.6, 0.0, 0.1)),
         "a3": pq.Revolute(parent="a2", axis=(0.1, 1.0, 0.4), r_pn=(0.4, 0.1, 0.0)),
         "b1": pq.Revolute(axis=(0.2, 1.0, 0.3), r_pn=(0.9, 0.3, -0.1))},
        gravity=g, forces=forces,
    )
    q0, _ = tree.state(a1=0.4, a2=-0.3, a3=0.6, b1=0.2)
    kin = poses(tree, q0, np.zeros(tree.n_s), 0.0)
    rho_a = np.array([0.3, 0.1, -0.2])
    a, b = tree.index("a3"), tree.index("b1")
    point = kin.r[a] + kin.R[a] @ rho_a
    rho_b = kin.R[b].T @ (point - kin.r[b])  # the same point in b1's axes: Φ(q0) = 0
    pin = PinClosure(tree, "a3", rho_a, "b1", rho_b, axes="xyz")
    return kind(tree, phi=pin, q0=q0)  # independent: pivoted QR, repivoting


def _springs(damping=0.7):
    """A spring-damper from the coupler's middle to a ground point and a torsion spring on the rocker."""
    return [pq.SpringDamper("coupler", (B / 2, 0, 0), None, (0.4, 1.2, 0), 40.0, damping, length=0.3),
            pq.JointSpring("rocker", 5.0, damping / 2, q_ref=1.0)]


MODELS = {
    "spatial four-bar": lambda: four_bar(independent=[0]),
    "pendulum pinned to the ground": pendulum,
    "pendulum pinned off the rod's origin": lambda: pendulum(rho=0.2),
    "two loops, phi=[pin_1, pin_2]": two_loops,
    "spatial loop, spherical cut joint": spatial_loop,
    "tangent four-bar": lambda: four_bar(kind=TangentSystem),
    "tangent four-bar, redundant z row": lambda: four_bar(kind=TangentSystem, axes="xyz"),
    "four-bar with springs and gravity": lambda: four_bar(forces=_springs(), independent=[0]),
    "four-bar on a sympy UserJoint (kind GIVEN, F(q))": cam_four_bar,
}


def _kernel(system, q, s_dot):
    """s̈_tree by the compiled kernel itself: an error where it flags (a flagged call would fall back
    on the numpy path silently, which hides a kernel that is wrong enough to find A_dep singular)."""
    found = system.compiled_kernel().accelerations(system, np.asarray(q, float), np.asarray(s_dot, float), 0.0)
    assert found is not None, "the compiled kernel flagged the call"
    return found[0]


def _states(system, n=3, seed=7):
    """Projected states (q on Φ = 0) near q0 with moving minimal velocities."""
    rng = np.random.default_rng(seed)
    return [(system.project(system.q0 + 0.3 * rng.standard_normal(system.n_q)), rng.uniform(-3, 3, system.n_s))
            for _ in range(n)]


@pytest.mark.parametrize("name", MODELS)
def test_the_compiled_kernel_equals_the_numpy_path(name):
    """The compiled kernel's (s̈_tree, λ) against the numpy path (``method="dense"``: Φ's exact
    complex-step derivatives, numpy's partition or SVD and the dense Gauss form; module docstring
    of projeq.constraints.partitioned) at three projected states: both solve the same equations
    exactly, so they agree to round-off, 1e-13 relative (measured: s̈_tree ≤ 2.0e-14, λ ≤ 1.9e-14
    over these models, the largest for the spatial loop's s̈ and the two loops' λ), with s̈ the
    kernel's own answer (not flagged) and no fallback warned."""
    with _strict():
        system = MODELS[name]()
        assert system.compiled_kernel() is not None
        for q, s_dot in _states(system):
            s_ddot, lam = system.accelerations_tree(q, s_dot)
            assert np.array_equal(s_ddot, _kernel(system, q, s_dot))  # the kernel's own answer
            s_ddot_ref, lam_ref = system.accelerations_tree(q, s_dot, 0.0, "dense")
            assert np.abs(system.phi(q)).max() < 1e-12
            for value, reference in ((s_ddot, s_ddot_ref), (lam, lam_ref)):
                error = np.abs(value - reference).max() / np.abs(reference).max()
                assert error < 1e-13, (name, error)


def test_the_kernels_two_column_null_space_basis_is_the_numpy_paths():
    """The four-bar pinned along x alone: one row, mobility 2, the only model here whose null-space
    basis F has two columns (a mutant of F's off-diagonal entries survived the other models, issue
    37, item 8). The tangent kernel's own source, run interpreted (compiled, this model would be a
    specialization of its own, 27 s of compilation), against the numpy path (the same rows, numpy's SVD
    and F) at three projected states: measured s̈_tree 9.8e-15 and λ 2.5e-14 relative, bound 1e-13 as
    above."""
    system = four_bar(kind=TangentSystem, axes="x")
    assert system.n_s == 2
    kernel = CompiledClosure(system.tree, system.n_c, system._phi, "tangent", (ACTING,), compiled=False,
                             m_h=system.m_h, pins=pin_table(system._phi, system.m_h))
    for q, s_dot in _states(system):
        found = kernel.accelerations(system, q, s_dot, 0.0)
        assert found is not None, "the kernel flagged the call"
        s_ddot_ref, lam_ref = system.accelerations_tree(q, s_dot, 0.0, "dense")
        lam = np.linalg.lstsq(found[1].T, found[2] @ found[0] + found[3], rcond=None)[0]
        for value, reference in ((found[0], s_ddot_ref), (lam, lam_ref)):
            error = np.abs(value - reference).max() / np.abs(reference).max()
            assert error < 1e-13, error


def _sympy_four_bar():
    """A_s(q) and γ(q, q̇) = (d/dt A_s) q̇ of the four-bar's loop, coupler tip − rocker tip =
    A e(q1) + B e(q1 + q2) − (D, 0) − C e(q3), differentiated by sympy."""
    q = sp.symbols("q1:4")
    u = sp.symbols("u1:4")
    phi = sp.Matrix([A * sp.cos(q[0]) + B * sp.cos(q[0] + q[1]) - D - C * sp.cos(q[2]),
                     A * sp.sin(q[0]) + B * sp.sin(q[0] + q[1]) - C * sp.sin(q[2])])
    jac = phi.jacobian(q)
    gamma = (jac * sp.Matrix(u)).jacobian(q) * sp.Matrix(u)
    return sp.lambdify([q], jac, "numpy"), sp.lambdify([q, u], gamma, "numpy")


@pytest.mark.parametrize("g", [0.0, G])
def test_the_four_bars_accelerations_keep_their_accuracy_at_low_speed(g):
    """The four-bar's s̈_tree at rates scaled by 1, 1e-2, 1e-3 against the KKT system
    [M A_sᵀ; A_s 0] (s̈, −λ) = (−b, −γ) with A_s and γ from sympy and the tree's dense M, b
    (``tree_gauss_form(..., method="dense")``), ṡ_tree in the null space of the sympy A_s. Without
    gravity s̈ ∝ |ṡ|² comes from γ and the Coriolis terms alone, so a γ that lost relative accuracy
    at low speed would show at once: relative error ≤ 1e-12 at every scale for the compiled kernel
    (measured ≤ 4.1e-15 with and without gravity) and for the numpy path (``method="dense"``: Φ″ by
    the complex step inside Richardson's stencil; measured ≤ 1.0e-13, at scale 1 without gravity)."""
    jac, gamma = _sympy_four_bar()
    with _strict():
        system = four_bar(g=g, independent=[0])
        assert system.compiled_kernel() is not None
        for q, s_dot in _states(system, seed=11):
            A_s = np.array(jac(q), dtype=float)
            for scale in (1.0, 1e-2, 1e-3):
                crank = scale * (2.0 + abs(s_dot[0]))
                s_dot_tree = np.concatenate(([crank], -np.linalg.solve(A_s[:, 1:], A_s[:, 0] * crank)))
                assert np.allclose(system.tree_velocities(q, [crank]), s_dot_tree, rtol=1e-13, atol=0)
                M, b = system.tree_gauss_form(q, s_dot_tree, 0.0, method="dense")
                K = np.block([[M, A_s.T], [A_s, np.zeros((2, 2))]])
                rhs = -np.concatenate((b, np.array(gamma(q, s_dot_tree), dtype=float).ravel()))
                expected = np.linalg.solve(K, rhs)[:3]
                for s_ddot in (_kernel(system, q, [crank]), system.accelerations_tree(q, [crank], 0.0, "dense")[0]):
                    error = np.abs(s_ddot - expected).max() / np.abs(expected).max()
                    assert error < 1e-12, (scale, error)


def _power(system, q, s_dot, h=3e-4):
    """dE/dt along (q̇, s̈) by Richardson's extrapolation of central differences of the energy at
    projected neighbours (as tests/constraints/test_elastic_loop.py), and |T| + |V|."""
    q_dot, s_ddot = system.q_dot(q, s_dot), _kernel(system, q, s_dot)[system.independent]

    def energy(step):
        return sum(system.energy(system.project(q + step * q_dot), s_dot + step * s_ddot))

    def central(step):
        return (energy(step) - energy(-step)) / (2 * step)

    return (4 * central(h / 2) - central(h)) / 3, sum(abs(e) for e in system.energy(q, s_dot))


CONSERVATIVE = {
    "four-bar with an undamped spring and gravity": lambda: four_bar(forces=_springs(0.0), independent=[0]),
    "two loops with an undamped spring and gravity": lambda: two_loops(_springs(0.0)),
    # a TangentSystem: the run reaches a singular position at t ≈ 0.8 s, which partitioning cannot pass
    "tangent spatial loop with an undamped spring and gravity": lambda: spatial_loop(
        [pq.SpringDamper("a2", (0.3, 0.0, 0.0), "b1", (0.2, 0.1, 0.0), 30.0, 0.0, length=0.2)], kind=TangentSystem),
}


@pytest.mark.parametrize("name", CONSERVATIVE)
def test_a_conservative_pinned_mechanism_keeps_its_energy(name):
    """The work–energy theorem: gravity and the undamped springs are conservative and the cut
    joints' forces do no work on the closed loop, so dE/dt = 0 along (q̇, s̈) (Richardson's
    extrapolation of central differences, h = 3e-4: O(h⁴) truncation — 7e-10 for the spatial
    loop at h = 1e-3 — and ~1e-16/h round-off of |T| + |V|, with the projections' residuals; bound
    6e-11 of |T| + |V| per unit speed, measured ≤ 6.3e-12 for the spatial loop, ≤ 8.7e-13 for the
    others)."""
    with _strict():
        system = CONSERVATIVE[name]()
        assert system.compiled_kernel() is not None
        for q, s_dot in _states(system, seed=5):
            rate, size = _power(system, q, s_dot)
            assert abs(rate) < 6e-11 * size * (1 + np.abs(s_dot).max()), (rate, size)


@pytest.mark.parametrize("name", CONSERVATIVE)
def test_a_conservative_pinned_mechanism_runs_without_drift(name):
    """One second of motion (the independent velocity at 3 rad/s) in one compiled call per s̈: the
    energy is conserved to the integrator's tolerance (rtol 1e-8: drift bound 4e-7 of max |T| +
    max |V|, measured 1.2e-9 for the four-bar, 1.9e-8 for the two loops, 1.3e-8 for the tangent
    spatial loop) and the loops stay closed (projection onto Φ = 0: |Φ| ≤ 1e-11, measured ≤ 8.8e-13).
    (A kernel call that flags falls back on the numpy path silently here: the tests above take
    the kernel's own answer.)"""
    with _strict():
        system = CONSERVATIVE[name]()
        assert system.compiled_kernel() is not None
        assert "one compiled call" in system.evaluator().reason
        result = pq.simulate(system, 1.0, s_dot0=[3.0], n_points=51)
    energy = result.kinetic + result.potential
    scale = np.abs(result.kinetic).max() + np.abs(result.potential).max()
    assert np.abs(energy - energy[0]).max() < 4e-7 * scale
    assert np.abs(result.constraint_residual).max() < 1e-11
    assert np.abs(result.s_dot).max() > 1.0  # it did move


def test_a_phi_list_of_something_else_is_refused():
    """``phi=[...]`` takes cut joints of one tree only: anything else is a ValueError naming phi."""
    tree = _four_bar_tree()
    pin = PinClosure(tree, "coupler", (B, 0, 0), "rocker", (C, 0, 0), axes="xy")
    with pytest.raises(ValueError, match=r"^phi: "):
        ConstrainedSystem(tree, phi=[pin, "x"], q0=_four_bar_q0())
    with pytest.raises(ValueError, match=r"^phi: "):
        ConstrainedSystem(tree, phi=[], q0=_four_bar_q0())
    other = _four_bar_tree()
    with pytest.raises(ValueError, match=r"^phi: .*different trees"):
        ConstrainedSystem(tree, phi=[pin, PinClosure(other, "coupler", (B, 0, 0), None, (0, 0, 0), axes="z")],
                          q0=_four_bar_q0())


@pytest.mark.parametrize("as_list", [False, True], ids=["pin", "[pin]"])
def test_a_cut_joint_of_another_tree_is_refused(as_list):
    """A cut joint is stated on its own tree's bodies: given with another tree it is refused
    (ValueError naming phi), as pins of two different trees in one list are. Accepted, the compiled
    kernel (the pin's body numbers into ``tree``) and the numpy path (Φ on the pin's tree) solved
    different mechanisms without a word (crank 0.35 vs 0.3: s̈_tree[1] 51.57 vs 53.23)."""
    tree = _four_bar_tree()
    other = pq.System(
        {"crank": _rod(1.0, A), "coupler": _rod(2.0, B), "rocker": _rod(1.5, C)},
        {"crank": pq.Revolute(axis="z"), "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(0.35, 0, 0)),
         "rocker": pq.Revolute(axis="z", r_pn=(D, 0, 0))},
        gravity=(0, -G, 0),
    )
    pin = PinClosure(other, "coupler", (B, 0, 0), "rocker", (C, 0, 0), axes="xy")
    with pytest.raises(ValueError, match=r"^phi: the cut joints hold points of another tree"):
        ConstrainedSystem(tree, phi=[pin] if as_list else pin, q0=_four_bar_q0(), independent=[0], project_q0=True)
