"""The constrained s̈ in one compiled call (projeq.constraints.compiled): Φ compiled by numba,
its complex-step derivatives, the partition and the projection of the tree's compiled Gauss form
give the s̈_tree and λ of the numpy path (the same stencils, numpy linear algebra) to round-off,
and those of the dense reference form (Σ J_nᵀ M_n J_n, docs/theory.md §5, an independent
formulation of M and b); a Φ numba cannot compile warns once, naming it, and keeps the numpy path.
"""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import kernels
from projeq.constraints import compiled
from projeq.constraints.compiled import CompiledClosure, UncompiledClosureWarning
from projeq.constraints.partitioned import ConstrainedSystem

# the same stencils and the same M, b (tests/assembly/test_fast.py: ~1e-15 relative), summed in
# another order: measured ≤ 3.9e-14 of max(1, |s̈_tree|∞) on these scenes (s̈_tree and λ against the
# numpy path and the dense projection; the cut joint's γ 3.8e-14)
RTOL = 1e-13
BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
COMPILED_SCENES = ("four_bar", "quick_return", "simple_pendulum", "n_four_bar", "bricard", "andrews_squeezer")


def _states(model, count=3):
    rng = np.random.default_rng(5)
    return [(model.q0, model.s_dot0 + 2 * rng.standard_normal(model.n_s), float(t)) for t in rng.uniform(0, 1, count)]


def _close(a, b) -> bool:
    return bool(np.abs(a - b).max(initial=0.0) <= RTOL * max(1.0, np.abs(b).max(initial=0.0)))


def _loaded_four_bar(law=None):
    """The four-bar of rigid rods (a, b, c = 0.3, 1.0, 0.8 m on a ground link of 1 m, q = (crank,
    rocker, coupler relative to the crank); gravity −y) under every kind of compiled force law:
    a spring-damper between coupler and rocker and one from the crank to the ground, a joint
    spring on the coupler, a motor torque on the crank, a force at a point of the coupler (world
    frame) and a torque on the rocker (body frame); ``law`` one more."""
    a, b, c, d = 0.3, 1.0, 0.8, 1.0

    def rod(m, L):
        return pq.RigidBody(m, (L / 2, 0.0, 0.0), np.diag([1e-3, m * L * L / 12, m * L * L / 12]))

    laws = [pq.SpringDamper("coupler", (0.5, 0.0, 0.0), "rocker", (0.4, 0.0, 0.0), 40.0, damping=2.0, length=0.3),
            pq.SpringDamper("crank", (0.3, 0.0, 0.0), None, (0.2, 0.5, 0.0), 25.0, damping=0.5, length=0.1),
            pq.JointSpring("coupler", 8.0, damping=0.3, q_ref=0.2), pq.JointForce("crank", [1.5]),
            pq.Force("coupler", (0.5, -2.0, 0.3), point=(0.7, 0.0, 0.0)),
            pq.Torque("rocker", (0.0, 0.1, -0.8), frame="body")] + ([law] if law else [])
    tree = pq.System({"crank": rod(1.0, a), "rocker": rod(1.5, c), "coupler": rod(2.0, b)},
                     {"crank": pq.Revolute(axis="z"), "rocker": pq.Revolute(axis="z", r_pn=(d, 0.0, 0.0)),
                      "coupler": pq.Revolute(parent="crank", axis="z", r_pn=(a, 0.0, 0.0))},
                     gravity=(0.0, -9.81, 0.0), forces=laws)

    def closure(q, t):
        return [a * np.cos(q[0]) + b * np.cos(q[0] + q[2]) - d - c * np.cos(q[1]),
                a * np.sin(q[0]) + b * np.sin(q[0] + q[2]) - c * np.sin(q[1])]

    theta2, theta3 = pq.scenes.mechanisms.four_bar_angles(0.5, a, b, c, d)
    return ConstrainedSystem(tree, phi=closure, independent=[0], q0=(0.5, theta3, theta2 - 0.5), s_dot0=[3.0])


