"""A System from a URDF robot description: ``from_urdf(path, flexible={"link": RitzBeam(...)})``.

The file is read by yourdfpy (``pip install "projeq[urdf]"``; it brings trimesh and lxml, which
are heavy, hence an extra). Each link becomes a subsystem of the same name: a RigidBody with the
mass, the mass centre and the inertia tensor of its ``<inertial>`` element (the tensor given in
the inertial frame, turned into link coordinates, I_c = R I Rᵀ), a massless Frame where it has no
mass, or the subsystem the user puts in its place (``flexible``). Each joint becomes the joint of
its child link: its ``<origin>`` (xyz, rpy: R = R_z(yaw) R_y(pitch) R_x(roll)) is the joint
frame's placement on the parent link (``r_pn``, ``orientation``), its ``<axis>`` the axis in that
frame; revolute and continuous joints are Revolutes, prismatic ones Prismatics, fixed ones Fixed,
floating ones Free. The root link is fixed to the ground. A link's visual boxes, cylinders and
spheres (with their origins) become its subsystem's ``visuals`` (:class:`projeq.subsystems.Visual`),
which the viewer draws (``Result.animate``, ``projeq view``) instead of the solid of its inertia;
visual meshes are not read (a link drawn by meshes alone is drawn as the solid of its inertia).
What the equations of motion and the viewer do not use — joint limits, dynamics (damping,
friction), mimic tags, safety controllers, collision geometry, visual meshes — is reported in one
warning listing it.
"""

from __future__ import annotations

import os
import warnings
from xml.etree import ElementTree

import numpy as np

from projeq.joints import Fixed, Free, Prismatic, Revolute
from projeq.subsystems import Frame, RigidBody, Visual
from projeq.system import System

#: URDF joint types and the projeq joint that moves the same way (given its frame and axis)
JOINT_TYPES = {"revolute": Revolute, "continuous": Revolute, "prismatic": Prismatic}


class IgnoredWarning(UserWarning):
    """Parts of a URDF file that the equations of motion do not use (limits, geometry, ...)."""


def from_urdf(path, flexible: dict | None = None, gravity=(0.0, 0.0, -9.81)) -> System:
    """The System of the robot described in the URDF file at ``path``.

    Parameters
    ----------
    path : str or path-like
        The URDF file (meshes it names are not read).
    flexible : dict, optional
        ``{link name: subsystem}``: a subsystem (e.g. a :class:`projeq.RitzBeam`) that replaces
        the link's rigid body, attached at the link's frame by the link's joint.
    gravity : 3-vector
        Gravity in the root link's (ground) coordinates, m/s² (URDF's convention: z up).

    Returns
    -------
    System
        Subsystems named by the links, in the order of a walk from the root; coordinates
        ``"<link>.angle"`` (revolute), ``"<link>.position"`` (prismatic).
    """
    robot = _read(path)
    links = {link.name: link for link in robot.links}
    flexible = dict(flexible or {})
    unknown = sorted(set(flexible) - set(links))
    if unknown:
        raise ValueError(f"flexible: no link named {unknown} in {os.fspath(path)!r}; its links are {sorted(links)}")
    by_child = {joint.child: joint for joint in robot.joints}
    roots = [name for name in links if name not in by_child]
    if len(roots) != 1:
        raise ValueError(f"path: {os.fspath(path)!r} describes {len(roots)} trees (roots {roots}); expected one robot")
    subsystems, joints = {}, {}
    for name in _walk(roots[0], robot.joints):
        subsystems[name] = flexible[name] if name in flexible else _body(links[name])
        joints[name] = Fixed() if name == roots[0] else _joint(by_child[name])
    _report_ignored(robot, path)
    return System(subsystems, joints, gravity=gravity)


