"""The symbolic Projection Equation B(10)–(12) of Bremer (2009) (docs/theory.md §2)."""

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq import inertia
from projeq.symbolic import Body, gauss_form, projection_equation
from projeq.symbolic.examples import (
    PENDULUM_PARAMETERS, chain_parameters, kane_pendulum, lagrange_pendulum, n_link_pendulum,
)

RNG_SEED = 20261123
# two evaluations of the same equations in double precision, O(10²) operations on numbers
# of order 10²: round-off only. Each bound 10× the largest relative difference measured (or 100 ε):
# the 4-link pendulum vs scenes.chain 1.8e-14, the car 5.0e-15, Kane's and Lagrange's N = 3 pendulum
# 5.9e-16 (all were 1e-11)
RTOL = 1.9e-13
RTOL_CAR = 5e-14
RTOL_KANE = 100 * np.finfo(float).eps


x, y, gamma = Q_CAR = sp.symbols("x y gamma")
v_x, omega_z = S_CAR = sp.symbols("v_x omega_z")
m, c, C0, f_x, f_y, M_z = CAR_PARAMETERS = sp.symbols("m c C0 f_x f_y M_z")
K_CAR = sp.Matrix([[sp.cos(gamma), 0], [sp.sin(gamma), 0], [0, 1]])  # B(6) without v_y


def car_gauss_form():
    """B(11)–(12): body-fixed R (ω_IR = ω), v_c = (v_x, c ω_z), C^c = C° − m c²; f_x at O
    along x, f_y lateral at the mass centre, M_z about z (the loads of ``scenes.car``)."""
    car = Body(v_c=(v_x, c * omega_z, 0), omega=(0, 0, omega_z), m=m, I_c=sp.diag(0, 0, C0 - m * c**2),
               f=(f_x, f_y, 0), M=(0, 0, M_z), omega_IR=(0, 0, omega_z))
    return projection_equation({"car": car}, Q_CAR, S_CAR, K_CAR, CAR_PARAMETERS)


def test_car_is_B9():
    """B(9) (with f_y at the mass centre adding c f_y to the ω_z row, B(12)): M = diag(m, C°),
    rhs = −[[0, −m c ω_z], [m c ω_z, 0]] ṡ + (f_x, M_z + c f_y) — symbolically identical."""
    gauss = car_gauss_form()
    assert gauss.M == sp.diag(m, C0)
    G = sp.Matrix([[0, -m * c * omega_z], [m * c * omega_z, 0]])
    expected = -G * sp.Matrix(S_CAR) + sp.Matrix([f_x, M_z + c * f_y])
    assert sp.simplify(gauss.rhs - expected) == sp.zeros(2, 1)
    assert gauss.q == Q_CAR and gauss.s == S_CAR and gauss.t == sp.Symbol("t")
    assert r"\ddot{\omega_{z}}" in gauss.latex()


def test_compiled_car_equals_scenes_car_dense_and_recursive():
    """The compiled evaluator (lambdify, cse=True) gives the accelerations of projeq's dense
    and recursive evaluators of ``scenes.car`` at random parameters and states."""
    rng = np.random.default_rng(RNG_SEED)
    gauss = car_gauss_form()
    for _ in range(5):
        p = dict(zip(("m", "c", "f_x", "f_y", "M_z"), (rng.uniform(500, 2000), rng.uniform(0.2, 2.0), *rng.uniform(-3000, 3000, 3))))
        p["C0"] = p["m"] * p["c"] ** 2 + rng.uniform(200, 3000)
        system = pq.scenes.car(**p)
        evaluator = gauss.evaluator({sp.Symbol(k): v for k, v in p.items()})
        for _ in range(5):
            q, s_dot = rng.uniform(-5, 5, 3), np.array([rng.uniform(-20, 20), rng.uniform(-2, 2)])
            s_ddot = evaluator.accelerations(q, s_dot, 0.0)
            for method in ("recursive", "dense"):
                reference = system.accelerations(q, s_dot, method=method)
                assert np.allclose(s_ddot, reference, rtol=RTOL_CAR, atol=RTOL_CAR * np.abs(reference).max())


def chain_values():
    """The numbers of ``scenes.chain``: 1 kg, 1 m cylinders of radius 0.01 m, g = 9.81."""
    I_c = inertia.cylinder(m=1.0, radius=0.01, length=1.0, axis="z")
    return dict(zip(sp.symbols("m l J J_a g", positive=True), (1.0, 1.0, I_c[0, 0], I_c[2, 2], 9.81)))


def test_n_link_pendulum_equals_scenes_chain_dense_and_recursive():
    """Symbolic == numeric: the 4-link pendulum from mass-centre velocities (inertial frame,
    q-dependent I_c) equals ``scenes.chain(4)`` (joint chain T_np, F_n, docs/theory.md §4) in M and s̈
    at random states, for both numeric evaluators."""
    rng = np.random.default_rng(RNG_SEED)
    bodies, q, s, parameters = n_link_pendulum(4)
    evaluator = projection_equation(bodies, q, s, parameters=parameters).evaluator(chain_values())
    system = pq.scenes.chain(4)
    for _ in range(10):
        q_n, s_n = rng.uniform(-np.pi, np.pi, 4), rng.uniform(-3, 3, 4)
        M, _ = evaluator.gauss_form(q_n, s_n)
        M_ref, _ = system.gauss_form(q_n, s_n)
        assert np.allclose(M, M_ref, rtol=0, atol=RTOL * np.abs(M_ref).max())
        s_ddot = evaluator.accelerations(q_n, s_n)
        for method in ("recursive", "dense"):
            reference = system.accelerations(q_n, s_n, method=method)
            assert np.allclose(s_ddot, reference, rtol=0, atol=RTOL * (1 + np.abs(reference).max()))


