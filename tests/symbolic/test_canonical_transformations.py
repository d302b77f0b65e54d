"""Canonical transformations, action-angle variables, the principal function and Routh's elimination
of cyclic coordinates (projeq.symbolic.hamiltonian) against the problem-seminar book on Lagrange's
equations (lecture notes §II.7 and §§VI–VII, eqs. (47), (162)–(164), (174), (187), (202)–(207);
Problem 7, the simple pendulum; Problem 40, the projectile) and textbook closed forms."""

import numpy as np
import pytest
import sympy as sp
from scipy.special import ellipe, ellipk

from projeq.symbolic.hamiltonian import (Libration, canonical_transformation, poisson_bracket,
                                         principal_function, routhian, separate_hamilton_jacobi)

m, g, l, omega, v = sp.symbols("m g l omega v", positive=True)
t = sp.Symbol("t")
q, p, Q, P = sp.symbols("q p Q P")
Q_POS, P_POS = sp.symbols("Q P", positive=True)
EPS100 = 100 * np.finfo(float).eps  # round-off bound


def test_oscillator_F1_gives_action_angle_variables():
    """F₁(q, Q) = m ω q² cot Q / 2 (the book's §VI harmonic-oscillator example; Goldstein, Classical
    Mechanics, §9.3): q = √(2P/mω) sin Q, p = √(2mωP) cos Q and K = H = ω P, so Q = ω t + β and P = E/ω
    — P is the action J = ∮ p dq over 2π. Symbolic K; the relations checked at 5 random points of
    0 < Q < π (sympy writes sin Q as 1/√(1 + cot² Q)) to 100 ε (measured ≤ 4.4e-16)."""
    H = p**2 / (2 * m) + m * omega**2 * q**2 / 2
    F1 = m * omega * q**2 * sp.cot(Q_POS) / 2
    transformation = canonical_transformation(F1, 1, [q], [p], [Q_POS], [P_POS])
    assert sp.simplify(transformation.new_hamiltonian(H) - omega * P_POS) == 0
    old = transformation.old_variables()
    rng = np.random.default_rng(3)
    for Q_val, P_val, m_val, w_val in rng.uniform([0.1, 0.1, 0.5, 0.5], [3.0, 2.0, 2.0, 3.0], (5, 4)):
        at = {Q_POS: Q_val, P_POS: P_val, m: m_val, omega: w_val}
        q_book = np.sqrt(2 * P_val / (m_val * w_val)) * np.sin(Q_val)
        p_book = np.sqrt(2 * m_val * w_val * P_val) * np.cos(Q_val)
        assert float(old[q].subs(at)) == pytest.approx(q_book, rel=EPS100, abs=0)  # measured 1.1e-16
        assert float(old[p].subs(at)) == pytest.approx(p_book, rel=EPS100, abs=EPS100)


@pytest.mark.parametrize("kind, F, old", [(2, q * P, {q: Q, p: P}), (3, -p * Q, {q: Q, p: P}),
                                         (1, q * Q, {q: -P, p: Q}), (4, p * P, {q: -P, p: Q})])
def test_the_four_types_of_generating_function(kind, F, old):
    """The book's eq. (163) for each type: F₂ = qP and F₃ = −pQ give the identity, F₁ = qQ and
    F₄ = pP the exchange q = −P, p = Q (Goldstein, Classical Mechanics, Table 9.1); each is
    canonical, [q, p] = 1 in the new variables (the book's eq. (165)), and K = H ∘ (q, p) (164)."""
    transformation = canonical_transformation(F, kind, [q], [p], [Q], [P])
    assert transformation.old_variables() == old
    assert poisson_bracket(old[q], old[p], [Q], [P]) == 1
    H = p**2 / 2 + q**4
    assert sp.expand(transformation.new_hamiltonian(H) - H.subs(old)) == 0


def test_time_dependent_F2_adds_its_rate_to_the_hamiltonian():
    """F₂ = (q − v t) P, a frame moving at speed v: Q = q − v t, p = P and K = H + ∂F₂/∂t = P²/2m − v P
    (the book's eq. (164)); Hamilton's equations of K give Q̇ = P/m − v, the relative velocity."""
    transformation = canonical_transformation((q - v * t) * P, 2, [q], [p], [Q], [P], t)
    K = transformation.new_hamiltonian(p**2 / (2 * m))
    assert sp.expand(K - (P**2 / (2 * m) - v * P)) == 0
    assert sp.expand(K.diff(P) - (P / m - v)) == 0


PENDULUM_M, PENDULUM_L, PENDULUM_G = 1.3, 0.7, 9.81
PENDULUM = Libration(p**2 / (2 * PENDULUM_M * PENDULUM_L**2)
                     - PENDULUM_M * PENDULUM_G * PENDULUM_L * sp.cos(q), q, p)


