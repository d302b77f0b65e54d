"""Problems of the IFToMM library of computational benchmark problems for multibody dynamics
(M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody System Dynamics 16
(2006) 179–190; problems A01 simple pendulum, A02 N-four-bar mechanism, A03 Andrews' mechanism,
A04 Bricard's mechanism), as :class:`~projeq.constraints.partitioned.ConstrainedSystem` s in their
null-space form: trees closed by constraint equations, run through singular positions and with
redundant constraints (Bricard's mechanism takes that form by itself); and A05, the
stiff flyball governor, a tree with two stiff spring-dampers (:func:`flyball_governor`).

Each problem also has a reference that does not use the constraint equations: the pendulum's
closed form (Jacobi's elliptic functions) and the N-four-bar's parallelogram motion in one
coordinate (:func:`parallelogram_motion`).
"""

from __future__ import annotations

import numpy as np

from projeq.checks import count, non_negative, positive
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.forces import JointForce, SpringDamper
from projeq.joints import Fixed, Prismatic, Revolute
from projeq.scenes.mechanisms import slender_rod
from projeq.subsystems import Frame, PlanarBody, PointMass, RigidBody, inertia
from projeq.system import System


def simple_pendulum(m: float = 1.0, L: float = 1.0, g: float = 9.81, **options) -> ConstrainedSystem:
    """IFToMM A01: a point mass m on a massless rod of length L, in natural coordinates — the
    mass on x and y sliders held at distance L from the pivot by Φ = x² + y² − L² = 0;
    gravity −y. Starts at rest with the rod horizontal, (x, y) = (L, 0), the benchmark's start.
    ``options`` go to :class:`~projeq.constraints.partitioned.ConstrainedSystem` (default: its null-space form)."""
    tree = System({"x": Frame(), "mass": PointMass(positive("m", m))},
                  {"x": Prismatic(axis="x"), "mass": Prismatic(parent="x", axis="y")}, gravity=(0.0, -g, 0.0))
    return ConstrainedSystem(tree, phi=lambda q, t: [q[0] ** 2 + q[1] ** 2 - L * L], q0=(positive("L", L), 0.0),
                             **{"formulation": "null_space", **options})


def pendulum_angle(t, L: float = 1.0, g: float = 9.81, theta0: float = np.pi / 2) -> np.ndarray:
    """The angle from the downward vertical of a simple pendulum released from rest at θ0:
    sin(θ/2) = k sn(K(k) − ω t, k), k = sin(θ0/2), ω = √(g/L) (Jacobi's elliptic functions;
    e.g. Lawden, "Elliptic Functions and Applications", 1989, §5.2)."""
    from scipy.special import ellipj, ellipk  # here, not at the top: import projeq.scenes stays light

    k = np.sin(theta0 / 2)
    sn = ellipj(ellipk(k * k) - np.sqrt(g / L) * np.asarray(t, dtype=float), k * k)[0]
    return 2 * np.arcsin(k * sn)


def reference_solution(path) -> np.ndarray:
    """The rows (t, x, y) of a published reference file of the IFToMM benchmark library
    (``A01_solution_data.txt``: point P1 of A01 every 0.5 s; ``A02_solution_data.txt``: point B0 of
    A02 with N = 40 every 0.05 s, an ADAMS output whose header and trailing zero columns are
    skipped): every line that is numbers only, its first three columns. ValueError naming the
    file if it holds no such line or its times do not increase."""
    rows = []
    with open(path, encoding="latin-1") as lines:
        for line in lines:
            try:
                numbers = [float(word) for word in line.split()]
            except ValueError:
                continue
            if len(numbers) >= 3:
                rows.append(numbers[:3])
    data = np.array(rows).reshape(-1, 3)
    if not len(data) or not np.all(np.diff(data[:, 0]) > 0):
        raise ValueError(f"path: {path} holds no rows (t, x, y) with increasing t")
    return data


