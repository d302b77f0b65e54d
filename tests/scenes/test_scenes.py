"""The scenes' public contract (core issue): geometry, conventions, defaults."""

import numpy as np
import pytest

import projeq as pq

ROUND_OFF = 100 * np.finfo(float).eps  # identities that hold to round-off: 100 ε


@pytest.mark.parametrize("planar", [False, True])
def test_chain_hangs_along_minus_z_from_the_origin(planar):
    """Links of 1 m and 1 kg with the mass centre in the middle hang along −z at q = 0:
    the potential is −Σ m g (i + ½) for link i (0-based), g = 9.81."""
    system = pq.scenes.chain(4, planar=planar)
    _, potential = system.energy(np.zeros(4), np.zeros(4))
    assert potential == pytest.approx(-9.81 * sum(i + 0.5 for i in range(4)), rel=1e-14, abs=0)  # measured 0


def test_chain_angles_follow_the_right_hand_rule_about_y():
    """Right-hand rule about +y: rotating −z about +y by θ > 0 gives (−sin θ, 0, −cos θ), so
    the link's centre moves towards −x, and gravity pulls it back (θ̈ < 0)."""
    system = pq.scenes.chain(1)
    from projeq.assembly.kinematics import forward

    kin = forward(system, np.array([0.3]), np.zeros(1), 0.0)
    centre = kin.r[0] + kin.R[0] @ system.subsystem("link1").r_c
    # measured 0 (was allclose's defaults)
    assert np.allclose(centre, 0.5 * np.array([-np.sin(0.3), 0.0, -np.cos(0.3)]), rtol=0, atol=ROUND_OFF)
    assert system.accelerations([0.3], [0.0])[0] < 0


def test_one_link_is_a_compound_pendulum():
    """Small oscillations of one link: ω² = m g d / I_O with d = 0.5 m and
    I_O = m (3 r² + ℓ²)/12 + m d² for the solid cylinder (r = 0.01 m, ℓ = 1 m). The Jacobian is the
    complex step: 100 ε (measured 0; was 1e-8)."""
    system = pq.scenes.chain(1)
    A, _ = pq.linearize(system, q=[0.0], s_dot=[0.0])
    omega2 = -A[1, 0]
    I_O = (3 * 0.01**2 + 1.0) / 12 + 0.25
    assert omega2 == pytest.approx(9.81 * 0.5 / I_O, rel=ROUND_OFF, abs=0)


def test_scenes_come_with_default_initial_states():
    for name, scene in pq.scenes.SCENES.items():
        system = scene.build()
        assert system.q0.shape == (system.n_q,) and system.s_dot0.shape == (system.n_s,), name


def test_planar_chain_is_built_from_planar_bodies():
    system = pq.scenes.chain(3, planar=True)
    assert all(isinstance(sub, pq.PlanarBody) for sub in system.subsystems)
    assert all(isinstance(sub, pq.RigidBody) and not isinstance(sub, pq.PlanarBody) for sub in pq.scenes.chain(3).subsystems)


def test_every_scene_parameter_has_a_documented_unit():
    """Scenes as data: every keyword parameter of every registered scene has a unit entry
    ("-" marks a dimensionless number or a switch), so ``projeq list SCENE`` is complete."""
    from projeq.scenes.parameters import UNITS

    for name, scene in pq.scenes.SCENES.items():
        for parameter in pq.scenes.scene_parameters(scene):
            assert parameter.name in {**UNITS, **(scene.units or {})}, (name, parameter.name)


def test_build_scene_overrides_reach_the_model():
    """atwood with m1 = 3 kg: θ̈ = −ẍ/a, ẍ = (m1 − m2) g / (m1 + m2 + I/a²), I = ½ M a²
    (Problem 1, eq. (4) of the Lagrange seminars); one linear solve: 100 ε relative (measured 1.5e-16;
    was 1e-12)."""
    system = pq.scenes.build_scene("atwood", m1=3.0)
    x_ddot = (3.0 - 1.0) * 9.81 / (3.0 + 1.0 + 0.5 * 0.5)
    assert system.accelerations([0.0], [0.0])[0] == pytest.approx(-x_ddot / 0.1, rel=ROUND_OFF, abs=0)


def test_settings_parse_to_the_type_of_the_default():
    scene = pq.scenes.SCENES["car"]
    parsed = pq.scenes.parse_settings(scene, ["m=900", "q0=1, 2, 0.5", "s_dot0=(5.0, 0.0)"])
    assert parsed == {"m": 900.0, "q0": (1, 2, 0.5), "s_dot0": (5.0, 0.0)} and type(parsed["m"]) is float
    assert pq.scenes.parse_settings(pq.scenes.SCENES["chain"], ["planar=yes", "n=3"]) == {"planar": True, "n": 3}
    # a str parameter that also takes numbers: a name stays text, a tuple literal becomes the tuple
    disk = pq.scenes.SCENES["rolling_disk"]
    assert pq.scenes.parse_settings(disk, ["inertia=hoop"]) == {"inertia": "hoop"}
    assert pq.scenes.parse_settings(disk, ["inertia=(2e-6, 3e-6)"]) == {"inertia": (2e-6, 3e-6)}


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: pq.scenes.get_scene("chan"), "scene: unknown scene 'chan' \\(did you mean 'chain'\\?\\)"),
        (lambda: pq.scenes.build_scene("chain", links=3), "links: unknown parameter"),
        (lambda: pq.scenes.parse_settings(pq.scenes.SCENES["car"], ["q0=(1,"]), "q0: expected a number, a tuple"),
        (lambda: pq.scenes.parse_settings(pq.scenes.SCENES["car"], ["=1"]), "--set: expected name=value"),
    ],
    ids=["scene", "parameter", "literal", "setting"],
)
def test_bad_scene_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_the_registry_makes_a_symbolic_scene_on_first_use_and_takes_new_ones(monkeypatch):
    """scenes.SCENES lists every name, makes a symbolic scene when it is looked up (the same
    function as its module's), and registers and removes a user's scene (``projeq run`` not
    importing sympy: tests/test_import.py)."""
    assert "whipple_bicycle" in list(pq.scenes.SCENES)
    from projeq.scenes.bicycle import whipple_bicycle

    assert pq.scenes.SCENES["whipple_bicycle"].build is whipple_bicycle is pq.scenes.whipple_bicycle
    mine = pq.scenes.Scene(pq.scenes.chain, "a chain of mine", 1.0)
    monkeypatch.setitem(pq.scenes.SCENES, "mine", mine)
    assert pq.scenes.get_scene("mine") is mine and list(pq.scenes.SCENES)[-1] == "mine"