#: amplitude (°): relative bounds of ν τ = 1 and of J, each max(10 × the error measured, 100 ε)
BOUNDS = {10: (1.0e-10, 6.2e-13), 90: (4.1e-13, 2.2e-14), 170: (3.8e-11, 2.2e-14)}


@pytest.mark.parametrize("amplitude_deg", [10, 90, 170])
def test_pendulum_frequency_from_the_action_is_the_elliptic_period(amplitude_deg):
    """Problem 7, eq. (23): τ = 4 √(l/g) K(sin(α/2)); ν = ∂H/∂J (eq. (205)) = 1/τ (207) at the amplitudes
    10°, 90°, 170°, relative (measured 1.0e-11, 4.1e-14, 3.8e-12). The action itself,
    J = ∮ p dq = 16 m l √(g l) [E(k) − (1 − k²) K(k)], k = sin(α/2) (sin(q/2) = k sin u in ∮ p dq),
    relative (measured 6.2e-14, 6.7e-16, 5.6e-16). Each bound max(10× measured, 100 ε) (BOUNDS; they
    were 1e-10 and 1e-12 at every amplitude)."""
    alpha = np.radians(amplitude_deg)
    E = -PENDULUM_M * PENDULUM_G * PENDULUM_L * np.cos(alpha)
    k2 = np.sin(alpha / 2) ** 2
    period = 4 * np.sqrt(PENDULUM_L / PENDULUM_G) * ellipk(k2)
    frequency_bound, action_bound = BOUNDS[amplitude_deg]
    assert PENDULUM.frequency(E, (-alpha, alpha)) * period == pytest.approx(1, rel=frequency_bound, abs=0)
    J = 16 * PENDULUM_M * PENDULUM_L * np.sqrt(PENDULUM_G * PENDULUM_L) * (ellipe(k2) - (1 - k2) * ellipk(k2))
    assert PENDULUM.action(E, (-alpha, alpha)) == pytest.approx(J, rel=action_bound, abs=0)


def test_oscillator_action_and_frequency_symbolically():
    """Harmonic oscillator (the book's §VII.5): J = ∮ p dq = 2π E/ω and ν = ∂H/∂J = ω/2π, i.e. H = ω J/2π
    — the F₁ example's K = ω P with P = J/2π."""
    E = sp.Symbol("E", positive=True)
    oscillator = Libration(p**2 / (2 * m) + m * omega**2 * q**2 / 2, q, p)
    a = sp.sqrt(2 * E / (m * omega**2))
    assert sp.simplify(oscillator.action(E, (-a, a)) - 2 * sp.pi * E / omega) == 0
    assert sp.simplify(oscillator.frequency(E, (-a, a)) - omega / (2 * sp.pi)) == 0


def test_problem_40_principal_function_is_the_books_12_and_solves_hamilton_jacobi():
    """Problem 40, eq. (12): S = √(2mα₁) x − (2mα₂ − 2m²g y)^{3/2}/(3m²g) − (α₁ + α₂) t is W − E t (187)
    and satisfies H(q, ∂S/∂q) + ∂S/∂t = 0 (174); Jacobi's ∂S/∂α₁ = β₁ gives x = √(2α₁/m)(β₁ + t) (15)."""
    x, y, px, py = sp.symbols("x y p_x p_y")
    H = (px**2 + py**2) / (2 * m) + m * g * y
    separation = separate_hamilton_jacobi(H, [x, y], [px, py], cyclic=False)
    alpha1, E = sp.Symbol("alpha_x"), separation.E
    alpha2, beta1 = sp.symbols("alpha_2 beta_1")
    S = principal_function(separation, t).subs(E, alpha1 + alpha2)
    book = (sp.sqrt(2 * m * alpha1) * x - (alpha1 + alpha2) * t
            - (2 * m * alpha2 - 2 * m**2 * g * y) ** sp.Rational(3, 2) / (3 * m**2 * g))
    assert sp.simplify(S - book) == 0
    assert sp.simplify(H.subs({px: S.diff(x), py: S.diff(y)}) + S.diff(t)) == 0
    (x_of_t,) = sp.solve(sp.Eq(S.diff(alpha1), beta1), x)
    assert sp.simplify(x_of_t - sp.sqrt(2 * alpha1 / m) * (beta1 + t)) == 0


def lagrange_expression(L, q, q_dot, q_ddot):
    """d/dt ∂L/∂q̇ − ∂L/∂q for L(q, q̇) in plain symbols (chain rule with the accelerations q̈)."""
    momentum = [L.diff(v) for v in q_dot]
    return [sum(pk.diff(a) * b for a, b in zip(q + q_dot, q_dot + q_ddot)) - L.diff(qk)
            for pk, qk in zip(momentum, q)]


theta, phi, psi, theta_d, phi_d, psi_d, theta_dd = sp.symbols("theta phi psi theta_d phi_d psi_d theta_dd")


