"""Re-pivoting a coordinate partition during a run (issue 4, item 1; docs/theory.md §7).

A crank–rocker four-bar whose independent velocity is the rocker's rate q̇3: at the rocker's
extreme positions dq3/dq1 = 0 and the dependent block (crank, coupler) becomes singular.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import projeq as pq
from projeq.constraints.partitioned import POSITION_TOLERANCE, ConstrainedSystem, TangentSystem
from projeq.constraints.reactions import reactions
from projeq.scenes.mechanisms import four_bar

from .test_loops import _four_bar_reference

RTOL, ATOL = 1e-9, 1e-11
PARAMS = dict(a=0.3, b=1.0, c=0.8, d=1.0, m=(1.0, 2.0, 1.5), g=9.81)
THETA1, OMEGA1, T_END = 0.0, 6.0, 0.3  # the crank reaches the rocker's extreme at t ≈ 0.1 s


@pytest.fixture(scope="module")
def run():
    system = four_bar(**PARAMS, theta1=THETA1, omega1=OMEGA1).with_independent([1], repivot=True)
    return system, pq.simulate(system, T_END, t_eval=np.linspace(0, T_END, 31), rtol=RTOL, atol=ATOL)


@pytest.fixture(scope="module")
def reference(run):
    """The closed-loop Lagrange reference (test_loops'), integrated once for the module: its values
    at the run's output times and its dense output (solve_ivp's steps do not depend on t_eval)."""
    _, r = run
    return solve_ivp(_four_bar_reference(**PARAMS), (0, T_END), [THETA1, OMEGA1], t_eval=r.t, rtol=RTOL, atol=ATOL,
                     dense_output=True)


def test_rocker_partition_repivots_before_the_rocker_extreme(run, reference):
    """The rocker's extreme (outer dead centre) is where crank and coupler are collinear,
    |rocker tip| = a + b: cos θ1* = (d² + (a + b)² − c²) / (2 d (a + b)) (law of cosines).
    The run starts with ṡ = q̇3, switches once, shortly before the crank reaches θ1* (the
    time t* taken from the closed-loop Lagrange reference), to a partition without the rocker,
    and carries on to t_end."""
    _, r = run
    assert r.status == 0 and r.t[-1] == T_END
    assert [independent for _, independent, _ in r.partitions] == [(1,), (2,)]  # rocker, then coupler
    t_switch = r.partitions[1][0]
    a, b, c, d = (PARAMS[k] for k in "abcd")
    theta_star = np.arccos((d * d + (a + b) ** 2 - c * c) / (2 * d * (a + b)))
    t_star = brentq(lambda t: reference.sol(t)[0] - theta_star, 0, T_END)
    # κ grows like 1/|dq3/dq1| towards t*: the limit (108 here) is met ~11 ms before it
    assert t_star - 0.02 < t_switch < t_star, (t_switch, t_star)


def test_repivoted_run_agrees_with_the_explicitly_solved_loop(run, reference):
    """Across the switch the motion is that of the four-bar in the minimal coordinate θ1
    with its loop solved in closed form and Lagrange's equation (test_loops'
    reference, an independent formulation); the energy is conserved and the loop stays closed."""
    system, r = run
    # both integrated to rtol 1e-9: 10 rtol·|θ1| (achieved 2.5e-10 rad)
    assert np.abs(r.q[:, 0] - reference.y[0]).max() < 10 * RTOL * np.abs(reference.y[0]).max()
    # energies computed in each row's own partition: local errors of size rtol (achieved 3e-10)
    assert r.energy_drift < 100 * RTOL
    # the projection at the outputs stops at POSITION_TOLERANCE · max(1, |q|)
    assert np.abs(r.constraint_residual).max() <= POSITION_TOLERANCE * max(1.0, np.abs(r.q).max())


def test_multipliers_are_those_of_the_crank_partition(run):
    """The loop-closure forces λ do not depend on the partition: ``reactions`` reads each
    row in its own partition (``Result.partitions``) and agrees with the crank-partitioned
    system evaluated at the same tree velocities."""
    system, r = run
    crank = four_bar(**PARAMS, theta1=THETA1, omega1=OMEGA1)
    lam, errors = reactions(system, r), []
    (_, rocker, _), (t_switch, coupler, _) = r.partitions
    for rows, independent in ((r.t <= t_switch, rocker), (r.t > t_switch, coupler)):
        partition = system.with_independent(independent)
        for t, q, s_dot, lam_row in zip(r.t[rows], r.q[rows], r.s_dot[rows], lam[rows]):
            s_dot_crank = partition.tree_velocities(q, s_dot, t)[crank.independent]
            expected = crank.accelerations_tree(q, s_dot_crank, t)[1]
            errors.append(np.abs(lam_row - expected).max() / np.abs(expected).max())
    # same state, different A_dep solves: round-off and the differences' errors, amplified by κ ≤ 108
    # near the switch (measured 1.9e-14; bound 10× that, rounded up)
    assert max(errors) < 2e-13, max(errors)


def test_fixed_partition_stops_with_the_configuration():
    """Without ``repivot`` a user-fixed partition keeps its error: the run stops where A_dep
    becomes singular, naming the dependent velocities and q."""
    system = four_bar(**PARAMS, theta1=THETA1, omega1=OMEGA1).with_independent([1])
    with pytest.raises(pq.SimulationError, match=r"dependent velocities \[0, 2\] cannot be solved for at q = "):
        pq.simulate(system, T_END, rtol=RTOL, atol=ATOL, n_points=3)


def test_partitions_are_saved(run, tmp_path):
    _, r = run
    r.save(tmp_path / "run.npz")
    assert pq.Result.load(tmp_path / "run.npz").partitions == r.partitions


def test_energy_projection_follows_the_new_partition():
    """With ``method="RK45-projected"`` each step is projected onto the initial energy
    (projeq.simulation.integrators); after a switch the projection must read ṡ in the new partition.
    A point mass on x, z sliders kept on the unit circle, started at (0.6, −0.8) with ẋ = 4
    (speed 5, enough to pass the horizontal x = 1 where ẋ degenerates): the partition
    switches from ẋ to ż and the energy stays at the projection's round-off across it
    (conservation law). A coarse rtol keeps the run short; the projection does not depend on it."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
                     gravity=(0, 0, -9.81))
    system = ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - 1.0], q0=[0.6, -0.8],
                               independent=[0], s_dot0=[4.0], repivot=True)
    r = pq.simulate(system, 0.3, n_points=11, rtol=1e-6, atol=1e-8, method="RK45-projected")
    assert [independent for _, independent, _ in r.partitions] == [(0,), (1,)]
    # the loop-closure projection that follows the energy projection moves q by up to
    # POSITION_TOLERANCE (1e-12), E by |∇_q E| times that (measured 1.7e-13; RK45: 9e-7)
    assert r.energy_drift < 2e-12, r.energy_drift


