"""The spin-up beam (``scenes.spin_up_beam``, Ωs = 4 rad/s, Ts = 15 s, 20 s) in projeq and in
Exudyn's nonlinear ANCF cable (``ObjectANCFCable2D``, 16 elements, generalized-α,
h = 1e-3), with the CPU time of each and the in-plane tip deflection v(L, t) at t = 5, 10,
15, 20 s (in the hub frame, the direction of rotation).

Exudyn's beam is clamped at the hub axis by four coordinate constraints on its first node:
position (0, 0) and slope (cos θ(t), sin θ(t)) with θ(t) of ``spin_up_motion`` (Python
offset user functions, as a user of Exudyn would write them). Its beam is extensible
(EA = 2.8e7 N, centrifugal strain ρAΩ²L²/(2EA) ≈ 3e-5), projeq's default is inextensible.

    pip install exudyn
    python benchmarks/exudyn_spin_up.py [--json] [--n-shapes 4] [--rtol 1e-8]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from beam_convergence import TIMES, tip_deflection  # noqa: E402

from projeq.scenes.elastic import spin_up_motion  # noqa: E402

OMEGA_S, T_S, LENGTH, EI, EA, RHO_A = 4.0, 15.0, 10.0, 1.4e4, 2.8e7, 1.2  # spin_up_beam's defaults


def exudyn_tip_deflection(n_elements: int = 16, h: float = 1e-3) -> tuple[np.ndarray, float]:
    """v(L, t) at TIMES by Exudyn and the CPU time of its time integration."""
    import exudyn as exu
    from exudyn.itemInterface import CoordinateConstraint, MarkerNodeCoordinate, ObjectANCFCable2D, SensorNode
    from exudyn.beams import GenerateStraightLineANCFCable2D
    from exudyn.solver import SolveDynamic

    motion = spin_up_motion(OMEGA_S, T_S)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    template = ObjectANCFCable2D(physicsMassPerLength=RHO_A, physicsBendingStiffness=EI, physicsAxialStiffness=EA)
    nodes = GenerateStraightLineANCFCable2D(mbs, [0, 0, 0], [LENGTH, 0, 0], n_elements, template)[0]
    ground = mbs.AddNode(exu.itemInterface.NodePointGround())
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    # node 0's coordinates are displacements from the reference (0, 0, 1, 0) of (x, y, x', y')
    clamp = (lambda t: 0.0, lambda t: 0.0, lambda t: np.cos(motion(t)[0]) - 1.0, lambda t: np.sin(motion(t)[0]))
    for k, value in enumerate(clamp):  # the clamp follows the hub
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=k))
        mbs.AddObject(CoordinateConstraint(
            markerNumbers=[ground_marker, marker],
            offsetUserFunction=lambda mbs_, t, item, offset, value=value: value(t),
        ))
    tip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = int(round(TIMES[-1] / h))
    settings.timeIntegration.endTime = TIMES[-1]
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = h
    started = time.process_time()
    SolveDynamic(mbs, settings, exu.DynamicSolverType.GeneralizedAlpha)
    cpu = time.process_time() - started
    data = mbs.GetSensorStoredData(tip)  # rows (t, x, y, z)
    rows = [np.argmin(np.abs(data[:, 0] - t)) for t in TIMES]
    theta = np.array([motion(t)[0] for t in TIMES])
    x, y = data[rows, 1], data[rows, 2]
    return -np.sin(theta) * x + np.cos(theta) * y, cpu


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--n-shapes", type=int, default=4, help="projeq's Ritz functions per plane")
    parser.add_argument("--rtol", type=float, default=1e-8, help="projeq's integrator rtol (DOP853)")
    args = parser.parse_args(argv)
    v_ex, cpu_ex = exudyn_tip_deflection()
    v_pq, cpu_pq = tip_deflection(OMEGA_S, rtol=args.rtol, n_shapes=args.n_shapes, family="clamped_free")
    report = {
        "times": TIMES.tolist(), "exudyn_v": v_ex.tolist(), "exudyn_cpu_s": cpu_ex,
        "projeq_v": v_pq.tolist(), "projeq_cpu_s": cpu_pq,
        "max_difference_m": float(np.abs(v_pq - v_ex).max()), "cpu_ratio_projeq_over_exudyn": cpu_pq / cpu_ex,
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return report
    print(f"{'t s':>5} {'exudyn v m':>12} {'projeq v m':>12} {'difference':>11}")
    for t, a, b in zip(TIMES, v_ex, v_pq):
        print(f"{t:>5.0f} {a:>12.6f} {b:>12.6f} {b - a:>11.2e}")
    print(f"CPU: exudyn {cpu_ex:.2f} s, projeq {cpu_pq:.2f} s, ratio projeq/exudyn {cpu_pq / cpu_ex:.2f}")
    return report


if __name__ == "__main__":
    main()
