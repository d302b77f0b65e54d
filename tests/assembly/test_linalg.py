"""The pivots of the recursive pass and the Gauss form's mass matrix: a zero pivot (a motion
that moves no mass) and a negative one (which no mass distribution gives) get different
messages, each naming the joint."""

import warnings

import numpy as np
import pytest

from projeq.assembly.linalg import AccuracyWarning, SingularMassError, solve_spd


@pytest.mark.parametrize("D", [np.array([[0.0]]), np.diag([1.0, 0.0])])
def test_a_zero_pivot_is_a_motion_that_moves_no_mass(D):
    with pytest.raises(SingularMassError, match=r"joint 'elbow'.*moves no mass"):
        solve_spd(D, np.ones((len(D), 1)), "elbow", 1.0)


@pytest.mark.parametrize("D", [np.array([[-6.7e7]]), np.diag([1.0, -2.0])])
def test_a_negative_pivot_says_the_state_left_the_model(D):
    """A positive semi-definite M̂_n (Σ mass × velocity² ≥ 0) cannot give a negative pivot:
    the message names the eigenvalue and the state, not a massless motion."""
    with pytest.raises(SingularMassError, match=r"joint 'fore' is indefinite.*left the range") as error:
        solve_spd(D, np.ones((len(D), 1)), "fore", 1.0)
    assert "moves no mass" not in str(error.value) and f"{np.linalg.eigvalsh(D)[0]:.3g}" in str(error.value)


G, L1, L2 = 9.81, 1.0, 0.7


def _double_pendulum(m1: float, m2: float):
    """Two point masses on rods of L1 and L2 about parallel y axes, joint angles φ1 (from the
    vertical) and φ2 (relative to the upper rod)."""
    import projeq as pq

    bodies = {"upper": pq.PointMass(m1, (0, 0, -L1)), "lower": pq.PointMass(m2, (0, 0, -L2))}
    joints = {"upper": pq.Revolute(axis="y"), "lower": pq.Revolute(parent="upper", axis="y", r_pn=(0, 0, -L1))}
    return pq.System(bodies, joints, gravity=(0, 0, -G))


def _closed_form(m1: float, m2: float, q, s_dot):
    """s̈ of the double pendulum from its textbook equations in the absolute angles θ1 = φ1, θ2 = φ1 + φ2
    (Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed., 2002, §1.6 Lagrange's equations; e.g.
    Shinbrot et al., Am. J. Phys. 60, 491 (1992), eq. 1), the second divided by m2 L2 (no m2 left in it):
        (m1 + m2) L1 θ̈1 + m2 L2 cos(θ1 − θ2) θ̈2 = −m2 L2 θ̇2² sin(θ1 − θ2) − (m1 + m2) g sin θ1
        L1 cos(θ1 − θ2) θ̈1 + L2 θ̈2 = L1 θ̇1² sin(θ1 − θ2) − g sin θ2
    (a rotation about +y by φ takes the bob at (0, 0, −L) to x = −L sin φ: θ here is −φ, and s̈ flips
    sign with it, which the linear equations above absorb by g → −g applied to θ = −φ)."""
    th1, th2 = -q[0], -(q[0] + q[1])
    w1, w2 = -s_dot[0], -(s_dot[0] + s_dot[1])
    c, s = np.cos(th1 - th2), np.sin(th1 - th2)
    A = np.array([[(m1 + m2) * L1, m2 * L2 * c], [L1 * c, L2]])
    b = np.array([-m2 * L2 * w2 ** 2 * s - (m1 + m2) * G * np.sin(th1), L1 * w1 ** 2 * s - G * np.sin(th2)])
    th1_dd, th2_dd = np.linalg.solve(A, b)
    return np.array([-th1_dd, -(th2_dd - th1_dd)])


