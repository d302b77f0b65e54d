"""Results for other tools: a VTU time series for ParaView.

Each output time becomes two ``.vtu`` files in inertial coordinates. The bodies: beam centre
lines as polylines (subsystems that ``deform``, ``centre_line``) and every other subsystem
as a small frame glyph (three line segments along its axes), with the point data
``displacement`` (from the first time) and ``velocity`` (exact, from the kinematics). The
mechanism: a line from each subsystem's joint to its children's joints and to its centre of
mass, with the cell data ``body`` (numbers named in ``<name>_bodies.csv``). A ``.pvd``
collection file ties the steps together with their times. :func:`system_of` rebuilds the
model of a Result loaded from a file from its run record, so a saved run can be exported.
The files are VTK's XML UnstructuredGrid format in ASCII (:func:`vtu_lines`; Kitware, "VTK
File Formats", The VTK User's Guide, 11th ed., 2010, ch. 19), written here directly: a mesh of
line cells needs no mesh library, and ``projeq run`` does not pay for importing one.

Every file is written through :func:`written_atomically`: under a temporary name in its
directory, renamed when complete, so a full disk or a killed process never leaves a
truncated file under its final name.
"""

from __future__ import annotations

import os
import secrets
from contextlib import contextmanager
from pathlib import Path
from html import escape

import numpy as np

from projeq.assembly.kinematics import poses
from projeq.spatial import cross


@contextmanager
def written_atomically(path):
    """Yield a temporary path beside ``path`` (same directory and suffix, so writers that go
    by the suffix still work) for the caller to write; when the block ends without an error
    the file is renamed to ``path`` (``os.replace``, atomic on POSIX), else it is deleted.
    Readers thus see the old file or the complete new one, never a truncated one."""
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}-{secrets.token_hex(3)}.tmp{path.suffix}")
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


VTK_LINE = 3  # the VTK cell type of a two-point line


def _data_array(name: str, values, kind: str = "Float64") -> str:
    """One ``<DataArray>`` in ASCII: rows of ``values`` as its tuples, each number as the
    shortest text that reads back to the same float (``repr``)."""
    values = np.asarray(values)
    components = f' NumberOfComponents="{values.shape[1]}"' if values.ndim == 2 else ""
    text = " ".join(map(repr, values.ravel().tolist()))
    return f'<DataArray type="{kind}" Name="{name}"{components} format="ascii">{text}</DataArray>\n'


def vtu_lines(points, lines, point_data: dict | None = None, cell_data: dict | None = None) -> str:
    """The text of a ``.vtu`` file: an UnstructuredGrid of the ``points`` (n × 3) joined by line
    cells (``lines``: pairs of point numbers, VTK cell type :data:`VTK_LINE`), with
    ``point_data`` (name → n × 3 floats) and ``cell_data`` (name → one integer per line)."""
    lines = np.asarray(lines, dtype=np.int64).reshape(-1, 2)
    point_arrays = "".join(_data_array(name, values) for name, values in (point_data or {}).items())
    cell_arrays = "".join(_data_array(name, values, "Int64") for name, values in (cell_data or {}).items())
    return (
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n<UnstructuredGrid>\n'
        f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(lines)}">\n'
        f"<Points>\n{_data_array('Points', points)}</Points>\n"
        f"<Cells>\n{_data_array('connectivity', lines.ravel(), 'Int64')}"
        f"{_data_array('offsets', 2 * np.arange(1, len(lines) + 1), 'Int64')}"
        f"{_data_array('types', np.full(len(lines), VTK_LINE), 'UInt8')}</Cells>\n"
        f"<PointData>\n{point_arrays}</PointData>\n<CellData>\n{cell_arrays}</CellData>\n"
        "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
    )


def _tree_poses(system, q, s_dot, t):
    """(tree, poses) of the model at one state: its tree moving with the tree velocities (a
    ConstrainedSystem's F ṡ + f, a System's ṡ), computed once for both parts of a frame."""
    return system.tree, poses(system.tree, q, system.tree_velocities(q, s_dot, t), t)


def _draw(system, kin, q, stations: int, frame_size: float):
    """Points, velocities (inertial) and line cells of the ``system`` (a tree) in the poses
    ``kin`` (:func:`_tree_poses`)."""
    points, velocities, lines = [], [], []
    for n, sub in enumerate(system.subsystems):
        if sub.deforms:
            local, local_velocity = sub.centre_line(q[system.e_q_slice[n]], kin.y_dot[n], stations)
            chain = [(i, i + 1) for i in range(len(local) - 1)]
        else:
            local = np.vstack((np.zeros(3), frame_size * np.eye(3)))
            v_O, omega = kin.twist[n][:3], kin.twist[n][3:]
            local_velocity = v_O + cross(omega, local)
            chain = [(0, 1), (0, 2), (0, 3)]
        start = sum(len(p) for p in points)
        points.append(kin.r[n] + local @ kin.R[n].T)
        velocities.append(local_velocity @ kin.R[n].T)
        lines.extend((start + a, start + b) for a, b in chain)
    return np.vstack(points), np.vstack(velocities), np.array(lines)