def n_four_bar(n: int = 2, m: float = 1.0, L: float = 1.0, g: float = 9.81, speed: float = 1.0,
               **options) -> ConstrainedSystem:
    """IFToMM A02: n four-bar linkages in a row, 2n + 1 uniform bars of mass m and length L in the
    x–y plane, gravity −y: cranks ``crank0`` … ``crank<n>`` turn about (i L, 0) (absolute angles
    θ_i), coupler i hangs at the tip of crank i − 1 (angle relative to it) and is pinned at its
    other end to the tip of crank i (cut, Φ = 0: 2n rows). Where the bars are horizontal the 2n
    rows have rank n and the mobility jumps from 1 to n + 1 (the benchmark's singular
    positions). Starts with the cranks vertical and point B0 (the tip of crank0) moving at
    ``speed`` along +x. The benchmark specifies n = 40 (and 2 in the double four-bar of
    González, Dopico, Pastorino & Cuadrado, Nonlinear Dynamics 85 (2016) 1491–1508).
    ``options`` go to :class:`~projeq.constraints.partitioned.ConstrainedSystem` (default: its null-space form)."""
    n = count("n", n)
    rod = slender_rod(positive("m", m), positive("L", L))
    cranks, couplers = [f"crank{i}" for i in range(n + 1)], [f"coupler{i}" for i in range(1, n + 1)]
    joints = {name: Revolute(axis="z", r_pn=(i * L, 0.0, 0.0)) for i, name in enumerate(cranks)}
    joints |= {name: Revolute(parent=cranks[i], axis="z", r_pn=(L, 0.0, 0.0))
               for i, name in enumerate(couplers)}
    tree = System(dict.fromkeys(cranks + couplers, rod), joints, gravity=(0.0, -g, 0.0))
    crank, coupler = (tuple(tree.q_slice[tree.index(name)].start for name in names) for names in (cranks, couplers))

    def closure(q, t):
        """Tip of coupler i − (tip of crank i), i = 1 … n (pivots 1 apart): x rows, then y rows, on
        the rows q[i]; each crank's cosine and sine once, into one list (compiled by numba as written)."""
        rows = [q[0] * 0.0] * (2 * n)
        cos, sin = np.cos(q[crank[0]]), np.sin(q[crank[0]])
        for i in range(n):
            coupler_angle = q[crank[i]] + q[coupler[i]]
            cos_next, sin_next = np.cos(q[crank[i + 1]]), np.sin(q[crank[i + 1]])
            rows[i] = L * (cos + np.cos(coupler_angle) - 1.0 - cos_next)
            rows[n + i] = L * (sin + np.sin(coupler_angle) - sin_next)
            cos, sin = cos_next, sin_next
        return rows

    q0, s_dot0 = np.zeros(tree.n_q), np.zeros(tree.n_s)
    q0[list(crank)], q0[list(coupler)] = np.pi / 2, -np.pi / 2
    # ẋ_B0 = −L sin θ0 θ̇0; couplers translate
    s_dot0[list(crank)], s_dot0[list(coupler)] = -speed / L, speed / L
    return ConstrainedSystem(tree, phi=closure, q0=q0, independent=[tree.s_slice[tree.index("crank0")].start],
                             s_dot0=[-speed / L], **{"formulation": "null_space", **options})


def point_b0(system, q, s_dot) -> np.ndarray:
    """(x, y, ẋ, ẏ) of point B0, the tip of crank0 of :func:`n_four_bar`, for each row of q and
    of the model's velocities ṡ (any formulation of the same tree)."""
    i = system.tree.index("crank0")
    L = 2 * system.tree.subsystems[i].r_c[0]
    q, s_dot = np.atleast_2d(q), np.atleast_2d(s_dot)
    theta = q[:, system.tree.q_slice[i].start]
    column = system.tree.s_slice[i].start
    omega = np.array([system.tree_velocities(qi, si)[column] for qi, si in zip(q, s_dot)])
    return _tip(L, theta, omega)


