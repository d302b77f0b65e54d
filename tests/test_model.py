"""One model protocol (issue 14, item 3): a System and a ConstrainedSystem are both a
:class:`projeq.system.Model`, answer the same calls, and simulate, linearize, the reactions
and the export take either; a System is immutable, its kinematic plan built once."""

import numpy as np
import pytest

import projeq as pq
from projeq.assembly.kernels import has_numba
from projeq.assembly.kinematics import Plan, plan
from projeq.constraints.cut_joints import PinClosure
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.constraints.reactions import reactions
from projeq.scenes.mechanisms import four_bar_angles, slider_pendulum
from projeq.system import Model

# the order-n evaluators: "auto" (the compiled kernel with numba, else recursive) and "fast",
# which is the compiled kernel only (numba)
ORDER_N = ("recursive", "auto") + (("fast",) if has_numba() else ())

M, L, G = 2.0, 1.5, 9.81


def _pendulum() -> pq.System:
    """A point mass M on a massless rod L about y: q = θ from the downward vertical, with
    the bob at (−L sin θ, −L cos θ) in the x–z plane."""
    return pq.System({"bob": pq.PointMass(M, (0, 0, -L))}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -G))


def _spatial_four_bar() -> ConstrainedSystem:
    """A crank–rocker four-bar of spatial rigid rods on revolute joints about z (what the
    compiled kernel evaluates itself), the coupler tip pinned to the rocker tip (PinClosure)."""

    def rod(m, length):
        return pq.RigidBody(m, (length / 2, 0, 0), np.diag([1e-4, m * length**2 / 12, m * length**2 / 12]))

    a, b, c, d = 0.3, 1.0, 0.8, 1.0
    tree = pq.System(
        {"crank": rod(1.0, a), "coupler": rod(2.0, b), "rocker": rod(1.5, c)},
        {"crank": pq.Revolute(axis="z"), "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(a, 0, 0)),
         "rocker": pq.Revolute(axis="z", r_pn=(d, 0, 0))},
        gravity=(0, -G, 0),
    )
    theta2, theta3 = four_bar_angles(0.7, a, b, c, d)
    pin = PinClosure(tree, "coupler", (b, 0, 0), "rocker", (c, 0, 0), axes="xy")
    q0, _ = tree.state(crank=0.7, coupler=theta2 - 0.7, rocker=theta3)
    return ConstrainedSystem(tree, phi=pin, q0=q0, independent=[0])


def test_both_kinds_are_models():
    assert isinstance(_pendulum(), Model) and isinstance(slider_pendulum(), Model)


def test_a_constrained_system_answers_like_a_system():
    """The pendulum twice: a revolute joint (System, ṡ = θ̇), and x, z sliders held on the
    circle √(x² + z²) = L (ConstrainedSystem, ṡ = ẋ). At the same physical state (x, z) =
    L (−sin θ, −cos θ), ẋ = −L cos θ θ̇, the same calls give the same physics: energies,
    q̇ = (ẋ, ż) = L θ̇ (−cos θ, sin θ) and ẍ = −L cos θ θ̈ + L sin θ θ̇², with every evaluator.
    100 ε relative for the energies and q̇ (measured 0: the same numbers), 5.8e-13 for the accelerations
    (measured 5.8e-14 with each evaluator: the constraint's second derivative; were 3e-13 and 1e-10)."""
    system, constrained = _pendulum(), slider_pendulum(l=L, m=M, g=G)
    theta, theta_dot = 0.4, -1.3
    q, x_dot = L * np.array([-np.sin(theta), -np.cos(theta)]), -L * np.cos(theta) * theta_dot
    eps = np.finfo(float).eps
    expected_energy = system.energy([theta], [theta_dot])
    assert constrained.energy(q, [x_dot]) == pytest.approx(expected_energy, rel=100 * eps, abs=0)
    expected_q_dot = L * theta_dot * np.array([-np.cos(theta), np.sin(theta)])
    assert np.allclose(constrained.q_dot(q, [x_dot]), expected_q_dot, rtol=100 * eps, atol=0)
    for method in ("dense", *ORDER_N):
        theta_ddot = system.accelerations([theta], [theta_dot], 0.0, method=method)[0]
        x_ddot = constrained.accelerations(q, [x_dot], 0.0, method=method)[0]
        expected = -L * np.cos(theta) * theta_ddot + L * np.sin(theta) * theta_dot**2
        assert x_ddot == pytest.approx(expected, rel=5.8e-13), (method, x_ddot / expected - 1)
    M_min, b_min = constrained.gauss_form(q, [x_dot])
    assert -b_min[0] / M_min[0, 0] == pytest.approx(constrained.accelerations(q, [x_dot])[0], rel=1e-14)


