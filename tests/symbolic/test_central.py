"""Bremer's Central Equation B(2) as code (projeq.symbolic.central): Hamel's equations, the Projection
Equation, Kane's equations and Lagrange's equations with multipliers derived from one description, against
H. Bremer, "Problems in fast moving non-holonomic elastic systems", B(8), B(9), B(12), projeq's existing
derivations (the car scene's gauss_form, the multiplier model of the car, the knife-edge disc's Hamel and
Projection-Equation derivations) and sympy's KanesMethod."""

import numpy as np
import pytest
import sympy as sp
from sympy.physics import mechanics as me

from projeq.symbolic import gauss_form
from projeq.symbolic.central import central_equation
from projeq.symbolic.projection import Body

m, c, C0, f_x, f_y, M_c = sp.symbols("m c C0 f_x f_y M_c")
v_x, v_y, w_z = sp.symbols("v_x v_y omega_z")
v_x_dot, v_y_dot, w_z_dot = sp.symbols("v_x_dot v_y_dot omega_z_dot")
q = x, y, gamma = sp.symbols("x y gamma")
H_CAR = sp.Matrix([[sp.cos(gamma), sp.sin(gamma), 0], [-sp.sin(gamma), sp.cos(gamma), 0], [0, 0, 1]])  # B(6)


def car(forces=True):
    """B(5)–(6): the car in its body frame B (R = B), mass centre at c along x_B, C° = C^c + m c² about the
    rear axle O; force (f_x, f_y) at the mass centre and torque M_c about it; v_y = 0 the constraint."""
    loads = dict(f=(f_x, f_y, 0), M=(0, 0, M_c)) if forces else {}
    body = Body(v_c=(v_x, v_y + c * w_z, 0), omega=(0, 0, w_z), m=m, I_c=sp.diag(0, 0, C0 - m * c**2),
                omega_IR=(0, 0, w_z), **loads)
    return central_equation({"car": body}, q, (v_x, v_y, w_z), H_CAR, [v_y], (m, c, C0, f_x, f_y, M_c))


def vanish(X) -> bool:
    return sp.expand(sp.Matrix(X)) == sp.zeros(*sp.Matrix(X).shape)


def test_car_hamel_is_B8_then_B9():
    """B(8) before the constraint (Q₃ = c f_y + M_c, the moment about O), and after v_y = 0 the Gauss
    form B(9): diag(m, C°) (v̇_x, ω̇_z) + [0, −m c ω_z; m c ω_z, 0] (v_x, ω_z) = (f_x, Q₃); exact."""
    Q3 = c * f_y + M_c
    B8 = [m * v_x_dot - m * c * w_z**2 - m * w_z * v_y - f_x,
          m * v_y_dot + m * c * w_z_dot + m * w_z * v_x - f_y,
          C0 * w_z_dot + m * c * v_y_dot + m * c * v_x * w_z - Q3]
    assert vanish(car().hamel_residuals() - sp.Matrix(B8))
    hamel = car().hamel()
    assert hamel.M == sp.diag(m, C0)
    assert vanish(hamel.rhs - sp.Matrix([m * c * w_z**2 + f_x, -m * c * w_z * v_x + Q3]))


def test_car_projection_equation_is_B12_and_kane_equals_it():
    """B(11)–(12) literally: [1 0 0; 0 c 1] {[m 0; 0 mc; 0 C^c] s̈ + ω̃ [m 0; 0 mc; 0 C^c] ṡ − (f_x, f_y, M_c)}
    (C^c = C° − m c², ω̃ the spin of ω_z acting on (p_x, p_y, L_z)); the Projection Equation and Kane's
    equations from B(2) both equal it, exactly; Hamel's B(9) too (the same equations)."""
    F = sp.Matrix([[1, 0, 0], [0, c, 1]])
    momenta = sp.Matrix([[m, 0], [0, m * c], [0, C0 - m * c**2]])
    spin = sp.Matrix([[0, -w_z, 0], [w_z, 0, 0], [0, 0, 0]])
    s_dot, s_ddot = sp.Matrix([v_x, w_z]), sp.Matrix([v_x_dot, w_z_dot])
    B12 = F * (momenta * s_ddot + spin * momenta * s_dot - sp.Matrix([f_x, f_y, M_c]))
    b2 = car()
    for form in (b2.projection(), b2.kane(), b2.hamel()):
        assert vanish(form.M * s_ddot - form.rhs - B12)


