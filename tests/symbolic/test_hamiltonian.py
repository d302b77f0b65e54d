"""Poisson brackets, constants of motion and Hamilton–Jacobi separation (projeq.symbolic.hamiltonian)
against the problem-seminar book on Lagrange's equations (Seminars 1–11 with lecture notes; Seminar 10
"Hamilton–Jacobi theory", Problems 40–41, and Seminar 11 "Poisson brackets", Problems 43–44; the book
has no Problem 42)."""

import pytest
import sympy as sp

from projeq.symbolic import (constant_of_motion_rate, is_constant_of_motion, poisson_bracket,
                             separate_hamilton_jacobi)

m, g, k, qe, B, omega = sp.symbols("m g k q B omega", positive=True)
t = sp.Symbol("t")
x, y, z, px, py, pz = sp.symbols("x y z p_x p_y p_z")
E_POS = sp.Symbol("E", positive=True)


def vanishes(expression) -> bool:
    """expression ≡ 0 (positive symbols), after factoring the radicands (√((B²q² + 4km)²) → B²q² + 4km)."""
    factored = expression.replace(lambda e: e.is_Pow and e.exp.is_Rational and e.exp.q == 2,
                                  lambda e: sp.factor(e.base) ** e.exp)
    return sp.simplify(factored) == 0
H40 = (px**2 + py**2) / (2 * m) + m * g * y  # Problem 40, eq. (3)


def test_problem_40_additive_separation_gives_the_books_W1_W2():
    """Problem 40 (projectile, H = (p_x² + p_y²)/2m + m g y), first solution, eqs. (7)–(11):
    W = W1(x) + W2(y) with W1 = √(2 m α1) x, W2 = −(2 m α2 − 2 m² g y)^{3/2} / (3 m² g), α1 + α2 = E."""
    sep = separate_hamilton_jacobi(H40, [x, y], [px, py], cyclic=False)
    alpha1, E = sp.Symbol("alpha_x"), sep.E
    alpha2 = E - alpha1
    W1 = sp.sqrt(2 * m * alpha1) * x
    W2 = -(2 * m * alpha2 - 2 * m**2 * g * y) ** sp.Rational(3, 2) / (3 * m**2 * g)
    assert sp.simplify(sep.W[0] - W1) == 0
    assert sp.simplify(sep.W[1] - W2) == 0
    assert sep.constants == (alpha1, alpha2)
    # H(q, ∂W/∂q) = E identically (eq. (183))
    assert sp.simplify(H40.subs({px: sep.characteristic_function.diff(x),
                                 py: sep.characteristic_function.diff(y)}) - E) == 0


def test_problem_40_cyclic_x_and_jacobis_theorem_give_the_trajectory():
    """Problem 40, second solution, eqs. (22)–(40): x is cyclic, p_x = C (24), W = C x + W_y(y) (26);
    Jacobi's theorem ∂W/∂E = t + β₁, ∂W/∂C = β₂ with the initial state x = y = 0,
    p = m (v0 cos a, v0 sin a) = m (u, w) (19) gives x = u t, y = w t − g t²/2 (eqs. (21), (38), (40)),
    and β₂ = v0² sin a cos a / g = u w / g (35)."""
    u, w = sp.symbols("u w", positive=True)  # v0 cos a, v0 sin a of a launch angle 0 < a < π/2
    sep = separate_hamilton_jacobi(H40, [x, y], [px, py], E=E_POS)
    C, E = sp.Symbol("alpha_x"), sep.E
    assert sep.W[0] == C * x
    W = sep.characteristic_function
    values = {C: m * u, E: m * (u**2 + w**2) / 2}
    at_start = {x: 0, y: 0}
    beta1 = W.diff(E).subs(at_start).subs(values)  # t = 0
    beta2 = W.diff(C).subs(at_start).subs(values)
    assert sp.simplify(beta2 - u * w / g) == 0
    book_x, book_y = u * t, w * t - g * t**2 / 2
    # the book's trajectory satisfies both of Jacobi's equations (before the apex t = w/g, where p_y = +√…)
    on_path = {x: book_x, y: book_y}
    eq1 = (W.diff(E).subs(values) - t - beta1).subs(on_path)
    eq2 = (W.diff(C).subs(values) - beta2).subs(on_path)
    for fraction in (sp.Rational(1, 3), sp.Rational(1, 2), sp.Rational(9, 10)):
        assert sp.simplify(eq1.subs(t, fraction * w / g)) == 0
        assert sp.simplify(eq2.subs(t, fraction * w / g)) == 0
    # and a wrong trajectory does not (the check can fail)
    wrong = (W.diff(E).subs(values) - t - beta1).subs({x: book_x, y: book_y + t**3}).subs(t, w / (3 * g))
    assert sp.simplify(wrong) != 0


r, th, pr, pth = sp.symbols("r theta p_r p_theta")
H41 = pr**2 / (2 * m) + (pth - qe * B * r**2 / 2) ** 2 / (2 * m * r**2) + k * r**2 / 2  # Problem 41, eq. (46)


def test_problem_41_charged_particle_separates_in_polar_coordinates():
    """Problem 41 (charge in a magnetic field B and the potential k r²/2, H of eq. (46)): θ is cyclic,
    p_θ = α₂ (51), and the radial part gives (∂W/∂r)² = 2 m α₁ − (α₂/r − q B r/2)² − k m r² (eqs. (53)–(54),
    α₁ = E); p_θ and the radial function are constants of motion (eq. (166))."""
    sep = separate_hamilton_jacobi(H41, [r, th], [pr, pth], E=E_POS, integrate=False)
    alpha2, E = sp.Symbol("alpha_theta"), sep.E
    assert sep.W[1] == alpha2 * th and sep.momenta[1] == alpha2
    book = 2 * m * E - (alpha2 / r - qe * B * r / 2) ** 2 - k * m * r**2
    assert sp.simplify(sep.momenta[0] ** 2 - book) == 0
    assert is_constant_of_motion(pth, H41, [r, th], [pr, pth])
    radial = sep.functions[0].subs(alpha2, pth)
    assert is_constant_of_motion(radial, H41, [r, th], [pr, pth])


