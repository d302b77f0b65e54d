"""The elastic scenes keep the contract of issue 6 ("Scenes"): spin_up_beam's defaults and
hub motion, spinning_beam's spin and rotary inertia, elastic_arm's links, tip mass and
initial state."""

import inspect

import numpy as np
import pytest
import sympy as sp
from scipy.spatial.transform import Rotation

from projeq.scenes.elastic import elastic_arm, spin_up_beam, spin_up_motion, spinning_beam
from projeq.subsystems import PointMass, RitzBeam

#: a scene's parameters reproduced by sums and products of a few terms: round-off of the value
EXACT = 100 * np.finfo(float).eps


def _hub_pose(system, name, t):
    """(A, r, w) of the prescribed joint of subsystem ``name`` at time t."""
    joint = system.joints[system.index(name)]
    relative = joint.relative(np.zeros(0), np.zeros(0), t)
    return relative.A, relative.r, relative.w


def _rotation(axis, angle):
    """Rotation by ``angle`` about coordinate axis ``axis`` (right-hand rule)."""
    return Rotation.from_rotvec(angle * np.eye(3)[axis]).as_matrix()


def test_spin_up_beam_defaults_are_the_issues():
    """omega_s = 6 rad/s, t_s = 15 s, L = 10 m, EI = 1.4e4 N m² in both planes, EA = 2.8e7 N,
    ρA = 1.2 kg/m, gravity off, the beam named "beam", clamped on the z axis (hub radius
    0), bending in both planes. Mass ρAL = 12 kg and the axial stiffness EA/L of the
    linear axial function are exact sums of the quadrature (100 ε: measured 1.5e-16 and 3.3e-16 relative;
    the bounds were 1e-12, and allclose's default 1e-8 for the hub's pose, exact to 1.2e-16)."""
    defaults = {k: p.default for k, p in inspect.signature(spin_up_beam).parameters.items()}
    expected = {"omega_s": 6.0, "t_s": 15.0, "length": 10.0, "EI": 1.4e4, "EA": 2.8e7, "rho_A": 1.2, "gravity": 0.0}
    assert {k: defaults[k] for k in expected} == expected
    system = spin_up_beam(n_axial=1)
    beam = system.subsystem("beam")
    assert isinstance(beam, RitzBeam) and list(system.names) == ["beam"]
    assert beam.length == 10.0 and beam._EI == {"z": 1.4e4, "y": 1.4e4}
    assert beam.n_v == beam.n_w > 0 and beam.support == "clamped"
    assert beam.mass_weights.sum() == pytest.approx(12.0, rel=EXACT, abs=0)
    assert beam.K_e[0, 0] == pytest.approx(2.8e7 / 10.0, rel=EXACT, abs=0)  # u = (x/L) q: EA ∫(1/L)² dx
    assert np.array_equal(np.asarray(system.gravity, dtype=float), np.zeros(3))
    A, r, w = _hub_pose(system, "beam", 20.0)
    assert np.allclose(r, 0.0, rtol=0.0, atol=EXACT) and np.allclose(w[:5], 0.0, rtol=0.0, atol=EXACT)  # on the axis
    assert np.allclose(A, _rotation(2, 6.0 * (20.0 - 7.5)), rtol=0.0, atol=EXACT)


def test_spin_up_motion_is_the_issues_formula():
    """θ(t) = (Ωs/Ts)[t²/2 + (Ts/2π)²(cos(2πt/Ts) − 1)] for t ≤ Ts, Ωs (t − Ts/2) after
    (issue 6), with θ̇, θ̈ by sympy differentiation of this expression: round-off (2.5e-13: measured
    2.5e-14 at θ = 22, the cancellation in cos − 1 before Ts; 100 ε after it, measured 0; were 1e-12 and 1e-8).
    The spin is smooth at Ts (θ̇ = Ωs, θ̈ = 0 from both sides)."""
    t, omega_s, t_s = sp.Symbol("t"), 6.0, 15.0
    theta = omega_s / t_s * (t**2 / 2 + (t_s / (2 * sp.pi)) ** 2 * (sp.cos(2 * sp.pi * t / t_s) - 1))
    exact = sp.lambdify(t, [theta, theta.diff(t), theta.diff(t, 2)])
    motion = spin_up_motion(omega_s, t_s)
    for time in (0.0, 1.3, 7.5, 11.0, 15.0):
        assert np.allclose(motion(time), exact(time), rtol=0.0, atol=2.5e-13)
    for time in (15.0 + 1e-9, 40.0):
        assert np.allclose(motion(time), (omega_s * (time - t_s / 2), omega_s, 0.0), rtol=EXACT, atol=EXACT)
    assert np.allclose(motion(t_s)[1:], (omega_s, 0.0), rtol=0.0, atol=EXACT * omega_s)


