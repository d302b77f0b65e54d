"""ParaView export: a VTU series that meshio reads back with the right geometry."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np

import projeq as pq
from projeq.simulation.export import write_vtu_series
from projeq.scenes.elastic import elastic_arm


def test_vtu_series_of_an_elastic_arm(tmp_path):
    """Every output time is a .vtu listed in the .pvd with its time; the beam's tip point
    read back is where the kinematics puts it (link end + beam frame · r(L)), and the
    velocity point data of the hub frame origin is zero (it sits on the fixed axis)."""
    system = elastic_arm(n_shapes=2)
    result = pq.simulate(system, 0.05, method="RK45", rtol=1e-8, atol=1e-10, n_points=3)
    pvd = write_vtu_series(result, tmp_path, name="arm", stations=5)
    files = [d.attrib["file"] for d in ET.parse(pvd).getroot().iter("DataSet")]
    times = [float(d.attrib["timestep"]) for d in ET.parse(pvd).getroot().iter("DataSet")]
    assert len(files) == 3 and np.allclose(times, result.t)
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
    assert np.allclose(mesh.points[8], expected_tip, atol=1e-12)
    assert np.allclose(mesh.point_data["velocity"][0], 0.0, atol=1e-12)
    assert mesh.cells_dict["line"].shape == (3 + 4 + 3, 2)
