"""The motion of a Result to look at: one self-contained HTML page (three.js), a GIF or an MP4.

:func:`animate` writes by the file's suffix. The page (:func:`write_html`) plays the run in any
browser, offline: three.js (a pinned release, ``THREE_VERSION``, MIT licence, shipped with projeq in
``projeq/simulation/viewer/``) and the motion's numbers are inlined. A subsystem with ``visuals``
(:class:`projeq.subsystems.Visual`: boxes, cylinders, spheres, as :func:`projeq.from_urdf` reads
them from a URDF link) is drawn by them; other rigid bodies as the homogeneous box or cylinder of
the same mass and central inertia (:func:`equivalent_shape`; a planar body as a plate in its plane,
:func:`planar_shape`; a point mass as a small sphere), beams as tubes along their deformed centre
lines (the shape functions' field, :meth:`~projeq.subsystems.beam.RitzBeam.centre_line`), the
mechanism as thin rods from each joint to its children's joints and to its centre of mass, and each
subsystem's frame (at its joint) as axes that a checkbox shows. The poses are the ParaView export's
(:class:`projeq.simulation.export.Drawing`, :func:`~projeq.simulation.export.system_of`): a Result
loaded from a file is drawn with the scene its run record names.

A GIF (matplotlib's ``PillowWriter``) or MP4 (``FFMpegWriter``, where ffmpeg is found) shows the
same geometry projected on the viewing plane, for papers and slides.
"""

from __future__ import annotations

import json
import re
from importlib.resources import files
from pathlib import Path
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from projeq.simulation.export import Drawing, system_of, tree_poses, written_atomically
from projeq.subsystems import PlanarBody

THREE_VERSION = "0.170.0"  # npm's three@0.170.0, build/three.module.min.js: the last single-file module build
COLORS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7", "#9c755f")
SUFFIXES = (".html", ".gif", ".mp4")


class Shape(NamedTuple):
    """A homogeneous solid in a body's frame: ``kind`` ``"box"`` (size: edges along its axes x, y,
    z), ``"cylinder"`` (size: radius, length along its axis y, three.js's) or ``"sphere"`` (size:
    radius); ``rotation``: its axes in the body's frame (columns), the solid centred at r_c."""

    kind: str
    size: tuple
    rotation: NDArray


def equivalent_shape(m: float, I_c, symmetric: float = 1e-3) -> Shape:
    """The homogeneous box or cylinder of mass ``m`` whose inertia about its centre is ``I_c``.

    The principal moments λ and axes of I_c (``numpy.linalg.eigh``) invert the formulas of
    :mod:`projeq.subsystems.inertia`: a body with two moments equal to within ``symmetric``
    (relative) is a cylinder about the third axis, ½ m r² = λ_axis and m (3r² + ℓ²)/12 =
    λ_across; three equal moments give the sphere ⅖ m r² = λ; else a box of edges e_i with
    e_i² = 6 (λ_j + λ_k − λ_i)/m. Moments that no solid of positive size has (a thin disk's
    λ_axis = 2 λ_across, a rod's zero axial moment) are drawn with a thickness of 5 % of the
    largest size. ValueError for m ≤ 0 or an I_c that is not a symmetric 3 × 3 matrix with
    positive moments."""
    I_c = np.asarray(I_c, dtype=float)
    symmetric_3x3 = I_c.shape == (3, 3) and np.allclose(I_c, I_c.T, rtol=0, atol=1e-12 * np.abs(I_c).max())
    if not m > 0 or not symmetric_3x3:
        raise ValueError(f"I_c: expected a symmetric 3 x 3 inertia tensor and m > 0, got m = {m}, "
                         f"I_c = {I_c.tolist()}")
    lam, V = np.linalg.eigh(I_c)
    if not lam[2] > 0 or lam[0] < -1e-12 * lam[2]:
        raise ValueError(f"I_c: principal moments {lam.tolist()} (expected ≥ 0, not all zero)")
    V = V * np.sign(np.linalg.det(V))  # a rotation
    equal = np.isclose(lam[:, None], lam[None, :], rtol=symmetric, atol=0.0)
    if equal.all():
        return Shape("sphere", (float(np.sqrt(2.5 * lam.mean() / m)),), np.eye(3))
    if equal[0, 1] or equal[1, 2]:
        axis = 2 if equal[0, 1] else 0
        across = lam[[i for i in range(3) if i != axis]].mean()
        r2, l2 = 2.0 * lam[axis] / m, 12.0 * across / m
        r = np.sqrt(max(r2, 0.025**2 * l2))  # a rod without axial moment: a radius of 2.5 % of its length
        length = np.sqrt(max(l2 - 3.0 * r * r, (0.05 * r) ** 2))
        order = [(axis + 2) % 3, axis, (axis + 1) % 3]  # the symmetry axis as y, an even permutation
        return Shape("cylinder", (float(r), float(length)), V[:, order])
    edges2 = 6.0 * (lam.sum() - 2.0 * lam) / m
    edges = np.sqrt(np.maximum(edges2, (0.05 * np.sqrt(edges2.max())) ** 2))
    return Shape("box", tuple(float(e) for e in edges), V)