@pytest.mark.parametrize("method", ["recursive", "dense", "fast"])
@pytest.mark.parametrize("ratio", [1e-16, 1e-12, 1.0])
def test_a_light_bob_on_a_heavy_one_is_solved(method, ratio):
    """Passes if a double pendulum whose lower bob is ``ratio`` times the upper one's mass is solved
    by each evaluator, equal to the closed form to 100 ε max(1, |s̈|) (measured: 3.4e-16 max(1, |s̈|),
    the worst of the three evaluators and ratios, dense and fast at 1e-16). Before (issue 37, item 5), 1e-16 was refused as
    "singular (pivot 1e-16): it moves no mass": every pivot was compared with the heaviest body's
    scale, now each with the mass its joint carries (projeq.assembly.linalg.mass_scales)."""
    import projeq as pq

    system = _double_pendulum(2.0, 2.0 * ratio)
    q, s_dot = np.array([0.4, -0.9]), np.array([1.3, -0.6])
    expected = _closed_form(2.0, 2.0 * ratio, q, s_dot)
    with warnings.catch_warnings():  # dense: κ(M) = 2e16 from the scales alone; Cholesky does not feel it
        warnings.simplefilter("ignore", AccuracyWarning)
        got = system.accelerations(q, s_dot, method=method)
    error = np.abs(got - expected).max()
    assert error <= 100 * np.finfo(float).eps * max(1.0, np.abs(expected).max()), f"|s̈ − closed form| = {error:.3g}"


@pytest.mark.parametrize("method", ["recursive", "dense", "fast"])
@pytest.mark.filterwarnings("ignore::projeq.assembly.linalg.AccuracyWarning")  # dense: κ(M) = inf, refused next
def test_a_truly_massless_pivot_is_still_named(method):
    """Passes if a massless link between two joints on one axis (the pivot of the first cancels to
    round-off, +3.1e-16 here, ε times the body it carries: accepted if the link were measured by
    its own mass) and a massless leaf (pivot exactly 0) are still refused, naming the joint (the
    recursive and compiled passes) or the mass matrix (dense)."""
    import projeq as pq

    bob = pq.RigidBody(3.0, (0.1, 0.2, -1.0), np.diag([0.2, 0.3, 0.4]))
    coaxial = pq.System({"link": pq.Frame(), "bob": bob},  # an oblique axis: the link's pivot is +3.1e-16, not 0
                        {"link": pq.Revolute(axis=(1, 1, 0)), "bob": pq.Revolute(parent="link", axis=(1, 1, 0))})
    leaf = pq.System({"bob": pq.PointMass(3.0, (0, 0, -1.0)), "tip": pq.Frame()},
                     {"bob": pq.Revolute(axis="y"), "tip": pq.Revolute(parent="bob", axis="y", r_pn=(0, 0, -1.0))})
    for system, joint in ((coaxial, "link"), (leaf, "tip")):
        who = "system mass matrix M" if method == "dense" else f"joint {joint!r}"
        with pytest.raises(SingularMassError, match=f"{who}.*(singular|moves no mass)"):
            system.accelerations(np.array([0.3, 0.2]), np.array([0.5, -0.4]), method=method)


@pytest.mark.parametrize("ratio", [1e-16, 1.0])
def test_a_light_pendulum_beside_coupled_joints_is_solved(ratio):
    """Passes if a pendulum ``ratio`` times lighter than the geared pair it hangs from (a gear g follows
    the arm a at −2 θ̇_a: coupled joints, the compiled evaluator's projected M = Pᵀ M_all P) is solved by
    the compiled evaluator equal to the dense Gauss form (numpy's Cholesky of M, each pivot against the
    mass its velocity moves) to 100 ε max(1, |s̈|) (measured 4.0e-16 at 1e-16, 1.5e-15 at 1). Before, its one
    pivot bound was the heaviest body's scale and 1e-16 was refused as a singular M."""
    import projeq as pq

    bodies = {"a": pq.RigidBody(2.0, (0, 0, -0.5), np.diag([0.1, 0.1, 0.02])),
              "g": pq.RigidBody(1.0, (0, 0, 0), np.diag([0.05, 0.05, 0.01])),
              "light": pq.PointMass(2.0 * ratio, (0, 0, -0.7))}
    joints = {"a": pq.Revolute(axis="y"), "g": pq.Revolute(axis="y", r_pn=(1, 0, 0), coupling={"a": -2.0}),
              "light": pq.Revolute(parent="a", axis="y", r_pn=(0, 0, -1.0))}
    system = pq.System(bodies, joints, gravity=(0, 0, -G))
    q, s_dot = np.array([0.4, -0.9]), np.array([1.3, -0.6])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)
        dense = system.accelerations(q, s_dot, method="dense")
    error = np.abs(system.accelerations(q, s_dot, method="fast") - dense).max()
    assert error <= 100 * np.finfo(float).eps * max(1.0, np.abs(dense).max()), f"|fast − dense| = {error:.3g}"
