"""The constrained s̈ in one compiled call (projeq.constraints.compiled): Φ compiled by numba,
its complex-step derivatives, the partition and the projection of the tree's compiled Gauss form
give the s̈_tree and λ of the numpy path (the same stencils, numpy linear algebra) to round-off,
and those of the dense reference form (Σ J_nᵀ M_n J_n, docs/theory.md §5, an independent
formulation of M and b); a Φ numba cannot compile warns once, naming it, and keeps the numpy path.
"""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import kernels
from projeq.constraints import compiled
from projeq.constraints.compiled import CompiledClosure, UncompiledClosureWarning
from projeq.constraints.partitioned import ConstrainedSystem

# the same stencils and the same M, b (tests/assembly/test_fast.py: ~1e-15 relative), summed in
# another order: measured ≤ 2e-15 of max(1, |s̈_tree|∞) on these scenes
RTOL = 1e-13
COMPILED_SCENES = ("four_bar", "quick_return", "simple_pendulum", "n_four_bar", "bricard")


def _states(model, count=3):
    rng = np.random.default_rng(5)
    return [(model.q0, model.s_dot0 + 2 * rng.standard_normal(model.n_s), float(t)) for t in rng.uniform(0, 1, count)]


def _close(a, b) -> bool:
    return bool(np.abs(a - b).max(initial=0.0) <= RTOL * max(1.0, np.abs(b).max(initial=0.0)))


@pytest.mark.parametrize("name", COMPILED_SCENES)
def test_the_compiled_call_gives_the_numpy_paths_accelerations_and_multipliers(name):
    model = pq.scenes.SCENES[name].build()
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
        x_dot = model.evaluator().state_derivative(t, np.concatenate((q, s_dot)))  # simulate's right-hand side
        assert _close(x_dot, np.concatenate((model.q_dot(q, s_dot, t), reference[model.independent])))


@pytest.mark.parametrize("name, rule, constant", [("four_bar", "partitioned", 1e8), ("n_four_bar", "tangent", 1e-6)])
def test_the_kernel_interpreted_gives_the_compiled_numbers(name, rule, constant):
    """The kernel's source run as plain Python (Φ itself, the callees uncompiled) is the compiled
    algorithm step by step: the same s̈_tree, A_s, M and b to round-off."""
    model = pq.scenes.SCENES[name].build()
    interpreted = CompiledClosure(model.tree, model.n_c, model._phi, rule, (constant,), compiled=False)
    for q, s_dot, t in _states(model, 2):
        expected = model.compiled_kernel().accelerations(model, q, s_dot, t)
        found = interpreted.accelerations(model, q, s_dot, t)
        assert all(_close(a, b) for a, b in zip(found, expected))


def test_the_kernels_linear_algebra_equals_numpys():
    rng = np.random.default_rng(3)
    for m in (1, 2, 4):
        A = rng.standard_normal((m, m))
        assert np.allclose(compiled._inverse(A), np.linalg.inv(A), rtol=1e-12, atol=1e-12)
        D, x = A @ A.T + m * np.eye(m), rng.standard_normal(m)
        expected = np.linalg.solve(D, x)
        L = D.copy()
        assert kernels.cholesky(L, m, 1e-13)
        kernels.cholesky_solve(L, m, x)
        assert np.allclose(x, expected, rtol=1e-12, atol=1e-14)
    assert np.all(np.isinf(compiled._inverse(np.array([[1.0, 2.0], [2.0, 4.0]]))))
    assert not kernels.cholesky(np.array([[1.0, 1.0], [1.0, 1.0]]), 2, 1e-13)


def _pendulum(phi):
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return ConstrainedSystem(tree, phi=phi, q0=[0.6, -0.8], independent=[0])


def test_a_simulation_by_the_compiled_right_hand_side_equals_the_numpy_paths():
    """simulate takes ẋ = (q̇, s̈) from the compiled call (the evaluator's state_derivative); the
    four-bar over 0.5 s ends where the numpy path's right-hand side takes it, to the integrator's
    tolerance (the two differ by round-off per call)."""
    model = pq.scenes.four_bar()
    assert hasattr(model.evaluator(), "state_derivative")
    compiled_run = pq.simulate(model, 0.5, rtol=1e-10, atol=1e-12)
    numpy_model = pq.scenes.four_bar()
    numpy_model._compiled = None  # the numpy path, as for a Φ numba cannot compile
    assert not hasattr(numpy_model.evaluator(), "state_derivative")
    numpy_run = pq.simulate(numpy_model, 0.5, rtol=1e-10, atol=1e-12)
    assert np.abs(compiled_run.q[-1] - numpy_run.q[-1]).max() < 1e-8
    assert np.abs(compiled_run.s_dot[-1] - numpy_run.s_dot[-1]).max() < 1e-7


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
    assert model.compiled_kernel() is None and "not in one compiled call: Φ does not compile" in ev.reason
    reference = model._projected_accelerations(model.q0, np.array([0.4]), 0.0, None)[0][model.independent]
    assert all(np.array_equal(value, reference) for value in s_ddot)
    # the same Φ written on scalars compiles, and gives the same motion
    same = _pendulum(lambda q, t: [np.sqrt(q[0] ** 2 + q[1] ** 2) - 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert same.compiled_kernel() is not None
        assert _close(same.accelerations(same.q0, np.array([0.4])), reference)


@pytest.mark.parametrize("name, why", [("andrews_squeezer", "force laws")])
def test_models_outside_the_compiled_call_keep_the_numpy_path_saying_why(name, why):
    model = pq.scenes.SCENES[name].build()
    assert why in compiled.unsupported(model)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UncompiledClosureWarning)  # not looked at: no warning about Φ
        assert model.compiled_kernel() is None
        assert f"not in one compiled call: {compiled.unsupported(model)}" in model.evaluator().reason


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