def test_spherical_pendulum_routhian_and_the_conical_pendulum():
    """Spherical pendulum (θ from the downward vertical), φ cyclic (the book's §II.7, eq. (47)):
    L' = ½ m l² θ̇² − c²/(2 m l² sin²θ) + m g l cos θ; its θ equation is Lagrange's θ equation of L with
    φ̇ = c/(m l² sin²θ); ∂L'/∂θ = 0 gives the conical pendulum φ̇² = g/(l cos θ) (Landau & Lifshitz,
    Mechanics, §14, Problem 1)."""
    L = m * l**2 * (theta_d**2 + sp.sin(theta) ** 2 * phi_d**2) / 2 + m * g * l * sp.cos(theta)
    reduced = routhian(L, [theta, phi], [theta_d, phi_d], [phi])
    (c,) = reduced.c
    book = m * l**2 * theta_d**2 / 2 - c**2 / (2 * m * l**2 * sp.sin(theta) ** 2) + m * g * l * sp.cos(theta)
    assert sp.simplify(reduced.R - book) == 0
    (routh,) = lagrange_expression(reduced.R, [theta], [theta_d], [theta_dd])
    full = lagrange_expression(L, [theta, phi], [theta_d, phi_d], [theta_dd, sp.Symbol("phi_dd")])[0]
    assert sp.simplify(routh - full.subs(phi_d, reduced.cyclic_velocities[phi_d])) == 0
    steady = sp.solve(sp.Eq(reduced.R.diff(theta), 0), c**2)[0] / (m * l**2 * sp.sin(theta) ** 2) ** 2
    assert sp.simplify(steady - g / (l * sp.cos(theta))) == 0


def test_heavy_top_routhian_is_the_effective_potential():
    """Heavy symmetric top, Euler angles (φ precession, θ nutation, ψ spin), φ and ψ cyclic:
    L' = ½ I₁ θ̇² − (c_φ − c_ψ cos θ)²/(2 I₁ sin²θ) − c_ψ²/(2 I₃) − M g l cos θ (Goldstein, Classical
    Mechanics, §5.7, the effective potential); its θ equation equals Lagrange's θ equation of L with
    the cyclic velocities eliminated; both checked at 3 random states (100 ε relative)."""
    I1, I3, M = sp.symbols("I_1 I_3 M", positive=True)
    L = (I1 * (theta_d**2 + phi_d**2 * sp.sin(theta) ** 2) / 2 + I3 * (psi_d + phi_d * sp.cos(theta)) ** 2 / 2
         - M * g * l * sp.cos(theta))
    reduced = routhian(L, [theta, phi, psi], [theta_d, phi_d, psi_d], [phi, psi])
    c_phi, c_psi = reduced.c
    book = (I1 * theta_d**2 / 2 - (c_phi - c_psi * sp.cos(theta)) ** 2 / (2 * I1 * sp.sin(theta) ** 2)
            - c_psi**2 / (2 * I3) - M * g * l * sp.cos(theta))
    (routh,) = lagrange_expression(reduced.R, [theta], [theta_d], [theta_dd])
    full = lagrange_expression(L, [theta, phi, psi], [theta_d, phi_d, psi_d],
                               [theta_dd, sp.Symbol("phi_dd"), sp.Symbol("psi_dd")])[0]
    arguments = (theta, theta_d, theta_dd, c_phi, c_psi, I1, I3, M, g, l)
    values = sp.lambdify(arguments, [reduced.R, book, routh, full.subs(reduced.cyclic_velocities)])
    for point in np.random.default_rng(5).uniform(0.3, 1.5, (3, len(arguments))):
        R, R_book, equation, equation_full = values(*point)
        assert R == pytest.approx(R_book, rel=EPS100) and equation == pytest.approx(equation_full, rel=EPS100)


def test_bad_input():
    with pytest.raises(ValueError, match="kind: expected 1, 2, 3 or 4"):
        canonical_transformation(q * P, 5, [q], [p], [Q], [P])
    with pytest.raises(ValueError, match="type-1 generating function depends on"):
        canonical_transformation(q * P, 1, [q], [p], [Q], [P])
    with pytest.raises(ValueError, match="Q, P: expected 1 new pairs"):
        canonical_transformation(q * P, 2, [q], [p], [Q, theta], [P, phi])
    with pytest.raises(ValueError, match="turning_points"):
        PENDULUM.frequency(1.0, (-1.0, 1.0))
    with pytest.raises(ValueError, match=r"cyclic: L depends on \[theta\]"):
        routhian(theta_d**2 + sp.cos(theta), [theta], [theta_d], [theta])
    with pytest.raises(ValueError, match="cyclic: expected some of the coordinates"):
        routhian(theta_d**2, [theta], [theta_d], [phi])
