"""The energies on the compiled kinematics (:meth:`projeq.assembly.fast.FastEvaluator.energy`:
T = ½ Σ ẏ_nᵀ M_n ẏ_n with the kernel's M_n, V at the kernel's poses) against two independent
references: the reference kinematics with each subsystem's own kinetic energy
(``System.energy(method="recursive")``) on random trees with every compiled joint kind (spatial,
planar, coupled, rheonomic), every force law and RitzBeams; and the conservation of T + V along
the motion of conservative trees (dE/dt = ∇E · ẋ = 0), which fails if any term of T or V is
left out (gravity, a spring's or a beam's strain energy)."""

import functools
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import random_rotation, random_state, trees, with_couplings, with_every_law
from test_fast_beams import trees_with_beams

import projeq as pq
from projeq.assembly import kernels
from projeq.assembly.beam_fast import HubBeamEvaluator
from projeq.assembly.kinematics import poses
from projeq.constraints.reactions import joint_reactions
from projeq.joints.base import Relative
from projeq.spatial import rotation

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


@FEW
@given(trees(max_n=8, forces=False), st.booleans())
def test_energies_of_rows_together_are_each_rows_energy(tree, coupled):
    """FastEvaluator.energies (simulate's output rows: one compiled kinematics call for all rows,
    kernels.rows_kinematics, T and V stacked) equals :meth:`energy` row by row on trees with every
    joint kind (prescribed and turntable joints, of kind GIVEN, at each row's own time) and coupled
    joints, to round-off (T is summed in another order: measured ≤ 4.3e-16 relative on the scenes
    chain(5), double_pendulum, atwood, rolling_disk)."""
    system = with_couplings(tree) if coupled else tree.system
    states = [random_state(system, tree.rng, speed=3.0) for _ in range(4)]
    q_rows, s_rows, times = (np.array(column) for column in zip(*states))
    rows = np.array([system.energy(q, s_dot, t, method="fast") for q, s_dot, t in states])
    together = system.evaluator("fast").energies(q_rows, s_rows, times)
    np.testing.assert_allclose(together, rows, rtol=0, atol=4e-15 * (1.0 + np.abs(rows).max()))


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


# -- one beam on a hub whose motion is given (HubBeamEvaluator.energy) ----------------------------
class _ScrewHub(pq.Joint):
    """A hub without coordinates that turns by θ(t) = a t² about its axis e and advances p θ
    along it (rheonomic; no compiled kind: the hub kernel reads its ``relative_values``, kind
    GIVEN): A = rot(e, θ), r = p θ e, w = θ̇ (p e, e), ζ = θ̈ (p e, e)."""

    def __init__(self, axis, pitch, rate, **placement):
        super().__init__(None, **placement)
        self.axis, self.pitch, self.rate = np.asarray(axis, float) / np.linalg.norm(axis), pitch, rate

    def relative(self, q_n, s_dot_n, t):
        theta, theta_dot, theta_ddot = self.rate * t**2, 2 * self.rate * t, 2 * self.rate
        e, p = self.axis, self.pitch
        twist = np.concatenate((p * e, e))
        return Relative(rotation(e, theta), p * theta * e, np.zeros((6, 0)), theta_dot * twist, theta_ddot * twist)


def _hub_beam(hub: str, rate: float, rng, damping=0.02) -> pq.System:
    """A RitzBeam (bending both ways, axial, stiffening, damping) under tilted gravity on a hub
    ``hub`` placed at a random offset and orientation: turning at the spin-up θ = rate t² /
    (1 + t) (rheonomic), advancing along its axis, a screw motion (kind GIVEN) or fixed."""
    beam = pq.RitzBeam(1.3, 1.6, 20.0, EI_y=30.0, EA=700.0, n_v=2, n_w=2, n_u=1, family="clamped_free",
                       damping=damping)
    placement = {"r_pn": rng.uniform(-0.5, 0.5, 3), "orientation": random_rotation(rng)}
    axis = rng.standard_normal(3)
    motion = lambda t: (rate * t**2 / (1 + t), rate * (t**2 + 2 * t) / (1 + t) ** 2, 2 * rate / (1 + t) ** 3)  # noqa: E731
    joint = {"revolute": lambda: pq.Prescribed(pq.Revolute(axis=axis / np.linalg.norm(axis), **placement), motion),
             "prismatic": lambda: pq.Prescribed(pq.Prismatic(axis=axis / np.linalg.norm(axis), **placement), motion),
             "screw": lambda: _ScrewHub(axis, 0.3, rate, **placement),
             "fixed": lambda: pq.Fixed(**placement)}[hub]()
    return pq.System({"beam": beam}, {"beam": joint}, gravity=rng.uniform(-10, 10, 3))


