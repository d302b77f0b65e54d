"""Results for other tools: a VTU time series for ParaView (via meshio).

Each output time becomes one ``.vtu`` file with the system drawn in inertial coordinates:
beam centre lines as polylines (subsystems that ``deform``, ``centre_line``) and every other
subsystem as a small frame glyph (three line segments along its axes). Point data:
``displacement`` (from the first time) and ``velocity`` (exact, from the kinematics);
a ``.pvd`` collection file ties the steps together with their times.

Every file is written through :func:`written_atomically`: under a temporary name in its
directory, renamed when complete, so a full disk or a killed process never leaves a
truncated file under its final name.
"""

from __future__ import annotations

import os
import secrets
from contextlib import contextmanager
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
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


def _draw(system, q, s_dot, t, stations: int, frame_size: float):
    """Points, velocities (inertial) and line cells of the model at one state: its tree
    moving with the tree velocities (a ConstrainedSystem's F ṡ + f, a System's ṡ)."""
    system, s_dot = system.tree, system.tree_velocities(q, s_dot, t)
    kin = poses(system, q, s_dot, t)
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


def write_vtu_series(result, directory, name: str = "projeq", stations: int = 21, frame_size: float = 0.1) -> Path:
    """Write ``result`` as ``directory/name_####.vtu`` files and ``directory/name.pvd``.

    Needs ``result.system`` (a Result returned by :func:`projeq.simulate`). Returns the
    path of the ``.pvd`` file, which ParaView opens as a time series.
    """
    system = result.system
    if system is None:
        raise ValueError("result: has no system (loaded from a file?); export a Result from simulate()")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    entries, reference = [], None
    for k, (model, t, q, s_dot) in enumerate(zip(system.row_models(result), result.t, result.q, result.s_dot)):
        points, velocity, lines = _draw(model, q, s_dot, t, stations, frame_size)
        reference = points if reference is None else reference
        path = directory / f"{name}_{k:04d}.vtu"
        mesh = meshio.Mesh(points, [("line", lines)], point_data={"displacement": points - reference, "velocity": velocity})
        with written_atomically(path) as temporary:
            mesh.write(temporary)
        entries.append(f'    <DataSet timestep="{t:.12g}" part="0" file={quoteattr(path.name)}/>')
    pvd = directory / f"{name}.pvd"
    with written_atomically(pvd) as temporary:  # last: it names only files already complete
        temporary.write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            + "\n".join(entries)
            + "\n  </Collection>\n</VTKFile>\n"
        )
    return pvd
