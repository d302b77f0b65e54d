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
from numpy.typing import NDArray

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


def _write(path: Path, text: str) -> None:
    """``text`` (UTF-8) into the file ``path`` through :func:`written_atomically`, by the system
    calls alone (no file object: a series writes hundreds of small files)."""
    with written_atomically(path) as temporary:
        descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        try:
            data = memoryview(text.encode())
            while data:
                data = data[os.write(descriptor, data):]
        finally:
            os.close(descriptor)


VTK_LINE = 3  # the VTK cell type of a two-point line


def _numbers(values) -> str:
    """The entries of ``values``, row by row, each as the shortest text that reads back to the
    same number (``repr``)."""
    return " ".join(map(repr, np.asarray(values).ravel().tolist()))


def _opening(name: str, values, kind: str) -> str:
    """The opening tag of ``values``' ``<DataArray>`` in ASCII (rows of a 2-d array: its tuples)."""
    values = np.asarray(values)
    components = f' NumberOfComponents="{values.shape[1]}"' if values.ndim == 2 else ""
    return f'<DataArray type="{kind}" Name="{name}"{components} format="ascii">'


def _data_array(name: str, values, kind: str = "Float64") -> str:
    """One ``<DataArray>`` in ASCII: rows of ``values`` as its tuples (:func:`_numbers`)."""
    return f"{_opening(name, values, kind)}{_numbers(values)}</DataArray>\n"


class _VtuTemplate:
    """The text of a ``.vtu`` file (:func:`vtu_lines`) around the numbers of its points and
    point data: formed once for the frames of a series, which share their line cells, cell
    data and the shapes of their point arrays; :meth:`text` puts one frame's numbers in."""

    def __init__(self, points, lines, point_data: dict | None = None, cell_data: dict | None = None):
        lines = np.asarray(lines, dtype=np.int64).reshape(-1, 2)
        cell_arrays = "".join(_data_array(name, values, "Int64") for name, values in (cell_data or {}).items())
        self.parts = [
            '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt64">\n<UnstructuredGrid>\n'
            f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(lines)}">\n'
            f"<Points>\n{_opening('Points', points, 'Float64')}",
            "</DataArray>\n</Points>\n"
            f"<Cells>\n{_data_array('connectivity', lines.ravel(), 'Int64')}"
            f"{_data_array('offsets', 2 * np.arange(1, len(lines) + 1), 'Int64')}"
            f"{_data_array('types', np.full(len(lines), VTK_LINE), 'UInt8')}</Cells>\n<PointData>\n",
        ]
        for name, values in (point_data or {}).items():
            self.parts[-1] += _opening(name, values, "Float64")
            self.parts.append("</DataArray>\n")
        self.parts[-1] += f"</PointData>\n<CellData>\n{cell_arrays}</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"

    def text(self, *arrays) -> str:
        """The file with the numbers of ``arrays`` (the points, then each point data array)."""
        text = [self.parts[0]]
        for values, part in zip(arrays, self.parts[1:]):
            text += (_numbers(values), part)
        return "".join(text)


def vtu_lines(points, lines, point_data: dict | None = None, cell_data: dict | None = None) -> str:
    """The text of a ``.vtu`` file: an UnstructuredGrid of the ``points`` (n × 3) joined by line
    cells (``lines``: pairs of point numbers, VTK cell type :data:`VTK_LINE`), with
    ``point_data`` (name → n × 3 floats) and ``cell_data`` (name → one integer per line)."""
    return _VtuTemplate(points, lines, point_data, cell_data).text(points, *(point_data or {}).values())


def tree_poses(system, q, s_dot, t):
    """(tree, poses) of the model at one state: its tree moving with the tree velocities (a
    ConstrainedSystem's F ṡ + f, a System's ṡ), computed once for both parts of a frame."""
    return system.tree, poses(system.tree, q, system.tree_velocities(q, s_dot, t), t)


