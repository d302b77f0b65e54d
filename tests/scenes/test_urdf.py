"""URDF import (projeq.from_urdf): a small arm written here equals the same System built by hand;
a real robot (example-robot-data's UR5) equals Pinocchio on the same file in
benchmarks/urdf_pinocchio.py (run in its quick mode here where pin is installed)."""

import runpy
import warnings
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

import projeq as pq
from projeq.spatial import rotation_x, rotation_y, rotation_z

pytest.importorskip("yourdfpy", reason="yourdfpy is not installed (pip install 'projeq[urdf]')")
from projeq.scenes.urdf import IgnoredWarning  # noqa: E402

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><visual><geometry><box size="0.2 0.3 0.1"/></geometry></visual></link>
  <link name="upper">
    <inertial><origin xyz="0.1 0.02 -0.3" rpy="0.2 -0.4 0.7"/><mass value="2.5"/>
      <inertia ixx="0.08" ixy="0.004" ixz="-0.002" iyy="0.07" iyz="0.001" izz="0.02"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="0.6"/></geometry></collision>
    <visual><origin xyz="0 0 -0.3" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.05" length="0.6"/></geometry></visual>
    <visual><origin xyz="0 0 -0.6" rpy="0 0 0"/><geometry><sphere radius="0.07"/></geometry></visual>
  </link>
  <link name="slider">
    <inertial><origin xyz="0 0 0.05" rpy="0 0 0"/><mass value="0.8"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.004"/></inertial>
  </link>
  <link name="hand">
    <visual><geometry><mesh filename="package://arm/hand.stl"/></geometry></visual>
    <inertial><origin xyz="0.03 0 0" rpy="0 0.3 0"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0015"/></inertial>
  </link>
  <link name="tool"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.4" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <joint name="slide" type="prismatic"><parent link="upper"/><child link="slider"/>
    <origin xyz="0 0 -0.6" rpy="0 0 0"/><axis xyz="0.6 0 0.8"/><limit lower="0" upper="0.2" effort="10" velocity="1"/></joint>
  <joint name="wrist" type="continuous"><parent link="slider"/><child link="hand"/>
    <origin xyz="0.05 0 0" rpy="-0.5 0 1.0"/><axis xyz="1 0 0"/></joint>
  <joint name="flange" type="fixed"><parent link="hand"/><child link="tool"/><origin xyz="0.1 0 0" rpy="0 0 0"/></joint>
</robot>
"""


def rpy(roll, pitch, yaw):
    """URDF's fixed-axis roll, pitch, yaw: R = R_z(yaw) R_y(pitch) R_x(roll)."""
    return rotation_z(yaw) @ rotation_y(pitch) @ rotation_x(roll)


def by_hand():
    """The arm of ARM typed in as projeq objects."""
    R = rpy(0.2, -0.4, 0.7)
    upper_I = np.array([[0.08, 0.004, -0.002], [0.004, 0.07, 0.001], [-0.002, 0.001, 0.02]])
    R_hand = rpy(0.0, 0.3, 0.0)
    bodies = {"base": pq.Frame(), "upper": pq.RigidBody(2.5, (0.1, 0.02, -0.3), R @ upper_I @ R.T),
              "slider": pq.RigidBody(0.8, (0.0, 0.0, 0.05), np.diag([0.002, 0.003, 0.004])),
              "hand": pq.RigidBody(0.5, (0.03, 0.0, 0.0), R_hand @ np.diag([0.001, 0.002, 0.0015]) @ R_hand.T),
              "tool": pq.RigidBody(0.1, I_c=1e-4 * np.eye(3))}
    joints = {"base": pq.Fixed(),
              "upper": pq.Revolute("base", (0, 1, 0), r_pn=(0, 0, 0.4), orientation=rpy(0.1, 0.2, 0.3)),
              "slider": pq.Prismatic("upper", (0.6, 0, 0.8), r_pn=(0, 0, -0.6)),
              "hand": pq.Revolute("slider", (1, 0, 0), r_pn=(0.05, 0, 0), orientation=rpy(-0.5, 0.0, 1.0)),
              "tool": pq.Fixed("hand", r_pn=(0.1, 0, 0))}
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -9.81))


@pytest.fixture(scope="module")
def arm_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("urdf") / "arm.urdf"
    path.write_text(ARM)
    return path