def _tip(L: float, theta, omega) -> np.ndarray:
    """(x, y, ẋ, ẏ) of a crank's tip at angle θ turning at θ̇ (rows)."""
    return np.stack((L * np.cos(theta), L * np.sin(theta), -L * np.sin(theta) * omega, L * np.cos(theta) * omega),
                    axis=-1)


def parallelogram_motion(t, n: int = 2, m: float = 1.0, L: float = 1.0, g: float = 9.81, speed: float = 1.0,
                         rtol: float = 1e-12) -> np.ndarray:
    """(x, y, ẋ, ẏ) of B0 at times t for :func:`n_four_bar` moving as parallelograms — every crank
    at the same angle θ, the couplers translating —, the motion through the singular positions
    that keeps its velocity (the benchmark's). Lagrange's equation in θ alone:
    T = ½ ((n + 1)/3 + n) m L² θ̇², V = ((n + 1)/2 + n) m g L sin θ, integrated to ``rtol``."""
    from scipy.integrate import solve_ivp

    inertia, weight = ((n + 1) / 3 + n) * m * L * L, ((n + 1) / 2 + n) * m * g * L
    t = np.asarray(t, dtype=float)
    sol = solve_ivp(lambda _, x: [x[1], -weight * np.cos(x[0]) / inertia], (0.0, t.max()),
                    [np.pi / 2, -speed / L], t_eval=t, rtol=rtol, atol=rtol * 1e-2, method="DOP853")
    theta, omega = sol.y
    return _tip(L, theta, omega)


# Bricard's mechanism: the joints at the corners of the benchmark's figure, their axes, and the
# rods from each corner to the next (at q = 0 every body frame is parallel to the inertial one)
_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]], dtype=float)
_AXES = "yzxyzx"


def bricard(m: float = 1.0, L: float = 1.0, side: float = 0.1, g: float = 9.81, **options) -> ConstrainedSystem:
    """IFToMM A04: Bricard's overconstrained mechanism, five rods (mass m, length L, square section
    ``side``) in a chain of revolute joints from the ground at the origin (axis y) over the
    corners (L, 0, 0) z, (L, −L, 0) x, (L, −L, L) y, (0, −L, L) z back to the ground at (0, 0, L),
    axis x — the benchmark's figure; gravity −y. The last joint is cut: rod5's end on (0, 0, L)
    (3 rows) and its x-axis perpendicular to the ground's y and z (2 rows). Grübler's count is
    5 − 5 = 0, but the five rows have rank 4 everywhere: mobility 1, one row redundant (not
    removed: a ConstrainedSystem finds it on the constraint surface and takes the null-space form,
    ``redundant`` = (4,)). Starts at rest in the figure's configuration (q = 0).
    ``options`` go to :class:`~projeq.constraints.partitioned.ConstrainedSystem`."""
    m, L, side = positive("m", m), positive("L", L), positive("side", side)
    corners = L * _CORNERS
    names = [f"rod{i}" for i in range(1, 6)]
    subsystems, joints = {}, {}
    for i, name in enumerate(names):
        along = corners[i + 1] - corners[i]  # the rod in body axes (parallel to inertial ones at q = 0)
        edges = np.where(np.abs(along) > 0, L, side)  # the cuboid's edges along x, y, z
        I_c = np.diag(m * (np.sum(edges**2) - edges**2) / 12)
        subsystems[name] = RigidBody(m, along / 2, I_c)
        joints[name] = Revolute(parent=names[i - 1] if i else None, axis=_AXES[i],
                                r_pn=corners[i] - (corners[i - 1] if i else 0.0))
    tree = System(subsystems, joints, gravity=(0.0, -g, 0.0))
    columns = tuple(tree.q_slice[tree.index(name)].start for name in names)
    axes = tuple("xyz".index(axis) for axis in _AXES[:5])
    offsets = tuple(tuple(corners[i] - (corners[i - 1] if i else 0.0)) for i in range(6))  # corner to corner
    end = tuple(corners[5])

    def closure(q, t):
        """The chain's forward kinematics to rod5's far end in closed form, on the rows q[i] (a
        point, or a batch of points; compiled by numba as written): r += R ρ_i, then
        R ← R R_axis(q_i), whose columns (i, j) after the axis k turn as (c R_i + s R_j, −s R_i + c R_j);
        R by rows in one flat list (R[3 a + b] = R_ab), r and the five rows in another."""
        zero = q[columns[0]] * 0.0
        R = [zero + 1.0, zero, zero, zero, zero + 1.0, zero, zero, zero, zero + 1.0]
        r = [zero, zero, zero, zero, zero]  # r, then the rows R_10, R_20 of the last two
        for n in range(6):
            for a in range(3):
                r[a] = r[a] + R[3 * a] * offsets[n][0] + R[3 * a + 1] * offsets[n][1] + R[3 * a + 2] * offsets[n][2]
            if n == 5:
                break
            i, j = (axes[n] + 1) % 3, (axes[n] + 2) % 3
            c, s = np.cos(q[columns[n]]), np.sin(q[columns[n]])
            for a in range(3):
                R_i, R_j = R[3 * a + i], R[3 * a + j]
                R[3 * a + i], R[3 * a + j] = c * R_i + s * R_j, c * R_j - s * R_i
        for a in range(3):
            r[a] = r[a] - end[a]
        r[3], r[4] = R[3], R[6]
        return r

    return ConstrainedSystem(tree, phi=closure, q0=np.zeros(tree.n_q), **options)


