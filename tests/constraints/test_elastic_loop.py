"""A four-bar whose coupler is a RitzBeam (a flexible closed loop: the loop closes at the beam's
tip, which moves with its bending). Checked against independent statements: the tree's Gauss
form by the compiled kernel (projeq.assembly.kernels.gauss_form with the beam's n_y) equals the
dense J_nᵀ M_n J_n sums (docs/theory.md §5); the constrained s̈ keeps the loop closed to second
order, A_s s̈_tree + γ = 0 (the constraint Φ differentiated twice, docs/theory.md); and the model
conserves energy — gravity and strain are conservative and the loop's constraint forces do no
work — dE/dt = 0 along (q̇, s̈) at deformed, moving states (Richardson's extrapolation of
central differences)."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.scenes.mechanisms import four_bar_angles, slender_rod

A, B, C, D = 0.3, 1.0, 0.8, 1.0  # crank, coupler (the beam), rocker, ground


def _tip(beam, q_e):
    """The coupler's tip in its reference frame (the beam's slice at x = L, bent)."""
    station = np.array([beam.length])
    return beam.slices(q_e, beam.slice_field(station, beam.station_data(station)))[0][0]


@pytest.fixture(scope="module")
def loop():
    """The flexible four-bar: q = (crank q1, rocker q3, coupler q2 relative to the crank, the
    beam's two bending amplitudes); Φ = coupler tip − rocker tip in the plane."""
    beam = pq.RitzBeam(B, 2.0, 200.0, n_v=2, n_w=0, family="clamped_free")
    tree = pq.System({"crank": slender_rod(1.0, A), "rocker": slender_rod(1.5, C), "coupler": beam},
                     {"crank": pq.Revolute(axis="z"), "rocker": pq.Revolute(axis="z", r_pn=(D, 0.0, 0.0)),
                      "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0.0, 0.0))},
                     gravity=(0.0, -9.81, 0.0))

    def closure(q, t):
        q1, q3, q2 = q[0], q[1], q[2]
        r = _tip(beam, q[3:])
        c, s = np.cos(q1 + q2), np.sin(q1 + q2)
        return [A * np.cos(q1) + c * r[0] - s * r[1] - D - C * np.cos(q3),
                A * np.sin(q1) + s * r[0] + c * r[1] - C * np.sin(q3)]

    theta2, theta3 = four_bar_angles(0.5, A, B, C, D)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the closure is Python (numpy path), not batched: said, not tested here
        system = pq.ConstrainedSystem(tree, phi=closure, independent=[0, 3, 4], q0=(0.5, theta3, theta2 - 0.5, 0, 0),
                                      s_dot0=[3.0, 0.0, 0.0])
        rng = np.random.default_rng(5)
        states = []
        for _ in range(3):
            q = system.q0 + np.concatenate((0.3 * rng.standard_normal(3), 0.01 * rng.standard_normal(2)))
            states.append((system.project(q), rng.uniform(-3, 3, 3)))
        yield system, states


def test_the_trees_gauss_form_is_compiled_and_equals_the_dense_one(loop):
    system, states = loop
    assert system.compiled_tree()
    for q, s_dot in states:
        s_dot_tree = system.tree_velocities(q, s_dot)
        M, b = system.tree_gauss_form(q, s_dot_tree, 0.0)
        M_dense, b_dense = system.tree_gauss_form(q, s_dot_tree, 0.0, method="dense")
        assert np.abs(M - M_dense).max() <= 1e-12 * np.abs(M_dense).max()
        assert np.abs(b - b_dense).max() <= 1e-12 * max(1.0, np.abs(b_dense).max())


def test_the_loop_stays_closed_to_second_order(loop):
    system, states = loop
    for q, s_dot in states:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s_ddot_tree, _ = system.accelerations_tree(q, s_dot, 0.0)
        s_dot_tree = system.tree_velocities(q, s_dot)
        A_s = system.phi_q(q)
        residual = A_s @ s_ddot_tree + system.gamma(q, s_dot_tree)
        assert np.abs(residual).max() <= 1e-9 * max(1.0, np.abs(A_s).max() * np.abs(s_ddot_tree).max())


def test_energy_is_conserved(loop):
    system, states = loop

    def power(q, s_dot, h=1e-5):  # a stiff beam: the central difference's error is 1.9e4 h² of |T| + |V|
        q_dot, s_ddot = system.q_dot(q, s_dot), system.accelerations(q, s_dot, 0.0)

        def E(step):
            return sum(system.energy(system.project(q + step * q_dot), s_dot + step * s_ddot))

        def central(step):
            return (E(step) - E(-step)) / (2 * step)

        return (4 * central(h / 2) - central(h)) / 3, sum(abs(e) for e in system.energy(q, s_dot))

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for q, s_dot in states:
            rate, scale = power(q, s_dot)
            assert abs(rate) < 1e-7 * scale * (1 + np.abs(s_dot).max())
