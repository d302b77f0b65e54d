"""Driven mechanisms: a four-bar whose crank follows a given motion θ1(t) (a joint prescribed
in time, :class:`projeq.Prescribed`) and is closed by a cut joint (:class:`projeq.PinClosure`),
so that Φ(q, t) depends on t through the crank: with the motion in sympy the closure kernel
evaluates it (−∂Φ/∂t and γ from the chain's twists and accelerations, the prescribed joint's
relative motion a compiled callback: exact), with a callable motion too (the callable compiled), and
with a callable numba cannot compile the numpy path (complex steps through the poses, stencils for
Φ″). Checked against independent statements: the
loop's closed form (the rocker and coupler angles by intersecting the circles about the crank pin
and the rocker pivot, differentiated symbolically by sympy for the rates and accelerations), and
the power balance — the only force that works on the mechanism is the driving torque τ of the
prescribed joint (the cut joint's pair of forces acts at one point and does no work), so
τ θ̇1 = dE/dt (Richardson's extrapolation of central differences along the motion)."""

import warnings

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.constraints.compiled import UncompiledClosureWarning
from projeq.constraints.reactions import joint_reactions
from projeq.constraints.partitioned import TangentSystem
from projeq.scenes.mechanisms import four_bar_angles, slender_rod

A, B, C, D = 0.3, 1.0, 0.8, 1.0  # crank, coupler, rocker, ground
THETA0, OMEGA, AMPLITUDE = 0.5, 3.0, 0.4  # θ1(t) = θ0 + Ω t + a sin(2t): a non-uniform drive


def _motion():
    t = sp.Symbol("t")
    return THETA0 + OMEGA * t + AMPLITUDE * sp.sin(2 * t)


def _closed_form():
    """t ↦ (q, q̇, q̈) of the tree coordinates (rocker q3, coupler q2 relative to the crank) from
    the loop's closed form (:func:`projeq.scenes.mechanisms.four_bar_angles` written in sympy),
    differentiated symbolically."""
    t = sp.Symbol("t")
    theta1 = _motion()
    P = sp.Matrix([A * sp.cos(theta1), A * sp.sin(theta1)])
    e_vec = sp.Matrix([D, 0]) - P
    e = sp.sqrt(e_vec.dot(e_vec))
    u = e_vec / e
    along = (B ** 2 - C ** 2 + e ** 2) / (2 * e)
    X = P + along * u + sp.sqrt(B ** 2 - along ** 2) * sp.Matrix([-u[1], u[0]])
    q = sp.Matrix([sp.atan2(X[1], X[0] - D), sp.atan2(X[1] - P[1], X[0] - P[0]) - theta1])
    f = sp.lambdify(t, [q, q.diff(t), q.diff(t, 2)], "numpy")
    return lambda time: tuple(np.array(v, dtype=float).ravel() for v in f(time))