# Andrews' squeezing mechanism: the data of Hairer & Wanner, "Solving Ordinary Differential Equations II",
# 2nd ed. (1996), §VII.7, Table 7.1 (after Schiehlen, "Multibody Systems Handbook", 1990): lengths in m
ANDREWS = dict(
    m=(0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498),  # bodies 1..7: β Θ γ Φ δ Ω ε
    I=(2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5),
    xa=-0.06934, ya=-0.00227, xb=-0.03635, yb=0.03273, xc=0.014, yc=0.072,
    d=28e-3, da=115e-4, e=2e-2, ea=1421e-5, rr=7e-3, ra=92e-5, ss=35e-3, sa=1874e-5, sb=1043e-5,
    sc=18e-3, sd=2e-2, ta=2308e-5, tb=916e-5, u=4e-2, ua=1228e-5, ub=449e-5, zf=2e-2, zt=4e-2, fa=1421e-5,
    c0=4530.0, l0=7785e-5, mom=33e-3,
)
# the consistent initial angles of Hairer & Wanner (β, Θ, γ, Φ, δ, Ω, ε), at rest
ANDREWS_Q0 = (-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
              0.222668390165885884674473185609, 0.487364979543842550225598953530,
              -0.222668390165885884674473185609, 1.23054744454982119249735015568)
ANDREWS_ANGLES = ("beta", "theta", "gamma", "phi", "delta", "omega", "epsilon")


