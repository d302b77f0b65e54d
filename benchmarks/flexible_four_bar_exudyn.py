"""The flexible four-bar of examples/constraints.py part 2 in projeq and in Exudyn: crank and
rocker angles and the coupler's deflection over 1 s, both codes refined until their own
discretisation errors are known, and CPU times (time.process_time, one run).

The mechanism: crank a = 0.3 m (1 kg), rocker c = 0.8 m (1.5 kg), uniform slender rods
(centroidal moment m L²/12), ground link d = 1 m, gravity 9.81 m/s² along −y; the coupler is an
elastic beam b = 1 m, ρA = 2 kg/m, EI = 200 N m², no rotary inertia, its root at the crank pin,
its tip pinned to the rocker's tip. At t = 0 the crank is at 0.5 rad turning at 3 rad/s, the
loop closed (``four_bar_angles``), the coupler straight and every body moving with the rigid
four-bar's velocities (``system.tree_velocities``: rocker −0.3251 rad/s, coupler −1.0542 rad/s).

projeq: ``RitzBeam(n_v, family="clamped_free")`` on a revolute joint at the crank pin (the beam's
reference frame is the root tangent; it has no mass of its own), the tip held by
``PinClosure(..., axes="xy")``; the beam is inextensible, with the linear curvature v″ and the
second-order foreshortening u₂ (``stiffening=True``, docs/theory.md §10).

Exudyn 1.13: crank and rocker are ``ObjectRigidBody2D`` on ``NodeRigidBody2D``, pinned to the
ground by ``RevoluteJoint2D``; the coupler is n ``ObjectANCFCable2D`` elements
(``NodePoint2DSlope1``, EA = 1e7 N: nearly inextensible, exact curvature), gravity by
``LoadMassProportional`` on every body; ``RevoluteJoint2D`` joins the crank's tip to the first
node's position and the last node's position to the rocker's tip. The first node's slope is
free: projeq's beam is clamped to the coupler joint's massless frame, which turns freely on the
crank (q₂ is a coordinate), so the root carries no moment — the root slope of the cable plays
the part of q₂ (clamping it to the crank itself would weld coupler to crank, another
mechanism). Generalized-α (spectral radius 0.9, Exudyn's default), Newton absolute tolerance
1e-6 N (with 1e-7 the 32-element runs cut their steps and their crank angle drifted by 4e-4
rad).

Compared at t = 0.1, 0.2, …, 1 s: the crank angle, the rocker angle, the tip deflection v(L) from
the root tangent (projeq: ``beam.displacement(q_e, L)``; Exudyn: the tip's offset from the root
node normal to its slope vector) and the mid-span deflection from the chord (both: the offset of
the point x = L/2 from the line root–tip). projeq: ``simulate`` defaults at n_v = 2, and RK45 at
rtol 1e-10, atol 1e-12 for n_v = 2, 4, 6, 8 (its own error: the change from n_v = 6 to 8);
Exudyn: 8, 16, 32 elements at h = 1e-3, then h halved to 1.25e-4 (its own error: the larger
change from half the elements or twice the step). Per quantity: each code's finest run, their
difference and each code's own error; then every run's CPU time and largest differences from
both finest runs; then Exudyn's difference by its axial stiffness. Measured (one run, 2 shared cores):

    python benchmarks/flexible_four_bar_exudyn.py --n-v 2 4 6 8   # 5 min; default --n-v 2 4 6: 2.5 min
    python benchmarks/flexible_four_bar_exudyn.py --quick         # 20 ms (no Exudyn: projeq's runs alone)

    crank angle, rad: projeq n_v=8 tight vs exudyn 32 el h=0.000125
    t (s)     projeq     exudyn  difference  projeq error  exudyn error
    -----  ---------  ---------  ----------  ------------  ------------
     0.10   0.591839   0.591836     2.1e-06       1.6e-06       7.2e-07
     0.20   0.288254   0.288255    -1.0e-06       2.7e-06       1.9e-06
     0.30  -0.180677  -0.180670    -6.3e-06       1.1e-06       5.9e-07
     0.40  -0.737749  -0.737739    -1.0e-05       2.8e-07       9.8e-07
     0.50  -1.678180  -1.678178    -2.1e-06       2.4e-05       2.9e-06
     0.60  -3.003699  -3.003662    -3.7e-05       1.3e-05       6.9e-06
     0.70  -3.676438  -3.676410    -2.9e-05       6.2e-06       3.7e-06
     0.80  -3.988555  -3.988545    -1.0e-05       7.4e-07       7.7e-07
     0.90  -4.085669  -4.085666    -3.3e-06       5.2e-07       5.4e-07
     1.00  -3.998475  -3.998481     6.0e-06       2.2e-06       1.6e-06

    rocker angle, rad: projeq n_v=8 tight vs exudyn 32 el h=0.000125
    t (s)    projeq    exudyn  difference  projeq error  exudyn error
    -----  --------  --------  ----------  ------------  ------------
     0.10  1.541151  1.541151     6.8e-08       7.8e-08       1.2e-07
     0.20  1.586878  1.586874     3.6e-06       6.0e-07       9.8e-07
     0.30  1.771020  1.771015     5.2e-06       5.9e-07       4.3e-07
     0.40  2.048850  2.048846     4.3e-06       1.3e-07       4.7e-07
     0.50  2.332470  2.332478    -7.4e-06       3.9e-06       9.2e-07
     0.60  2.294168  2.294178    -9.7e-06       2.7e-06       1.3e-06
     0.70  2.111687  2.111697    -9.5e-06       2.0e-06       8.9e-07
     0.80  2.001385  2.001388    -3.7e-06       2.5e-07       3.4e-07
     0.90  1.965197  1.965198    -1.1e-06       2.1e-07       9.2e-08
     1.00  1.997717  1.997714     2.5e-06       8.3e-07       5.5e-07

    tip deflection v(L) from the root tangent, m: projeq n_v=8 tight vs exudyn 32 el h=0.000125
    t (s)     projeq     exudyn  difference  projeq error  exudyn error
    -----  ---------  ---------  ----------  ------------  ------------
     0.10  -0.000988  -0.000978    -9.6e-06       1.9e-05       6.6e-06
     0.20   0.004627   0.004607     2.0e-05       1.3e-05       3.2e-05
     0.30   0.004827   0.004765     6.2e-05       3.6e-05       4.3e-06
     0.40   0.002622   0.002591     3.1e-05       1.3e-05       3.9e-05
     0.50   0.010395   0.010534    -1.4e-04       5.7e-05       4.3e-05
     0.60  -0.004389  -0.004415     2.6e-05       6.8e-05       3.4e-05
     0.70   0.002100   0.002155    -5.6e-05       1.1e-05       2.1e-05
     0.80   0.000816   0.000885    -6.9e-05       7.0e-05       2.4e-05
     0.90   0.006109   0.006049     6.0e-05       4.2e-05       4.2e-05
     1.00   0.000911   0.000913    -2.8e-06       9.3e-05       3.1e-05

    mid-span deflection from the chord, m: projeq n_v=8 tight vs exudyn 32 el h=0.000125
    t (s)     projeq     exudyn  difference  projeq error  exudyn error
    -----  ---------  ---------  ----------  ------------  ------------
     0.10   0.000340   0.000341    -1.4e-06       4.1e-07       2.9e-07
     0.20  -0.001447  -0.001459     1.2e-05       8.1e-06       2.2e-07
     0.30  -0.001532  -0.001529    -3.3e-06       5.2e-06       2.9e-07
     0.40  -0.000674  -0.000674     2.3e-08       3.6e-06       3.7e-06
     0.50  -0.003009  -0.003020     1.1e-05       1.6e-05       2.6e-06
     0.60   0.001256   0.001240     1.6e-05       1.1e-05       2.9e-06
     0.70  -0.000717  -0.000698    -1.9e-05       1.4e-05       2.7e-06
     0.80  -0.000304  -0.000308     4.4e-06       1.6e-05       6.1e-06
     0.90  -0.001892  -0.001890    -1.8e-06       1.3e-07       1.2e-06
     1.00  -0.000251  -0.000245    -5.7e-06       1.4e-05       2.3e-06

    runs: CPU (time.process_time, this process) and max |difference| over the 10 times from projeq n_v=8 tight and from exudyn 32 el h=0.000125 (rad, m)
    run                      method            cpu (s)  crank vs projeq  rocker vs projeq  tip vs projeq  sag vs projeq  crank vs exudyn  rocker vs exudyn  tip vs exudyn  sag vs exudyn
    -----------------------  ----------------  -------  ---------------  ----------------  -------------  -------------  ---------------  ----------------  -------------  -------------
    projeq n_v=2 defaults    RK45                 4.80          6.7e-04           1.4e-04        2.5e-03        7.9e-04          6.3e-04           1.3e-04        2.5e-03        7.9e-04
    projeq n_v=2 tight       RK45                 9.65          6.7e-04           1.4e-04        2.5e-03        7.9e-04          6.3e-04           1.3e-04        2.5e-03        7.9e-04
    projeq n_v=4 tight       RK45                34.40          1.2e-04           2.0e-05        3.6e-04        7.7e-05          1.2e-04           2.7e-05        4.9e-04        9.2e-05
    projeq n_v=6 tight       RK45                74.08          2.4e-05           3.9e-06        9.3e-05        1.6e-05          3.5e-05           1.2e-05        2.0e-04        3.3e-05
    projeq n_v=8 tight       RK45               128.93          0.0e+00           0.0e+00        0.0e+00        0.0e+00          3.7e-05           9.7e-06        1.4e-04        1.9e-05
    exudyn 8 el h=0.001      gen-α h=0.001        0.12          1.3e-04           3.6e-05        3.3e-04        6.4e-05          9.0e-05           2.6e-05        3.0e-04        4.5e-05
    exudyn 16 el h=0.001     gen-α h=0.001        0.24          1.3e-04           3.6e-05        3.2e-04        6.4e-05          9.0e-05           2.6e-05        3.0e-04        4.4e-05
    exudyn 32 el h=0.001     gen-α h=0.001        0.58          1.3e-04           3.6e-05        3.3e-04        6.4e-05          9.0e-05           2.6e-05        3.0e-04        4.4e-05
    exudyn 16 el h=0.0005    gen-α h=0.0005       0.39          6.9e-05           1.6e-05        2.5e-04        2.5e-05          3.2e-05           6.5e-06        1.7e-04        1.2e-05
    exudyn 16 el h=0.00025   gen-α h=0.00025      0.82          4.4e-05           1.1e-05        1.8e-04        1.9e-05          7.1e-06           1.2e-06        4.2e-05        6.1e-06
    exudyn 32 el h=0.00025   gen-α h=0.00025      2.01          4.4e-05           1.1e-05        1.8e-04        1.9e-05          6.9e-06           1.3e-06        4.3e-05        6.1e-06
    exudyn 16 el h=0.000125  gen-α h=0.000125     1.60          3.8e-05           9.5e-06        1.3e-04        1.9e-05          9.6e-07           2.4e-07        1.7e-05        1.3e-06
    exudyn 32 el h=0.000125  gen-α h=0.000125     4.01          3.7e-05           9.7e-06        1.4e-04        1.9e-05          0.0e+00           0.0e+00        0.0e+00        0.0e+00

    Exudyn 16 el h=0.000125 by its axial stiffness: max |difference| from projeq n_v=8 tight over the 10 times (rad, m)
    EA (N)  cpu (s)  crank vs projeq  rocker vs projeq  tip vs projeq  sag vs projeq
    ------  -------  ---------------  ----------------  -------------  -------------
     1e+06     1.37          3.8e-04           1.0e-04        4.0e-04        7.3e-05
     1e+07     1.56          3.8e-05           9.5e-06        1.3e-04        1.9e-05
     1e+08     1.43          1.6e-05           3.3e-06        8.2e-05        1.4e-05

What agrees to what. The crank and rocker angles agree to 3.7e-5 and 1.0e-5 rad over the
whole second (the crank turns through 4.6 rad); that difference is the cable's stretching: it
falls as 1/EA (3.8e-4, 3.8e-5 rad at EA = 1e6, 1e7 N) to 1.6e-5 rad at EA = 1e8 N (crank),
within projeq's own error there (2.4e-5 rad at t = 0.5 s). The cut joint's force in projeq is
up to 30 N (12 N on average; ``pq.reactions``, n_v = 2): an axial strain N/EA ≤ 3e-6 at EA =
1e7 N lengthens the coupler by up to 3 µm, ~1e-5 rad on the 0.3 m crank — the size measured.
The mid-span deflection from the chord (up to 3.0 mm) agrees to 1.9e-5 m (1.4e-5 m at EA =
1e8 N), the level of projeq's n_v = 6 → 8 change (1.6e-5 m). The tip deflection from the root
tangent (up to 10.5 mm) agrees to 1.4e-4 m (8.2e-5 m at EA = 1e8 N), against own errors of up
to 9.3e-5 m (projeq, n_v = 6 → 8) and 4.3e-5 m (Exudyn, h = 2.5e-4 → 1.25e-4): it is the
slowest quantity to converge in both codes, as it carries the root slope and so the higher
bending modes (projeq's clamped–free functions approach n_v = 8 as 2.5e-3, 3.6e-4, 9.3e-5 m
for n_v = 2, 4, 6; Exudyn's generalized-α has a period error on the higher modes, pinned–pinned
(nπ)²√(EI/ρA)/L² = 99, 395, 888, 1579 rad/s, that asks for h ≤ 2.5e-4: at h = 1e-3 its tip is
off by 3e-4 m). The geometric terms beyond projeq's second-order beam theory, which made the
spin-up's difference (benchmarks/exudyn_spin_up.py), are negligible here: the deflection is at
most 1.05 % of L, so they are ~(v/L)² ≈ 1e-4 of it, ≤ 1e-6 m, below the differences measured.
So the codes agree within their discretisation errors once the cable's stretching is taken
out; no difference is left that would point to projeq.

Cost: Exudyn's finest run (32 elements, h = 1.25e-4) takes 4 s CPU, its 16-element run at
h = 2.5e-4 (within 4.2e-5 m of it) 0.8 s; projeq's n_v = 6 run at rtol 1e-10 74 s, its default
n_v = 2 run 4.8 s (but 2.5e-3 m off in the tip deflection: two functions are too few for this
loop). projeq's explicit steps are bound by the beam's stiff bending modes (n_v = 8: 8.0e5
evaluations of s̈); Radau at rtol 1e-10 did not finish n_v = 4 in 300 s (one core), and
``simulate``'s default for n_v = 4 over 1 s (DOP853) fails at t = 0.361 s with a degenerate
partition (q ~ 1e9; n_v = 6 at 0.155 s) — the reason the converged runs name RK45. Its cause:
``simulate`` restarts scipy's solver at each of its 20 segments, scipy's initial-step guess there
is ~40× the stable step (9.7e-3 against 2.6e-4 s at t = 0.125 s of a 0.5 s run), and the
partition check raises on that trial step's wild stage instead of letting the step be
rejected; with ``n_segments=1`` or ``first_step=1e-4`` the same DOP853 run passes (68,447
evaluations) and ends where RK45 at rtol 1e-10 does.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # single-threaded CPU times, as benchmarks/exudyn_spin_up.py
import argparse
import importlib.util
import time
import warnings

import numpy as np

import projeq as pq
from projeq.scenes.mechanisms import four_bar_angles, slender_rod
from projeq.studies.bench_peers import exudyn_generalized_alpha
from projeq.studies.table import Table

A, B, C, D = 0.3, 1.0, 0.8, 1.0  # crank, coupler (the beam), rocker, ground link, m
M_CRANK, M_ROCKER = 1.0, 1.5  # kg, uniform slender rods (centroidal moment m L²/12)
RHO_A, EI = 2.0, 200.0  # kg/m, N m²
G = 9.81  # m/s², along −y
THETA1, OMEGA1 = 0.5, 3.0  # crank angle (rad) and rate (rad/s) at t = 0


def projeq_model(n_v: int = 2):
    """The ConstrainedSystem of examples/constraints.py part 2 with ``n_v`` clamped–free
    functions, and its beam."""
    beam = pq.RitzBeam(B, rho_A=RHO_A, EI_z=EI, n_v=n_v, n_w=0, family="clamped_free")
    tree = pq.System({"crank": slender_rod(M_CRANK, A), "rocker": slender_rod(M_ROCKER, C), "coupler": beam},
                     {"crank": pq.Revolute(axis="z"), "rocker": pq.Revolute(axis="z", r_pn=(D, 0.0, 0.0)),
                      "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(A, 0.0, 0.0))},
                     gravity=(0.0, -G, 0.0))
    pin = pq.PinClosure(tree, "coupler", (B, 0.0, 0.0), "rocker", (C, 0.0, 0.0), axes="xy")
    theta2, theta3 = four_bar_angles(THETA1, A, B, C, D)
    system = pq.ConstrainedSystem(tree, phi=pin, independent=[0, *range(3, 3 + n_v)],
                                  q0=(THETA1, theta3, theta2 - THETA1, *[0.0] * n_v), s_dot0=[OMEGA1, *[0.0] * n_v])
    return system, beam


def _beam_measures(r_root, t_root, r_mid, r_tip):
    """(tip deflection from the root tangent, mid-span deflection from the chord) of points
    given as (n, 2) arrays; t_root need not be a unit vector."""
    def cross(u, v):
        return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]

    t_hat = t_root / np.linalg.norm(t_root, axis=1)[:, None]
    chord = r_tip - r_root
    c_hat = chord / np.linalg.norm(chord, axis=1)[:, None]
    return cross(t_hat, chord), cross(c_hat, r_mid - r_root)


def projeq_run(times, n_v: int = 2, **options) -> dict:
    """Crank and rocker angles, tip deflection v(L) in the coupler's (root tangent) frame and
    mid-span deflection from the chord at ``times`` by ``simulate`` (``options``: its knobs),
    with the CPU time of ``simulate``."""
    system, beam = projeq_model(n_v)
    system.evaluator().accelerations(system.q0, system.s_dot0, 0.0)  # compile/load outside the clock
    times = np.asarray(times, float)
    started = time.process_time()
    result = pq.simulate(system, float(times[-1]), t_eval=np.concatenate(([0.0], times)), **options)
    cpu = time.process_time() - started
    q_e = result.q[1:, 3:]
    r = beam.displacement(q_e, [0.0, B / 2, B]) + np.array([0.0, B / 2, B])[:, None] * np.array([1.0, 0.0, 0.0])
    tip, sag = _beam_measures(r[:, 0, :2], np.tile([1.0, 0.0], (len(times), 1)), r[:, 1, :2], r[:, 2, :2])
    return {"crank": result.q[1:, 0], "rocker": result.q[1:, 1], "tip": tip, "sag": sag, "cpu": cpu,
            "method": result.method, "nfev": result.nfev}


def exudyn_run(times, n_elements: int = 16, h: float = 1e-3, axial_stiffness: float = 1e7,
               newton_atol: float = 1e-6, spectral_radius: float | None = None) -> dict:
    """The same quantities by Exudyn (module docstring: the model) and the CPU time of its
    ``SolveDynamic`` (generalized-α, step ``h``)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadMassProportional,
        MarkerBodyMass,
        MarkerBodyPosition,
        MarkerNodePosition,
        NodePoint2DSlope1,
        NodeRigidBody2D,
        ObjectANCFCable2D,
        ObjectGround,
        ObjectRigidBody2D,
        RevoluteJoint2D,
        SensorNode,
    )

    times = np.asarray(times, float)
    system, _ = projeq_model(2)
    omega1, omega3, omega2_rel = system.tree_velocities(system.q0, system.s_dot0)[:3]
    theta2, theta3 = four_bar_angles(THETA1, A, B, C, D)
    omega2 = omega1 + omega2_rel

    def e(angle):
        return np.array([np.cos(angle), np.sin(angle)])

    def perp(angle):
        return np.array([-np.sin(angle), np.cos(angle)])

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    gravity = [0.0, -G, 0.0]
    ground = mbs.AddObject(ObjectGround())

    def rod(mass, length, pivot, angle, omega):
        """A rigid rod turning about ``pivot`` at ``angle``, rate ``omega``; its marker at the pivot
        and at its tip (local x from the centre of mass)."""
        centre = np.asarray(pivot) + length / 2 * e(angle)
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*centre, angle],
                                           initialVelocities=[*(omega * length / 2 * perp(angle)), omega]))
        body = mbs.AddObject(ObjectRigidBody2D(mass=mass, inertia=mass * length**2 / 12, nodeNumber=node))
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=body)), loadVector=gravity))
        ends = [mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[s * length / 2, 0.0, 0.0])) for s in (-1, 1)]
        mbs.AddObject(RevoluteJoint2D(markerNumbers=[
            mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[*pivot, 0.0])), ends[0]]))
        return node, ends[1]

    crank, crank_tip = rod(M_CRANK, A, (0.0, 0.0), THETA1, omega1)
    rocker, rocker_tip = rod(M_ROCKER, C, (D, 0.0), theta3, omega3)
    # the coupler: straight from the crank pin P along θ2, moving rigidly with the four-bar
    P, v_P = A * e(THETA1), omega1 * A * perp(THETA1)
    nodes = []
    for k in range(n_elements + 1):
        s = k * B / n_elements
        nodes.append(mbs.AddNode(NodePoint2DSlope1(
            referenceCoordinates=[*(P + s * e(theta2)), *e(theta2)],
            initialVelocities=[*(v_P + omega2 * s * perp(theta2)), *(omega2 * perp(theta2))])))
    for k in range(n_elements):
        cable = mbs.AddObject(ObjectANCFCable2D(length=B / n_elements, massPerLength=RHO_A,
                                                bendingStiffness=EI, axialStiffness=axial_stiffness,
                                                nodeNumbers=[nodes[k], nodes[k + 1]]))
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=cable)), loadVector=gravity))
    # its root pinned to the crank's tip (the slope free: the coupler's revolute joint), its tip to the rocker's
    mbs.AddObject(RevoluteJoint2D(markerNumbers=[crank_tip, mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[0]))]))
    mbs.AddObject(RevoluteJoint2D(markerNumbers=[rocker_tip, mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[-1]))]))
    coordinates = exu.OutputVariableType.Coordinates
    watched = {"crank": crank, "rocker": rocker, "root": nodes[0], "mid": nodes[n_elements // 2], "tip": nodes[-1]}
    sensors = {name: mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, writeToFile=False,
                                              outputVariableType=coordinates)) for name, node in watched.items()}
    mbs.Assemble()
    cpu = exudyn_generalized_alpha(mbs, float(times[-1]), h, newton_atol, spectral_radius)
    values = {}
    for name, sensor in sensors.items():
        data = mbs.GetSensorStoredData(sensor)
        rows = [int(np.argmin(np.abs(data[:, 0] - t))) for t in times]
        reference = np.asarray(mbs.GetNodeParameter(watched[name], "referenceCoordinates"), float)
        values[name] = data[rows, 1:] + reference
    tip, sag = _beam_measures(values["root"][:, :2], values["root"][:, 2:4], values["mid"][:, :2], values["tip"][:, :2])
    return {"crank": values["crank"][:, 2], "rocker": values["rocker"][:, 2], "tip": tip, "sag": sag, "cpu": cpu,
            "method": f"gen-α h={h:g}", "nfev": None}