def test_car_matches_the_scene_derivation():
    """projeq's own derivation of the car scene, gauss_form(scenes.car()) (m = 1200, c = 1.2, C° = 3228, no
    forces): the same M and rhs as Hamel's, the Projection Equation's and Kane's forms from B(2), exactly."""
    from projeq.scenes import car as car_scene

    scene = gauss_form(car_scene())
    names = dict(zip(scene.q + scene.s, q + (v_x, w_z)))
    values = {m: 1200, c: sp.Rational(6, 5), C0: 3228}
    b2 = car(forces=False)
    for form in (b2.hamel(), b2.projection(), b2.kane()):
        for ours, theirs in ((form.M, scene.M), (form.rhs, scene.rhs)):
            difference = (ours.subs(values) - theirs.xreplace(names)).applyfunc(sp.nsimplify)
            assert vanish(difference)


def test_car_lagrange_with_multipliers_is_the_existing_multiplier_model():
    """Lagrange with multipliers from B(2) (H = E, the constrained row −sin γ ẋ + cos γ ẏ = 0 of H adjoined
    with λ) equals projeq's multiplier model of the car (projeq.studies.compare_multipliers, the lecture's
    K(7)), exactly."""
    from projeq.studies.compare_multipliers import car_multiplier_system

    ours = car(forces=False).lagrange().lagrange_equations()
    theirs = car_multiplier_system({m: m, c: c, C0: C0}).lagrange_equations()
    names = {f.func.__name__: f for f in theirs.atoms(sp.core.function.AppliedUndef)}
    ours = ours.xreplace({f: names[f.func.__name__] for f in ours.atoms(sp.core.function.AppliedUndef)})
    g_t = names["gamma"]
    assert vanish(sp.expand(ours - theirs).subs(sp.sin(g_t) ** 2, 1 - sp.cos(g_t) ** 2))


def test_car_kane_matches_sympys_kanes_method():
    """Kane's form from B(2) against sympy's KanesMethod (independent: its own kinematics from frames and
    points, v_y the dependent speed with the velocity constraint v_y = 0): mass matrix and forcing of the
    independent speeds equal, exactly."""
    xs, ys, gs = me.dynamicsymbols("x y gamma")
    u1, u2, u3 = me.dynamicsymbols("v_x v_y omega_z")
    N = me.ReferenceFrame("N")
    B = N.orientnew("B", "Axis", [gs, N.z])
    O = me.Point("O")
    O.set_vel(N, u1 * B.x + u2 * B.y)
    G = O.locatenew("G", c * B.x)
    G.v2pt_theory(O, N, B)
    B.set_ang_vel(N, u3 * B.z)
    body = me.RigidBody("car", G, B, m, (me.inertia(B, 0, 0, C0 - m * c**2), G))
    kd = [xs.diff() - u1 * sp.cos(gs) + u2 * sp.sin(gs), ys.diff() - u1 * sp.sin(gs) - u2 * sp.cos(gs),
          gs.diff() - u3]
    kane = me.KanesMethod(N, [xs, ys, gs], [u1, u3], kd_eqs=kd, u_dependent=[u2], velocity_constraints=[u2])
    fr, frstar = kane.kanes_equations([body], [(G, f_x * B.x + f_y * B.y), (B, M_c * B.z)])
    accelerations = {u1.diff(): v_x_dot, u3.diff(): w_z_dot, u2.diff(): 0}
    plain = {u1: v_x, u3: w_z, u2: 0, gs: gamma}
    ours = car().kane()
    assert vanish(ours.M * sp.Matrix([v_x_dot, w_z_dot]) - ours.rhs + (fr + frstar).subs(accelerations).xreplace(plain))