def _pendulum_gauss_form(route: str, n: int):
    """The n-link pendulum's Gauss form from its velocity expressions (B(10)) or from the
    numeric ``scenes.chain(n)`` with symbolic parameters (the recursive chain, docs/theory.md §6)."""
    if route == "velocities":
        bodies, q, s, parameters = n_link_pendulum(n)
        return projection_equation(bodies, q, s, parameters=parameters)
    return gauss_form(pq.scenes.chain(n), chain_parameters(n))


@pytest.mark.parametrize("route, reference", [("velocities", "kane"), ("system", "kane"), ("system", "lagrange")])
def test_n_link_pendulum_equals_kanes_and_lagranges_method(route, reference):
    """Projection Equation == sympy.physics.mechanics KanesMethod and LagrangesMethod
    (the N-link pendulum, N = 3): M and rhs (M u̇ = forcing) agree at random
    states and random parameters, for both symbolic routes (Lagrange once: it is slow)."""
    rng = np.random.default_rng(RNG_SEED)
    gauss = _pendulum_gauss_form(route, 3)
    q_k, u_k, M_k, forcing = (kane_pendulum if reference == "kane" else lagrange_pendulum)(3)
    theirs = sp.lambdify([q_k, u_k, PENDULUM_PARAMETERS], [M_k, forcing], cse=True)
    ours = sp.lambdify([gauss.q, gauss.s, PENDULUM_PARAMETERS], [gauss.M, gauss.rhs], cse=True)
    for _ in range(10):
        state = rng.uniform(-np.pi, np.pi, 3), rng.uniform(-3, 3, 3), rng.uniform(0.5, 3.0, 5)
        (M, rhs), (M_ref, rhs_ref) = ours(*state), theirs(*state)
        assert np.allclose(M, M_ref, rtol=0, atol=RTOL_KANE * np.abs(M_ref).max())
        assert np.allclose(np.ravel(rhs), np.ravel(rhs_ref), rtol=0,
                           atol=RTOL_KANE * (np.abs(rhs_ref).max() + np.abs(M_ref).max()))


def test_simulate_with_the_compiled_evaluator_equals_the_recursive_one():
    """``projeq.simulate(system, evaluator=compiled)`` reproduces the recursive run of the
    3-link chain: same right-hand side to round-off, so the trajectories differ by the
    integrator's error control only: the same steps, 1.4e-15 rad apart at rtol = 1e-10 over 1 s (at most
    2.2e-14 over 0.5 and 2 s and rtol 1e-9, 1e-11; the bound 2.2e-13 is 10 times that, was 1e-8)."""
    bodies, q, s, parameters = n_link_pendulum(3)
    evaluator = projection_equation(bodies, q, s, parameters=parameters).evaluator(chain_values())
    system = pq.scenes.chain(3)
    ours = pq.simulate(system, 1.0, evaluator=evaluator, rtol=1e-10, atol=1e-12, n_points=21)
    reference = pq.simulate(system, 1.0, evaluator="recursive", rtol=1e-10, atol=1e-12, n_points=21)
    assert np.abs(ours.q - reference.q).max() < 2.2e-13


def test_undeclared_symbols_are_named():
    k = sp.Symbol("k")
    body = Body(v_c=(v_x, c * omega_z, 0), omega=(0, 0, omega_z), m=m, I_c=sp.zeros(3), f=(k * x, 0, 0))
    with pytest.raises(ValueError, match="^car.f: depends on undeclared symbols k"):
        projection_equation({"car": body}, Q_CAR, S_CAR, K_CAR, (m, c))


def test_mismatched_dimensions_are_refused_by_name():
    body = Body(v_c=(v_x, 0), omega=(0, 0, omega_z), m=m, I_c=sp.zeros(3))
    with pytest.raises(ValueError, match=r"^car.v_c: expected a 3-vector, got shape \(2, 1\)"):
        projection_equation({"car": body}, Q_CAR, S_CAR, K_CAR, (m,))
    body = Body(v_c=(v_x, 0, 0), omega=(0, 0, omega_z), m=m, I_c=sp.zeros(2))
    with pytest.raises(ValueError, match="^car.I_c: expected a 3×3"):
        projection_equation({"car": body}, Q_CAR, S_CAR, K_CAR, (m,))
    with pytest.raises(ValueError, match=r"^K: expected shape \(3, 2\)"):
        projection_equation({"car": body}, Q_CAR, S_CAR, K_CAR.T, (m,))
    with pytest.raises(ValueError, match="^K: required"):
        projection_equation({"car": body}, Q_CAR, S_CAR, parameters=(m,))


def test_evaluator_needs_every_parameter_value():
    with pytest.raises(ValueError, match="^values: no number given for the parameters C0"):
        car_gauss_form().evaluator({m: 1.0, c: 1.0, f_x: 0.0, f_y: 0.0, M_z: 0.0})
