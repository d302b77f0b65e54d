"""Result.animate and ``projeq view``: the HTML page that plays a run (three.js inlined), its data
against closed forms, the GIF/MP4 writers, and the page in a real browser (Debian's chromium,
headless, offline; skipped where /usr/bin/chromium is absent).

The trajectories are prescribed, not simulated (the page draws any q(t)): no integration, no
compiled kernel, so the file stays cheap."""

from __future__ import annotations

import json
import re
import subprocess
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import projeq as pq
from projeq import Result, scenes
from projeq.cli.commands import main
from projeq.spatial import rotation_x
from projeq.simulation.animation import THREE_VERSION, equivalent_shape, motion, write_html
from projeq.subsystems import Visual, inertia

ROUND_OFF = 100 * np.finfo(float).eps  # identities that hold to round-off: 100 ε

CHROMIUM = Path("/usr/bin/chromium")
T = np.linspace(0.0, 1.0, 21)


def prescribed(system, q, metadata=None) -> Result:
    """A Result whose rows are the given q (n × n_q) at the times T, at rest (ṡ = 0)."""
    n = len(q)
    return Result(t=T[:n], q=np.asarray(q, dtype=float), s_dot=np.zeros((n, system.n_s)), kinetic=np.zeros(n),
                  potential=np.zeros(n), constraint_residual=np.zeros((n, 0)), metadata=metadata or {},
                  system=system)


def pendulum_angles():
    return np.column_stack((np.pi / 2 * np.cos(2 * T), 0.8 * np.sin(3 * T)))


def flexible_arm_rows(system):
    q = np.zeros((len(T), system.n_q))
    q[:, :3] = np.column_stack((0.3 + T, -0.4 * np.cos(T), 0.2 * T))
    q[:, 3] = 0.05 * np.sin(4 * T)  # the first bending function: the tube bends
    return q


def bicycle_rows(system):
    q = np.tile(system.q0, (len(T), 1))
    q[:, 0] = 5.0 * T            # x: forward 5 m in 1 s, more than the bicycle's size (the camera follows)
    q[:, 5] = -5.0 * T / 0.3     # θ_R: the rear wheel turns
    q[:, 7] = -5.0 * T / 0.35    # θ_F
    return q


@cache
def bicycle():
    """The Whipple bicycle, built once for this file (its user joint and contacts from sympy: 1.5 s)."""
    return scenes.whipple_bicycle()


def rotated(tensor, R):
    return R @ tensor @ R.T


def test_equivalent_shape_inverts_the_inertia_formulas():
    """Box, cylinder (about each axis), sphere from projeq.subsystems.inertia, turned by a random
    rotation: the solid found has the same sizes, and its inertia by the forward formula turned by
    its rotation is I_c again (measured 5.5e-16 relative; bound 1e-14, 45 ε); the sizes to 100 ε relative
    (measured ≤ 3.1e-15 over three rotations, 0 for the sphere and the disk; were rel 1e-14 and 1e-9 with
    pytest's absolute 1e-12, up to 6.7e-11 of the disk's thickness)."""
    from scipy.spatial.transform import Rotation

    R = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
    box = equivalent_shape(3.0, rotated(inertia.box(3.0, 0.2, 0.5, 1.3), R))
    assert box.kind == "box" and sorted(box.size) == pytest.approx([0.2, 0.5, 1.3], rel=ROUND_OFF, abs=0)
    I_box = rotated(inertia.box(3.0, *box.size), box.rotation)
    assert np.abs(I_box - rotated(inertia.box(3.0, 0.2, 0.5, 1.3), R)).max() < 1e-14 * np.abs(I_box).max()
    for axis in "xyz":
        I_c = rotated(inertia.cylinder(2.0, 0.1, 0.9, axis=axis), R)
        cylinder = equivalent_shape(2.0, I_c)
        assert cylinder.kind == "cylinder"
        assert cylinder.size == pytest.approx((0.1, 0.9), rel=ROUND_OFF, abs=0)
        assert np.linalg.det(cylinder.rotation) == pytest.approx(1.0, abs=ROUND_OFF)  # measured 2.2e-16
        # three.js's cylinder has its axis along y
        I_back = rotated(inertia.cylinder(2.0, *cylinder.size, axis="y"), cylinder.rotation)
        assert np.abs(I_back - I_c).max() < 1e-14 * np.abs(I_c).max()
    sphere = equivalent_shape(5.0, inertia.sphere(5.0, 0.25))
    assert sphere.kind == "sphere" and sphere.size == pytest.approx((0.25,), rel=ROUND_OFF, abs=0)
    disk = equivalent_shape(1.0, inertia.disk(1.0, 0.3, axis="y"))  # no thickness: drawn 5 % of r thick
    assert disk.kind == "cylinder" and disk.size == pytest.approx((0.3, 0.015), rel=ROUND_OFF, abs=0)
    with pytest.raises(ValueError, match="I_c"):
        equivalent_shape(1.0, np.diag([1.0, -2.0, 1.0]))
    with pytest.raises(ValueError, match="I_c"):
        equivalent_shape(0.0, np.eye(3))


