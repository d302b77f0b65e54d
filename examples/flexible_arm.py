"""A three-link planar arm whose last link is elastic, built from scratch (tutorial
docs/tutorials/flexible_arm.md).

Two rigid links and a RitzBeam (0.8 m, ρA = 0.8 kg/m, EI_z = 40 N m², four polynomial
bending functions in the plane) carrying a 0.3 kg tip mass, all turning about z; gravity
along −y. The checked facts:

1. The elastic link alone, clamped, with its tip mass: the lowest bending frequency of the
   linearised model equals the root of the frequency equation of a clamped-free
   Euler–Bernoulli beam with a point mass m at its free end (boundary conditions
   w(0) = w′(0) = 0, EI w″(L) = 0, EI w‴(L) = −m ω² w(L)):
   1 + cos λ cosh λ + μ λ (cos λ sinh λ − sin λ cosh λ) = 0, μ = m/(ρA L),
   ω = λ² √(EI/(ρA L⁴)); with μ = 0 this is the clamped-free beam of Blevins (1979),
   Table 8-1. Ritz converges to it from above; four functions give it to 1e-6.
2. The undamped arm released from rest conserves its energy (rtol 1e-8: drift < 1e-6).
3. The order-n recursion and the dense Gauss form give the same s̈ (two formulations),
   within the dense solve's forward-error bound cond(M) ε (docs/theory.md §16).

Run: python examples/flexible_arm.py  (PROJEQ_QUICK=1: a 0.1 s run instead of 1 s; the four
Ritz functions make the model stiff, and DOP853 needs ~1e5 evaluations per simulated second)
"""

import os

import numpy as np
from scipy.optimize import brentq

import projeq as pq
from projeq import plots

L, RHO_A, EI, TIP = 0.8, 0.8, 40.0, 0.3
G = 9.81


def flexible_link(n_v=4, damping=0.0):
    """The elastic last link: bending v in the arm's plane only (n_w = 0)."""
    return pq.RitzBeam(L, rho_A=RHO_A, EI_z=EI, n_v=n_v, n_w=0, damping=damping)


def arm(n_v=4, damping=0.0):
    """Shoulder, elbow and wrist turn about z; each link's joint sits at its parent's end."""
    link1 = pq.RigidBody(1.5, r_c=(0.3, 0, 0), I_c=pq.inertia.cylinder(1.5, 0.02, 0.6, axis="x"))
    link2 = pq.RigidBody(1.0, r_c=(0.25, 0, 0), I_c=pq.inertia.cylinder(1.0, 0.02, 0.5, axis="x"))
    return pq.System(
        subsystems={"upper": link1, "fore": link2, "beam": flexible_link(n_v, damping), "tip": pq.PointMass(TIP)},
        joints={
            "upper": pq.Revolute(axis="z"),
            "fore": pq.Revolute(parent="upper", axis="z", r_pn=(0.6, 0, 0)),
            "beam": pq.Revolute(parent="fore", axis="z", r_pn=(0.5, 0, 0)),
            "tip": pq.Fixed(parent="beam", r_pn=(L, 0, 0)),   # at the beam's end station
        },
        gravity=(0, -G, 0),
    )


def clamped_beam(n_v):
    """The elastic link clamped to the ground with its tip mass, no gravity."""
    return pq.System(
        subsystems={"beam": flexible_link(n_v), "tip": pq.PointMass(TIP)},
        joints={"beam": pq.Fixed(), "tip": pq.Fixed(parent="beam", r_pn=(L, 0, 0))},
    )


def lowest_frequency(system):
    """The smallest |Im λ| of the linearisation at rest (rad/s)."""
    lin = pq.linearize(system, q=np.zeros(system.n_q), s_dot=np.zeros(system.n_s))
    frequencies = np.abs(np.linalg.eigvals(lin.A).imag)
    return frequencies[frequencies > 1e-9].min()


def exact_frequency():
    mu = TIP / (RHO_A * L)

    def frequency_equation(lam):
        return 1 + np.cos(lam) * np.cosh(lam) + mu * lam * (np.cos(lam) * np.sinh(lam) - np.sin(lam) * np.cosh(lam))

    lam = brentq(frequency_equation, 0.5, 1.8751)   # below the clamped-free beam's 1.8751
    return lam**2 * np.sqrt(EI / (RHO_A * L**4))


QUICK = bool(os.environ.get("PROJEQ_QUICK"))

# 1. Ritz convergence of the lowest frequency against the closed form
omega = exact_frequency()
print(f"lowest bending frequency, closed form: {omega:.6f} rad/s")
for n_v in (1, 2, 3, 4):
    ritz = lowest_frequency(clamped_beam(n_v))
    print(f"  {n_v} Ritz function(s): {ritz:.6f} rad/s, relative error {(ritz - omega) / omega:.1e}")
assert abs(ritz - omega) < 1e-6 * omega

# 2. The arm released from rest, bent by gravity as it falls
system = arm()
q0 = np.array([0.0, 0.4, 0.3] + [0.0] * 4)   # shoulder, elbow, wrist (rad), 4 Ritz coordinates
result = pq.simulate(system, 0.1 if QUICK else 1.0, q0=q0, s_dot0=np.zeros(system.n_s),
                     method="DOP853", rtol=1e-8, atol=1e-10)
print(f"energy drift {result.energy_drift:.1e}")
assert result.energy_drift < 1e-6

# 3. two formulations of the same equations at the final state
q, s_dot = result.q[-1], result.s_dot[-1]
recursive = system.accelerations(q, s_dot, method="recursive")
dense = system.accelerations(q, s_dot, method="dense")
# the dense solve's forward error is up to cond(M) ε (here cond(M) ≈ 4e7: the elastic
# coordinates' mass is small next to the links'); the recursion's is at round-off
bound = 10 * np.linalg.cond(system.mass_matrix(q)) * np.finfo(float).eps * np.abs(dense).max()
assert np.abs(recursive - dense).max() <= bound

beam = system.subsystem("beam")
tip = beam.deflection(result, L)
print(f"largest tip deflection in the plane: {1000 * np.abs(tip[:, 1]).max():.2f} mm")
plots.tip_deflection(result, beam).savefig("flexible_arm_tip.png")
plots.time_history(result).savefig("flexible_arm_history.png")