def andrews_squeezer(**options) -> ConstrainedSystem:
    """IFToMM A03: Andrews' squeezing mechanism, seven planar bodies driven by the torque mom on the
    crank β against a spring (stiffness c0, rest length l0) from the triangle γ to the ground point
    C; no gravity (Hairer & Wanner 1996, §VII.7, data of :data:`ANDREWS`). The tree: the crank
    ``beta`` about O with ``theta`` at its end (angle Θ relative), the triangle ``gamma`` about B,
    ``delta`` and ``epsilon`` about A with ``phi`` and ``omega`` on them (relative angles Φ, Ω);
    the three ends of theta, gamma, phi and omega meet at point E (six closure rows, mobility 1).
    The subsystems are named after Hairer & Wanner's angles (:data:`ANDREWS_ANGLES`), each the one
    coordinate of its joint; starts at rest at their consistent angles (:data:`ANDREWS_Q0`).
    ``options`` go to :class:`~projeq.constraints.partitioned.ConstrainedSystem` (default: its null-space form)."""
    a = ANDREWS
    m, I = dict(zip(ANDREWS_ANGLES, a["m"])), dict(zip(ANDREWS_ANGLES, a["I"]))
    centre = {"beta": (a["ra"], 0.0), "theta": (-a["da"], 0.0), "gamma": (a["sb"], -a["sa"]),
              "delta": (a["ta"], a["tb"]), "phi": (0.0, a["ea"] - a["e"]), "epsilon": (-a["ub"], -a["ua"]),
              "omega": (a["zf"] - a["fa"], 0.0)}
    joints = {"beta": Revolute(axis="z"), "theta": Revolute(parent="beta", axis="z", r_pn=(a["rr"], 0.0, 0.0)),
              "gamma": Revolute(axis="z", r_pn=(a["xb"], a["yb"], 0.0)),
              "delta": Revolute(axis="z", r_pn=(a["xa"], a["ya"], 0.0)),
              "phi": Revolute(parent="delta", axis="z", r_pn=(a["zt"], 0.0, 0.0)),
              "epsilon": Revolute(axis="z", r_pn=(a["xa"], a["ya"], 0.0)),
              "omega": Revolute(parent="epsilon", axis="z", r_pn=(0.0, -a["u"], 0.0))}
    bodies = {name: PlanarBody(m[name], (*centre[name], 0.0), I[name], plane="xy") for name in joints}
    forces = [JointForce("beta", [a["mom"]]),
              SpringDamper("gamma", (a["sd"], -a["sc"], 0.0), None, (a["xc"], a["yc"], 0.0), a["c0"], length=a["l0"])]
    tree = System(bodies, joints, forces=forces)
    column = {name: tree.q_slice[tree.index(name)].start for name in ANDREWS_ANGLES}
    i_beta, i_theta, i_gamma, i_phi, i_delta, i_omega, i_epsilon = (column[name] for name in ANDREWS_ANGLES)
    rr, d, ss, e, zt, u, zf = (a[key] for key in ("rr", "d", "ss", "e", "zt", "u", "zf"))
    x_a, y_a, x_b, y_b = (a[key] for key in ("xa", "ya", "xb", "yb"))

    def closure(q, t):
        """Point E from theta minus E from gamma, from phi and from omega (x, y rows), on the
        rows q[i] and captured numbers (compiled by numba as written)."""
        beta, theta, gamma, phi, delta = q[i_beta], q[i_theta], q[i_gamma], q[i_phi], q[i_delta]
        omega, epsilon = q[i_omega], q[i_epsilon]
        e_x = rr * np.cos(beta) - d * np.cos(beta + theta)
        e_y = rr * np.sin(beta) - d * np.sin(beta + theta)
        return [e_x - x_b - ss * np.sin(gamma), e_y - y_b + ss * np.cos(gamma),
                e_x - x_a - zt * np.cos(delta) - e * np.sin(phi + delta),
                e_y - y_a - zt * np.sin(delta) + e * np.cos(phi + delta),
                e_x - x_a - u * np.sin(epsilon) - zf * np.cos(omega + epsilon),
                e_y - y_a + u * np.cos(epsilon) - zf * np.sin(omega + epsilon)]

    q0 = np.zeros(tree.n_q)
    q0[[column[name] for name in ANDREWS_ANGLES]] = ANDREWS_Q0
    return ConstrainedSystem(tree, phi=closure, q0=q0, independent=[tree.s_slice[tree.index("beta")].start],
                             **{"formulation": "null_space", **options})


def andrews_angles(system, q) -> np.ndarray:
    """The rows of q as Hairer & Wanner's angles (β, Θ, γ, Φ, δ, Ω, ε) (the same for ṡ_tree)."""
    return np.atleast_2d(q)[:, [system.tree.q_slice[system.tree.index(name)].start for name in ANDREWS_ANGLES]]