def test_the_condition_of_a_turning_constraint_is_taken_at_the_time_asked():
    """A bead on a rod through the origin that turns at ω in the x–z plane, Φ = −x sin ωt + z cos ωt:
    A_s = (−sin ωt, cos ωt), its null space N = (cos ωt, sin ωt), and with x the independent velocity
    (chosen at q0 = (1, 0), t = 0) κ = 1/σ_min(N_ind) = 1/|cos ωt| in closed form. ``condition(q)``
    is taken at t = 0, the time q0 is given at (it sets the repivoting limit); measured exact at ωt = 0,
    0.5 and ±1 (bound 100 ε)."""
    tree = pq.System({"x": pq.Frame(), "bead": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bead": pq.Prismatic(parent="x", axis="z")},
                     gravity=(0, 0, 0))
    omega = 1.0
    rod = lambda q, t: [-q[0] * np.sin(omega * t) + q[1] * np.cos(omega * t)]
    system = TangentSystem(tree, phi=rod, q0=[1.0, 0.0])
    assert system.independent.tolist() == [0]
    assert system.condition(system.q0) == 1.0
    for t in (0.5, 1.0, -1.0):
        expected = 1.0 / abs(np.cos(omega * t))
        assert abs(system.condition(system.q0, t) - expected) <= 100 * np.finfo(float).eps * expected
