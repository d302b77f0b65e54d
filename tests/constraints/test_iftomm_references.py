"""IFToMM A01, A02 and A05 against the benchmark library's published reference solutions (issue 35).

Library of computational benchmark problems of the IFToMM Technical Committee for Multibody
Dynamics: M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS
simulation software", Multibody System Dynamics 16 (2006) 179–190. Its rules: an error of 1e-3
(high precision) in the output quantity over the whole horizon. The reference files are found
through the environment variable PROJEQ_DATA (the folder holding ``iftomm/``; ``.ci/run`` sets
it); a test that needs one skips, naming the file, where it is absent. Each is compared with
its closed form too, always: the files print 6 significant digits (5e-6 m at 1 m), and the A02
file is an ADAMS run 4.1e-6 m from the exact parallelogram motion. The long horizons (2000 s,
20 s) run in ``benchmarks/iftomm.py``; here shortened ones.
"""

import os
from pathlib import Path

import numpy as np
import pytest

import projeq as pq
from projeq.scenes.iftomm import (
    flyball_governor, n_four_bar, parallelogram_motion, pendulum_angle, point_b0, reference_solution, simple_pendulum,
)

A01 = "iftomm_A01_simple_pendulum_solution.txt"
A02 = "iftomm_A02_n_four_bar_N40_solution.txt"


def reference(name: str) -> np.ndarray:
    """The rows (t, x, y) of the reference file ``name``, or a skip naming it."""
    root = os.environ.get("PROJEQ_DATA")
    path = Path(root, "iftomm", name) if root else None
    if path is None or not path.is_file():
        pytest.skip(f"{name}: the IFToMM reference file is not here (PROJEQ_DATA names the folder holding iftomm/{name})")
    return reference_solution(path)


def pendulum_point(t) -> np.ndarray:
    """P1 = (x, y) of A01 from the closed form: x = L sin θ, y = −L cos θ (L = 1)."""
    theta = pendulum_angle(t)
    return np.column_stack((np.sin(theta), -np.cos(theta)))


def test_a01_closed_form_and_file_agree():
    """The file starts at x = −1 although the specification's text says +1: it is the mirror image
    (x → −x) of the specified motion; mirrored, it agrees with Jacobi's closed form to 5.0e-7 m over
    the whole 2000 s (largest coordinate difference; the file prints 6 digits)."""
    data = reference(A01)
    assert data[0].tolist() == [0.0, -1.0, 0.0] and data[-1, 0] == 2000.0
    mirrored = np.column_stack((-data[:, 1], data[:, 2]))
    error = np.abs(mirrored - pendulum_point(data[:, 0])).max()
    assert 1e-7 < error < 1e-6, error


def test_a01_follows_the_reference_file():
    """A01 over its first 10 s (21 rows of the file) at rtol 1e-9: P1 within 5.5e-7 m of the
    mirrored file's rows (the file's own rounding and distance from the exact motion, 5.0e-7;
    bound 10×) and 8.6e-8 m of the closed form (bound 10×). The full 2000 s meets the
    benchmark's 1e-3 in benchmarks/iftomm.py."""
    data = reference(A01)
    rows = data[data[:, 0] <= 10.0]
    r = pq.simulate(simple_pendulum(), 10.0, t_eval=rows[:, 0], rtol=1e-9, method="DOP853")
    P1 = r.q[:, :2]
    file_error = np.abs(P1 - np.column_stack((-rows[:, 1], rows[:, 2]))).max()
    exact_error = np.abs(P1 - pendulum_point(r.t)).max()
    assert file_error < 5.5e-6, file_error
    assert exact_error < 8.6e-7, exact_error


def test_a02_n40_follows_the_reference_file():
    """A02 with the benchmark's N = 40 over its first 0.2 s (5 rows of the ADAMS file) at rtol 1e-9:
    B0 within 4.8e-6 m of the file (measured 4.8e-7 over 0.5 s: the file's own distance from the
    exact motion there, 4.1e-6 over its 20 s; bound 10×) and within 4.3e-9 m of the parallelogram
    motion (measured 4.3e-10; bound 10×)."""
    data = reference(A02)
    rows = data[data[:, 0] <= 0.2]
    system = n_four_bar(40)
    # RK45, simulate's pick for closed loops, named: the pick's measure of the fastest mode costs 5 s at N = 40
    r = pq.simulate(system, 0.2, t_eval=rows[:, 0], rtol=1e-9, method="RK45")
    B0 = point_b0(system, r.q, r.s_dot)[:, :2]
    file_error, exact_error = (np.abs(B0 - other).max()
                               for other in (rows[:, 1:], parallelogram_motion(r.t, n=40)[:, :2]))
    assert file_error < 4.8e-6, file_error
    assert exact_error < 4.3e-9, exact_error


def test_a05_reaches_the_exudyn_reference_at_10_s():
    """A05 has no published data file; its reference is an Exudyn run of the full specification
    (kinematic tree, h = 2e-5): s(10 s) = 0.6196234 m. projeq at its defaults (simulate picks Radau
    for the stiff dampers) ends 4.8e-7 m from it (the issue asks 1e-4; bound 10× the measured)."""
    r = pq.simulate(flyball_governor(), 10.0, n_points=3)
    assert r.method == "Radau"
    error = abs(r.q[-1, 1] - 0.6196234)
    assert error < 4.8e-6, error
