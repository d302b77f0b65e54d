"""Hamel's coefficients and equations (Bremer (2009) B(3)–(9), docs/theory.md §8)."""

import pytest
import sympy as sp

from projeq.symbolic import Body, hamel_coefficients, hamel_equations, projection_equation

x, y, gamma = Q_CAR = sp.symbols("x y gamma")
v_x, v_y, omega_z = S_CAR = sp.symbols("v_x v_y omega_z")
S_DDOT = sp.symbols("vdot_x vdot_y omegadot_z")
m, c, C0, f_x, f_y, M_z = PARAMETERS = sp.symbols("m c C0 f_x f_y M_z")
# B(6): ṡ = H(q) q̇ with the body-frame velocities of the rear-axle point and the yaw rate
H_CAR = sp.Matrix([[sp.cos(gamma), sp.sin(gamma), 0], [-sp.sin(gamma), sp.cos(gamma), 0], [0, 0, 1]])
# B(5): v_c = (v_x, v_y + c ω_z) in the body frame, C^c = C° − m c²
T_CAR = m / 2 * (v_x**2 + (v_y + c * omega_z) ** 2) + (C0 - m * c**2) / 2 * omega_z**2
Q_B8 = [f_x, f_y, M_z]  # the generalised forces written in B(8)


def car_hamel(T):
    return hamel_equations(T, Q_CAR, S_CAR, H_CAR, Q_B8, S_DDOT, parameters=PARAMETERS)


def test_car_coefficients_are_those_of_B7_B8():
    """B(7)–(8): β₂^{3,1} = −1, β₁^{3,2} = +1, β₁^{2,3} = −1, β₂^{1,3} = +1, β₁^{1,3} = 0
    (1-based, β_ν^{μ,n} = beta[ν−1, μ−1, n−1]); B(4): β_ν^{μ,n} = −β_ν^{n,μ}; row 3 of H
    (ω_z = γ̇) is holonomic, so β₃ ≡ 0."""
    beta = hamel_coefficients(H_CAR, Q_CAR)
    assert (beta[1, 2, 0], beta[0, 2, 1], beta[0, 1, 2], beta[1, 0, 2], beta[0, 0, 2]) == (-1, 1, -1, 1, 0)
    for nu in range(3):
        for mu in range(3):
            for n in range(3):
                assert beta[nu, mu, n] == -beta[nu, n, mu]
    assert all(beta[2, mu, n] == 0 for mu in range(3) for n in range(3))


def test_coefficients_vanish_for_holonomic_velocities():
    """B(4) text: β ≡ 0 when every s_ν is a coordinate (H. Schwarz's rule). H = ∂s/∂q of a
    nonlinear change of coordinates s(q) (cylindrical with a sheared height, regular for q1 ≠ 0)."""
    q = sp.symbols("q1:4")
    s_of_q = sp.Matrix([q[0] * sp.cos(q[1]), q[0] * sp.sin(q[1]), q[2] + q[0] * q[1] ** 2])
    beta = hamel_coefficients(s_of_q.jacobian(q), q)
    assert all(beta[nu, mu, n] == 0 for nu in range(3) for mu in range(3) for n in range(3))


def test_car_equations_are_B8_and_after_v_y_0_B9_as_the_projection_equation():
    """B(8) row by row from B(3) with all three speeds; inserting v_y = 0 (and v̇_y = 0)
    afterwards gives B(9), identical to the Projection Equation B(11)–(12) of the same car
    (projeq.symbolic.projection_equation, body-fixed reference frame)."""
    eqs = car_hamel(T_CAR)
    vdx, vdy, wdz = S_DDOT
    B8 = [
        m * vdx - m * c * omega_z**2 - m * omega_z * v_y - f_x,
        m * vdy + m * c * wdz + m * omega_z * v_x - f_y,
        C0 * wdz + m * c * vdy + m * c * v_x * omega_z - M_z,
    ]
    assert all(sp.simplify(e - b) == 0 for e, b in zip(eqs, B8))
    constrained = [eqs[n].subs({v_y: 0, vdy: 0}) for n in (0, 2)]
    # the Projection Equation, with v_y = 0 inserted before the derivation (B(11))
    car = Body(v_c=(v_x, c * omega_z, 0), omega=(0, 0, omega_z), m=m, I_c=sp.diag(0, 0, C0 - m * c**2),
               f=(f_x, f_y, 0), M=(0, 0, M_z - c * f_y), omega_IR=(0, 0, omega_z))
    K = sp.Matrix([[sp.cos(gamma), 0], [sp.sin(gamma), 0], [0, 1]])
    gauss = projection_equation({"car": car}, Q_CAR, (v_x, omega_z), K, PARAMETERS)
    projection = gauss.M * sp.Matrix([vdx, wdz]) - gauss.rhs  # M s̈ − rhs = 0
    # B(8)'s Q_3 = M_z: a torque M_z about O, i.e. M_z − c f_y about the mass centre for f_y at O
    assert all(sp.simplify(h - p) == 0 for h, p in zip(constrained, projection))
    assert sp.simplify(constrained[0] - (m * vdx - m * c * omega_z**2 - f_x)) == 0  # B(9), row 1


def test_inserting_v_y_0_before_hamel_is_wrong():
    """docs/theory.md §8, B(8) text: with v_y = 0 put into T first, ∂T/∂v_y loses its m c ω_z, and
    the first equation misses the centripetal term −m c ω_z² of B(9)."""
    right = car_hamel(T_CAR)[0].subs({v_y: 0, S_DDOT[1]: 0})
    wrong = car_hamel(T_CAR.subs(v_y, 0))[0].subs({v_y: 0, S_DDOT[1]: 0})
    assert sp.simplify(wrong - right) == m * c * omega_z**2


def test_singular_H_is_refused_by_name():
    r, phi = sp.symbols("r phi")
    with pytest.raises(ValueError, match="^H: singular for every q"):
        hamel_coefficients(sp.Matrix([[1, r], [2, 2 * r]]), (r, phi))
    with pytest.raises(ValueError, match=r"^H: singular at q = \{r: 0\}"):
        hamel_coefficients(sp.diag(1, r), (phi, r), at={r: 0})


def test_mismatched_dimensions_are_refused_by_name():
    with pytest.raises(ValueError, match="^H: must be square"):
        hamel_coefficients(H_CAR[:2, :], Q_CAR)
    with pytest.raises(ValueError, match="^H: has 3 rows but there are 2 speeds"):
        hamel_equations(T_CAR, Q_CAR, S_CAR[:2], H_CAR, Q_B8, parameters=PARAMETERS)
    with pytest.raises(ValueError, match="^Q: expected 3 generalised forces"):
        hamel_equations(T_CAR, Q_CAR, S_CAR, H_CAR, Q_B8[:2], parameters=PARAMETERS)


def test_undeclared_symbols_are_named():
    with pytest.raises(ValueError, match="^T: depends on undeclared symbols C0, c"):
        hamel_equations(T_CAR, Q_CAR, S_CAR, H_CAR, Q_B8, parameters=(m, f_x, f_y, M_z))