def _read(path):
    """The URDF model by yourdfpy, without meshes; ValueError for a missing or malformed file."""
    try:
        import yourdfpy
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError('from_urdf reads URDF files with yourdfpy: pip install "projeq[urdf]"') from None
    if not os.path.isfile(path):
        raise ValueError(f"path: no URDF file at {os.fspath(path)!r}")
    try:  # well-formed XML first: yourdfpy recovers from a broken file by guessing
        ElementTree.parse(path)
    except ElementTree.ParseError as exc:
        raise ValueError(f"path: {os.fspath(path)!r} is not well-formed XML: {exc}") from exc
    try:
        return yourdfpy.URDF.load(os.fspath(path), build_scene_graph=False, build_collision_scene_graph=False,
                                  load_meshes=False, load_collision_meshes=False).robot
    except Exception as exc:  # noqa: BLE001 — yourdfpy's and lxml's errors, each named
        raise ValueError(f"path: cannot read {os.fspath(path)!r} as URDF: {type(exc).__name__}: {exc}") from exc


def _walk(root: str, urdf_joints) -> list[str]:
    """The link names, parents before children (breadth first from the root, in file order)."""
    children = {}
    for joint in urdf_joints:
        children.setdefault(joint.parent, []).append(joint.child)
    order, queue = [], [root]
    while queue:
        name = queue.pop(0)
        order.append(name)
        queue += children.get(name, [])
    return order


def _body(link):
    """A RigidBody of the link's inertial element (a Frame where it has none, or no mass), drawn
    by the link's visual primitives."""
    inertial = link.inertial
    if inertial is None or not inertial.mass:
        body = Frame()
    else:
        pose = np.eye(4) if inertial.origin is None else np.asarray(inertial.origin, float)
        R = pose[:3, :3]
        inertia = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia, float)
        body = RigidBody(float(inertial.mass), r_c=pose[:3, 3], I_c=R @ inertia @ R.T)
    body.visuals = _visuals(link)
    return body


def _visuals(link) -> tuple:
    """The link's visual primitives (box, cylinder, sphere) placed by their origins; meshes are
    left out (reported by :func:`_report_ignored`)."""
    visuals = []
    for visual in link.visuals:
        geometry = visual.geometry
        origin = np.eye(4) if visual.origin is None else np.asarray(visual.origin, float)
        if geometry is None:
            continue
        if geometry.box is not None:
            visuals.append(Visual("box", tuple(geometry.box.size), origin))
        elif geometry.cylinder is not None:
            visuals.append(Visual("cylinder", (geometry.cylinder.radius, geometry.cylinder.length), origin))
        elif geometry.sphere is not None:
            visuals.append(Visual("sphere", (geometry.sphere.radius,), origin))
    return tuple(visuals)


def _joint(joint):
    """The projeq joint of a URDF joint, placed by its origin, about or along its axis."""
    pose = np.eye(4) if joint.origin is None else np.asarray(joint.origin, float)
    place = {"parent": joint.parent, "r_pn": pose[:3, 3], "orientation": pose[:3, :3]}
    if joint.type == "fixed":
        return Fixed(**place)
    if joint.type == "floating":
        return Free(**place)
    if joint.type not in JOINT_TYPES:
        raise ValueError(f"path: joint {joint.name!r} is of type {joint.type!r}; from_urdf reads "
                         f"{sorted([*JOINT_TYPES, 'fixed', 'floating'])}")
    axis = (1.0, 0.0, 0.0) if joint.axis is None else joint.axis  # URDF's default axis
    return JOINT_TYPES[joint.type](axis=axis, **place)


def _report_ignored(robot, path) -> None:
    """One IgnoredWarning listing what the file states and neither the equations of motion nor
    the viewer use."""
    parts = {
        "joint limits": [j.name for j in robot.joints if j.limit is not None],
        "joint dynamics (damping, friction)": [j.name for j in robot.joints if j.dynamics is not None],
        "mimic joints": [j.name for j in robot.joints if j.mimic is not None],
        "safety controllers": [j.name for j in robot.joints if j.safety_controller is not None],
        "collision geometry": [link.name for link in robot.links if link.collisions],
        "visual meshes (drawn as the solid of the inertia)": [
            link.name for link in robot.links
            if any(v.geometry is not None and v.geometry.mesh is not None for v in link.visuals)],
        "transmissions": [t.name for t in robot.transmission],
    }
    found = [f"{what} ({len(names)}: {', '.join(names[:4])}{', …' if len(names) > 4 else ''})"
             for what, names in parts.items() if names]
    if found:
        warnings.warn(f"from_urdf: {os.fspath(path)!r}: ignored (not part of the equations of motion): "
                      + "; ".join(found), IgnoredWarning, stacklevel=3)
