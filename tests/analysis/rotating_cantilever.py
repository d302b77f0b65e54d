"""The exact frequencies of the uniform cantilever on a hub turning about a transverse axis:
Wright et al.'s table and their Frobenius power series, extended to a hub radius and to the
lead-lag plane. Test oracles for RitzBeam (tests/subsystems/test_beam.py) and the Campbell
diagram (tests/analysis/test_campbell.py)."""

import numpy as np
from scipy.optimize import brentq

# Wright, Smith, Thresher & Wang (1982), "Vibration modes of centrifugally stiffened
# beams", J. Appl. Mech. 49:197–202, Table 1 (reproduced by Banerjee 2000, J. Sound Vib.
# 233:857–875): first flapwise frequency ω/√(EI/(ρA L⁴)) of a uniform cantilever with zero
# hub radius at the nondimensional spin η = Ω/√(EI/(ρA L⁴)).
WRIGHT_1982 = {0: 3.5160, 1: 3.6816, 2: 4.1373, 3: 4.7973, 4: 5.5850, 5: 6.4495}


def frobenius_determinant(lam, eta, hub_radius=0.0, terms=200):
    """Frequency determinant of the rotating uniform cantilever by the Frobenius power series
    of Wright et al. (1982): w'''' − (N w′)′ = λ² w on 0 ≤ ξ ≤ 1 (EI = ρA = L = 1) with the
    centrifugal axial force N = η² [r (1 − ξ) + (1 − ξ²)/2] of a root at the hub radius r.
    w = Σ a_k ξ^k has
    a_(k+4) = [η² ((r + ½)(k+1)(k+2) a_(k+2) − r (k+1)² a_(k+1) − ½ k(k+1) a_k) + λ² a_k]
              / ((k+1)(k+2)(k+3)(k+4))
    (r = 0: Wright et al.'s recurrence); clamped: a₀ = a₁ = 0; free: w″(1) = w‴(1) = 0
    (N(1) = 0). The series is entire; 200 terms reach round-off for λ < 100 and r ≤ 1."""
    ends = []
    for a_2, a_3 in ((1.0, 0.0), (0.0, 1.0)):
        a = np.zeros((terms + 4,) + np.shape(lam))  # λ may be an array of trial values
        a[2], a[3] = a_2, a_3
        for k in range(terms):
            axial = eta**2 * ((hub_radius + 0.5) * (k + 1) * (k + 2) * a[k + 2]
                              - hub_radius * (k + 1) ** 2 * a[k + 1] - 0.5 * k * (k + 1) * a[k])
            a[k + 4] = (axial + lam * lam * a[k]) / ((k + 1) * (k + 2) * (k + 3) * (k + 4))
        k = np.arange(len(a))
        ends.append(((k * (k - 1)) @ a, (k * (k - 1) * (k - 2)) @ a))
    (moment_1, shear_1), (moment_2, shear_2) = ends
    return moment_1 * shear_2 - moment_2 * shear_1


def frobenius_frequencies(eta, hub_radius=0.0, count=3, lead_lag=False):
    """The lowest ``count`` roots λ of :func:`frobenius_determinant` (flapwise), bracketed on a
    grid and refined by brentq (xtol 1e-13). In the plane of rotation the inextensible beam
    has the same equation with −η² v added (the centrifugal load's component along the
    deflection): v'''' − (N v′)′ − η² v = λ² v, so λ_lead-lag² = λ_flap² − η²."""
    grid = np.linspace(0.5, 70.0, 1500)
    values = frobenius_determinant(grid, eta, hub_radius)
    brackets = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))[:count]
    flap = np.array([brentq(frobenius_determinant, grid[i], grid[i + 1], args=(eta, hub_radius), xtol=1e-13)
                     for i in brackets])
    return np.sqrt(flap**2 - eta**2) if lead_lag else flap