# the published reference solution at t = 0.03 s (t, angles (β, Θ, γ, Φ, δ, Ω, ε) in rad, their rates in
# rad/s): Mazzia & Magherini, "Test Set for IVP Solvers", release 2.4 (2008), problem "andrews",
# computed by PSIDE at tolerance 1e-14 — the data of Hairer & Wanner 1996, §VII.7
ANDREWS_REFERENCE = (
    0.03,
    np.array([0.1581077119629904e+02, -0.1575637105984298e+02, 0.4082224013073101e-01, -0.5347301163226948e+00,
              0.5244099658805304e+00, 0.5347301163226948e+00, 0.1048080741042263e+01]),
    np.array([0.1139920302151208e+04, -0.1424379294994111e+04, 0.1103291221937134e+02, 0.1929337464421385e+02,
              0.5735699284790808e+00, -0.1929337464421385e+02, 0.3231791658026955e+00]),
)


def andrews_error(system, q, s_dot) -> float:
    """The largest relative difference of the angles and rates at q, ṡ (the state at
    ANDREWS_REFERENCE[0]) from the published reference solution."""
    t, angles, rates = ANDREWS_REFERENCE
    ours = andrews_angles(system, q)[0], andrews_angles(system, system.tree_velocities(q, s_dot))[0]
    return float(max(np.abs(x / ref - 1).max() for x, ref in zip(ours, (angles, rates))))


def andrews_balance(system, r) -> np.ndarray:
    """T + V − E₀ − mom (β − β₀) along a Result of :func:`andrews_squeezer`: the energy balance of the
    benchmark (zero: the drive's work goes into the mechanism's energy)."""
    energy, beta = r.kinetic + r.potential, andrews_angles(system, r.q)[:, 0]
    return energy - energy[0] - ANDREWS["mom"] * (beta - beta[0])


# IFToMM A05, the stiff flyball governor: the benchmark's data (González, Dopico, Lugrís & Cuadrado 2006)
FLYBALL = dict(length=1.0, width=0.01, side=0.1, density=3000.0, ball=5.0, K=8e5, C=4e4, rest=0.5, half_ab=0.05,
               s0=0.5, alpha0=np.pi / 6, omega0=2 * np.pi, g=9.81)


def flyball_governor(K: float = FLYBALL["K"], C: float = FLYBALL["C"], omega0: float = FLYBALL["omega0"],
                     s0: float = FLYBALL["s0"], alpha0: float = FLYBALL["alpha0"]) -> System:
    """IFToMM A05, the stiff flyball governor: a vertical shaft (1 × 0.01 × 0.01 m, density
    3000 kg/m³: 0.3 kg) turning freely about z on the ground at the origin; on it a slider
    (0.1 m cube, 3 kg, ``slider``: its height s along the shaft) and, hinged at the shaft's top
    at A, B = (±0.05, 0, 1) m about ±y, two rods (as the shaft, ``rod_ac``, ``rod_bd``: their
    angle α below the horizontal, outward) with 5 kg point masses at their far ends (``ball_c``,
    ``ball_d``). The coupler rods of Watt's governor are replaced by spring-dampers (stiffness K,
    damping C, rest length 0.5 m) from the slider's sides E, F = (±0.05, 0, s) to the rods'
    midpoints; gravity −z. Starts at the benchmark's s = 0.5 m, α = 30° (the springs at their rest
    length) with the whole governor turning at ``omega0`` = 2π rad/s. Stiff: the dampers'
    eigenvalue −C/m ≈ −8000 1/s against the governor's motion of about 1 Hz.
    (González, Dopico, Lugrís & Cuadrado, Multibody System Dynamics 16 (2006) 179–190, problem
    A05.) The reference quantity is s(t); :func:`flyball_steady_state` gives where it settles."""
    d = FLYBALL
    L, w, rho, a = d["length"], d["width"], d["density"], d["half_ab"]
    m_bar, m_slider = rho * L * w * w, rho * d["side"] ** 3
    K, C = positive("K", K), non_negative("C", C)
    rod = {side: RigidBody(m_bar, (sign * L / 2, 0.0, 0.0), inertia.box(m_bar, L, w, w))
           for side, sign in (("ac", 1.0), ("bd", -1.0))}
    subsystems = {"shaft": RigidBody(m_bar, (0.0, 0.0, L / 2), inertia.box(m_bar, w, w, L)),
                  "slider": RigidBody(m_slider, (0.0, 0.0, 0.0), inertia.box(m_slider, *[d["side"]] * 3)),
                  "rod_ac": rod["ac"], "ball_c": PointMass(d["ball"]), "rod_bd": rod["bd"], "ball_d": PointMass(d["ball"])}
    joints = {"shaft": Revolute(axis="z"), "slider": Prismatic(parent="shaft", axis="z"),
              "rod_ac": Revolute(parent="shaft", axis="y", r_pn=(a, 0.0, L)),
              "ball_c": Fixed(parent="rod_ac", r_pn=(L, 0.0, 0.0)),
              "rod_bd": Revolute(parent="shaft", axis=(0.0, -1.0, 0.0), r_pn=(-a, 0.0, L)),
              "ball_d": Fixed(parent="rod_bd", r_pn=(-L, 0.0, 0.0))}
    springs = [SpringDamper("slider", (sign * a, 0.0, 0.0), name, (sign * L / 2, 0.0, 0.0), K, C, length=d["rest"])
               for name, sign in (("rod_ac", 1.0), ("rod_bd", -1.0))]
    return System(subsystems, joints, gravity=(0.0, 0.0, -d["g"]), forces=springs,
                  q0=[0.0, positive("s0", s0), alpha0, alpha0], s_dot0=[omega0, 0.0, 0.0, 0.0])


