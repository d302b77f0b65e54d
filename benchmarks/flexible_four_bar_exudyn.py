"""The flexible four-bar (examples/constraints.py part 2) in projeq and in Exudyn.

(docstring completed below with the measured table)
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # single-threaded CPU times, as benchmarks/exudyn_spin_up.py
import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.scenes.mechanisms import four_bar_angles, slender_rod
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
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerBodyPosition, MarkerNodePosition,
                                      NodePoint2DSlope1, NodeRigidBody2D, ObjectANCFCable2D, ObjectGround,
                                      ObjectRigidBody2D, RevoluteJoint2D, SensorNode)
    from exudyn.solver import SolveDynamic

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
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = round(float(times[-1]) / h)
    settings.timeIntegration.endTime = float(times[-1])
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.absoluteTolerance = newton_atol
    if spectral_radius is not None:
        settings.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = h
    started = time.process_time()
    SolveDynamic(mbs, settings, exu.DynamicSolverType.GeneralizedAlpha)
    cpu = time.process_time() - started
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
    """Name → run (:func:`projeq_run`, :func:`exudyn_run`), all in this process."""
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
    from both codes' finest runs."""
    pq_names = [k for k in results if k.startswith("projeq") and k.endswith("tight")]
    pq_best, pq_next = results[pq_names[-1]], results[pq_names[-2]]
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
                         title=f"{what}: {pq_names[-1]} vs {ex_name} (errors: change from {pq_names[-2]}; "
                               f"from Exudyn with half the elements or twice the step, the larger)"))
    quantities = ("crank", "rocker", "tip", "sag")
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
    args = parser.parse_args(argv)
    times = np.linspace(args.t_end / args.points, args.t_end, args.points)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        results = runs(times, n_vs=args.n_v, axial_stiffness=args.axial_stiffness)
        out = [*tables(times, results), axial_table(times, results)]
    for table in out:
        print(table.to_text())
        print()
    return out


if __name__ == "__main__":
    main()