def test_spinning_beam_spins_about_its_own_axis():
    """α = Ω t about x (B(16)–(23)); ``rho_I`` gives both bending axes ρI and the polar
    moment 2ρI (circular section); exact to round-off (100 ε: measured 1.1e-16; the bounds were 1e-12 and
    allclose's default 1e-8)."""
    system = spinning_beam(omega=2.5, rho_I=0.01)
    A, r, w = _hub_pose(system, "beam", 0.8)
    assert np.allclose(A, _rotation(0, 2.0), rtol=0.0, atol=EXACT) and np.allclose(r, 0.0, rtol=0.0, atol=EXACT)
    assert np.allclose(w, [0, 0, 0, 2.5, 0, 0], rtol=EXACT, atol=EXACT)
    beam = system.subsystem("beam")
    assert np.allclose(beam.rotary / beam.weights[:, None], [0.02, 0.01, 0.01], rtol=EXACT, atol=0.0)
    assert spinning_beam().subsystem("beam").rotary is None


def test_elastic_arm_links_tip_mass_and_initial_state():
    """Rigid first link of length l1, the beam on its end, the tip mass on the beam's
    station x = L (so T of the tip depends on q_e); initial spin ``omega0`` and a 1 cm
    in-plane tip deflection; total mass m1 + ρAL + m_tip. All exact to round-off (100 ε: measured 0; the
    bounds were 1e-12 and allclose's default 1e-8)."""
    system = elastic_arm(l1=0.4, length=0.8, rho_A=2.0, tip_mass=0.3, omega0=1.5)
    beam, tip = system.subsystem("beam"), system.subsystem("tip")
    assert isinstance(tip, PointMass) and system.joints[system.index("tip")].parent == "beam"
    assert np.allclose(system.joints[system.index("tip")].r_pn, [0.8, 0.0, 0.0], rtol=0.0, atol=EXACT)
    assert np.allclose(system.joints[system.index("beam")].r_pn, [0.4, 0.0, 0.0], rtol=0.0, atol=EXACT)
    q_e = system.q0[system.e_q_slice[system.index("beam")]]
    assert beam.displacement(q_e, [0.8])[0, 1:] == pytest.approx([0.01, 0.0], abs=EXACT * 0.01)  # (v, w) at the tip
    assert system.s_dot0[0] == 1.5 and np.allclose(system.s_dot0[1:], 0.0, rtol=0.0, atol=EXACT * 1.5)
    total = system.subsystem("link1").m + beam.mass_weights.sum() + tip.m
    assert total == pytest.approx(1.0 + 1.6 + 0.3, rel=EXACT, abs=0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: spin_up_beam(t_s=0.0), "t_s: must be positive"),
        (lambda: spin_up_beam(omega_s=float("nan")), "omega_s"),
        (lambda: spin_up_beam(n_shapes=0), "n_shapes"),
        (lambda: spin_up_beam(n_axial=-1), "n_axial"),
        (lambda: spin_up_beam(EI=-1.0), "^EI: must be positive"),  # the scene's name (was RitzBeam's EI_z)
        (lambda: elastic_arm(n_shapes=2.5), "n_shapes"),
        (lambda: spinning_beam(omega=float("inf")), "omega"),
        (lambda: spinning_beam(rho_I=-1e-3), "rho_I"),
    ],
    ids=["t_s", "omega_s", "n_shapes", "n_axial", "EI", "arm-n_shapes", "omega", "rho_I"],
)
def test_bad_elastic_scene_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()