def test_double_pendulum_page_holds_the_bobs_closed_form_positions(tmp_path):
    """The bobs (point masses at (0, 0, −l) in their link frames, hinged about y) are drawn where
    the closed form puts them: r₁ = −l₁ (sin θ₁, 0, cos θ₁), r₂ = r₁ − l₂ (sin(θ₁+θ₂), 0,
    cos(θ₁+θ₂)); rounded to 1e-6 of the scale's decade (measured 5e-7 m; bound 1e-6 m); their
    frames' quaternions are the turns about y by θ₁ and θ₁ + θ₂ (1 − |⟨q, q_exact⟩| measured 5.2e-7,
    6-digit rounding; bound 5e-6). The page
    is written, inlines three.js and its data read back equal motion()'s."""
    system = scenes.double_pendulum()
    theta = pendulum_angles()
    result = prescribed(system, theta)
    doc = motion(result)
    points = np.array(doc["links"]["points"]).reshape(len(T), -1, 3)  # joints, then centres of mass
    r1 = -np.column_stack((np.sin(theta[:, 0]), 0 * T, np.cos(theta[:, 0])))
    r2 = r1 - np.column_stack((np.sin(theta.sum(1)), 0 * T, np.cos(theta.sum(1))))
    assert np.abs(points[:, 2] - r1).max() < 1e-6 and np.abs(points[:, 3] - r2).max() < 1e-6
    assert np.abs(points[:, 1] - r1).max() < 1e-6  # bob2's joint sits at bob1
    poses = np.array(doc["poses"]).reshape(len(T), 2, 7)  # the frames turn about y by θ₁, θ₁ + θ₂
    for frame, angle in ((0, theta[:, 0]), (1, theta.sum(1))):
        half = np.column_stack((0 * T, np.sin(angle / 2), 0 * T, np.cos(angle / 2)))  # (x, y, z, w)
        assert np.abs(np.abs(np.sum(poses[:, frame, 3:] * half, axis=1)) - 1).max() < 5e-6
    assert [s["kind"] for s in doc["shapes"]] == ["sphere", "sphere"] and doc["up"] == [0.0, 0.0, 1.0]
    assert abs(doc["view"][1]) > 0.7  # looking along the hinge axis y, at the plane of the motion
    assert doc["follow"] is False
    page = result.animate(tmp_path / "pendulum.html").read_text()
    assert f'const t=\\"{THREE_VERSION.split(".")[1]}\\"' in page and "class OrbitControls" in page
    ours = page.split("PROJEQ_THREE")[0] + page.split('id="projeq-data"')[1]  # the page but three.js's source
    assert "https://" not in ours  # nothing fetched
    data = re.search(r'id="projeq-data">(.*?)</script>', page, re.DOTALL).group(1)
    assert json.loads(data) == json.loads(json.dumps(doc))
    assert page.count("</script>") == 4  # the inlined sources cannot close their elements
    with pytest.raises(ValueError, match="path"):
        result.animate(tmp_path / "pendulum.png")
    with pytest.raises(ValueError, match="stations"):
        motion(result, stations=1)