PROJEQ_TIGHT = {"method": "RK45", "rtol": 1e-10, "atol": 1e-12}
#: Exudyn's (elements, h): the brief's 8, 16, 32 elements at h = 1e-3 and 16 at 5e-4, then halved steps
#: (its tip deflection still moves by 1e-4 m from h = 5e-4 to 2.5e-4: generalized-α's period error)
EXUDYN_RUNS = ((8, 1e-3), (16, 1e-3), (32, 1e-3), (16, 5e-4), (16, 2.5e-4), (32, 2.5e-4), (16, 1.25e-4),
               (32, 1.25e-4))
QUANTITIES = {"crank": "crank angle, rad", "rocker": "rocker angle, rad",
              "tip": "tip deflection v(L) from the root tangent, m", "sag": "mid-span deflection from the chord, m"}


def _exudyn_name(n, h):
    return f"exudyn {n} el h={h:g}"


def runs(times, n_vs=(2, 4, 6), exudyn=EXUDYN_RUNS, axial_stiffness=1e7) -> dict:
    """Name → run (:func:`projeq_run`, :func:`exudyn_run`; ``exudyn=()``: projeq's alone), all in this
    process."""
    out = {"projeq n_v=2 defaults": projeq_run(times, 2)}
    for n_v in n_vs:
        out[f"projeq n_v={n_v} tight"] = projeq_run(times, n_v, **PROJEQ_TIGHT)
    for n, h in exudyn:
        out[_exudyn_name(n, h)] = exudyn_run(times, n, h, axial_stiffness=axial_stiffness)
    return out