def _flyball_geometry(alpha, s, K: float = FLYBALL["K"]):
    """Of :func:`flyball_governor` at rod angle α and slider height s (complex under a complex
    step): I_zz (the governor's moment of inertia about the shaft), V (gravity and the springs'
    potential ½ K (ℓ − ℓ₀)² each) and ℓ (the springs' length)."""
    d = FLYBALL
    L, w, a, g = d["length"], d["width"], d["half_ab"], d["g"]
    m_bar, m_slider, m_ball = d["density"] * L * w * w, d["density"] * d["side"] ** 3, d["ball"]
    reach = L * np.cos(alpha)  # horizontal reach of a rod from its hinge
    rod_own = m_bar * (2 * w * w * np.sin(alpha) ** 2 + (L * L + w * w) * np.cos(alpha) ** 2) / 12  # e_zᵀ I_c e_z
    I_zz = (m_bar * 2 * w * w / 12 + m_slider * 2 * d["side"] ** 2 / 12
            + 2 * (rod_own + m_bar * (a + reach / 2) ** 2 + m_ball * (a + reach) ** 2))
    rise = L - L / 2 * np.sin(alpha) - s  # rod midpoint above the slider's centre; E and A both at ±a
    ell = np.sqrt((reach / 2) ** 2 + rise**2)
    V = (2 * g * (m_bar * (L - L / 2 * np.sin(alpha)) + m_ball * (L - L * np.sin(alpha)))
         + m_slider * g * s + m_bar * g * L / 2 + K * (ell - d["rest"]) ** 2)
    return I_zz, V, ell