def test_flexible_arm_tube_is_the_beams_deformed_centre_line():
    """The beam's tube starts at its joint (the frame "last") and ends at the tip mass fixed on its
    end station (the frame "tip", placed by the joint on the beam's port): equal after the page's
    rounding to 1e-6 m (measured 0: the same numbers to 1e-16 before it; bound 1.1e-6 m, one
    rounding step), while the deflection moves the tip off the undeformed line by 4.6 cm (> 2 cm).
    The rigid links are the cylinders of their inertia (r = 0.02 m, ℓ = 0.6, 0.5 m)."""
    system = scenes.flexible_arm()
    doc = motion(prescribed(system, flexible_arm_rows(system)))
    (tube,) = doc["tubes"]
    line = np.array(tube["points"]).reshape(len(T), tube["stations"], 3)
    poses = np.array(doc["poses"]).reshape(len(T), len(doc["frames"]), 7)
    last, tip = doc["frames"].index("last"), doc["frames"].index("tip")
    assert np.abs(line[:, 0] - poses[:, last, :3]).max() < 1.1e-6
    assert np.abs(line[:, -1] - poses[:, tip, :3]).max() < 1.1e-6
    from scipy.spatial.transform import Rotation

    straight = poses[:, last, :3] + Rotation.from_quat(poses[:, last, 3:]).apply([0.8, 0.0, 0.0])
    assert np.abs(line[:, -1] - straight).max() > 0.02  # deformed
    cylinders = {doc["frames"][s["frame"]]: s["size"] for s in doc["shapes"] if s["kind"] == "cylinder"}
    # round-off: measured ≤ 1.1e-16 relative, the up vector exact (were rel 1e-9 and pytest's defaults)
    assert cylinders["upper"] == pytest.approx([0.02, 0.6], rel=ROUND_OFF, abs=0)
    assert cylinders["fore"] == pytest.approx([0.02, 0.5], rel=ROUND_OFF, abs=0)
    assert doc["up"] == pytest.approx([0.0, 1.0, 0.0], rel=0, abs=ROUND_OFF)


def test_bicycle_wheels_are_cylinders_about_their_axles_and_the_camera_follows():
    """MJPR's wheels (I_yy about the axle, I_xx = I_zz across) are cylinders along the wheel
    frames' y (three.js's cylinder axis): r = √(2 I_yy/m); the frame is z-down, so up is −z; a run
    of 5 m, more than the bicycle's size, is followed by the camera."""
    from projeq.scenes.bicycle import bicycle_parameters

    p = bicycle_parameters(None)
    system = bicycle()
    doc = motion(prescribed(system, bicycle_rows(system)))
    wheels = {doc["frames"][s["frame"]]: s for s in doc["shapes"] if s["kind"] == "cylinder"}
    from scipy.spatial.transform import Rotation

    for name, m, I_yy in (("rear_wheel", p["m_R"], p["I_Ryy"]), ("front_wheel", p["m_F"], p["I_Fyy"])):
        # measured 0 (was rel 1e-9)
        assert wheels[name]["size"][0] == pytest.approx(np.sqrt(2 * I_yy / m), rel=ROUND_OFF, abs=0)
        axis = Rotation.from_quat(wheels[name]["quaternion"]).apply([0.0, 1.0, 0.0])
        assert abs(axis[1]) == pytest.approx(1.0, abs=ROUND_OFF)  # measured 2.2e-16 (was 1e-9)
    assert doc["up"] == pytest.approx([0.0, 0.0, -1.0], rel=0, abs=ROUND_OFF) and doc["follow"] is True
    centre = np.array(doc["centre"]).reshape(len(T), 3)
    assert centre[-1, 0] - centre[0, 0] == pytest.approx(5.0, abs=1e-5)  # the bicycle moved 5 m forward


def drawn_by_visuals():
    """A crank (PlanarBody, mass centre off its joint), a disk-like PlanarBody on it (mass centre at
    its joint) and, on the ground, a frame and an arm drawn by their Visuals (box, cylinder, sphere,
    the cylinder turned and moved by its origin)."""
    origin = np.eye(4)
    origin[:3, :3], origin[:3, 3] = rotation_x(np.pi / 2), (0.0, 0.0, -0.3)  # its axis z along −y
    arm = pq.RigidBody(2.0, (0.0, 0.0, -0.3), inertia.cylinder(2.0, 0.05, 0.6, axis="z"))
    arm.visuals = (Visual("cylinder", (0.05, 0.6), origin), Visual("sphere", (0.08,)))
    post = pq.Frame()
    post.visuals = (Visual("box", (0.1, 0.2, 0.4)),)
    bodies = {"crank": pq.PlanarBody(1.5, (0.2, 0.0, 0.0), 0.02, plane="xy"),
              "disk": pq.PlanarBody(0.5, (0.0, 0.0, 0.0), 0.01, plane="xy"),
              "post": post, "arm": arm}
    joints = {"crank": pq.Revolute(axis="z"), "disk": pq.Revolute("crank", "z", r_pn=(0.4, 0.0, 0.0)),
              "post": pq.Fixed(r_pn=(1.0, 0.0, 0.0)), "arm": pq.Revolute("post", "x", r_pn=(0.0, 0.0, 0.2))}
    return pq.System(bodies, joints, gravity=(0.0, -9.81, 0.0))


def visuals_rows(system):
    return np.column_stack((2.0 * T, -3.0 * T, 0.5 * np.sin(3 * T)))