HUB_SCENES = {
    "spin-up, gravity": lambda rate, rng: pq.scenes.spin_up_beam(omega_s=rate, t_s=5.0, n_shapes=2, n_axial=1,
                                                                 gravity=9.81),
    "spin-up precomputed, unstiffened": lambda rate, rng: pq.scenes.spin_up_beam(
        omega_s=rate, t_s=5.0, n_shapes=2, stiffening=False, precomputed_integrals=True),
    "spinning": lambda rate, rng: pq.scenes.spinning_beam(omega=rate, n_shapes=3),
    "spinning, rotary inertia": lambda rate, rng: pq.scenes.spinning_beam(omega=rate, rho_I=1e-2, n_shapes=2),
    **{f"{hub} hub": functools.partial(lambda hub, rate, rng: _hub_beam(hub, rate, rng), hub)
       for hub in ("revolute", "prismatic", "screw", "fixed")},
}


@FEW
@given(st.sampled_from(sorted(HUB_SCENES)), st.floats(0.2, 8.0), st.floats(0.0, 12.0), st.integers(0, 2**32 - 1))
def test_hub_beam_energy_equals_the_reference(scene, rate, t, seed):
    """T and V of the hub kernel (T = ½ ẏᵀ M_n ẏ with the kernel's M_n and the hub's twist; V,
    the beam's own at the kernel's pose) equal each subsystem's own kinetic and potential
    energy on the reference kinematics at random states, spin rates and times, on every hub
    kind the kernel knows (revolute, prismatic, fixed) and one it reads (GIVEN); the default
    energy of these systems is the hub kernel's."""
    rng = np.random.default_rng(seed)
    system = HUB_SCENES[scene](rate, rng)
    assert system.evaluator(None).name == "hub_beam" and system.evaluator("hub_beam").compiled
    q, s_dot = 0.05 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the unstiffened beam may spin too fast: said once
        fast = system.energy(q, s_dot, t, method="hub_beam")
        reference = system.energy(q, s_dot, t, method="recursive")
        assert system.energy(q, s_dot, t) == fast  # the default is the compiled one
    # measured 1.1e-15 relative at most (was 1e-13)
    np.testing.assert_allclose(fast, reference, rtol=100 * np.finfo(float).eps,
                               atol=100 * np.finfo(float).eps * (1.0 + sum(abs(e) for e in reference)))


@pytest.mark.parametrize("hub", ["revolute", "prismatic", "screw"])
def test_hub_beam_energy_balance_under_a_driven_hub(hub):
    """dE/dt = W · ẏ: the rate of the compiled E = T + V along the motion of an undamped beam
    (time included: the hub moves as given) is the power of the wrench W the hub transmits
    (:func:`projeq.constraints.reactions.joint_reactions`, B(14) on the reference kinematics)."""
    rng = np.random.default_rng(5)
    system = _hub_beam(hub, 2.0, rng, damping=0.0)
    q, s_dot, t = 0.05 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s), 1.3
    s_ddot = system.accelerations(q, s_dot, t)

    def rate(h):  # central differences of E along (q̇, s̈, 1)
        E = [sum(system.energy(q + step * s_dot, s_dot + step * s_ddot, t + step)) for step in (h, -h)]
        return (E[0] - E[1]) / (2 * h)

    E_dot = (4 * rate(5e-5) - rate(1e-4)) / 3  # Richardson: error O(h⁴)
    power = joint_reactions(system, q, s_dot, t)["beam"] @ poses(system, q, s_dot, t).y_dot[0]
    scale = sum(abs(e) for e in system.energy(q, s_dot, t))
    assert abs(power) > 1e-2 * scale  # the hub does work here
    assert abs(E_dot - power) < 1e-8 * scale


def test_hub_beam_energy_is_compiled_only():
    """The interpreted hub path (``compiled=False``) has no energy of its own: it is refused,
    naming why (its systems' default energy is then the reference one)."""
    system = pq.scenes.spinning_beam(n_shapes=2)
    interpreted = HubBeamEvaluator(system, compiled=False)
    with pytest.raises(ValueError, match="method: the 'hub_beam' energy is compiled only.*compiled=False"):
        interpreted.energy(np.full(system.n_q, 0.01), np.ones(system.n_s), 0.5)


@pytest.mark.parametrize("spin", [0.5, 3.0])
def test_compiled_energy_says_where_an_unstiffened_beam_spins_too_fast(spin):
    """A beam without stiffening in a tree, turned about an axis across it faster than its first
    bending frequency, is unstable (ω_lag² = ω₁² − Ω² < 0): the compiled energy (what simulate's
    rows call) says so by the beam's RuntimeWarning, as the reference terms do; slower, nothing."""
    beam = pq.RitzBeam(1.0, 2.0, 1.0, n_v=2, n_w=0, stiffening=False, family="clamped_free")
    system = pq.System({"hub": pq.RigidBody(1.0, (0.0, 0.0, 0.0), 0.1 * np.eye(3)), "beam": beam},
                       {"hub": pq.Revolute(axis="z"), "beam": pq.Fixed("hub")})
    s_dot = np.array([spin * beam.first_frequency, 0.0, 0.0])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        system.energy(system.q0, s_dot, 0.0, method="fast")
    assert [w.category for w in said] == ([RuntimeWarning] if spin > 1 else [])
