"""projeq.from_urdf against Pinocchio on the same URDF files: real robots (UR5, 6 revolute joints;
Panda, 9 joints; a double pendulum on continuous joints) from the PyPI package example-robot-data,
which ships its URDF files offline.

Mass matrix (Pinocchio's CRBA) and s̈ = M⁻¹(τ − b) with τ = 0 under gravity (Pinocchio's ABA)
against projeq's mass matrix and its compiled and order-n s̈, at random states; relative errors
printed, and whether they are within 1e-10. Then the same robot with its last link replaced by a
RitzBeam runs ``simulate`` on the compiled path (no fallback warning) for a short time.

Needs ``pip install "projeq[urdf]" pin example-robot-data`` (pin: about 820 MB installed, 55 s;
hence not in the test extra). ``--quick``: 3 states and a 0.05 s flexible run (what the test runs).
"""

from __future__ import annotations

import os
import argparse
import time
import warnings
from importlib import metadata
from pathlib import Path

import numpy as np

import projeq as pq
from projeq.scenes.urdf import IgnoredWarning

#: the robots compared: UR5 (6 revolute joints), Panda (7 revolute and 2 prismatic finger joints, whose
#: mimic tag both tools ignore) and a double pendulum on continuous joints (Pinocchio: (cos θ, sin θ))
ROBOTS = ("ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
          "double_pendulum_description/urdf/double_pendulum_continuous.urdf")


def robot_file(name: str) -> Path:
    """The URDF file ``robots/<name>`` that example-robot-data installs (under its share folder)."""
    for entry in metadata.files("example-robot-data") or ():
        if str(entry).endswith("robots/" + name):
            return Path(entry.locate())
    raise SystemExit(f"example-robot-data does not ship robots/{name}")


def compare(path: Path, n_states: int, rng) -> float:
    """Largest relative difference of M and s̈ between projeq and Pinocchio over random states."""
    import pinocchio as pin
    import yourdfpy

    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredWarning)
        system = pq.from_urdf(path)
    child = {joint.name: joint.child for joint in yourdfpy.URDF.load(
        str(path), build_scene_graph=False, load_meshes=False, build_collision_scene_graph=False,
        load_collision_meshes=False).robot.joints}
    # Pinocchio's joints in its order, each by the child link it moves: projeq's coordinate of that link
    order = [system.q_index(child[name]).start for name in list(model.names)[1:]]
    evaluator = system.evaluator()
    worst = 0.0
    for _ in range(n_states):
        q, s_dot = rng.uniform(-np.pi, np.pi, system.n_q), rng.uniform(-2, 2, system.n_s)
        q_pin = np.concatenate([_pinocchio_q(joint.nq, q[i]) for joint, i in zip(list(model.joints)[1:], order)])
        v_pin = s_dot[order]
        M_pin = pin.crba(model, data, q_pin)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        a_pin = pin.aba(model, data, q_pin, v_pin, np.zeros(model.nv))
        M = system.mass_matrix(q)[np.ix_(order, order)]
        worst = max(worst, np.abs(M - M_pin).max() / np.abs(M_pin).max())
        for a in (evaluator.accelerations(q, s_dot, 0.0), system.accelerations(q, s_dot, method="recursive")):
            worst = max(worst, np.abs(a[order] - a_pin).max() / (1 + np.abs(a_pin).max()))
    return worst


def _pinocchio_q(nq: int, angle: float) -> list:
    """A one-dof joint's configuration in Pinocchio: the angle or position, or (cos θ, sin θ) for a
    continuous joint (nq = 2)."""
    return [np.cos(angle), np.sin(angle)] if nq == 2 else [angle]


def flexible_run(path: Path, t_end: float) -> tuple[str, float]:
    """The robot with its last moving link (wrist_3_link) a RitzBeam: simulate's method and wall time,
    with every warning an error but the ignored-parts report."""
    beam = pq.RitzBeam(0.25, rho_A=0.8, EI_z=30.0, EI_y=30.0, n_v=2, n_w=2)  # a 0.25 m tube, 0.2 kg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredWarning)
        system = pq.from_urdf(path, flexible={"wrist_3_link": beam})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        evaluator = system.evaluator()
        assert evaluator.name == "fast" and evaluator.evaluator.interpreted == [], evaluator
        started = time.perf_counter()
        # at simulate's defaults: its DOP853 starts at a stable step for the beam's modes
        # (driver.stable_first_step; scipy's own guess failed at t = 5.6 ms, D_n indefinite)
        result = pq.simulate(system, t_end, s_dot0=0.1 * np.ones(system.n_s), n_points=11)
    return result.method, time.perf_counter() - started


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 states and a 0.05 s flexible run")
    args = parser.parse_args(argv)
    rng, worst = np.random.default_rng(1), 0.0
    for name in ROBOTS:
        path = robot_file(name)
        found = compare(path, 3 if args.quick else 50, rng)
        print(f"{path.name}: projeq vs Pinocchio, M and s̈, largest relative difference {found:.2e}")
        worst = max(worst, found)
    print(f"within 1e-10: {'yes' if worst <= 1e-10 else 'no'}")
    method, seconds = flexible_run(robot_file(ROBOTS[0]), 0.05 if args.quick else 1.0)
    print(f"UR5 with wrist_3_link a RitzBeam: simulate compiled, {method}, {seconds:.2f} s wall")
    return 0 if worst <= 1e-10 else 1


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    raise SystemExit(main())