def test_planar_bodies_are_plates_with_their_moment_about_the_normal():
    """A PlanarBody is drawn as a box in its plane whose moment about the normal is the body's
    (the formula of projeq.subsystems.inertia.box turned by the box's rotation: measured 2.2e-16
    relative, bound 1e-14, 45 ε): a bar along r_c where the mass centre is off the joint, a square
    plate where it is at the joint (not the sphere of the isotropic tensor its scalar I_c gives)."""
    doc = motion(prescribed(drawn_by_visuals(), visuals_rows(None)))
    shapes = {doc["frames"][s["frame"]]: s for s in doc["shapes"] if s["frame"] < 2}
    from scipy.spatial.transform import Rotation

    for name, m, I_n in (("crank", 1.5, 0.02), ("disk", 0.5, 0.01)):
        shape = shapes[name]
        assert shape["kind"] == "box"
        R = Rotation.from_quat(shape["quaternion"]).as_matrix()
        I_c = R @ inertia.box(m, *shape["size"]) @ R.T
        assert abs(I_c[2, 2] / I_n - 1) < 1e-14, I_c[2, 2] / I_n - 1
        assert abs(R[2, 2]) == pytest.approx(1.0, abs=ROUND_OFF)  # thin along the normal z; measured 0
    # measured 5.6e-17 (was 1e-12)
    assert shapes["crank"]["size"][0] == pytest.approx(10 * shapes["crank"]["size"][1], rel=ROUND_OFF, abs=0)
    # measured 0 (were pytest's defaults, rel 1e-6, and rel 1e-12 with its absolute 1e-12)
    along_x = Rotation.from_quat(shapes["crank"]["quaternion"]).apply([1.0, 0, 0])
    assert along_x == pytest.approx([1.0, 0, 0], rel=0, abs=ROUND_OFF)
    assert shapes["disk"]["size"][0] == pytest.approx(shapes["disk"]["size"][1], rel=ROUND_OFF, abs=0)


def test_visuals_are_drawn_where_given():
    """A subsystem's Visuals replace the solid of its inertia, in its frame: the arm's cylinder of
    r = 0.05, ℓ = 0.6 at its origin, its axis (URDF's z, turned to −y) as three.js's y, and the
    sphere; the massless post's box (a Frame: no solid without a visual). Bad visuals are named."""
    from scipy.spatial.transform import Rotation

    doc = motion(prescribed(drawn_by_visuals(), visuals_rows(None)))
    frames = doc["frames"]
    arm = [s for s in doc["shapes"] if frames[s["frame"]] == "arm"]
    post = [s for s in doc["shapes"] if frames[s["frame"]] == "post"]
    assert [s["kind"] for s in arm] == ["cylinder", "sphere"] and [s["kind"] for s in post] == ["box"]
    cylinder, sphere = arm
    assert cylinder["size"] == [0.05, 0.6] and cylinder["position"] == [0.0, 0.0, -0.3]
    axis = Rotation.from_quat(cylinder["quaternion"]).apply([0.0, 1.0, 0.0])
    assert np.abs(axis - [0.0, -1.0, 0.0]).max() < 1e-15
    assert sphere["size"] == [0.08] and post[0]["size"] == [0.1, 0.2, 0.4]
    with pytest.raises(ValueError, match="kind"):
        Visual("cone", (1.0, 2.0))
    with pytest.raises(ValueError, match="size: a cylinder takes 2"):
        Visual("cylinder", (1.0,))
    with pytest.raises(ValueError, match="origin"):
        Visual("box", (1.0, 1.0, 1.0), np.diag([1.0, 1.0, -1.0, 1.0]))


def saved_run(folder: Path) -> Path:
    """A run folder as projeq run writes it (run.json listing the .npz with its record)."""
    system = scenes.double_pendulum()
    result = prescribed(system, pendulum_angles(), metadata={"scene": "double_pendulum", "parameters": {}})
    folder.mkdir()
    result.save(folder / "double_pendulum.npz")
    record = {"scene": "double_pendulum", "files": ["double_pendulum.npz"]}
    (folder / "run.json").write_text(json.dumps(record))
    return folder