def test_a_small_arm_equals_the_same_arm_by_hand(arm_file):
    """Mass matrix and s̈ (order-n) of the imported arm = the hand-built one's at random states
    (measured 0 here, 4e-16 before; bound 100 ε relative, was 1e-13); the limits and the collision
    geometry are reported in one warning."""
    with pytest.warns(IgnoredWarning) as said:
        system = pq.from_urdf(arm_file)
    assert len(said) == 1
    assert "joint limits (2: shoulder, slide)" in str(said[0].message)
    assert "collision geometry (1: upper)" in str(said[0].message)
    assert "visual meshes (drawn as the solid of the inertia) (1: hand)" in str(said[0].message)
    reference = by_hand()
    assert system.coordinates() == reference.coordinates()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, s_dot = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
        M = reference.mass_matrix(q)
        expected = reference.accelerations(q, s_dot, method="recursive")
        got = system.accelerations(q, s_dot, method="recursive")
        assert np.abs(system.mass_matrix(q) - M).max() <= 100 * np.finfo(float).eps * np.abs(M).max()
        assert np.abs(got - expected).max() <= 100 * np.finfo(float).eps * (1 + np.abs(expected).max())


def test_a_flexible_link_replaces_the_rigid_one(arm_file):
    """flexible={"hand": RitzBeam(...)}: the beam is the hand's subsystem, on the wrist joint."""
    beam = pq.RitzBeam(0.3, rho_A=1.0, EI_z=50.0, n_v=2, n_w=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredWarning)
        system = pq.from_urdf(arm_file, flexible={"hand": beam})
    assert system.subsystem("hand") is beam and system.n_s == 3 + 2


def test_visual_primitives_are_drawn(arm_file):
    """The links' visual box, cylinder and sphere are their subsystems' Visuals with their origins
    and the viewer's solids (the massless base's box too); the hand, drawn by a mesh (not read),
    is the box of its inertia; the page carries them (its data equal motion()'s, test_viewer.py)."""
    from scipy.spatial.transform import Rotation

    from projeq.simulation.animation import motion
    from tests.simulation.test_viewer import prescribed

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredWarning)
        system = pq.from_urdf(arm_file)
    cylinder, sphere = system.subsystem("upper").visuals
    assert (cylinder.kind, cylinder.size) == ("cylinder", (0.05, 0.6))
    assert (sphere.kind, sphere.size) == ("sphere", (0.07,))
    assert np.abs(cylinder.origin[:3, :3] - rotation_x(np.pi / 2)).max() < 1e-15
    assert cylinder.origin[:3, 3].tolist() == [0.0, 0.0, -0.3]
    assert sphere.origin[:3, 3].tolist() == [0.0, 0.0, -0.6]
    doc = motion(prescribed(system, np.zeros((2, system.n_q))))
    shapes = {(doc["frames"][s["frame"]], s["kind"]): s for s in doc["shapes"]}
    assert shapes["base", "box"]["size"] == [0.2, 0.3, 0.1]
    drawn = shapes["upper", "cylinder"]
    assert drawn["size"] == [0.05, 0.6] and drawn["position"] == [0.0, 0.0, -0.3]
    axis = Rotation.from_quat(drawn["quaternion"]).apply([0.0, 1.0, 0.0])  # three.js's y: URDF's z turned
    assert np.abs(axis - rotation_x(np.pi / 2)[:, 2]).max() < 1e-15
    assert shapes["upper", "sphere"]["position"] == [0.0, 0.0, -0.6]
    moments = np.array([0.001, 0.002, 0.0015])  # the hand's: a box of edges² 6 (Σλ − 2λ_i)/m
    edges = np.sqrt(6 * (moments.sum() - 2 * moments) / 0.5)
    assert sorted(shapes["hand", "box"]["size"]) == pytest.approx(sorted(edges), rel=1e-12)
    assert ("slider", "box") in shapes and ("tool", "sphere") in shapes  # no visuals: their inertias' solids


def test_bad_input_is_named(arm_file, tmp_path):
    with pytest.raises(ValueError, match="path: no URDF file"):
        pq.from_urdf(tmp_path / "missing.urdf")
    with pytest.raises(ValueError, match="flexible: no link named \\['elbow'\\]"):
        pq.from_urdf(arm_file, flexible={"elbow": pq.Frame()})
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'>")
    with pytest.raises(ValueError, match="path: .* is not well-formed XML"):
        pq.from_urdf(broken)
    planar = tmp_path / "planar.urdf"
    planar.write_text(ARM.replace('type="prismatic"', 'type="planar"'))
    with pytest.raises(ValueError, match="joint 'slide' is of type 'planar'"), warnings.catch_warnings():
        warnings.simplefilter("ignore", IgnoredWarning)
        pq.from_urdf(planar)


def test_the_pinocchio_benchmark_quick_mode(capsys):
    """benchmarks/urdf_pinocchio.py --quick: UR5 (example-robot-data) against Pinocchio, mass
    matrix and s̈ at random states to 1e-10 relative (measured in its output)."""
    pytest.importorskip("pinocchio", reason="pin is not installed (pip install pin example-robot-data)")
    try:  # a package of URDF files, no module to import
        metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    benchmark = runpy.run_path(str(Path(__file__).resolve().parents[2] / "benchmarks" / "urdf_pinocchio.py"))
    assert benchmark["main"](["--quick"]) == 0
    assert "within 1e-10: yes" in capsys.readouterr().out