def flyball_steady_state(K: float = FLYBALL["K"], angular_momentum: float | None = None) -> dict:
    """Where :func:`flyball_governor` (spring stiffness K) settles once its dampers have taken
    out the relative motion. The shaft turns freely, so the angular momentum L_z about it is
    conserved (default: the benchmark start's, I_zz(30°, 0.5 m) · 2π), and the relative
    equilibria — the governor turning rigidly at ω = L_z / I_zz — are the stationary points of
    the amended potential V_A(α, s) = V(α, s) + L_z² / (2 I_zz(α)) (Routh's reduction of the
    cyclic shaft angle; Marsden & Ratiu, "Introduction to Mechanics and Symmetry", 2nd ed.
    (1999), §8.5, the amended potential): ∂V_A/∂s = 0, the slider's weight against the two
    spring forces, and ∂V_A/∂α = ∂V/∂α − ½ ω² ∂I_zz/∂α = 0, the rods' gravity and spring moments
    against the centrifugal one. V and I_zz in closed form (:func:`_flyball_geometry`), their
    derivatives by the complex step (exact to round-off), the roots by Brent's method, s(α) inside
    α's. Returns α, s, ω and ℓ (the springs' length) there."""
    from scipy.optimize import brentq

    K = positive("K", K)
    L_z = (_flyball_geometry(FLYBALL["alpha0"], FLYBALL["s0"], K)[0] * FLYBALL["omega0"]
           if angular_momentum is None else positive("angular_momentum", angular_momentum))

    def amended(alpha, s):
        I_zz, V, _ = _flyball_geometry(alpha, s, K)
        return V + L_z * L_z / (2 * I_zz)

    def rate(f, x):  # df/dx by the complex step
        return f(x + 1e-30j).imag / 1e-30

    def slider_height(alpha):  # ∂V_A/∂s = 0 at this α, between 0.9 m below the rods' midpoints and their height
        top = FLYBALL["length"] * (1 - np.sin(alpha) / 2)
        return brentq(lambda s: rate(lambda x: amended(alpha, x), s), top - 0.9, top, xtol=1e-15)

    alpha = brentq(lambda x: rate(lambda y: amended(y, slider_height(y.real)), x), 0.05, np.pi / 2 - 0.05,
                   xtol=1e-14)
    s = slider_height(alpha)
    I_zz, _, ell = _flyball_geometry(alpha, s, K)
    return {"alpha": alpha, "s": s, "omega": L_z / I_zz, "length": ell}


def flyball_spring_rate(q, s_dot) -> np.ndarray:
    """ℓ̇ of the spring on rod AC of :func:`flyball_governor` for rows of q = (φ, s, α_AC, α_BD) and
    ṡ, by differentiating the closed form ℓ² = (½L cos α)² + (L − ½L sin α − s)² (E and A both
    0.05 m from the shaft; independent of the SpringDamper law's kinematics)."""
    L = FLYBALL["length"]
    q, s_dot = np.atleast_2d(q), np.atleast_2d(s_dot)
    s, alpha, s_rate, alpha_rate = q[:, 1], q[:, 2], s_dot[:, 1], s_dot[:, 2]
    reach, rise = L / 2 * np.cos(alpha), L - L / 2 * np.sin(alpha) - s
    return (-reach * L / 2 * np.sin(alpha) * alpha_rate - rise * (L / 2 * np.cos(alpha) * alpha_rate + s_rate)) \
        / np.hypot(reach, rise)


def flyball_balance(r, C: float = FLYBALL["C"], samples: int = 20_001) -> np.ndarray:
    """T + V − E₀ + W_d at the output times of a symmetric run of :func:`flyball_governor` (α_AC = α_BD)
    with dense output: W_d = ∫ 2 C ℓ̇² dt, the work the two dampers dissipated, by Simpson's rule
    on ``samples`` points of ``r.sol`` spaced evenly, and as many spaced geometrically from 1e-9 of
    the run after its start, where the dampers' transient (time constant m/C ≈ 1e-4 s) decays
    (zero: the energy balance)."""
    from scipy.integrate import cumulative_simpson

    span = r.t[-1] - r.t[0]
    t = np.union1d(np.linspace(r.t[0], r.t[-1], samples), r.t[0] + np.geomspace(1e-9 * span, span, samples))
    q, s_dot = (np.asarray(x).T for x in r.sol(t))
    dissipated = cumulative_simpson(2 * C * flyball_spring_rate(q, s_dot) ** 2, x=t, initial=0.0)
    return r.energy - r.energy[0] + np.interp(r.t, t, dissipated)