def _driven_four_bar():
    """The loaded four-bar with one more law, a force given as a callable of t (compiled by numba)."""
    return _loaded_four_bar(pq.Force("rocker", lambda t, q, s_dot: np.array([0.0, np.sin(t), 0.0])))


MODELS = {name: pq.scenes.SCENES[name].build for name in COMPILED_SCENES} | {"loaded_four_bar": _loaded_four_bar,
                                                                             "driven_four_bar": _driven_four_bar}


@pytest.mark.parametrize("name", MODELS)
def test_the_compiled_call_gives_the_numpy_paths_accelerations_and_multipliers(name):
    """… on every scene the kernel takes, and on a loop under every kind of compiled force law
    (whose loads the kernel adds by the fast evaluator's own loop, projeq.assembly.loads)."""
    model = MODELS[name]()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert model.compiled_kernel() is not None
        assert "one compiled call" in model.evaluator().reason
    for q, s_dot, t in _states(model):
        s_ddot_tree, lam = model.accelerations_tree(q, s_dot, t)
        reference, A_s, M, b = model._projected_accelerations(q, s_dot, t, None)
        lam_reference = np.linalg.lstsq(A_s.T, M @ reference + b, rcond=None)[0]
        assert _close(s_ddot_tree, reference)
        assert _close(lam, lam_reference)
        dense, lam_dense = model.accelerations_tree(q, s_dot, t, method="dense")
        assert _close(s_ddot_tree, dense) and _close(lam, lam_dense)
        assert np.array_equal(model.accelerations(q, s_dot, t), s_ddot_tree[model.independent])
        assert np.array_equal(model.evaluator().accelerations(q, s_dot, t), s_ddot_tree[model.independent])
        # a complex step through the evaluator takes the numpy path (the kernel is real): its imaginary part kept
        step = model.evaluator().accelerations(q, s_dot + 1e-20j, t)
        assert np.iscomplexobj(step) and _close(step.real, reference[model.independent])
        x_dot = model.evaluator().state_derivative(t, np.concatenate((q, s_dot)))  # simulate's right-hand side
        assert _close(x_dot, np.concatenate((model.q_dot(q, s_dot, t), reference[model.independent])))


@pytest.mark.parametrize("name, rule, constant", [("four_bar", "partitioned", 1e8), ("n_four_bar", "tangent", 1e-6),
                                                  ("loaded_four_bar", "partitioned", 1e8),
                                                  ("andrews_squeezer", "tangent", 1e-6)])
def test_the_kernel_interpreted_gives_the_compiled_numbers(name, rule, constant):
    """The kernel's source run as plain Python (Φ itself, the callees uncompiled) is the compiled
    algorithm step by step: the same s̈_tree, A_s, M and b to round-off."""
    model = MODELS[name]()
    interpreted = CompiledClosure(model.tree, model.n_c, model._phi, rule, (constant,), compiled=False)
    for q, s_dot, t in _states(model, 2):
        expected = model.compiled_kernel().accelerations(model, q, s_dot, t)
        found = interpreted.accelerations(model, q, s_dot, t)
        assert all(_close(a, b) for a, b in zip(found, expected))


def test_the_kernels_linear_algebra_equals_numpys():
    """The kernel's inverse and Cholesky solve equal numpy's to 100 ε relative (measured 2.0e-15 and
    2.7e-16 on these matrices; the bounds were 1e-12)."""
    rng = np.random.default_rng(3)
    exact = 100 * np.finfo(float).eps
    for m in (1, 2, 4):
        A = rng.standard_normal((m, m))
        assert np.allclose(compiled._inverse(A), np.linalg.inv(A), rtol=exact, atol=0.0)
        D, x = A @ A.T + m * np.eye(m), rng.standard_normal(m)
        expected = np.linalg.solve(D, x)
        L = D.copy()
        assert kernels.cholesky(L, m, 1e-13)
        kernels.cholesky_solve(L, m, x)
        assert np.allclose(x, expected, rtol=exact, atol=0.0)
    assert np.all(np.isinf(compiled._inverse(np.array([[1.0, 2.0], [2.0, 4.0]]))))
    assert not kernels.cholesky(np.array([[1.0, 1.0], [1.0, 1.0]]), 2, 1e-13)