def test_problem_41_motion_for_zero_angular_momentum():
    """Problem 41 with p_θ = 0 (α₂ = 0), eqs. (58)–(64): ∂W/∂α₁ = t + β₁ integrates to
    (1/Ω) arcsin(r Ω √(m/(2α₁))) (62), Ω = √(ω_L² + ω²), ω_L = q B/2m, ω² = k/m, so r = A |sin(Ω t + φ)|
    with A = √(2α₁/(m Ω²)) (63)–(64); and ∂W/∂α₂ = β₂ gives θ = const − ω_L t (61)."""
    sep = separate_hamilton_jacobi(H41, [r, th], [pr, pth], E=E_POS, integrate=False)
    alpha2, E = sp.Symbol("alpha_theta"), sep.E
    p_r = sep.momenta[0]
    omega_L, Omega = qe * B / (2 * m), sp.sqrt((qe * B / (2 * m)) ** 2 + k / m)
    book_62 = sp.asin(r * Omega * sp.sqrt(m / (2 * E))) / Omega
    # ∂W/∂α₁ = ∫ ∂p_r/∂α₁ dr: compare the integrands at a radius inside the motion (r < A)
    integrand = p_r.diff(E).subs(alpha2, 0)
    inside = {r: sp.sqrt(2 * E / (m * Omega**2)) / 3}
    assert vanishes((integrand - book_62.diff(r)).subs(inside))
    # θ: ∂p_r/∂α₂ = ω_L ∂p_r/∂α₁ at α₂ = 0, so θ + ω_L (t + β₁) = β₂
    assert vanishes((p_r.diff(alpha2) - omega_L * p_r.diff(E)).subs(alpha2, 0).subs(inside))
    # the amplitude A of (64): p_r vanishes at r = A
    assert vanishes(p_r.subs(alpha2, 0).subs(r, sp.sqrt(2 * E / (m * Omega**2))))
    assert not vanishes(p_r.subs(alpha2, 0).subs(r, sp.sqrt(E / (m * Omega**2))))  # r = A/√2 is no turning point


def test_problem_43_canonical_and_angular_momentum_brackets():
    """Problem 43, eqs. (2)–(7): [x, p_x] = 1, [q_j, q_k] = [p_j, p_k] = 0, [q_j, p_k] = δ_jk, and
    [L_x, L_y] = L_z, [L_y, L_z] = L_x, [L_z, L_x] = L_y for L = r × p."""
    q, p = [x, y, z], [px, py, pz]
    assert poisson_bracket(x, px, q, p) == 1
    for j in range(3):
        for kk in range(3):
            assert poisson_bracket(q[j], q[kk], q, p) == 0 and poisson_bracket(p[j], p[kk], q, p) == 0
            assert poisson_bracket(q[j], p[kk], q, p) == (1 if j == kk else 0)
    L = sp.Matrix(q).cross(sp.Matrix(p))
    for i in range(3):
        assert sp.expand(poisson_bracket(L[i], L[(i + 1) % 3], q, p) - L[(i + 2) % 3]) == 0


def test_problem_44_isotropic_oscillator_tensor_is_conserved():
    """Problem 44, eqs. (8)–(27): for H = Σ p_n²/2m + m ω² Σ q_n²/2 the functions
    T_kl = p_k p_l + (m ω)² q_k q_l are constants of motion, [q_k, H] = p_k/m and [p_k, H] = −m ω² q_k (26);
    with a wrong factor (m ω)² → m ω² the bracket does not vanish."""
    q, p = sp.symbols("q1:4"), sp.symbols("p1:4")
    H = sum(pi**2 for pi in p) / (2 * m) + m * omega**2 * sum(qi**2 for qi in q) / 2
    for kk in range(3):
        assert sp.simplify(poisson_bracket(q[kk], H, q, p) - p[kk] / m) == 0
        assert sp.simplify(poisson_bracket(p[kk], H, q, p) + m * omega**2 * q[kk]) == 0
        for ll in range(3):
            assert is_constant_of_motion(p[kk] * p[ll] + (m * omega) ** 2 * q[kk] * q[ll], H, q, p)
    assert not is_constant_of_motion(p[0] * p[1] + m * omega**2 * q[0] * q[1], H, q, p)


def test_explicitly_time_dependent_constant_of_motion():
    """Eq. (166) with ∂f/∂t: for a free particle H = p²/2m, x − p t/m (the initial position) is conserved,
    [f, H] = −p/m and ∂f/∂t = +… cancel; x alone is not (dx/dt = p/m)."""
    H = px**2 / (2 * m)
    assert is_constant_of_motion(x - px * t / m, H, [x], [px], t)
    assert sp.simplify(constant_of_motion_rate(x, H, [x], [px], t) - px / m) == 0


def test_bad_input():
    with pytest.raises(ValueError, match="q, p: expected as many"):
        poisson_bracket(x, px, [x, y], [px])
    with pytest.raises(ValueError, match="couples"):
        separate_hamilton_jacobi((px**2 + py**2) / 2 + x * y, [x, y], [px, py])
    with pytest.raises(ValueError, match="depends on t"):
        separate_hamilton_jacobi(px**2 / 2 + t * x, [x], [px])
