"""Driven block, Problem 11 of the Lagrange seminars: a block B moves
vertically by the given law s = A sin Ωt (28) (downwards positive) and a mass m hangs
from it on a spring of stiffness k and natural length l₀.

The block is a ``Prescribed`` prismatic joint (rheonomic, no coordinate of its own). The
mass is modelled twice:

- "absolute": on a prismatic joint from the ground (depth y) with a point-to-point
  SpringDamper to the block; the seminars' q = y − l with l = l₀ + m g/k (31)–(34);
- "relative": on a prismatic joint *of the block* whose coordinate is the spring length
  l₁, with a JointSpring; q = l₁ + s − l (31).
"""

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from _linear import in_request_units

G = 9.81
M, K, L0, M_BLOCK = 0.4, 25.0, 0.5, 2.0  # kg, N/m, m, kg (the block's mass must not matter)
A_DRIVE = 0.03  # m
DOWN = (0.0, 0.0, -1.0)
T_SYM = sp.Symbol("t")
L_EQ = L0 + M * G / K  # l = l₀ + Δl, Δl = m g / k: eqs. (32)–(34)
OMEGA0 = np.sqrt(K / M)  # eq. (30)


def driven(variant, Omega):
    drive = pq.Prescribed(pq.Prismatic(axis=DOWN), A_DRIVE * sp.sin(Omega * T_SYM))  # eq. (28)
    if variant == "absolute":
        joints = {"block": drive, "mass": pq.Prismatic(axis=DOWN)}
        forces = [pq.SpringDamper("block", (0.0, 0.0, 0.0), "mass", (0.0, 0.0, 0.0), K, length=L0)]
    else:
        joints = {"block": drive, "mass": pq.Prismatic(parent="block", axis=DOWN)}
        forces = [pq.JointSpring("mass", K, q_ref=L0)]
    return pq.System(
        subsystems={"block": pq.PointMass(M_BLOCK), "mass": pq.PointMass(M)},
        joints=joints,
        gravity=(0.0, 0.0, -G),
        forces=forces,
        q0=[L_EQ],
    )


VARIANTS = ["absolute", "relative"]
OMEGAS = [0.5 * OMEGA0, 1.7 * OMEGA0]  # below and above resonance (D changes sign)
OMEGA_IDS = ["Omega=0.5w0", "Omega=1.7w0"]


@pytest.mark.parametrize("Omega", OMEGAS, ids=OMEGA_IDS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_driven_block_equation_of_motion(variant, Omega):
    """Problem 11, eqs. (39)–(40) of the Lagrange seminars:
    q̈ + ω₀² q = ω₀² s(t), ω₀² = k/m, at random (q, q̇, t); the block's motion enters
    through the prescribed joint (in the relative model also through its acceleration:
    l̈₁ = q̈ − s̈)."""
    system = driven(variant, Omega)
    rng = np.random.default_rng(11)
    for t, dq, v in rng.uniform([0.0, -0.1, -1.0], [3.0, 0.1, 1.0], size=(6, 3)):
        s, s_ddot = A_DRIVE * np.sin(Omega * t), -A_DRIVE * Omega**2 * np.sin(Omega * t)
        q = dq  # the seminars' q
        coordinate = q + L_EQ if variant == "absolute" else q - s + L_EQ
        accel = system.accelerations([coordinate], [v], t=t)[0]
        q_ddot = accel if variant == "absolute" else accel + s_ddot
        # terms of size k·0.1 m/m ≈ 6 m/s² and g cancel: round-off, 100 ε of g (measured 8.4e-15 m/s²;
        # was 1e-12 of g)
        round_off = 100 * np.finfo(float).eps
        assert q_ddot == pytest.approx(OMEGA0**2 * (s - q), rel=round_off, abs=round_off * G)
        # dense = recursive: measured 1.3e-13 m/s² (was 1e-12 relative + 1e-12 g)
        np.testing.assert_allclose(system.accelerations([coordinate], [v], t=t, method="dense"), accel,
                                   rtol=0, atol=1.3e-12)


@pytest.mark.parametrize("Omega", OMEGAS, ids=OMEGA_IDS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_driven_block_forced_response(variant, Omega):
    """Problem 11, eqs. (29), (43)–(47) of the Lagrange seminars:
    q(t) = C sin(ω₀t + φ) + D sin Ωt with D = A ω₀²/(ω₀² − Ω²) (46), and C, φ fixed by
    q(0) = q₀, q̇(0) = v₀: C sin φ = q₀, C ω₀ cos φ = v₀ − D Ω. Checked over several
    periods of both frequencies.
    """
    system = driven(variant, Omega)
    q0, v0 = 0.02, -0.1
    D = A_DRIVE * OMEGA0**2 / (OMEGA0**2 - Omega**2)
    C = np.hypot(q0, (v0 - D * Omega) / OMEGA0)
    phi = np.arctan2(q0, (v0 - D * Omega) / OMEGA0)
    coordinate0 = q0 + L_EQ  # s(0) = 0 in both models
    v_coordinate0 = v0 if variant == "absolute" else v0 - A_DRIVE * Omega  # l̇₁ = q̇ − ṡ
    rtol, atol = 1e-10, 1e-12
    t_end = 4 * 2 * np.pi / min(OMEGA0, Omega)
    res = pq.simulate(system, t_end, q0=[coordinate0], s_dot0=[v_coordinate0], method="DOP853", rtol=rtol,
                      atol=atol)
    q_ref = C * np.sin(OMEGA0 * res.t + phi) + D * np.sin(Omega * res.t)
    # the coordinate (≈ l ≈ 0.66 m) is what the integrator controls: its error in units
    # of the request, with |coordinate| as the scale; ≤ 8 fast periods of a linear
    # oscillator keep it within 5 units as in scipy's solve_ivp tests
    coordinate_ref = q_ref + L_EQ if variant == "absolute" else q_ref - A_DRIVE * np.sin(Omega * res.t) + L_EQ
    assert in_request_units(res.q[:, 0], coordinate_ref, rtol, atol).max() < 5
