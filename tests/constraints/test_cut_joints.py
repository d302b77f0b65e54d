"""Cut joints: the wrench of a loop's cut joint from its multipliers (issue 4, item 2; docs/theory.md §7)."""

import numpy as np
import pytest

import projeq as pq
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.constraints.cut_joints import PinClosure
from projeq.assembly.kinematics import forward
from projeq.constraints.reactions import joint_reactions
from projeq.scenes.mechanisms import four_bar

M_ROD, L_ROD, G = 1.3, 0.9, 9.81


@pytest.fixture(scope="module")
def pendulum():
    """A uniform rod (x–y plane, along its body x from its joint) on x and y sliders, its end
    pinned to the origin by a cut revolute joint: a physical pendulum, ψ its angle."""
    tree = pq.System(
        {"x": pq.Frame(), "y": pq.Frame(), "rod": pq.PlanarBody(M_ROD, (L_ROD / 2, 0, 0), M_ROD * L_ROD**2 / 12)},
        {"x": pq.Prismatic(axis="x"), "y": pq.Prismatic(parent="x", axis="y"),
         "rod": pq.Revolute(parent="y", axis="z")},
        gravity=(0, -G, 0),
    )
    pin = PinClosure(tree, "rod", (0, 0, 0), None, (0, 0, 0), axes="xy")
    return ConstrainedSystem(tree, phi=pin, q0=[0.0, 0.0, -np.pi / 2]), pin


@pytest.mark.parametrize("theta, omega", [(0.0, 0.0), (0.7, 2.0), (2.0, -1.5)])
def test_pin_force_of_a_physical_pendulum(pendulum, theta, omega):
    """Newton's law for the centre of a uniform rod swinging about its end (θ from the
    downward vertical, θ̈ = −3g sin θ / (2L) from I_end = mL²/3): the pin pulls the rod
    towards the pin with m (g cos θ + (L/2) θ̇²) and pushes it along the swing direction
    with (m g / 4) sin θ. Both from the cut joint's multipliers, and the tree's own joints
    (the sliders and the rod's revolute) carry nothing: the pin holds the rod."""
    system, pin = pendulum
    psi = theta - np.pi / 2  # rod axis e_r = (cos ψ, sin ψ) points from the pin to the centre
    W = joint_reactions(system, [0.0, 0.0, psi], [omega], cuts={"pin": pin})
    f_body = W["pin"][:2]  # the planar wrench (f_x, f_y, m_z) in the rod's axes: e_r = x, e_θ = y
    scale = M_ROD * (G + L_ROD * omega**2)
    # algebraic, with the cut joint's A_s and γ exact (the compiled kernel's own, from the chain):
    # round-off, bound 2e-15 (measured 1.0e-16, 6.5e-17, 0 and 2.0e-16 for the tree's joints)
    assert abs(f_body[0] + M_ROD * (G * np.cos(theta) + L_ROD / 2 * omega**2)) < 2e-15 * scale
    assert abs(f_body[1] - M_ROD * G / 4 * np.sin(theta)) < 2e-15 * scale
    assert abs(W["pin"][2]) < 2e-15 * scale  # applied at O_rod: no moment about it
    for name in ("x", "y", "rod"):
        assert np.abs(W[name]).max() < 2e-15 * scale


def test_pin_closure_is_the_four_bars_loop():
    """The four-bar's loop (coupler tip on rocker tip, written out in test_loops' scene) is
    the pin closure of those two points along x and y."""
    system = four_bar()
    pin = PinClosure(system.tree, "coupler", (1.0, 0, 0), "rocker", (0.8, 0, 0), axes="xy")
    for q in ([0.5, 1.2, -0.3], [2.0, -0.4, 1.1]):
        assert np.abs(pin(q) - system.phi(np.array(q))).max() < 1e-15  # the same formula: round-off


def test_four_bar_joints_carry_no_force_along_their_free_directions():
    """The Projection Equation per joint: with the cut joint's force applied where it acts,
    every tree joint's transmitted wrench has no part along its free directions, F_nᵀ W_n = 0
    (without the cut force the crank joint would carry (A_sᵀλ)_crank ≠ 0); Newton's third
    law at the pin: the rocker receives −λ."""
    crank = four_bar()
    tree = crank.tree
    pin = PinClosure(tree, "coupler", (1.0, 0, 0), "rocker", (0.8, 0, 0), axes="xy")
    system = ConstrainedSystem(tree, phi=pin, independent=[0], q0=crank.q0, s_dot0=[3.0])
    W = joint_reactions(system, system.q0, [3.0], cuts={"pin": pin})
    kin = forward(tree, system.q0, system.tree_velocities(system.q0, [3.0]), 0.0)
    scale = np.abs(W["pin"]).max()
    for n, name in enumerate(tree.names):
        # A_s and γ of the nonlinear closure exact (the compiled kernel's, from the chain's body
        # Jacobians and the points' accelerations): round-off, bound 6e-15 (measured 5.9e-16)
        assert np.abs(kin.F[n].T @ W[name]).max() < 6e-15 * scale
    assert np.abs(W["crank"]).max() > 0.1 * scale  # the crank joint does carry the loop
    lam = system.accelerations_tree(system.q0, [3.0])[1]
    rocker = pin.wrenches(kin, lam)[tree.index("rocker")]
    # round-off (measured 1.4e-16 of the pin's largest force component)
    assert np.allclose(kin.R[tree.index("rocker")][:2, :2] @ rocker[:2], -lam, rtol=0, atol=2e-15 * scale)