def _quaternions(R: NDArray) -> NDArray:
    """(x, y, z, w) of the rotation matrices ``R`` (…, 3, 3), three.js's order, each of the sign
    nearest the previous one along the first axis (so that interpolating takes the short way)."""
    from scipy.spatial.transform import Rotation

    shape = R.shape[:-2]
    quat = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat().reshape(*shape, 4)
    if quat.ndim == 3:  # (time, body, 4): continuity in time
        for k in range(1, len(quat)):
            flip = np.sum(quat[k] * quat[k - 1], axis=-1) < 0
            quat[k, flip] *= -1
    return quat


def planar_shape(body: PlanarBody) -> Shape:
    """A plate in the plane of a :class:`projeq.PlanarBody` whose moment about the plane's normal
    is the body's, I_n (the only moment of inertia its motion knows): a bar along the in-plane
    part of r_c (joint → mass centre), as wide and thick as a tenth of its length ℓ, where r_c
    has one, m (ℓ² + (ℓ/10)²)/12 = I_n; else a square plate of edge a, a tenth as thick,
    m (a² + a²)/12 = I_n (:func:`projeq.subsystems.inertia.box`)."""
    m, r_c = body.m, body.r_c
    normal = np.eye(3)[{"xy": 2, "yz": 0, "zx": 1, "xz": 1}[body.plane]]
    I_n = normal @ body.I_c @ normal
    along = r_c - (r_c @ normal) * normal
    if np.linalg.norm(along) > 1e-9 * np.sqrt(I_n / m):
        length = np.sqrt(12.0 * I_n / (1.01 * m))
        size = (length, 0.1 * length, 0.1 * length)
    else:
        along, edge = np.roll(normal, 1), np.sqrt(6.0 * I_n / m)
        size = (edge, edge, 0.1 * edge)
    along = along / np.linalg.norm(along)
    rotation = np.column_stack((along, np.cross(normal, along), normal))
    return Shape("box", tuple(float(e) for e in size), rotation)


def _visual_shape(visual) -> tuple[Shape, NDArray]:
    """(Shape, centre) of a :class:`projeq.subsystems.Visual`: URDF's cylinder along its z is
    three.js's along y (the axes turned cyclically, a rotation)."""
    rotation = visual.origin[:3, :3]
    if visual.kind == "cylinder":
        rotation = rotation[:, [1, 2, 0]]
    return Shape(visual.kind, visual.size, rotation), visual.origin[:3, 3]


def _inertia_shape(sub, scale: float, heaviest: float) -> tuple[Shape, NDArray] | None:
    """(Shape, centre) of a rigid subsystem's inertia (a PlanarBody's plate, :func:`planar_shape`;
    a point mass as a sphere of 4 % of ``scale`` by the cube root of its share of the largest
    mass; else :func:`equivalent_shape`), None for a massless one."""
    m, r_c, I_c = sub.rigid_inertia
    if not m > 0:
        return None
    if np.abs(I_c).max() <= 1e-12 * m * scale**2:
        return Shape("sphere", (0.04 * scale * (m / heaviest) ** (1 / 3),), np.eye(3)), r_c
    if isinstance(sub, PlanarBody):
        return planar_shape(sub), r_c
    return equivalent_shape(m, I_c), r_c


def _shapes(tree, scale: float) -> list[dict]:
    """The solids of the tree's rigid subsystems in their frames: a subsystem's ``visuals``
    (:class:`projeq.subsystems.Visual`, URDF's primitives) where it has them, else the solid of
    its inertia (:func:`_inertia_shape`); massless frames without visuals and deforming
    subsystems have none."""
    rigid = [(n, sub) for n, sub in enumerate(tree.subsystems) if not sub.deforms
             and (sub.visuals or sub.rigid_inertia is not None)]
    heaviest = max((sub.rigid_inertia[0] for _, sub in rigid if sub.rigid_inertia is not None), default=1.0)
    shapes = []
    for n, sub in rigid:
        solids = [_visual_shape(v) for v in sub.visuals] or [_inertia_shape(sub, scale, heaviest)]
        shapes += [{"frame": n, "kind": shape.kind, "size": list(shape.size),
                    "position": np.asarray(centre, dtype=float).tolist(),
                    "quaternion": _quaternions(shape.rotation).tolist(), "color": COLORS[n % len(COLORS)]}
                   for shape, centre in filter(None, solids)]
    return shapes