def _pendulum(phi):
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return ConstrainedSystem(tree, phi=phi, q0=[0.6, -0.8], independent=[0])


def test_a_simulation_by_the_compiled_right_hand_side_equals_the_numpy_paths():
    """simulate takes ẋ = (q̇, s̈) from the compiled call (the evaluator's state_derivative); the
    four-bar over 0.5 s ends where the numpy path's right-hand side takes it: the two differ by round-off
    per call, and the runs by 9.1e-15 in q and 1.1e-13 in ṡ (at most 2.8e-14 and 1.4e-13 over
    t_end = 0.3, 0.5, 1 s and rtol = 1e-9, 1e-10, 1e-11; the bounds are 10 times those, were 1e-8 and 1e-7)."""
    model = pq.scenes.four_bar()
    assert hasattr(model.evaluator(), "state_derivative")
    compiled_run = pq.simulate(model, 0.5, rtol=1e-10, atol=1e-12)
    numpy_model = pq.scenes.four_bar()
    numpy_model._compiled = None  # the numpy path, as for a Φ numba cannot compile
    assert not hasattr(numpy_model.evaluator(), "state_derivative")
    numpy_run = pq.simulate(numpy_model, 0.5, rtol=1e-10, atol=1e-12)
    assert np.abs(compiled_run.q[-1] - numpy_run.q[-1]).max() < 3e-13
    assert np.abs(compiled_run.s_dot[-1] - numpy_run.s_dot[-1]).max() < 1.5e-12


