"""Coordinates by name: what joints and subsystems declare, the Model's names, states set by
name, the tree's order (the declared one whenever parents come first), names in Results."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq import plots
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.simulation.integrators import conserves_energy


def rod():
    return pq.RigidBody(1.0, (0.5, 0, 0), np.diag([1e-4, 1 / 12, 1 / 12]))


def test_the_joints_and_a_beam_name_their_coordinates_with_units():
    system = pq.System(
        {"base": pq.Frame(), "slider": pq.Frame(), "arm": rod(),
         "beam": pq.RitzBeam(1.0, rho_A=1.0, EI_z=10.0, n_v=2, n_w=1)},
        {"base": pq.Free(), "slider": pq.Prismatic(parent="base", axis="x"),
         "arm": pq.Revolute(parent="slider", axis="z"), "beam": pq.Revolute(parent="arm", axis="z")})
    names = [name for name, _ in system.coordinates()]
    assert names == ["base.r_x", "base.r_y", "base.r_z", "base.quat_w", "base.quat_x", "base.quat_y", "base.quat_z",
                     "slider.position", "arm.angle", "beam.angle", "beam.v[0]", "beam.v[1]", "beam.w[0]"]
    assert dict(system.coordinates())["beam.v[1]"] == "m" and dict(system.coordinates())["arm.angle"] == "rad"
    velocities = dict(system.velocities())
    assert len(velocities) == system.n_s and velocities["base.omega_z"] == "rad/s"
    assert velocities["beam.w[0]_dot"] == "m/s" and velocities["slider.position_dot"] == "m/s"


def test_user_joints_and_duck_typed_subsystems_get_defaults():
    """A UserJoint from sympy is named by its symbols, one from callables q[i]/s_dot[i];
    a subsystem that does not subclass Subsystem gets e[i]."""
    import sympy as sp

    x, u = sp.symbols("x u")
    joint = pq.UserJoint.from_sympy([x], [u], sp.eye(3), sp.Matrix([x, 0, 0]), sp.Matrix([1, 0, 0, 0, 0, 0]),
                                    sp.Matrix([[1]]))
    system = pq.System({"cart": pq.PointMass(1.0)}, {"cart": joint})
    assert system.coordinates() == (("cart.x", ""),) and system.velocities() == (("cart.u", ""),)
    assert pq.Joint().coordinates() == () and pq.Revolute().velocities() == (("angle_dot", "rad/s"),)


def test_a_state_by_name():
    system = pq.scenes.chain(3)
    q0, s_dot0 = system.state(link2=0.2, q={"link3.angle": -0.1}, s_dot={"link1": 1.5})
    assert q0.tolist() == [0.5, 0.2, -0.1] and s_dot0.tolist() == [1.5, 0.0, 0.0]
    with pytest.raises(ValueError, match=r"elbow: no entry of q has that name; valid are the subsystems "
                                         r"\['link1', 'link2', 'link3'\]"):
        system.state(elbow=0.3)
    with pytest.raises(ValueError, match=r"s_dot\['link1'\] \(link1.angle_dot\): expected 1 entries"):
        system.state(s_dot={"link1": [1.0, 2.0]})
    assert system.q_index("link2.angle") == 1 and system.q_index("link3") == slice(2, 3)


def test_a_constrained_systems_velocities_are_its_partitions():
    four_bar = pq.scenes.four_bar()
    assert four_bar.velocities() == (("crank.angle_dot", "rad/s"),)
    assert four_bar.with_independent([1]).velocities() == (("rocker.angle_dot", "rad/s"),)
    q0, s_dot0 = four_bar.state(s_dot={"crank": 2.0})
    assert np.array_equal(q0, four_bar.q0) and s_dot0.tolist() == [2.0]
    with pytest.raises(ValueError, match="rocker.angle_dot: no entry of s_dot"):
        four_bar.state(s_dot={"rocker.angle_dot": 1.0})


def test_the_tree_keeps_the_declared_order_when_parents_come_first():
    """Roots and children interleaved (crank, its coupler, then the rocker on the ground): q is
    in that order; a child declared before its parent is moved, with a warning naming the
    order, and a constraint by q_index reads the same entries either way."""
    joints = {"crank": pq.Revolute(axis="z"), "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(0.3, 0, 0)),
              "rocker": pq.Revolute(axis="z", r_pn=(1.0, 0, 0))}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tree = pq.System(dict.fromkeys(joints, rod()), joints)
    assert tree.names == ("crank", "coupler", "rocker")
    backwards = {name: joints[name] for name in ("coupler", "crank", "rocker")}
    with pytest.warns(UserWarning, match=r"follow the subsystems parents first, \['crank', 'coupler', 'rocker'\], "
                                         r"not in the declared order \['coupler', 'crank', 'rocker'\]"):
        moved = pq.System({name: rod() for name in backwards}, backwards)
    assert moved.names == tree.names and moved.coordinates() == tree.coordinates()


def test_a_result_carries_the_names_and_keeps_them_in_its_file(tmp_path):
    system = pq.scenes.elastic_arm(n_shapes=2)
    result = pq.simulate(system, 0.02, n_points=3)
    assert result.coordinates == system.coordinates() and result.velocities == system.velocities()
    result.save(tmp_path / "arm.npz")
    loaded = pq.Result.load(tmp_path / "arm.npz")
    assert loaded.coordinates == result.coordinates and loaded.column_names(units=True)[0][0] == "link1.angle (rad)"


def test_plots_group_by_kind_and_draw_the_drift_panel_only_with_constraints():
    """elastic_arm: joint angles (rad) and elastic coordinates (m) on separate axes, then their
    velocities; its drift figure has no constraint panel. The car (rear-axle constraint) has one,
    its axis floored at round-off."""
    system = pq.scenes.elastic_arm(n_shapes=2)
    result = pq.simulate(system, 0.02, n_points=3)
    fig = plots.grouped_history(result)
    labels = [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel()]
    assert labels == ["joint angles\n(rad)", "elastic coordinates\n(m)", "angular velocities\n(rad/s)",
                      "elastic velocities\n(m/s)"]
    axes = [ax for ax in fig.axes if ax.get_ylabel()]
    assert [t.get_text() for t in axes[0].get_legend().get_texts()] == ["link1.angle", "beam.angle"]
    assert len(plots.drift(result).axes) == 1
    car = pq.simulate(pq.scenes.car(), 0.2, n_points=5)
    assert plots.drift(car).axes[1].get_ylim()[0] == plots.ROUND_OFF


def test_conserves_energy_tells_a_driven_model_from_a_free_one():
    """The free double pendulum conserves T + V; the spin-up beam's hub is driven (prescribed)."""
    pendulum, beam = pq.scenes.double_pendulum(), pq.scenes.spin_up_beam()
    assert conserves_energy(pendulum, pendulum.q0, pendulum.s_dot0)
    assert not conserves_energy(beam, beam.q0, beam.s_dot0)


def test_initial_states_and_sweep_outputs_by_name(tmp_path):
    """A System's q0 and s_dot0 as dicts by name; a sweep's outputs by name are the final
    values of those columns (the same as q<i> / s_dot<i>)."""
    from projeq.simulation.sweep import sweep

    system = pq.System({"a": rod(), "b": rod()},
                       {"a": pq.Revolute(axis="y"), "b": pq.Revolute(parent="a", axis="y", r_pn=(1, 0, 0))},
                       q0={"b.angle": 0.4}, s_dot0={"a": 1.0})
    assert system.q0.tolist() == [0.0, 0.4] and system.s_dot0.tolist() == [1.0, 0.0]
    table = sweep("double_pendulum", grid={"l1": [0.5, 1.0]}, outputs=["bob2.angle_dot", "s_dot1"], t_end=0.05,
                  workers=1, progress=False)
    assert np.array_equal(table["bob2.angle_dot"], table["s_dot1"]) and np.all(table["status"] == 0)
    with pytest.raises(ValueError, match="no coordinate or velocity 'elbow.angle'"):
        sweep("double_pendulum", grid={"l1": [0.5]}, outputs=["elbow.angle"], progress=False)
