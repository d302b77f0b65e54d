"""Bad states fed to every public evaluator of an unconstrained System (issue 37, item 1).

Wrong shapes, NaN, inf, 1e200 (finite, but its products overflow), complex and strided input,
to System.accelerations, gauss_form, mass_matrix, energy, q_dot, K, linearize and each
evaluator's own ``accelerations`` (the right-hand side :func:`projeq.simulate` calls). The public
entry points refuse each with a ValueError naming the argument; the evaluators check type,
dtype and shape before any kernel runs (before, ``chain(5).evaluator("fast").accelerations`` read
past a q of 2 entries and returned [2.7e-320, ...]), take complex states (the complex step of
projeq.analysis.jacobians) and copy strided ones, and give back a non-finite s̈ or an error for a
non-finite state, never a finite number.
"""

import warnings

import numpy as np
import pytest

import projeq as pq

EVALUATORS = ["fast", "recursive", "dense", "auto"]


@pytest.fixture(scope="module")
def chain():
    """chain(3): three rods on revolute joints, the compiled kernels' rigid path."""
    return pq.scenes.chain(3)


@pytest.fixture(scope="module")
def beam():
    """The spin-up beam: one RitzBeam on a prescribed hub, the 'hub_beam' evaluator's."""
    return pq.scenes.spin_up_beam(n_shapes=2)


def _state(system):
    """A moving state off every singularity: q0 turned by 0.3, ṡ = 0.7."""
    return system.q0 + 0.3, np.full(system.n_s, 0.7)


def _models(chain, beam):
    return {"fast": chain, "recursive": chain, "dense": chain, "auto": chain, "hub_beam": beam}


SHAPES = {
    "q-short": (lambda q, s: (q[:2], s), "^q: expected {n_q} entries, got shape \\(2,\\)"),
    "q-2d": (lambda q, s: (q[None, :], s), "^q: expected {n_q} entries, got shape \\(1, {n_q}\\)"),
    "q-scalar": (lambda q, s: (0.1, s), "^q: expected {n_q} entries, got shape \\(\\)"),
    "s_dot-long": (lambda q, s: (q, np.append(s, 1.0)), "^s_dot: expected {n_s} entries"),
    "s_dot-one": (lambda q, s: (q, s[:1]), "^s_dot: expected {n_s} entries, got shape \\(1,\\)"),
    "q-string": (lambda q, s: ("up", s), "^q: expected"),
}


@pytest.mark.parametrize("method", EVALUATORS + ["hub_beam"])
@pytest.mark.parametrize("case", sorted(SHAPES))
def test_an_evaluator_refuses_a_state_of_the_wrong_shape(chain, beam, method, case):
    """Passes if each evaluator refuses a q or ṡ of the wrong shape or type by name, before any
    kernel reads it (before: the compiled one read past a short q, [2.7e-320, −1.6e-319, ...],
    took a short ṡ as finite garbage, and a q of shape (1, n) started a 2-minute compilation
    ending in a TypingError; the reference ones raised a bare IndexError)."""
    system = _models(chain, beam)[method]
    change, message = SHAPES[case]
    q, s_dot = change(*_state(system))
    with pytest.raises(ValueError, match=message.format(n_q=system.n_q, n_s=system.n_s)):
        system.evaluator(method).accelerations(q, s_dot, 0.0)


@pytest.mark.parametrize("method", EVALUATORS + ["hub_beam"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e200], ids=["nan", "inf", "1e200"])
def test_an_evaluator_never_returns_finite_numbers_for_a_bad_state(chain, beam, method, bad):
    """Passes if each evaluator, given NaN, inf or 1e200 in ṡ (whose squares overflow in the
    velocity terms), raises or returns a non-finite s̈ (the evaluators are the unchecked
    right-hand side: projeq.simulate checks x and ẋ, the public entry points name the state)."""
    system = _models(chain, beam)[method]
    q, s_dot = _state(system)
    s_dot[-1] = bad
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            s_ddot = system.evaluator(method).accelerations(q, s_dot, 0.0)
        except (FloatingPointError, ValueError):
            return
    assert not np.all(np.isfinite(s_ddot)), f"finite s̈ {s_ddot} at ṡ = {s_dot}"


@pytest.mark.parametrize("method", EVALUATORS + ["hub_beam"])
def test_an_evaluator_copies_a_strided_state_and_takes_a_complex_one(chain, beam, method):
    """Passes if a strided view (every other entry of a longer array), a big-endian q and a list ṡ
    give the contiguous state's s̈ exactly, and a complex state (the complex step) the real one's s̈ in its real part to
    100 ε max|s̈| (measured: 4.4e-15 = 6.4 ε max|s̈|, the recursive evaluator's complex arithmetic),
    with the imaginary part of a step i h along ṡ nonzero (it is differentiated)."""
    system = _models(chain, beam)[method]
    q, s_dot = _state(system)
    ev = system.evaluator(method)
    expected = ev.accelerations(q, s_dot, 0.0)
    strided_q, strided_s = np.repeat(q, 2)[::2], np.repeat(s_dot, 2)[::2]
    assert not strided_q.flags.c_contiguous
    np.testing.assert_array_equal(ev.accelerations(strided_q, strided_s, 0.0), expected)
    big_endian = q.astype(">f8")  # as read from some files: converted, not compiled for
    np.testing.assert_array_equal(ev.accelerations(big_endian, list(s_dot), 0.0), expected)
    stepped = ev.accelerations(q.astype(complex), s_dot + 1e-20j, 0.0)
    np.testing.assert_allclose(stepped.real, expected, rtol=0.0, atol=100 * np.finfo(float).eps * np.abs(expected).max())
    assert np.abs(stepped.imag).max() > 0.0