def test_projeq_view_writes_the_page_of_a_run_folder_or_npz(tmp_path, capsys, monkeypatch):
    """``projeq view RUN`` rebuilds the scene from the record and writes <scene>.html beside the
    NPZ; --out FILE.gif --fps 5 writes a GIF of 6 frames over the run's 1 s, 200 ms each; .mp4
    without ffmpeg is one message, exit 1; a bad suffix or no run: exit 2."""
    folder = saved_run(tmp_path / "run")
    assert main(["view", str(folder)]) == 0
    page = folder / "double_pendulum.html"
    assert page.is_file() and str(page) in capsys.readouterr().out
    pytest.importorskip("PIL", reason="Pillow (a dependency of matplotlib) writes GIFs")
    gif = tmp_path / "swing.gif"
    assert main(["view", str(folder / "double_pendulum.npz"), "--out", str(gif), "--fps", "5"]) == 0
    from PIL import Image

    with Image.open(gif) as movie:
        assert movie.n_frames == 6 and movie.size == (600, 450) and movie.info["duration"] == 200
    from matplotlib import animation as movies

    monkeypatch.setattr(movies.writers, "is_available", lambda name: name != "ffmpeg")
    assert main(["view", str(folder), "--out", str(tmp_path / "swing.mp4")]) == 1
    assert "needs ffmpeg" in capsys.readouterr().err
    assert not (tmp_path / "swing.mp4").exists()
    assert main(["view", str(folder), "--out", str(tmp_path / "swing.png")]) == 2
    assert main(["view", str(tmp_path / "nothing")]) == 2
    assert "run: no run folder" in capsys.readouterr().err


def chromium(page: Path, at: float, profile: str, screenshot: Path) -> subprocess.Popen:
    """Headless Chromium on ``page#t=at`` (played from the start to ``at``), offline: no
    background networking, updates or sync; a new profile; the DOM dumped after the play (to
    ``screenshot``.dom: it holds the inlined three.js, more than a pipe buffers) and a screenshot,
    the log to ``screenshot``.log. Software WebGL (SwiftShader) is asked for explicitly: no GPU here."""
    with open(screenshot.with_suffix(".dom"), "w") as dom, open(screenshot.with_suffix(".log"), "w") as log:
        return subprocess.Popen(
            [str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--no-first-run",
             f"--user-data-dir={profile}", "--virtual-time-budget=1000",
             "--window-size=560,420", f"--screenshot={screenshot}", "--dump-dom", f"{page.as_uri()}#t={at}"],
            stdout=dom, stderr=log)


@pytest.mark.skipif(not CHROMIUM.exists(), reason="no /usr/bin/chromium (Debian's package chromium): "
                    "the pages are not loaded in a browser here")
def test_pages_play_in_headless_chromium_offline(tmp_path):
    """Each page (double pendulum, flexible arm, bicycle, bodies drawn by visuals and plates)
    loads from a file in headless Chromium with no network, plays to t = 0.5 s and stops there with
    no error (the page's collector of errors, uncaught exceptions and console.error stays empty),
    and its picture then differs from its first one (the page compares its canvas, data-changed);
    the double pendulum's screenshot after the play differs from that of its first frame (#t=0) in
    many pixels (measured 1.4 %)."""
    from matplotlib.image import imread

    arm, bike = scenes.flexible_arm(), bicycle()
    models = {"double_pendulum": (scenes.double_pendulum(), pendulum_angles()),
              "flexible_arm": (arm, flexible_arm_rows(arm)), "whipple_bicycle": (bike, bicycle_rows(bike)),
              "visuals": (drawn_by_visuals(), visuals_rows(None))}
    shots = {}
    for name, (system, rows) in models.items():
        page = write_html(prescribed(system, rows), tmp_path / f"{name}.html", title=name)
        for at in (0.0, 0.5) if name == "double_pendulum" else (0.5,):
            shot = shots[name, at] = tmp_path / f"{name}-{at}.png"
            # one at a time: several browsers at once on two cores have kept each other from ending
            process = chromium(page, at, tempfile.mkdtemp(dir=tmp_path), shot)
            assert process.wait(timeout=60) == 0, shot.with_suffix(".log").read_text()[-2000:]
            dom = shot.with_suffix(".dom").read_text()
            errors = re.search(r'<pre id="projeq-errors">(.*?)</pre>', dom, re.DOTALL).group(1)
            assert errors == "", errors
            status = re.search(r'<span id="projeq-status"[^>]*>', dom).group(0)
            assert 'data-state="stopped"' in status and f">stopped at t = {at:g}<" in dom, status
            assert f'data-changed="{str(at > 0).lower()}"' in status, (name, status)
    first, played = (imread(shots["double_pendulum", at]) for at in (0.0, 0.5))
    changed = np.abs(first - played).max(axis=-1) > 0.1
    assert changed.mean() > 0.002, changed.mean()