#: every scene's sizes and masses (SI), each of which must be positive
SIZES = {
    "double_pendulum": ("m1", "m2", "l1", "l2"),
    "atwood": ("m1", "m2", "pulley_mass", "radius"),
    "quick_return": ("A", "H", "m_a", "m_b"),
    "four_bar": ("a", "b", "c", "d"),
    "flexible_four_bar": ("a", "b", "c", "d", "EI"),
    "sphere_on_sphere": ("a", "b", "m"),
    "bar_on_wall": ("l", "m"),
    "slider_pendulum": ("l", "m"),
    "spin_up_beam": ("t_s", "length", "EI", "EA", "rho_A"),
    "spinning_beam": ("length", "EI", "rho_A", "rho_I"),
    "rotating_blade": ("length", "EI", "rho_A"),
    "elastic_arm": ("l1", "m1", "length", "rho_A", "EI", "tip_mass"),
    "simple_pendulum": ("m", "L"),
    "n_four_bar": ("m", "L"),
    "bricard": ("m", "L", "side"),
    "flyball_governor": ("K", "s0"),
    "knife_edge_disc": ("m", "r", "I", "J"),
    "rolling_disk": ("m_disk", "R"),
    "car": ("m", "C0"),
    "barhorst_particle": ("m",),
    "nonholonomic_particle": ("m",),
}


@pytest.mark.parametrize("value", [0.0, -0.5, float("nan")], ids=["zero", "negative", "nan"])
@pytest.mark.parametrize("scene, name", [(s, n) for s, names in SIZES.items() for n in names],
                         ids=[f"{s}-{n}" for s, names in SIZES.items() for n in names])
def test_a_scene_refuses_a_size_or_mass_that_is_not_positive_by_its_own_name(scene, name, value):
    """Passes if a zero, negative or NaN size or mass is a ValueError that begins with the
    scene's parameter name (a mass may add " (mass)"). Before, double_pendulum(l1=-1),
    slider_pendulum(l=0), bar_on_wall(l=-1), quick_return(A=0), four_bar(d=0) were built (silent
    nonsense: the slider pendulum's Φ = |x| holds the bob at the origin); others were refused
    under another name (elastic_arm(l1=0) as "length", spin_up_beam(EI=-1) as "EI_z",
    knife_edge_disc(I=0) as "I_c", rolling_disk(m_disk=0) as "m (mass)"); spin_up_beam(EA=-1)
    passed unchecked."""
    problem = "non-finite" if np.isnan(value) else "must be positive"
    with pytest.raises(ValueError, match=rf"^{name}( \(mass\))?: {problem}"):
        getattr(pq.scenes, scene)(**{name: value})


@pytest.mark.parametrize("m, message", [
    ((1.0, -2.0, 1.5), r"^m\[1\]: must be positive, got -2.0"),
    ((1.0, 2.0), r"^m: expected the three masses \(crank, coupler, rocker\) in kg, got \(1.0, 2.0\)"),
], ids=["negative", "two"])
def test_the_four_bar_names_its_bad_mass(m, message):
    """Passes if a bad link mass of the four-bar is named by its index; before, (1, −2, 1.5) was
    refused as the coupler rod's "I_c (moment about the plane normal)", and two masses raised a
    bare IndexError."""
    with pytest.raises(ValueError, match=message):
        pq.scenes.four_bar(m=m)


@pytest.mark.parametrize("name", ["m1", "m2", "pulley_mass"])
def test_build_scene_names_the_atwood_mass_it_was_given(name):
    """Passes if build_scene("atwood", m1=nan) (and m2, pulley_mass) is a ValueError that begins
    with that parameter; before, all three were named "m" (the PointMass's or RigidBody's own
    parameter), so that the message did not say which of the three masses was wrong."""
    with pytest.raises(ValueError, match=rf"^{name}: non-finite entries \(NaN or inf\)"):
        pq.scenes.build_scene("atwood", **{name: float("nan")})


@pytest.mark.parametrize("value", [-0.5, float("nan")], ids=["negative", "nan"])
def test_rotating_blade_refuses_a_hub_radius_below_zero(value):
    """The hub radius may be zero (a blade clamped on the axis), not negative or NaN."""
    with pytest.raises(ValueError, match=r"^hub_radius: "):
        pq.scenes.rotating_blade(hub_radius=value)
