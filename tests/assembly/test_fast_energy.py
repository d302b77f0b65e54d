"""The energies on the compiled kinematics (:meth:`projeq.assembly.fast.FastEvaluator.energy`:
T = ½ Σ ẏ_nᵀ M_n ẏ_n with the kernel's M_n, V at the kernel's poses) against two independent
references: the reference kinematics with each subsystem's own kinetic energy
(``System.energy(method="recursive")``) on random trees with every compiled joint kind (spatial,
planar, coupled, rheonomic), every force law and RitzBeams; and the conservation of T + V along
the motion of conservative trees (dE/dt = ∇E · ẋ = 0), which fails if any term of T or V is
left out (gravity, a spring's or a beam's strain energy)."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from strategies import random_state, trees, with_couplings, with_every_law
from test_fast_beams import trees_with_beams

import projeq as pq
from projeq.assembly import kernels

pytestmark = pytest.mark.skipif(not kernels.has_numba(), reason="numba is not installed")

FEW = settings(max_examples=max(5, settings().max_examples // 5), deadline=None,
               suppress_health_check=[HealthCheck.too_slow])


def _agree(system, q, s_dot, t):
    """The compiled energies equal the reference ones to round-off of the terms' size."""
    fast = system.energy(q, s_dot, t, method="fast")
    reference = system.energy(q, s_dot, t, method="recursive")
    scale = 1.0 + sum(abs(e) for e in reference)
    np.testing.assert_allclose(fast, reference, rtol=0, atol=1e-13 * scale)
    assert system.energy(q, s_dot, t) == fast  # the default is the compiled one


@FEW
@given(trees(max_n=10))
def test_energy_on_spatial_trees_with_every_joint_and_law(tree):
    """Every spatial joint kind (prescribed and turntable: rheonomic), damped and callable
    laws (with or without a potential), and every law once more with constant loads."""
    system = with_every_law(tree)
    _agree(system, *random_state(system, tree.rng, speed=3.0))


@FEW
@given(trees(max_n=10, planar=True))
def test_energy_on_planar_trees(tree):
    """Planar bodies: the kernel's spatial twist and M⁶ against the selected ẏ = S twist and
    S M⁶ Sᵀ."""
    _agree(tree.system, tree.q, tree.s_dot, tree.t)


@FEW
@given(trees(max_n=6))
def test_energy_with_coupled_joints(tree):
    system = with_couplings(tree)
    _agree(system, *random_state(system, tree.rng))


@FEW
@given(trees_with_beams())
def test_energy_of_trees_with_beams(tree):
    """Elastic bodies: ẏ_n = (twist, q̇_e), M_n at q_e; gravity on the slices and strain energy."""
    _agree(tree.system, tree.q, tree.s_dot, tree.t)


def test_energy_of_a_constrained_scene_is_its_trees():
    system = pq.scenes.four_bar()
    q, s_dot = system.q0, system.s_dot0 + 0.7
    s_dot_tree = system.tree_velocities(q, s_dot)
    _agree(system.tree, q, s_dot_tree, 0.0)
    assert system.energy(q, s_dot) == system.tree.energy(q, s_dot_tree, 0.0, method="fast")


def _power(system, q, s_dot, t=0.0, h=1e-4):
    """dE/dt of the compiled E = T + V along ẋ = (q̇, s̈), by central differences at h and h/2
    combined by Richardson's extrapolation (error O(h⁴): the central difference alone, O(h²),
    was 1.9e-6 of |T| + |V| at h = 1e-5 on a tree of free joints and spring-dampers, 3.5e-8 at
    1e-6, shrinking as h² — conserved, but above the tests' 1e-7), and |T| + |V|."""
    q_dot, s_ddot = system.q_dot(q, s_dot, t), system.accelerations(q, s_dot, t)

    def E(step):
        return sum(system.energy(system.normalized(q + step * q_dot), s_dot + step * s_ddot, t))

    def central(step):
        return (E(step) - E(-step)) / (2 * step)

    return (4 * central(h / 2) - central(h)) / 3, sum(abs(e) for e in system.energy(q, s_dot, t))


@FEW
@given(trees(max_n=6, forces="conservative", scleronomic=True))
def test_compiled_energy_is_conserved_on_conservative_trees(tree):
    """Gravity, joint springs and spring-dampers without damping: dE/dt = 0."""
    power, scale = _power(tree.system, tree.q, tree.s_dot)
    assert abs(power) < 1e-7 * scale * (1 + np.abs(tree.s_dot).max(initial=0.0))


def _beam_on_a_spring(gravity):
    """A RitzBeam (bending and stiffening, no damping) on a revolute joint with a joint spring
    and a spring-damper to the ground, carrying a point mass at its tip."""
    beam = pq.RitzBeam(1.2, 2.0, 40.0, EI_y=30.0, n_v=2, n_w=1, stiffening=True)
    return pq.System(
        {"beam": beam, "tip": pq.PointMass(0.5)},
        {"beam": pq.Revolute(None, (0.0, 0.3, 1.0)), "tip": pq.Fixed("beam", (1.2, 0.0, 0.0))},
        gravity=gravity,
        forces=[pq.JointSpring("beam", 3.0, q_ref=0.2),
                pq.SpringDamper(None, (0.5, 0.5, 0.0), "tip", (0.0, 0.0, 0.0), 7.0)],
    )


def test_compiled_energy_is_conserved_with_a_beam():
    system = _beam_on_a_spring((0.0, -9.81, -2.0))
    q = np.array([0.4, 0.05, -0.03, 0.02])
    power, scale = _power(system, q, np.array([1.0, -2.0, 3.0, 1.5]))
    assert abs(power) < 1e-7 * scale


def test_an_unknown_energy_method_is_refused_by_name():
    system = pq.scenes.chain(2)
    with pytest.raises(ValueError, match="method: unknown energy evaluation 'dense'"):
        system.energy(system.q0, system.s_dot0, 0.0, method="dense")