def _view(points: NDArray, up: NDArray) -> NDArray:
    """The direction from the scene to the camera: the points' direction of least spread (the
    normal of a planar motion), turned 30° about ``up`` and raised 20° above the horizon."""
    centred = points - points.mean(axis=0)
    normal = np.linalg.svd(centred[:: max(1, len(centred) // 4000)], full_matrices=False)[2][-1]
    normal = normal - normal.dot(up) * up
    if np.linalg.norm(normal) < 1e-6:  # the motion's plane is horizontal: look from the side
        normal = np.cross(up, np.eye(3)[np.argmin(np.abs(up))])
    normal /= np.linalg.norm(normal)
    side = np.cross(up, normal)
    a, e = np.radians(30.0), np.radians(20.0)
    return np.cos(e) * (np.cos(a) * normal + np.sin(a) * side) + np.sin(e) * up


def motion(result, system=None, stations: int = 21) -> dict:
    """What the page and the movies draw, for each output time of ``result`` (in the model
    ``system``, default :func:`~projeq.simulation.export.system_of` the result): the poses of the
    subsystems' frames (x, y, z and quaternion x, y, z, w), the beams' centre lines (``stations``
    points each), the mechanism's points and links, the solids, the direction "up" (against
    gravity, else z), the camera's direction and distance (3.2 times the mechanism's size when
    the camera follows it, else 2.4 times the whole motion's: a field of view of 35° with a
    margin), the centre of the points per time
    (the camera follows it when it travels more than the mechanism's size, else it looks at the
    centre of the box around the whole motion, ``target``) and the ground grid."""
    if not isinstance(stations, (int, np.integer)) or stations < 2:
        raise ValueError(f"stations: expected an integer ≥ 2 points along each beam, got {stations!r}")
    if len(result.t) == 0:
        raise ValueError("result: has no output rows; there is no motion to draw")
    system = system if system is not None else system_of(result)
    tree = system.tree
    drawing = Drawing(tree, stations, 0.0)
    deforming = [n for n, sub in enumerate(tree.subsystems) if sub.deforms]
    starts = np.cumsum([0] + [stations if sub.deforms else 4 for sub in tree.subsystems])
    R, r, lines, joints = [], [], [], []
    for model, t, q, s_dot in zip(system.row_models(result), result.t, result.q, result.s_dot):
        kin = tree_poses(model, q, s_dot, t)[1]
        N = len(tree.names)
        R.append(np.array(kin.R[:N])), r.append(np.array(kin.r[:N]))
        points = drawing.bodies(kin, q)[0]
        lines.append([points[starts[n]: starts[n] + stations] for n in deforming])
        joints.append(drawing.mechanism(kin))
    R, r, joints = np.array(R), np.array(r), np.array(joints)
    lines = np.array(lines).reshape(len(result.t), len(deforming), stations, 3)
    every = np.concatenate((r, joints, lines.reshape(len(result.t), -1, 3)), axis=1)  # (time, points, 3)
    scale = float(max(np.ptp(every, axis=1).max(), 1e-3))
    shapes = _shapes(tree, scale)
    solids = [r[:, s["frame"]] + R[:, s["frame"]] @ s["position"] + h * np.array(e)[:, None].T
              for s in shapes for h in (max(s["size"]) / 2, -max(s["size"]) / 2) for e in np.eye(3)]
    if solids:  # the solids' extent too (a bicycle's wheels and rider reach beyond its joints)
        every = np.concatenate((every, np.stack(solids, axis=1)), axis=1)
        scale = float(np.ptp(every, axis=1).max())
    centre = every.mean(axis=1)
    g = np.asarray(getattr(tree, "gravity", np.zeros(3)), dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    travel = float(np.ptp(centre, axis=0).max())
    flat = every.reshape(-1, 3)
    heights = flat @ up
    ground = flat.mean(axis=0) + (heights.min() - flat.mean(axis=0) @ up) * up
    size = 2.0 * (scale + travel)
    return {
        "t": _rounded(result.t, 9), "frames": list(tree.names), "poses": _rounded(np.concatenate(
            (r, _quaternions(R)), axis=-1), 6, scale),
        "shapes": shapes,
        "tubes": [{"name": tree.names[n], "stations": stations, "radius": 0.012 * scale,
                   "color": COLORS[n % len(COLORS)],
                   "points": _rounded(lines[:, k], 6, scale)} for k, n in enumerate(deforming)],
        "links": {"pairs": drawing.links["lines"].ravel().tolist(), "count": joints.shape[1],
                  "points": _rounded(joints, 6, scale), "radius": 0.006 * scale},
        "scale": scale, "up": up.tolist(), "view": _view(flat, up).tolist(),
        "distance": 3.2 * scale if travel > scale else 2.4 * float(np.ptp(flat, axis=0).max()),
        "centre": _rounded(centre, 6, scale), "target": ((flat.min(axis=0) + flat.max(axis=0)) / 2).tolist(),
        "follow": travel > scale, "axes": 0.1 * scale,
        "grid": {"size": size, "divisions": 20, "centre": ground.tolist()},
    }


def _rounded(values, digits: int, scale: float = 0.0) -> list:
    """``values`` flattened, each rounded to ``digits`` significant digits (relative to ``scale``
    where given, so that a coordinate near zero is not written to 16 digits)."""
    values = np.asarray(values, dtype=float).ravel()
    if scale:
        step = 10.0 ** (np.floor(np.log10(scale)) - digits)
        return (np.round(values / step) * step).round(15).tolist()
    return [float(f"{v:.{digits}g}") for v in values]


def _resource(name: str) -> str:
    return files("projeq.simulation").joinpath("viewer", name).read_text(encoding="utf-8")


def _script(text: str) -> str:
    """``text`` as a JavaScript string literal that cannot end its ``<script>`` element."""
    return json.dumps(text).replace("<", "\\u003c")


def html(result, system=None, stations: int = 21, title: str | None = None) -> str:
    """The page of :func:`write_html` as text."""
    document = motion(result, system, stations)
    title = title or str((result.metadata or {}).get("scene", "projeq run"))
    parts = {"TITLE": _escape(title), "THREE_VERSION": THREE_VERSION,
             "THREE_SOURCE": _script(_resource("three.module.min.js")),
             "ORBIT_SOURCE": _script(_resource("OrbitControls.js")),
             "DATA": json.dumps(document, separators=(",", ":")).replace("<", "\\u003c")}
    return re.sub(r"\{\{(\w+)\}\}", lambda match: parts[match.group(1)], _resource("viewer.html"))


def _escape(text: str) -> str:
    from html import escape

    return escape(text)


def write_html(result, path, system=None, stations: int = 21, title: str | None = None) -> Path:
    """Write the page that plays ``result`` (module docstring) to ``path``; returns the path."""
    path = Path(path)
    text = html(result, system, stations, title)
    with written_atomically(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return path


def _outline(shape: dict) -> list[NDArray]:
    """Polylines (k, 3) of a solid's edges in its body's frame: a box's 12 edges, a cylinder's two
    rims and four sides, a sphere's three great circles."""
    from scipy.spatial.transform import Rotation

    s = shape["size"]
    angle = np.linspace(0.0, 2 * np.pi, 25)
    circle = np.column_stack((np.cos(angle), np.zeros_like(angle), np.sin(angle)))  # about y
    if shape["kind"] == "box":
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * np.array(s) / 2
        pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if (a ^ b).bit_count() == 1]
        local = [corners[[a, b]] for a, b in pairs]
    elif shape["kind"] == "cylinder":
        rim = s[0] * circle
        local = [rim + (0, -s[1] / 2, 0), rim + (0, s[1] / 2, 0)]
        local += [np.array([rim[k] + (0, -s[1] / 2, 0), rim[k] + (0, s[1] / 2, 0)]) for k in (0, 6, 12, 18)]
    else:
        local = [s[0] * circle[:, order] for order in ([0, 1, 2], [1, 0, 2], [0, 2, 1])]
    rotation = Rotation.from_quat(shape["quaternion"]).as_matrix()
    return [np.asarray(shape["position"]) + line @ rotation.T for line in local]


def write_movie(result, path, system=None, stations: int = 21, fps: int = 25, max_frames: int = 250) -> Path:
    """A GIF (Pillow) or MP4 (ffmpeg) of ``result`` at ``fps`` frames per second of simulated time
    (fewer where the run has fewer output rows or more than ``max_frames`` would be needed; the
    movie then shows an output row per frame at a rate that keeps it in real time as far as
    whole frames per second allow): the geometry of :func:`motion` projected on the plane
    normal to the page's viewing direction, with the time written on it. RuntimeError when the
    suffix's writer is missing (ffmpeg for MP4), naming what to install or write instead."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation
    from scipy.spatial.transform import Rotation

    path = Path(path)
    writers = {".gif": "pillow", ".mp4": "ffmpeg"}
    if path.suffix not in writers:
        raise ValueError(f"path: a movie is written as .gif or .mp4, got {str(path)!r}")
    if not animation.writers.is_available(writers[path.suffix]):
        raise RuntimeError(f"path: {path.suffix} needs {writers[path.suffix]} (matplotlib's "
                           f"'{writers[path.suffix]}' movie writer), which was not found; install it or "
                           "write "
                           ".gif (Pillow, which comes with matplotlib) or .html instead")
    if not (isinstance(fps, (int, np.integer)) and fps > 0):
        raise ValueError(f"fps: expected a positive integer, got {fps!r}")
    doc = motion(result, system, stations)
    t, N = np.array(doc["t"]), len(doc["frames"])
    up, view = np.array(doc["up"]), np.array(doc["view"])
    right = np.cross(up, view)
    right /= np.linalg.norm(right)
    screen = np.column_stack((right, np.cross(view, right)))  # world → (x, y) on the page
    poses = np.array(doc["poses"]).reshape(len(t), N, 7)
    joints = np.array(doc["links"]["points"]).reshape(len(t), -1, 3)
    pairs = np.array(doc["links"]["pairs"]).reshape(-1, 2)
    tubes = [np.array(tube["points"]).reshape(len(t), tube["stations"], 3) for tube in doc["tubes"]]
    outlines = [(shape["frame"], shape["color"], _outline(shape)) for shape in doc["shapes"]]
    duration = t[-1] - t[0]
    count = int(min(max_frames, len(t), np.ceil(duration * fps) + 1))  # no frame twice
    rows = np.searchsorted(t, np.linspace(t[0], t[-1], count), side="right") - 1
    rate = max(1, round((count - 1) / duration)) if duration > 0 else fps  # real time where it can be
    every = np.concatenate([joints.reshape(-1, 3)] + [tube.reshape(-1, 3) for tube in tubes]) @ screen
    half = 0.6 * doc["scale"]
    centres = np.array(doc["centre"]).reshape(len(t), 3) @ screen
    fig, ax = plt.subplots(figsize=(6, 4.5), dpi=100)

    def draw(k):
        ax.clear()
        i = rows[k]
        R = Rotation.from_quat(poses[i, :, 3:]).as_matrix()
        for frame, color, lines in outlines:
            for line in lines:
                ax.plot(*((poses[i, frame, :3] + line @ R[frame].T) @ screen).T, color=color, lw=1.5)
        for a, b in pairs:
            ax.plot(*(joints[i, [a, b]] @ screen).T, color="#555555", lw=2)
        for tube, spec in zip(tubes, doc["tubes"]):
            ax.plot(*(tube[i] @ screen).T, color=spec["color"], lw=4, solid_capstyle="round")
        if doc["follow"]:
            ax.set_xlim(centres[i, 0] - 2.0 * half, centres[i, 0] + 2.0 * half)  # the mechanism's size
            ax.set_ylim(centres[i, 1] - 1.5 * half, centres[i, 1] + 1.5 * half)  # and a margin, at 4:3
        else:
            ax.set_xlim(every[:, 0].min() - 0.2 * half, every[:, 0].max() + 0.2 * half)
            ax.set_ylim(every[:, 1].min() - 0.2 * half, every[:, 1].max() + 0.2 * half)
        ax.set_aspect("equal", adjustable="box")
        ax.set_title(f"t = {t[i]:.3f} s", loc="left", fontsize=10)
        ax.set_xticks([]), ax.set_yticks([])

    movie = animation.FuncAnimation(fig, draw, frames=count)
    writer = animation.PillowWriter(fps=rate) if path.suffix == ".gif" else animation.FFMpegWriter(fps=rate)
    try:
        with written_atomically(path) as temporary:
            movie.save(temporary, writer=writer)
    finally:
        plt.close(fig)
    return path


def animate(result, path, system=None, stations: int = 21, **options) -> Path:
    """Write the motion of ``result`` to ``path`` by its suffix: ``.html`` the page
    (:func:`write_html`, ``title`` among ``options``), ``.gif`` or ``.mp4`` a movie
    (:func:`write_movie`, ``fps`` and ``max_frames`` among ``options``). ValueError for another
    suffix; returns the path."""
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise ValueError(f"path: expected a file ending in {', '.join(SUFFIXES)}, got {str(path)!r}")
    if path.suffix.lower() == ".html":
        return write_html(result, path, system, stations, **options)
    return write_movie(result, path, system, stations, **options)