def _tree(coupler, motion):
    return pq.System({"crank": slender_rod(1.0, A), "rocker": slender_rod(1.5, C), "coupler": coupler},
                     {"crank": pq.Prescribed(pq.Revolute(axis="z"), motion),
                      "rocker": pq.Revolute(axis="z", r_pn=(D, 0.0, 0.0)),
                      "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0.0, 0.0))},
                     gravity=(0.0, -9.81, 0.0))


def _callable_motion(t):
    """θ1(t) and its derivatives written by hand (complex-safe: numpy operations)."""
    return (THETA0 + OMEGA * t + AMPLITUDE * np.sin(2 * t), OMEGA + 2 * AMPLITUDE * np.cos(2 * t),
            -4 * AMPLITUDE * np.sin(2 * t))


def _python_motion(t):
    """The same motion through a Python function numba does not compile (the joint in Python)."""
    return _callable_motion(t)


def _driven(coupler=None, motion=None, kind=pq.ConstrainedSystem):
    """The driven four-bar (default: a rigid coupler, the sympy motion) as a ``kind`` of constrained
    model, and its pin; a callable numba cannot compile takes the numpy path (warned: not tested here)."""
    tree = _tree(slender_rod(2.0, B) if coupler is None else coupler, _motion() if motion is None else motion)
    pin = pq.PinClosure(tree, "coupler", (B, 0.0, 0.0), "rocker", (C, 0.0, 0.0), axes="xy")
    theta2, theta3 = four_bar_angles(THETA0, A, B, C, D)
    q0 = (theta3, theta2 - THETA0) + (0.0,) * (tree.n_q - 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore" if motion is _python_motion else "error", UncompiledClosureWarning)
        system = kind(tree, phi=pin, q0=q0)
        assert (system.compiled_kernel() is None) == (motion is _python_motion)
    return system, pin


@pytest.fixture(scope="module")
def exact():
    return _closed_form()


@pytest.mark.parametrize("motion, kind, bound", [
    (None, pq.ConstrainedSystem, 1e-14),  # the kernel: measured 1.1e-15
    (None, TangentSystem, 1e-14),  # the tangent kernel (f the particular solution by the SVD): 1.1e-15
    (_callable_motion, pq.ConstrainedSystem, 1e-14),  # the kernel, the callable compiled: 1.1e-15
    (_python_motion, pq.ConstrainedSystem, 1e-11),  # the numpy path: 1.4e-12 (1.4e-10 unscaled)
], ids=["compiled", "compiled-tangent", "compiled-callable", "numpy"])
def test_a_driven_four_bar_follows_the_closed_form(exact, motion, kind, bound):
    """The default correction (projection onto Φ(q, t) = 0 at each output's time) keeps q on the
    closed form to round-off, and the velocities (f = A_dep⁻¹ b_s, b_s = −∂Φ/∂t: no minimal
    velocity is left) and accelerations (γ with its rheonomic parts; on the numpy path their
    stencils along t scaled by the drive's rate) equal its symbolic derivatives. Before, a sympy
    motion cast the complex step in t to float — ∂Φ/∂t = 0, silently: the rocker lagged 0.16 rad
    after 0.5 s (with Baumgarte's correction) —, the default correction refused Φ(q, t), and no
    driven mechanism was one compiled call."""
    system, _ = _driven(motion=motion, kind=kind)
    assert system.n_s == 0 and system.rheonomic
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UncompiledClosureWarning)
        result = pq.simulate(system, 2.0, n_points=21)
    for t, q in zip(result.t, result.q):
        q_exact, q_dot_exact, q_ddot_exact = exact(t)
        assert np.abs(q - q_exact).max() <= 1e-14  # measured 4.4e-16
        q_dot = system.tree_velocities(q, [], t)
        assert np.abs(q_dot - q_dot_exact).max() <= 1e-14 * np.abs(q_dot_exact).max()  # 5.2e-16
        s_ddot_tree, _ = system.accelerations_tree(q_exact, [], t)
        assert np.abs(s_ddot_tree - q_ddot_exact).max() <= bound * np.abs(q_ddot_exact).max()


def _richardson(f, x, h=1e-3):
    """f′(x) by central differences at h, h/2, h/4 and Richardson's extrapolation (error O(h⁶))."""
    d = [(f(x + k) - f(x - k)) / (2 * k) for k in (h, h / 2, h / 4)]
    d1, d2 = (4 * d[1] - d[0]) / 3, (4 * d[2] - d[1]) / 3
    return (16 * d2 - d1) / 15


def _driving_power(system, pin, q, s_dot, t):
    """τ θ̇1: the prescribed joint's moment about its axis (the wrench it transmits to the crank,
    :func:`projeq.constraints.reactions.joint_reactions`) times the crank's rate."""
    W = joint_reactions(system, q, s_dot, t, cuts={"pin": pin})["crank"]  # a planar body's (f_x, f_y, M_z)
    return W[2] * _callable_motion(t)[1]


def test_the_driving_torque_does_the_work_of_the_rigid_four_bar(exact):
    """τ θ̇1 = dE/dt with E = T + V of the closed-form motion (the tree's energy at the exact
    q, q̇ and t), at five times of a period."""
    system, pin = _driven()
    for t in np.linspace(0.1, 2.0, 5):
        def energy(time):
            q, q_dot, _ = exact(time)
            return sum(system.tree.energy(q, q_dot, time))
        q, _, _ = exact(t)
        power, rate = _driving_power(system, pin, q, [], t), _richardson(energy, t)
        assert abs(power - rate) <= 1e-11 * max(1.0, abs(rate))  # measured 1.8e-12


def test_the_driving_torque_does_the_work_of_a_flexible_four_bar():
    """The same drive with a RitzBeam coupler pinned at its tip (n_s = 2: the beam's bending
    amplitudes are the minimal velocities): τ θ̇1 = dE/dt along (q̇, s̈, 1) at bent, vibrating
    states — strain energy and kinetic energy of the bending included."""
    beam = pq.RitzBeam(B, 2.0, 200.0, n_v=2, n_w=0, family="clamped_free")
    system, pin = _driven(coupler=beam)
    assert system.n_s == 2
    rng = np.random.default_rng(3)
    for t in (0.2, 0.9):
        q = system.project(system.q0 + np.concatenate((0.2 * rng.standard_normal(2), 0.01 * rng.standard_normal(2))), t)
        s_dot = rng.uniform(-0.5, 0.5, 2)
        q_dot = system.q_dot(q, s_dot, t)
        s_ddot = system.accelerations(q, s_dot, t)

        def energy(h):
            return sum(system.energy(q + h * q_dot, s_dot + h * s_ddot, t + h))
        power, rate = _driving_power(system, pin, q, s_dot, t), _richardson(energy, 0.0)
        scale = abs(sum(map(abs, system.energy(q, s_dot, t))))
        assert abs(power - rate) <= 1e-9 * scale  # measured 1.8e-10 (the differences along the beam's vibration)