def _public(system):
    """Each public evaluator of ``system`` as f(q, ṡ)."""
    return {
        "accelerations": system.accelerations,
        "gauss_form": system.gauss_form,
        "mass_matrix": lambda q, s_dot: system.mass_matrix(q),
        "energy": system.energy,
        "q_dot": system.q_dot,
        "K": lambda q, s_dot: system.K(q),
        "linearize": lambda q, s_dot: pq.linearize(system, q, s_dot, require_steady=False),
    }


PUBLIC = ["accelerations", "gauss_form", "mass_matrix", "energy", "q_dot", "K", "linearize"]
TAKES_S_DOT = ["accelerations", "gauss_form", "energy", "q_dot", "linearize"]


@pytest.mark.parametrize("entry, case", [(entry, case) for entry in PUBLIC for case in sorted(SHAPES)
                                         if entry in TAKES_S_DOT or not case.startswith("s_dot")])
def test_a_public_evaluator_refuses_a_state_of_the_wrong_shape(chain, entry, case):
    """Passes if each public entry point refuses a q (or ṡ) of the wrong shape or type by name
    (before: K and q_dot took a short q as arrays and answered, or raised a bare numpy error)."""
    change, message = SHAPES[case]
    q, s_dot = change(*_state(chain))
    with pytest.raises(ValueError, match=message.format(n_q=chain.n_q, n_s=chain.n_s)):
        _public(chain)[entry](q, s_dot)


@pytest.mark.parametrize("entry", [e for e in PUBLIC if e not in ("q_dot", "K")])
@pytest.mark.parametrize("bad", [np.nan, np.inf], ids=["nan", "inf"])
def test_a_public_evaluator_refuses_a_non_finite_state(chain, entry, bad):
    """Passes if NaN or inf in q is refused by name at the entry point (q_dot and K take arrays
    unchecked, as the integrators pass them: see test_q_dot_and_K_propagate_what_they_are_given)."""
    q, s_dot = _state(chain)
    q[1] = bad
    with pytest.raises(ValueError, match=r"^q: non-finite entries \(NaN or inf\) at flat index \[1\]"):
        _public(chain)[entry](q, s_dot)


@pytest.mark.parametrize("entry", ["accelerations", "gauss_form", "energy", "linearize"])
def test_a_state_that_overflows_is_named(chain, entry):
    """Passes if ṡ = 1e200 (finite, but ω² overflows in the velocity terms: s̈ was NaN "without
    a word") raises a ValueError naming ṡ and its size. The reference: (1e200)² = inf in floating
    point, checked here."""
    with np.errstate(over="ignore"):
        assert np.isinf(np.float64(1e200) ** 2)
    q, s_dot = _state(chain)
    s_dot[0] = 1e200
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with pytest.raises(ValueError, match=r"^s_dot: .* is not finite at this state \(largest \|s_dot\| = 1e\+200\)"):
            _public(chain)[entry](q, s_dot)


@pytest.mark.parametrize("entry", [e for e in PUBLIC if e not in ("energy",)])
def test_a_complex_state_is_refused_not_cast(chain, entry):
    """Passes if a complex q given as a list (a user's, not the complex step's arrays) is refused
    by name; before, numpy dropped its imaginary part with a ComplexWarning and the answer was
    that of the real part. q_dot and K take complex arrays: the complex step differentiates them."""
    q, s_dot = _state(chain)
    q = list(q.astype(complex) + 0.5j)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning either
        with pytest.raises(ValueError, match=r"^q: expected real numbers, got complex ones \(entry 0 is "):
            _public(chain)[entry](q, s_dot if entry != "q_dot" else list(s_dot))


def test_energy_of_a_complex_state_is_the_complex_step(chain):
    """Passes if energy at a complex state is complex (the complex step of the energy gradient,
    documented): its imaginary part over h is dT/dṡ₀ · 1 = (M ṡ)₀, to 100 ε relative (measured 1.8e-16;
    was 1e-12), not dropped."""
    q, s_dot = _state(chain)
    kinetic, _ = chain.energy(q.astype(complex), s_dot + np.eye(chain.n_s)[0] * 1e-20j)
    expected = (chain.mass_matrix(q) @ s_dot)[0]
    assert abs(kinetic.imag / 1e-20 - expected) <= 100 * np.finfo(float).eps * abs(expected)


@pytest.mark.parametrize("entry", PUBLIC)
def test_a_public_evaluator_takes_a_strided_state(chain, entry):
    """Passes if every entry point gives the contiguous state's answer exactly for strided views."""
    q, s_dot = _state(chain)
    strided_q, strided_s = np.repeat(q, 2)[::2], np.repeat(s_dot, 2)[::2]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        expected, got = _public(chain)[entry](q, s_dot), _public(chain)[entry](strided_q, strided_s)
    parts = (lambda r: list(r) if isinstance(r, tuple) or entry == "linearize" else [r])  # (M, b), (T, V), (A, B)
    for a, b in zip(parts(got), parts(expected), strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("entry", ["q_dot", "K"])
def test_q_dot_and_k_propagate_what_they_are_given(chain, entry):
    """Passes if q_dot and K, which take arrays unchecked (the integrators' calls), give NaN for NaN
    (never a finite number), and refuse NaN in a list by name."""
    q, s_dot = _state(chain)
    q[0], s_dot[0] = np.nan, np.nan
    assert np.isnan(_public(chain)[entry](q, s_dot)).any() or entry == "K"  # K = E of revolute joints
    with pytest.raises(ValueError, match=r"^q: non-finite entries"):
        _public(chain)[entry](list(q), list(s_dot))