def _skeleton(tree, kin):
    """Points and line cells of the mechanism at one state, with the cell data ``body`` (the
    subsystem's number in ``system.names``) and ``kind``: 0 a line from a subsystem's joint
    to the joint of a child, 1 from its joint to its centre of mass (rigid bodies: from
    ``rigid_inertia``). Deforming subsystems are left to their centre lines (:func:`_draw`);
    ``tree`` and ``kin`` as :func:`_draw`'s."""
    points, lines, body, kind = [np.asarray(r, dtype=float) for r in kin.r[: len(tree.names)]], [], [], []
    for n, sub in enumerate(tree.subsystems):
        if sub.deforms:
            continue
        for child in (c for c, p in enumerate(tree.parent) if p == n):
            lines.append((n, child)), body.append(n), kind.append(0)
        if sub.rigid_inertia is not None and np.any(sub.rigid_inertia[1] != 0):
            points.append(kin.r[n] + kin.R[n] @ sub.rigid_inertia[1])
            lines.append((n, len(points) - 1)), body.append(n), kind.append(1)
    return np.vstack(points), np.array(lines, dtype=int).reshape(-1, 2), np.array(body), np.array(kind)


def system_of(result):
    """The model of ``result``: ``result.system`` (a Result from :func:`projeq.simulate`), or
    for a Result loaded from a file the scene its run record names, built again with the
    recorded parameters (``result.metadata``, written by ``projeq run``); ValueError when
    neither is there."""
    if result.system is not None:
        return result.system
    record = result.metadata or {}
    if "scene" not in record:
        raise ValueError("result: has no system and no run record naming its scene (saved by an earlier version, "
                         "or by Result.save without metadata); export a Result from simulate()")
    from projeq.scenes import resolve_scene

    try:
        return resolve_scene(record["scene"]).build(**record.get("parameters", {}))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"result: cannot rebuild its scene {record['scene']!r} from the recorded parameters: {exc}") from None


def write_vtu_series(result, directory, name: str = "projeq", stations: int = 21, frame_size: float = 0.1,
                     system=None) -> Path:
    """Write ``result`` as ``directory/name_####.vtu`` files (the bodies: beam centre lines,
    frame glyphs), ``directory/name_mechanism_####.vtu`` (the mechanism: lines joining each
    subsystem's joint to its children's joints and to its centre of mass, cell data ``body``
    and ``kind``, :func:`_skeleton`), ``directory/name_bodies.csv`` (body number, subsystem
    name, joint type) and ``directory/name.pvd``, which ParaView opens as a time series of
    the two parts.

    ``system``: the model (default :func:`system_of` the result: its own, or the scene its
    run record names, so that a saved run can be exported later). Returns the ``.pvd`` path.
    """
    system = system if system is not None else system_of(result)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    entries, reference = [], None
    for k, (model, t, q, s_dot) in enumerate(zip(system.row_models(result), result.t, result.q, result.s_dot)):
        tree, kin = _tree_poses(model, q, s_dot, t)
        points, velocity, lines = _draw(tree, kin, q, stations, frame_size)
        reference = points if reference is None else reference
        meshes = {0: (f"{name}_{k:04d}.vtu", vtu_lines(points, lines, point_data={
            "displacement": points - reference, "velocity": velocity}))}
        joints, links, body, kind = _skeleton(tree, kin)
        if len(links):
            meshes[1] = (f"{name}_mechanism_{k:04d}.vtu", vtu_lines(joints, links, cell_data={"body": body, "kind": kind}))
        for part, (file, text) in meshes.items():
            with written_atomically(directory / file) as temporary:
                temporary.write_text(text)
            entries.append(f'    <DataSet timestep="{t:.12g}" part="{part}" file="{escape(file)}"/>')
    tree = system.tree
    with written_atomically(directory / f"{name}_bodies.csv") as temporary:
        temporary.write_text("body,name,joint\n" + "".join(
            f"{n},{label},{type(joint).__name__}\n" for n, (label, joint) in enumerate(zip(tree.names, tree.joints))))
    pvd = directory / f"{name}.pvd"
    with written_atomically(pvd) as temporary:  # last: it names only files already complete
        temporary.write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            + "\n".join(entries)
            + "\n  </Collection>\n</VTKFile>\n"
        )
    return pvd