def test_knife_edge_disc_forms_equal_the_existing_derivations():
    """The knife-edge disc (the lecture on non-holonomic systems, slides 28–37) as B(2) with the speeds
    (ψ̇, ϕ̇, θ̇, c₁, c₂), c₁ = c₂ = 0 the rolling constraints: Hamel's equations, the Projection Equation and
    Kane's equations from it equal projeq's derivations hamel_disc() (constraints after B(3)) and
    projection_disc() (B(10), R = E) at 3 random states and parameter sets, to 100 ε (measured ≤ 4.4e-16)."""
    from projeq.symbolic.formulation_examples import central_disc, hamel_disc, projection_disc

    b2 = central_disc()
    symbols = [*b2.q, *b2.independent, *b2.parameters]
    references = [hamel_disc(), projection_disc()]
    for form in (b2.hamel(), b2.projection(), b2.kane()):
        ours = sp.lambdify(symbols, [form.M, form.rhs])
        theirs = [sp.lambdify(symbols, [R.M, R.rhs]) for R in references]
        for point in np.random.default_rng(0).uniform(0.2, 1.2, (3, len(symbols))):
            M, rhs = ours(*point)
            for reference in theirs:
                M_ref, rhs_ref = reference(*point)
                assert np.allclose(M, M_ref, rtol=0, atol=100 * np.finfo(float).eps * np.abs(M_ref).max())
                assert np.allclose(rhs, rhs_ref, rtol=0, atol=100 * np.finfo(float).eps * np.abs(rhs_ref).max())


def test_bad_input():
    body = Body(v_c=(v_x, 0, 0), omega=(0, 0, w_z), m=m, I_c=sp.eye(3))
    with pytest.raises(ValueError, match="H: expected shape"):
        central_equation({"b": body}, q, (v_x, w_z), H_CAR, parameters=(m,))
    with pytest.raises(ValueError, match="constrained: expected some"):
        central_equation({"b": body}, q, (v_x, v_y, w_z), H_CAR, [f_x], (m,))
    with pytest.raises(ValueError, match="b.v_c: depends on undeclared symbols m"):
        central_equation({"b": Body(v_c=(m, 0, 0), omega=(0, 0, 0), m=1, I_c=sp.eye(3))}, q, (v_x, v_y, w_z), H_CAR)
    with pytest.raises(ValueError, match="H: singular"):
        central_equation({"b": body}, q, (v_x, v_y, w_z), sp.zeros(3, 3), parameters=(m,))


def test_rolling_disc_kane_matches_sympys_kanes_method():
    """The rolling (knife-edge) disc: Kane's form from B(2) (central_disc(), speeds (ψ̇, ϕ̇, θ̇), rolling
    constraints c₁ = c₂ = 0) against sympy's KanesMethod built independently from frames and points
    (Y = R_z(ψ), E = Y R_x(ϕ), disc D = E R_y(θ); contact point at rest, centre G = C − r e_z(E), weight
    m g along the downward N.z, inertia diag(I, J, I) in E): mass matrix and forcing equal at 3 random
    states to 100 ε (measured ≤ 2.2e-16)."""
    from projeq.symbolic.formulation_examples import central_disc

    psi, phi, th = me.dynamicsymbols("psi phi theta")
    u1, u2, u3 = me.dynamicsymbols("u1:4")
    b2 = central_disc()
    I, J, g, m_disc, r = b2.parameters
    N = me.ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [psi, N.z])
    E = Y.orientnew("E", "Axis", [phi, Y.x])
    D = E.orientnew("D", "Axis", [th, E.y])
    D.set_ang_vel(N, u1 * Y.z + u2 * E.x + u3 * E.y)
    C = me.Point("C")
    C.set_vel(N, 0)
    G = C.locatenew("G", -r * E.z)
    G.v2pt_theory(C, N, D)
    disc = me.RigidBody("disc", G, D, m_disc, (me.inertia(E, I, J, I), G))
    kd = [psi.diff() - u1, phi.diff() - u2, th.diff() - u3]
    kane = me.KanesMethod(N, [psi, phi, th], [u1, u2, u3], kd_eqs=kd)
    kane.kanes_equations([disc], [(G, m_disc * g * N.z)])
    plain = dict(zip([psi, phi, th, u1, u2, u3], [*b2.q[2:], *b2.independent]))
    symbols = [*b2.q, *b2.independent, *b2.parameters]
    form = b2.kane()
    ours = sp.lambdify(symbols, [form.M, form.rhs])
    theirs = sp.lambdify(symbols, [kane.mass_matrix.xreplace(plain), kane.forcing.xreplace(plain)])
    for point in np.random.default_rng(1).uniform(0.2, 1.2, (3, len(symbols))):
        for a, b in zip(ours(*point), theirs(*point)):
            a, b = np.asarray(a, float).ravel(), np.asarray(b, float).ravel()
            assert np.abs(a - b).max() <= 100 * np.finfo(float).eps * np.abs(b).max()