class Drawing:
    """What the frames of a ``tree``'s series share, formed once: the bodies' line cells (a
    deforming subsystem's centre line of ``stations`` points, every other subsystem's frame glyph
    of ``frame_size``: three segments along its axes) and the mechanism's (lines from each
    subsystem's joint to its children's joints and to its centre of mass, with the cell data
    ``body`` and ``kind``); :meth:`bodies` and :meth:`mechanism` give one frame's points."""

    def __init__(self, tree, stations: int, frame_size: float):
        self.tree, self.stations = tree, stations
        self.glyph = np.vstack((np.zeros(3), frame_size * np.eye(3)))
        lines, start = [], 0
        for sub in tree.subsystems:
            count = stations if sub.deforms else 4
            chain = [(i, i + 1) for i in range(count - 1)] if sub.deforms else [(0, 1), (0, 2), (0, 3)]
            lines.extend((start + a, start + b) for a, b in chain)
            start += count
        self.lines = np.array(lines)
        self.links, self.centres = self._skeleton(tree)

    @staticmethod
    def _skeleton(tree) -> tuple[dict, list]:
        """The mechanism's line cells {lines, body, kind} (kind 0: a line from a subsystem's joint to
        the joint of a child, 1: from its joint to its centre of mass, ``rigid_inertia``'s r_c) over
        the points [joints..., centres of mass...], and (n, r_c) of each centre of mass. Deforming
        subsystems are left to their centre lines."""
        lines, body, kind, centres = [], [], [], []
        N = len(tree.names)
        for n, sub in enumerate(tree.subsystems):
            if sub.deforms:
                continue
            for child in (c for c, p in enumerate(tree.parent) if p == n):
                lines.append((n, child)), body.append(n), kind.append(0)
            if sub.rigid_inertia is not None and np.any(sub.rigid_inertia[1] != 0):
                centres.append((n, sub.rigid_inertia[1]))
                lines.append((n, N + len(centres) - 1)), body.append(n), kind.append(1)
        return {"lines": np.array(lines, dtype=int).reshape(-1, 2), "body": np.array(body),
                "kind": np.array(kind)}, centres

    def bodies(self, kin, q) -> tuple[NDArray, NDArray]:
        """Points and velocities (inertial) of the bodies' part in the poses ``kin``
        (:func:`tree_poses`) at q."""
        points, velocities, tree = [], [], self.tree
        for n, sub in enumerate(tree.subsystems):
            if sub.deforms:
                local, local_velocity = sub.centre_line(q[tree.e_q_slice[n]], kin.y_dot[n], self.stations)
            else:
                local = self.glyph
                v_O, omega = kin.twist[n][:3], kin.twist[n][3:]
                local_velocity = v_O + cross(omega, local)
            points.append(kin.r[n] + local @ kin.R[n].T)
            velocities.append(local_velocity @ kin.R[n].T)
        return np.vstack(points), np.vstack(velocities)

    def mechanism(self, kin) -> NDArray:
        """The mechanism's points in the poses ``kin``: the joints (the subsystems' origins), then
        the centres of mass."""
        joints = [np.asarray(r, dtype=float) for r in kin.r[: len(self.tree.names)]]
        return np.vstack(joints + [kin.r[n] + kin.R[n] @ r_c for n, r_c in self.centres])


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
    and ``kind``, :class:`Drawing`), ``directory/name_bodies.csv`` (body number, subsystem
    name, joint type) and ``directory/name.pvd``, which ParaView opens as a time series of
    the two parts.

    ``system``: the model (default :func:`system_of` the result: its own, or the scene its
    run record names, so that a saved run can be exported later). Returns the ``.pvd`` path.
    """
    system = system if system is not None else system_of(result)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    drawing, entries, reference, templates = Drawing(system.tree, stations, frame_size), [], None, None
    links = drawing.links["lines"]
    for k, (model, t, q, s_dot) in enumerate(zip(system.row_models(result), result.t, result.q, result.s_dot)):
        kin = tree_poses(model, q, s_dot, t)[1]
        points, velocity = drawing.bodies(kin, q)
        reference = points if reference is None else reference
        joints = drawing.mechanism(kin) if len(links) else None
        if templates is None:  # the files' text but for the numbers, the same in every frame
            templates = (_VtuTemplate(points, drawing.lines, point_data={"displacement": points, "velocity": velocity}),
                         _VtuTemplate(joints, links, cell_data={"body": drawing.links["body"],
                                                                "kind": drawing.links["kind"]}) if len(links) else None)
        meshes = {0: (f"{name}_{k:04d}.vtu", templates[0].text(points, points - reference, velocity))}
        if len(links):
            meshes[1] = (f"{name}_mechanism_{k:04d}.vtu", templates[1].text(joints))
        for part, (file, text) in meshes.items():
            _write(directory / file, text)
            entries.append(f'    <DataSet timestep="{t:.12g}" part="{part}" file="{escape(file)}"/>')
    tree = system.tree
    _write(directory / f"{name}_bodies.csv", "body,name,joint\n" + "".join(
        f"{n},{label},{type(joint).__name__}\n" for n, (label, joint) in enumerate(zip(tree.names, tree.joints))))
    pvd = directory / f"{name}.pvd"
    _write(pvd, '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
           + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")  # last: it names only files already complete
    return pvd