def axial_table(times, results: dict, stiffnesses=(1e6, 1e7, 1e8), n_elements: int = 16, h: float = 1.25e-4) -> Table:
    """Exudyn's difference from projeq's finest run against its axial stiffness EA (Newton's
    absolute tolerance scaled with EA): the share of the difference that is the cable's
    stretching, absent in projeq's inextensible beam."""
    pq_names = [k for k in results if k.startswith("projeq") and k.endswith("tight")]
    pq_best = results[pq_names[-1]]
    quantities = ("crank", "rocker", "tip", "sag")
    rows = []
    for EA in stiffnesses:
        r = exudyn_run(times, n_elements, h, axial_stiffness=EA, newton_atol=1e-6 * max(1.0, EA / 1e7))
        rows.append((EA, r["cpu"], *[float(np.abs(r[k] - pq_best[k]).max()) for k in quantities]))
    return Table(("EA", "cpu", *[f"{k} vs projeq" for k in quantities]), rows, units={"EA": "N", "cpu": "s"},
                 formats={"EA": ".0e", "cpu": ".2f", **{f"{k} vs projeq": ".1e" for k in quantities}},
                 title=f"Exudyn {n_elements} el h={h:g} by its axial stiffness: max |difference| from {pq_names[-1]} "
                       f"over the {len(times)} times (rad, m)")


