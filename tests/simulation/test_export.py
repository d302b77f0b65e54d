"""ParaView export: a VTU series that meshio reads back with the right geometry."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import projeq as pq
from projeq.simulation.export import write_vtu_series
from projeq.spatial import rotation_z
from projeq.scenes.elastic import elastic_arm


def test_vtu_series_of_an_elastic_arm(tmp_path):
    """Every output time is a .vtu listed in the .pvd with its time; the beam's tip point
    read back is where the kinematics puts it (link end + beam frame · r(L)), and the
    velocity point data of the hub frame origin is zero (it sits on the fixed axis). All three to 100 ε of
    their scale (measured 0: the times are written exactly, the tip and the velocity are the kinematics'
    own numbers; were allclose's defaults rtol 1e-5, atol 1e-8 for the times, atol 1e-12 + rtol 1e-5)."""
    system = elastic_arm(n_shapes=2)
    result = pq.simulate(system, 0.05, method="RK45", rtol=1e-8, atol=1e-10, n_points=3)
    pvd = write_vtu_series(result, tmp_path, name="arm", stations=5)
    bodies = [d for d in ET.parse(pvd).getroot().iter("DataSet") if d.attrib["part"] == "0"]  # part 1: the mechanism
    files = [d.attrib["file"] for d in bodies]
    times = [float(d.attrib["timestep"]) for d in bodies]
    exact = 100 * np.finfo(float).eps
    assert len(files) == 3 and np.allclose(times, result.t, rtol=0, atol=exact * result.t[-1])
    mesh = meshio.read(tmp_path / files[-1])
    # layout: link1 frame (4 points), beam centre line (5 points), tip frame (4 points)
    assert mesh.points.shape == (13, 3)
    beam = system.subsystem("beam")
    q_e = result.q[-1, system.e_q_slice[system.index("beam")]]
    theta1, theta2 = result.q[-1, 0], result.q[-1, 1]
    tip_local = beam.displacement(q_e, [beam.length])[0] + [beam.length, 0, 0]
    c1, s1, c12, s12 = np.cos(theta1), np.sin(theta1), np.cos(theta1 + theta2), np.sin(theta1 + theta2)
    R12 = np.array([[c12, -s12, 0], [s12, c12, 0], [0, 0, 1]])
    expected_tip = np.array([0.5 * c1, 0.5 * s1, 0.0]) + R12 @ tip_local
    assert np.allclose(mesh.points[8], expected_tip, rtol=0, atol=exact * np.abs(expected_tip).max())
    assert np.allclose(mesh.point_data["velocity"][0], 0.0, rtol=0,
                       atol=exact * np.abs(mesh.point_data["velocity"]).max())
    assert mesh.cells_dict["line"].shape == (3 + 4 + 3, 2)


def test_the_double_pendulums_mechanism_joins_its_joints_by_1_m_links(tmp_path):
    """The mechanism part of the ParaView series: a line from the upper joint (the origin) to
    the lower joint and from each joint to its bob (point masses at 1 m): three line cells
    of length l1 = l2 = 1 m, the lower joint at r = l1 (−sin θ1, 0, −cos θ1), the first rod
    (along −z at θ1 = 0) turned by θ1 about +y. Both to round-off, 100 ε (measured 1.1e-16 and 5.6e-17;
    the bounds were 1e-12, and allclose's default rtol 1e-5 for the joint)."""
    system = pq.scenes.double_pendulum()
    result = pq.simulate(system, 0.3, n_points=4)
    pvd = write_vtu_series(result, tmp_path, name="dp")
    mechanism = [d.attrib["file"] for d in ET.parse(pvd).getroot().iter("DataSet") if d.attrib["part"] == "1"]
    assert len(mechanism) == 4
    mesh = meshio.read(tmp_path / mechanism[-1])
    lines = mesh.cells_dict["line"]
    lengths = np.linalg.norm(mesh.points[lines[:, 1]] - mesh.points[lines[:, 0]], axis=1)
    exact = 100 * np.finfo(float).eps
    assert lines.shape == (3, 2) and np.allclose(lengths, 1.0, rtol=0, atol=exact)
    theta1 = result.q[-1, 0]
    assert np.allclose(mesh.points[1], [-np.sin(theta1), 0.0, -np.cos(theta1)], rtol=0, atol=exact)
    assert mesh.cell_data["body"][0].tolist() == [0, 0, 1] and mesh.cell_data["kind"][0].tolist() == [0, 1, 1]
    assert (tmp_path / "dp_bodies.csv").read_text().splitlines() == ["body,name,joint", "0,bob1,Revolute",
                                                                     "1,bob2,Revolute"]


def test_a_saved_run_is_exported_from_its_run_record(tmp_path):
    """A Result loaded from a file has no system; its run record (metadata: scene and
    parameters) rebuilds it, and the export equals the one of the Result in memory."""
    system = pq.scenes.double_pendulum(l1=0.5)
    result = pq.simulate(system, 0.2, n_points=3)
    path = tmp_path / "dp.npz"
    from dataclasses import replace

    replace(result, metadata={"scene": "double_pendulum", "parameters": {"l1": 0.5}}).save(path)
    later = write_vtu_series(pq.Result.load(path), tmp_path / "later", name="dp")
    now = write_vtu_series(result, tmp_path / "now", name="dp")
    for part in ("dp_0002.vtu", "dp_mechanism_0002.vtu"):
        assert np.array_equal(meshio.read(later.parent / part).points, meshio.read(now.parent / part).points)
    pq.Result.save(result, tmp_path / "bare.npz")
    with pytest.raises(ValueError, match="no run record"):
        write_vtu_series(pq.Result.load(tmp_path / "bare.npz"), tmp_path / "bare")


def test_the_spin_up_beams_frames_are_its_centre_line_turned_by_the_hub(tmp_path):
    """The default run's scene (a beam on a prescribed hub): each frame's points are the
    centre line (x + u, v, w)(q_e) at the stations (RitzBeam.displacement) turned by the hub
    angle θ(t) about z; ``displacement`` is the points less the first frame's, and
    ``velocity`` the rate of the points along (q̇_e, 1) by central differences (an independent
    statement of R J ẏ); the beam's line cells join neighbouring stations, and a beam alone
    has no mechanism part."""
    system = pq.scenes.spin_up_beam(n_shapes=2)
    result = pq.simulate(system, 6.0, n_points=4)
    pvd = write_vtu_series(result, tmp_path, name="beam", stations=5)
    parts = [(d.attrib["part"], d.attrib["file"]) for d in ET.parse(pvd).getroot().iter("DataSet")]
    assert [part for part, _ in parts] == ["0"] * 4
    beam, hub = system.subsystem("beam"), system.joints[0]
    x = np.linspace(0.0, beam.length, 5)

    def centre_line(q_e, t):
        return (beam.displacement(q_e, x) + np.outer(x, (1.0, 0.0, 0.0))) @ rotation_z(hub.angles(t)[0]).T

    first, h = None, 1e-6
    for (_, file), t, q_e, q_e_dot in zip(parts, result.t, result.q, result.s_dot):
        mesh = meshio.read(tmp_path / file)
        points = centre_line(q_e, t)
        first = points if first is None else first
        velocity = (centre_line(q_e + h * q_e_dot, t + h) - centre_line(q_e - h * q_e_dot, t - h)) / (2 * h)
        # points and displacements to 100 ε of the length (measured 1.8e-15 m; were 1e-12 of it), the
        # velocity to central differences' round-off ε·|x|/h ≈ 2e-9 (measured 1.3e-9 m/s; was 1e-6)
        exact = 100 * np.finfo(float).eps * beam.length
        np.testing.assert_allclose(mesh.points, points, rtol=0, atol=exact)
        np.testing.assert_allclose(mesh.point_data["displacement"], points - first, rtol=0, atol=exact)
        np.testing.assert_allclose(mesh.point_data["velocity"], velocity, rtol=0,
                                   atol=1e-9 * (1.0 + np.abs(velocity).max()))
        assert mesh.cells_dict["line"].tolist() == [[i, i + 1] for i in range(4)]