def test_a_phi_numba_cannot_compile_warns_once_naming_it_and_keeps_the_numpy_numbers():
    geometry = {"length": 1.0}  # a dict: numba cannot type it

    def rod_from_a_dict(q, t):
        return [np.sqrt(q[0] ** 2 + q[1] ** 2) - geometry["length"]]

    model = _pendulum(rod_from_a_dict)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = model.evaluator()
        s_ddot = [ev.accelerations(model.q0, np.array([0.4]), 0.0) for _ in range(3)]
        model.evaluator()
    warned = [w for w in said if issubclass(w.category, UncompiledClosureWarning)]
    assert len(warned) == 1 and "rod_from_a_dict" in str(warned[0].message)
    assert model.compiled_kernel() is None
    assert "not in one compiled call: numba cannot compile Φ (test_a_phi_numba_cannot" in ev.reason
    reference = model._projected_accelerations(model.q0, np.array([0.4]), 0.0, None)[0][model.independent]
    assert all(np.array_equal(value, reference) for value in s_ddot)
    # the same Φ written on scalars compiles, and gives the same motion
    same = _pendulum(lambda q, t: [np.sqrt(q[0] ** 2 + q[1] ** 2) - 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert same.compiled_kernel() is not None
        assert _close(same.accelerations(same.q0, np.array([0.4])), reference)


class _Profile:
    """A Python object numba cannot read."""

    def value(self, t):
        return np.sin(t)


def _pythonic_four_bar():
    """The loaded four-bar with one more law, a force given as a callable numba cannot compile."""
    profile = _Profile()
    return _loaded_four_bar(pq.Force("rocker", lambda t, q, s_dot: np.array([0.0, profile.value(t), 0.0])))


def _planar_pendulum():
    """A disc on a Planar joint (a joint that states its own relative motion), its centre held on
    a circle."""
    tree = pq.System({"bob": pq.RigidBody(1.0, (0.0, 0.0, 0.0), 0.1 * np.eye(3))}, {"bob": pq.Planar()},
                     gravity=(0, -9.81, 0))
    return ConstrainedSystem(tree, phi=lambda q, t: [q[0] ** 2 + q[1] ** 2 - 1.0], q0=[1.0, 0.0, 0.0],
                             independent=[1, 2])


class _Shaker:
    """A Python object numba cannot read: its method gives the base's motion."""

    def motion(self, t):
        return 0.1 * np.sin(t), 0.1 * np.cos(t), -0.1 * np.sin(t)


def _shaken_pendulum():
    """The pendulum of :func:`_pendulum` on a base shaken along y by a Prescribed joint whose motion
    calls a Python object's method (numba cannot compile it: the joint states its own relative motion
    in Python, with no coordinate of its own)."""
    shaker = _Shaker()
    shake = pq.Prescribed(pq.Prismatic(axis="y"), lambda t: shaker.motion(t))
    tree = pq.System({"base": pq.Frame(), "x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"base": shake, "x": pq.Prismatic(parent="base", axis="x"),
                      "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return ConstrainedSystem(tree, phi=lambda q, t: [q[0] ** 2 + q[1] ** 2 - 1.0], q0=[0.6, -0.8], independent=[0])


def _breathing_circle():
    """The pendulum of :func:`_pendulum` on a circle whose radius breathes, |q| = 1 + 0.1 sin t: Φ a
    function of t (a cut joint's dependence on t through a prescribed joint compiles; a function's
    does not)."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - 1.0 - 0.1 * np.sin(t)], q0=[0.6, -0.8],
                             independent=[0])


def _driven_bead():
    """A bead on a circle in the xz-plane, driven along y at a given speed: a Pfaffian row
    A q̇ = b with b ≠ 0 (ẏ = 0.1 m/s)."""
    tree = pq.System({"x": pq.Frame(), "y": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "y": pq.Prismatic(parent="x", axis="y"),
                      "bob": pq.Prismatic(parent="y", axis="z")}, gravity=(0, 0, -9.81))
    return ConstrainedSystem(tree, phi=lambda q, t: [q[0] ** 2 + q[2] ** 2 - 1.0], A=lambda q, t: [[0.0, 1.0, 0.0]],
                             b=lambda q, t: [0.1], q0=[0.6, 0.0, -0.8], independent=[0])


class _OwnRule(ConstrainedSystem):
    """Coordinate partitioning restated by a subclass (its own F, here the inherited one)."""

    def F(self, q, t=0.0, constraint_matrix=None):
        return super().F(q, t, constraint_matrix)


OUTSIDE = {
    "Pfaffian with b ≠ 0": (_driven_bead, "Pfaffian constraints A(q, t) q̇ = b(q, t) with b ≠ 0"),
    "callable load numba refuses": (_pythonic_four_bar, "force law 6 (Force) runs in Python: numba cannot compile"),
    "joint with K ≠ E": (_planar_pendulum, "joints with q̇ ≠ ṡ (K ≠ E): 'bob' (Planar)"),
    "joint stating its motion": (_shaken_pendulum, "joint 'base' (Prescribed) states its own relative motion"),
    "Baumgarte's correction": (lambda: pq.scenes.four_bar(correction="baumgarte"), "correction 'baumgarte'"),
    "Φ a function of t": (_breathing_circle, "Φ depends on t (a function of t, not cut joints)"),
    "own rule": (lambda: _OwnRule(pq.scenes.four_bar().tree, phi=pq.scenes.four_bar()._phi,
                                  q0=pq.scenes.four_bar().q0, independent=[0]), "F by its own rule"),
}


@pytest.mark.parametrize("case", OUTSIDE)
def test_models_outside_the_compiled_call_say_so_once_naming_the_piece_and_keep_the_numpy_path(case):
    """No silent fall-back: the first look for the kernel (the evaluator simulate takes) warns once
    per model, naming the piece that keeps it out; later evaluations do not warn again, and the
    numbers are the numpy path's."""
    build, why = OUTSIDE[case]
    model = build()
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = model.evaluator()
        q, s_dot = model.q0, model.s_dot0
        values = [ev.accelerations(q, s_dot, 0.0) for _ in range(2)]
        assert model.compiled_kernel() is None and model.evaluator() is not None
    warned = [str(w.message) for w in said if issubclass(w.category, UncompiledClosureWarning)]
    assert len(warned) == 1 and why in warned[0] and "not one compiled call" in warned[0], warned
    assert f"not in one compiled call: {why}" in ev.reason
    reference = model._tree_accelerations(q, s_dot, 0.0, "dense")[0][model.independent]
    assert all(_close(value, reference) for value in values)


def test_a_degenerate_partition_met_by_the_compiled_call_raises_the_numpy_paths_error():
    """With crank and coupler in line (|X| = a + b for the coupler tip X) the rocker is at an
    extreme position and its rate cannot be the independent velocity: the kernel flags it, and
    the numpy path names it."""
    model = pq.scenes.four_bar().with_independent([1], repivot=False)
    a, b, c, d = 0.3, 1.0, 0.8, 1.0
    x = ((a + b) ** 2 - c * c + d * d) / (2 * d)
    y = np.sqrt((a + b) ** 2 - x * x)
    q = np.array([np.arctan2(y, x), np.arctan2(y, x - d), 0.0])
    assert np.abs(model.phi(q)).max() < 1e-14
    kernel = model.compiled_kernel()
    assert kernel.accelerations(model, q, np.array([0.5]), 0.0) is None
    with pytest.raises(ValueError, match="independent: the dependent velocities"):
        model.accelerations_tree(q, np.array([0.5]), 0.0)


def test_a_force_law_without_a_value_in_the_compiled_call_raises_the_numpy_paths_error():
    """A spring-damper whose two points coincide (the crank's pivot and the ground's origin) has no
    direction: the kernel flags it, and the numpy path names the law."""
    model = _loaded_four_bar(pq.SpringDamper("crank", (0.0, 0.0, 0.0), None, (0.0, 0.0, 0.0), 1.0))
    assert model.compiled_kernel().accelerations(model, model.q0, model.s_dot0, 0.0) is None
    with pytest.raises(ValueError, match="the two points coincide"):
        model.accelerations_tree(model.q0, model.s_dot0, 0.0)


@pytest.mark.parametrize("shape", [(1, 2), (2, 3), (4, 5), (5, 5), (6, 7)])
def test_the_kernels_jacobi_svd_equals_lapacks(shape):
    """One-sided Jacobi (Demmel & Veselić 1992) against numpy's LAPACK SVD: the same singular
    values to round-off (a redundant row: a zero one), U Σ Vᵀ = A, V orthogonal, and the rows of
    Vᵀ beyond the rank in the null space."""
    m, n = shape
    A = np.random.default_rng(m * n).standard_normal(shape)
    if m == n:
        A[-1] = A[0] + A[1]  # a redundant row, as Bricard's
    U, sigma, Vt = compiled._svd(A)
    expected = np.linalg.svd(A, compute_uv=False)
    r = len(expected)
    assert np.abs(sigma[:r] - expected).max() <= 1e-14 * expected[0]
    assert np.abs(sigma[r:]).max(initial=0.0) <= 1e-14 * expected[0]
    assert np.abs((U[:, :r] * sigma[:r]) @ Vt[:r] - A).max() <= 1e-14 * expected[0]
    assert np.abs(Vt @ Vt.T - np.eye(n)).max() <= 1e-14
    rank = int(np.sum(expected > 1e-12 * expected[0]))
    assert np.abs(A @ Vt[rank:].T).max(initial=0.0) <= 1e-14 * expected[0]


def _with_singular_values(rng, m: int, n: int, sigma) -> np.ndarray:
    """U diag(σ) Vᵀ, m × n, with random orthogonal U, V (QR of Gaussian matrices)."""
    U = np.linalg.qr(rng.standard_normal((m, m)))[0]
    V = np.linalg.qr(rng.standard_normal((n, n)))[0]
    S = np.zeros((m, n))
    S[np.arange(len(sigma)), np.arange(len(sigma))] = sigma
    return U @ S @ V.T


def _svd_cases():
    """(name, A): m ≤ 8, n ≤ 9 — full rank, rank-deficient (some σ exactly 0 in exact arithmetic),
    repeated singular values, zero rows, more rows than columns, rank 0."""
    rng = np.random.default_rng(2026)
    for m, n in ((1, 1), (1, 4), (3, 5), (6, 7), (8, 9), (5, 5), (7, 3), (8, 8)):
        p = min(m, n)
        yield f"{m}x{n} full rank", _with_singular_values(rng, m, n, rng.uniform(0.1, 1.0, p))
        if p > 1:
            yield f"{m}x{n} rank {p - 1}", _with_singular_values(rng, m, n, [*rng.uniform(0.1, 1.0, p - 1), 0.0])
            yield f"{m}x{n} repeated", _with_singular_values(rng, m, n, [0.7] * (p // 2) + [0.3] * (p - p // 2))
            A = _with_singular_values(rng, m, n, rng.uniform(0.1, 1.0, p))
            A[rng.choice(m, size=max(1, m // 3), replace=False)] = 0.0
            yield f"{m}x{n} zero rows", A
        yield f"{m}x{n} rank 0", np.zeros((m, n))


@pytest.mark.parametrize("svd", [compiled._jacobi_svd, compiled._lapack_svd], ids=["jacobi", "lapack"])
def test_the_kernels_svd_gives_lapacks_singular_values_null_space_and_pseudo_inverse(svd):
    """Both of the kernels' SVDs — QR-preconditioned one-sided Jacobi (Drmač & Veselić 2008; norms
    updated by the rotations, de Rijk 1989), and LAPACK's in the form the kernels read — against
    numpy's LAPACK SVD on matrices of the sizes of a loop's A_s: the same singular values, the same
    null space (its orthogonal projector: the basis of a null space of dimension > 1 is not unique)
    and the same pseudo-inverse V Σ⁺ Uᵀ over the nonzero singular values (unique, also where
    singular values repeat), each to 3e-14 of its size; U Σ Vᵀ = A and V orthogonal (Jacobi's
    measured at most 2.7e-15 of the size, V's orthogonality; the bound was 1e-13)."""
    tol = 3e-14
    for name, A in _svd_cases():
        m, n = A.shape
        U, sigma, Vt = svd(A)
        expected = np.linalg.svd(A, compute_uv=False)
        scale = max(expected.max(initial=0.0), 1e-300)
        rank = int(np.sum(expected > 1e-10 * scale))
        assert np.abs(sigma[:len(expected)] - expected).max() <= tol * scale, name
        assert np.abs(sigma[len(expected):]).max(initial=0.0) <= tol * scale, name
        assert np.all(np.diff(sigma) <= 0.0), name
        assert np.abs((U * sigma) @ Vt - A).max() <= tol * scale, name
        assert np.abs(Vt @ Vt.T - np.eye(n)).max() <= tol, name
        null = Vt[rank:].T @ Vt[rank:]
        expected_null = np.eye(n) - np.linalg.pinv(A, rcond=1e-10) @ A
        assert np.abs(null - expected_null).max() <= tol, name
        pseudo_inverse = (Vt[:rank].T / sigma[:rank]) @ U[:, :rank].T
        expected_inverse = np.linalg.pinv(A, rcond=1e-10)
        assert np.abs(pseudo_inverse - expected_inverse).max() <= tol * max(1.0, np.abs(expected_inverse).max()), name


def test_the_kernels_svd_is_lapacks_from_its_size_on_and_nan_where_lapack_refuses():
    """_svd takes LAPACK's from LAPACK_SVD_SIZE entries on (the A02 N-four-bar's 80 × 81 with N = 40:
    the same factors as _lapack_svd's, bit for bit) and Jacobi's below (12 × 13); the two agree at
    80 × 81 to 1e-13 in σ and the null space (measured 7.7e-15 and 3.3e-16); A with a NaN gives NaN
    factors, which the kernel flags, not LAPACK's error."""
    rng = np.random.default_rng(80)
    large, small = rng.standard_normal((80, 81)), rng.standard_normal((12, 13))
    assert large.size >= compiled.LAPACK_SVD_SIZE > small.size
    for A, routine in ((large, compiled._lapack_svd), (small, compiled._jacobi_svd)):
        assert all(np.array_equal(a, b) for a, b in zip(compiled._svd(A), routine(A)))
    (_, sigma_l, Vt_l), (_, sigma_j, Vt_j) = compiled._lapack_svd(large), compiled._jacobi_svd(large)
    assert np.abs(sigma_l - sigma_j).max() <= 1e-13 * sigma_l[0]
    assert np.abs(np.outer(Vt_l[-1], Vt_l[-1]) - np.outer(Vt_j[-1], Vt_j[-1])).max() <= 1e-13
    large[3, 4] = np.nan
    assert all(np.isnan(factor).all() for factor in compiled._lapack_svd(large))


def test_a_closure_that_calls_lapack_holds_blas_to_one_thread_while_its_kernel_runs():
    """The A02 N-four-bar with N = 10 (A_s 20 × 21: LAPACK's SVD) runs its kernel with every BLAS library at
    one thread and gives the threads back after (on a machine of one core both are 1: then only the latter
    is shown); its loop model says so to the compiled loop, which holds them the same way. The four-bar
    (A_s 2 × 3: Jacobi's) leaves them alone."""
    from threadpoolctl import threadpool_info

    from projeq.scenes.iftomm import n_four_bar

    def blas_threads():
        return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"]

    before = blas_threads()
    model, small = n_four_bar(10), pq.scenes.four_bar()
    closure = model.compiled_kernel()
    assert closure.lapack and not small.compiled_kernel().lapack
    assert closure.loop_model(model).lapack
    seen, call = [], closure._kernel_call
    closure._kernel_call = lambda *arguments: (seen.append(blas_threads()), call(*arguments))[1]
    closure.minimal_accelerations(model, model.q0, model.s_dot0, 0.0)
    assert seen[0] == [1] * len(before)
    assert blas_threads() == before


def test_the_closure_linalg_benchmark_runs_and_both_variants_give_the_same_accelerations(capsys):
    """benchmarks/closure_linalg.py --quick runs (the kernels of both variants interpreted: nothing to
    compile), and the kernels with their hand-written SVD (QR-preconditioned one-sided Jacobi) and
    Gauss–Jordan inverse give the s̈_tree of the same kernels with LAPACK's (numba's np.linalg, as the
    numpy path): another algorithm for the same null space, pseudo-inverse and A_dep⁻¹, agreeing to
    round-off (measured 3.7e-16 four-bar, 1.1e-17 simple pendulum, 2.9e-15 double four-bar, relative
    to max(1, |s̈_tree|); bound 100 ε)."""
    spec = importlib.util.spec_from_file_location("closure_linalg", BENCHMARKS / "closure_linalg.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    found = module.main(["--quick"])
    assert [row["model"] for row in found["rows"]] == ["four_bar", "simple_pendulum", "A02 N=2"]
    assert not found["compile"]
    assert max(row["difference"] for row in found["rows"]) <= 100 * np.finfo(float).eps, found["rows"]
    assert "LAPACK/hand" in capsys.readouterr().out


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e-6])
def test_a_cut_joint_is_the_kernels_own_and_equals_the_hand_written_closure(scale):
    """The loaded four-bar's loop stated as a cut joint (PinClosure: coupler tip on rocker tip):
    the compiled kernel evaluates its Φ, A_s and γ = Φ″(q̇, q̇) itself — the chain's body Jacobians
    and the tip's acceleration at s̈ = 0, no complex step — and they equal those of the hand-written
    closure a e(θ₁) + b e(θ₁ + θ₂) − d e_x − c e(θ₃) (its complex step), and so do s̈_tree and λ, at
    rates 1, 1e-3 and 1e-6 of 3 rad/s: γ ∝ |q̇|² keeps its relative accuracy at any speed (measured
    at every scale: A_s 4e-16, γ 4e-14 — the hand-written closure's stencil —, s̈_tree and λ 2e-15)."""
    hand = _loaded_four_bar()
    pin = pq.PinClosure(hand.tree, "coupler", (1.0, 0.0, 0.0), "rocker", (0.8, 0.0, 0.0), axes="xy")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # compiled, exact
        system = ConstrainedSystem(hand.tree, phi=pin, independent=[0], q0=hand.q0)
        assert system.compiled_kernel() is not None and system._cut_joint_rows() is not None
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = hand.project(hand.q0 + 0.4 * rng.standard_normal(3))
        s_dot = scale * 3.0 * rng.uniform(-1, 1, 1)
        s_dot_tree = hand.tree_velocities(q, s_dot)
        assert np.abs(system.phi(q) - hand.phi(q)).max() <= 1e-15
        assert _close(system.phi_q(q), hand.phi_q(q))
        gamma = hand.gamma(q, s_dot_tree)
        assert np.abs(system.gamma(q, s_dot_tree) - gamma).max() <= RTOL * np.abs(gamma).max()
        s_ddot_tree, lam = system.accelerations_tree(q, s_dot)
        expected, lam_expected = hand.accelerations_tree(q, s_dot)
        assert _close(s_ddot_tree, expected) and _close(lam, lam_expected)


def test_a_cut_joints_exact_jacobian_is_the_hand_written_closures():
    """∂ẋ/∂x of the loaded four-bar closed by a cut joint, by the complex step through the kernel's
    own cut-joint rows (an analytic function of q and q̇: at q + i h e_j they give the exact
    derivative), equals that of the hand-written closure, whose Φ_q and γ under the outer step come
    from the nested stencils of projeq.analysis.differentiation (their error, ~1e-12 relative, sets
    the bound; measured 2.4e-12)."""
    from projeq.analysis.jacobians import state_jacobian

    hand = _loaded_four_bar()
    pin = pq.PinClosure(hand.tree, "coupler", (1.0, 0.0, 0.0), "rocker", (0.8, 0.0, 0.0), axes="xy")
    system = ConstrainedSystem(hand.tree, phi=pin, independent=[0], q0=hand.q0)
    assert system._cut_joint_rows().complex_safe
    x = np.concatenate((hand.q0, [3.0]))
    expected, how = state_jacobian(hand, x, 0.0)
    found, _ = state_jacobian(system, x, 0.0)
    assert how == "exact"
    assert np.abs(found - expected).max() <= 1e-11 * np.abs(expected).max()


def test_an_augmented_system_takes_the_cut_joints_compiled_rows():
    """The augmented Lagrangian (AugmentedSystem: its own rule, not one compiled call) of the loaded
    four-bar closed by a cut joint reads Φ_q and γ from the compiled cut-joint rows (not the numpy
    path's complex steps through the poses), and its accelerations equal those of the same system
    with the hand-written closure at moving consistent states (same algorithm, the rows from another
    statement: 8e-14 relative, measured 8.0e-15, was 1e-12; s̈ 511 µs, 3214 µs with the numpy rows,
    560 µs with the hand-written closure)."""
    from projeq.constraints.augmented import AugmentedSystem

    hand = _loaded_four_bar()
    pin = pq.PinClosure(hand.tree, "coupler", (1.0, 0.0, 0.0), "rocker", (0.8, 0.0, 0.0), axes="xy")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UncompiledClosureWarning)  # its own rule: said, and not the point here
        pinned = AugmentedSystem(hand.tree, phi=pin, q0=hand.q0)
        written = AugmentedSystem(hand.tree, phi=hand._phi, q0=hand.q0)
        assert pinned._cut_joint_rows() is not None and pinned.compiled_kernel() is None
        rng = np.random.default_rng(4)
        for _ in range(3):
            q = hand.project(hand.q0 + 0.4 * rng.standard_normal(3))
            s_dot = hand.tree_velocities(q, 3.0 * rng.uniform(-1, 1, 1))  # on A_s ṡ = 0
            expected = written.accelerations(q, s_dot)
            error = np.abs(pinned.accelerations(q, s_dot) - expected).max() / np.abs(expected).max()
            assert error <= 8e-14, error