def tables(times, results: dict, exudyn=EXUDYN_RUNS) -> list[Table]:
    """Per quantity: each code's finest value, their difference and each code's own
    discretisation error (its finest run's change from the next coarser: projeq's last n_v
    against the one before; Exudyn's last run against half its elements and against twice
    its step, the larger) at ``times``; then per run its CPU time and largest differences
    from both codes' finest runs (``exudyn=()``: projeq's runs alone, from its finest)."""
    pq_names = [k for k in results if k.startswith("projeq") and k.endswith("tight")]
    pq_best, pq_next = results[pq_names[-1]], results[pq_names[-2]]
    quantities = ("crank", "rocker", "tip", "sag")
    if not exudyn:
        rows = [(name, r["method"], r["cpu"], *[float(np.abs(r[k] - pq_best[k]).max()) for k in quantities])
                for name, r in results.items()]
        columns = [f"{k} vs projeq" for k in quantities]
        return [Table(("run", "method", "cpu", *columns), rows, units={"cpu": "s"},
                      formats={"cpu": ".2f", **{c: ".1e" for c in columns}},
                      title=f"projeq's runs: CPU (time.process_time) and max |difference| over the "
                            f"{len(times)} times from {pq_names[-1]} (rad, m)")]
    n, h = exudyn[-1]
    ex_name = _exudyn_name(n, h)
    ex_best = results[ex_name]
    ex_coarser = [results[k] for k in (_exudyn_name(n // 2, h), _exudyn_name(n, 2 * h)) if k in results]
    out = []
    for key, what in QUANTITIES.items():
        pq_err = np.abs(pq_best[key] - pq_next[key])
        ex_err = np.max([np.abs(ex_best[key] - r[key]) for r in ex_coarser], axis=0)
        rows = [(t, p, e, p - e, pe, ee) for t, p, e, pe, ee in zip(times, pq_best[key], ex_best[key], pq_err, ex_err)]
        out.append(Table(("t", "projeq", "exudyn", "difference", "projeq error", "exudyn error"), rows,
                         units={"t": "s"}, formats={"t": ".2f", "projeq": ".6f", "exudyn": ".6f", "difference": ".1e",
                                                    "projeq error": ".1e", "exudyn error": ".1e"},
                         title=f"{what}: {pq_names[-1]} vs {ex_name}"))
    rows = [(name, r["method"], r["cpu"], *[float(np.abs(r[k] - pq_best[k]).max()) for k in quantities],
             *[float(np.abs(r[k] - ex_best[k]).max()) for k in quantities]) for name, r in results.items()]
    columns = [f"{k} vs {code}" for code in ("projeq", "exudyn") for k in quantities]
    out.append(Table(("run", "method", "cpu", *columns), rows, units={"cpu": "s"},
                     formats={"cpu": ".2f", **{c: ".1e" for c in columns}},
                     title=f"runs: CPU (time.process_time, this process) and max |difference| over the {len(times)} "
                           f"times from {pq_names[-1]} and from {ex_name} (rad, m)"))
    return out


def main(argv=None) -> list[Table]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated seconds (default 1)")
    parser.add_argument("--points", type=int, default=10, help="compared times, equally spaced up to t_end (default 10)")
    parser.add_argument("--axial-stiffness", type=float, default=1e7, help="Exudyn's EA in N (default 1e7)")
    parser.add_argument("--n-v", type=int, nargs="+", default=[2, 4, 6],
                        help="projeq's numbers of bending functions at tight rtol (default 2 4 6; the last two give its error)")
    parser.add_argument("--quick", action="store_true",
                        help="20 ms, 2 times, n_v = 2, 4, Exudyn 4 and 8 elements at h = 1e-3")
    args = parser.parse_args(argv)
    if args.quick:
        args.t_end, args.points, args.n_v = 0.02, 2, [2, 4]
    exudyn = ((4, 1e-3), (8, 1e-3)) if args.quick else EXUDYN_RUNS
    if importlib.util.find_spec("exudyn") is None:
        print("exudyn is not installed (pip install 'projeq[bench]'): its runs and the comparison left out")
        exudyn = ()
    times = np.linspace(args.t_end / args.points, args.t_end, args.points)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        results = runs(times, n_vs=args.n_v, exudyn=exudyn, axial_stiffness=args.axial_stiffness)
        out = tables(times, results, exudyn)
        if exudyn:
            out.append(axial_table(times, results, (1e7,), *exudyn[-1]) if args.quick
                       else axial_table(times, results))
    for table in out:
        print(table.to_text())
        print()
    return out


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