def test_the_evaluators_of_a_constrained_system_agree_to_round_off():
    """``method`` picks the tree's evaluator (dense Gauss form; recursive and compiled order
    n, through the free accelerations M s̈_free + b = 0): s̈ and the loop forces λ agree to
    round-off, 1e-14 relative (measured 2e-15 at three states of a four-bar)."""
    system = _spatial_four_bar()
    rng = np.random.default_rng(3)
    for s_dot in ([2.0], [-3.0], rng.standard_normal(1)):
        dense, lam = system.accelerations_tree(system.q0, s_dot, 0.0, "dense")
        for method in ORDER_N:
            s_ddot_tree, lam_method = system.accelerations_tree(system.q0, s_dot, 0.0, method)
            assert np.abs(s_ddot_tree - dense).max() < 1e-14 * np.abs(dense).max(), method
            assert np.abs(lam_method - lam).max() < 1e-14 * np.abs(lam).max(), method
            assert system.accelerations(system.q0, s_dot, method=method) == pytest.approx(
                dense[system.independent], rel=1e-14)


def test_linearize_takes_the_inputs_of_either_kind():
    """A horizontal force τ on the slider x of the constrained pendulum: small oscillations
    ẍ = −(g/L) x + τ/M (Newton, x = L θ); a torque τ on the revolute pendulum:
    θ̈ = −(g/L) θ + τ/(M L²). The dependent z is ignorable. B is exact (the Gauss form is
    linear in τ); A of the constrained one is exact too now (measured 2.6e-13 relative, was 1.1e-9 by
    second differences; bound 10 times that, was 5e-9), the tree's to round-off (measured 1.4e-16
    relative; 100 ε, was 1e-12)."""
    constrained = pq.linearize(slider_pendulum(l=L, m=M, g=G, theta0=0.0), inputs=["x"])
    assert constrained.states == ("x.q[0]", "x.s_dot[0]") and constrained.dropped == ("bob.q[0]",)
    assert np.abs(constrained.A - [[0, 1], [-G / L, 0]]).max() < 2.6e-12 * G / L
    assert constrained.B[:, 0].tolist() == [0.0, 1 / M]
    tree = pq.linearize(_pendulum(), inputs=["bob"])
    assert np.abs(tree.A - [[0, 1], [-G / L, 0]]).max() < 100 * np.finfo(float).eps * G / L
    assert tree.B[:, 0] == pytest.approx([0.0, 1 / (M * L * L)], rel=1e-14)


def test_a_system_has_no_multipliers():
    """A System's constraints are in its joints: no multipliers λ, no contact event."""
    system = _pendulum()
    assert system.n_lambda == 0 and system.accelerations_tree([0.3], [0.0])[1].shape == (0,)
    with pytest.raises(ValueError, match="system: contact events need a ConstrainedSystem"):
        pq.contact_event(system, 0)
    with pytest.raises(ValueError, match="system: reactions need a ConstrainedSystem"):
        reactions(system, pq.simulate(system, 0.1, n_points=2))


def test_a_system_is_immutable_with_its_plan_built_once():
    system = _pendulum()
    assert isinstance(system.plan, Plan) and plan(system) is system.plan
    with pytest.raises(AttributeError, match="System is immutable: cannot set 'gravity' after construction"):
        system.gravity = np.zeros(3)
    with pytest.raises(AttributeError, match="System is immutable: cannot set 'names'"):
        system.names = ("other",)
    with pytest.raises(AttributeError, match="System is immutable: cannot delete 'q0'"):
        del system.q0
    system.accelerations([0.3], [0.0])
    assert plan(system) is system.plan and "_plan" not in system._evaluators


@pytest.mark.parametrize(
    "call",
    [
        lambda: pq.simulate("pendulum", 1.0),
        lambda: pq.linearize(None),
        lambda: pq.joint_reactions({}, [0.0], [0.0]),
    ],
    ids=["simulate", "linearize", "joint_reactions"],
)
def test_only_a_model_is_taken(call):
    with pytest.raises(ValueError, match=r"^system: expected a System or a ConstrainedSystem"):
        call()


def test_a_constrained_system_names_its_evaluator():
    with pytest.raises(ValueError, match=r"^method: unknown evaluator 'newton'"):
        slider_pendulum().accelerations([0.479425538604203, -0.8775825618903728], [0.0], method="newton")


def test_each_input_once():
    with pytest.raises(ValueError, match=r"^inputs: each joint at most once"):
        pq.linearize(_pendulum(), inputs=["bob", "bob"])
