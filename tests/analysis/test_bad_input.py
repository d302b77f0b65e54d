"""Bad input to projeq.analysis (linearize, eigenvalue_sweep) is refused by name where it enters.

Each message is matched from its start, so that it begins with the parameter's name; the
silently wrong answers (a NaN threshold that passed every state as steady) are shown against
the state's own derivative.
"""

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.jacobians import state_jacobians
from projeq.analysis.linearize import state_derivative

ROD = {"m": 1.0, "r_c": (0, 0, -0.5), "I_c": np.diag([0.1, 0.1, 0.01])}


def _pendulum():
    """One rod on a revolute joint about y under gravity: equilibrium at q = 0 only."""
    return pq.System({"bob": pq.RigidBody(**ROD)}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81))


@pytest.mark.parametrize("tol, problem", [
    (np.nan, r"non-finite entries \(NaN or inf\)"),
    (np.inf, r"non-finite entries \(NaN or inf\)"),
    (-1e-8, "must be positive, got -1e-08"),
    (0.0, "must be positive, got 0.0"),
], ids=["nan", "inf", "negative", "zero"])
def test_tol_must_be_a_positive_threshold(tol, problem):
    """Passes if a threshold that is no threshold is refused by name. Before: tol = NaN (or
    inf) passed the pendulum at q = 0.3 rad, where s̈ = −4.14 rad/s² (its own derivative, checked
    here), as an equilibrium and returned A; a negative tol called the equilibrium q = 0 not steady."""
    system = _pendulum()
    assert abs(state_derivative(system, np.array([0.3, 0.0]), 0.0)[1]) > 4.0  # not an equilibrium
    with pytest.raises(ValueError, match=f"^tol: {problem}"):
        pq.linearize(system, [0.3], [0.0], tol=tol)
    with pytest.raises(ValueError, match=f"^tol: {problem}"):
        pq.linearize(system, [0.0], [0.0], tol=tol)


def test_require_steady_must_be_a_bool():
    """Passes if require_steady="no" (truthy: the checks ran) is refused by name."""
    with pytest.raises(ValueError, match="^require_steady: expected True or False, got 'no'"):
        pq.linearize(_pendulum(), [0.0], [0.0], require_steady="no")


def test_inputs_as_one_string_is_not_its_letters():
    """Passes if inputs="bob" is refused with the remedy; before, its letters 'b', 'o', 'b' were
    taken as joint names ("each joint at most once, got ['b', 'o', 'b']"), and in a system with
    joints 'a' and 'b' inputs="ab" would silently have meant both."""
    with pytest.raises(ValueError, match=r"^inputs: expected a sequence of joint names, got the string 'bob' "
                                         r"\(write \['bob'\]\)"):
        pq.linearize(_pendulum(), [0.0], [0.0], inputs="bob")


def test_ignore_must_be_a_sequence():
    """Passes if ignore=0 (one index, not a sequence) is refused by name, not a bare
    "TypeError: 'int' object is not iterable"."""
    with pytest.raises(ValueError, match="^ignore: must be 'auto', None or a sequence of coordinates, got 0"):
        pq.linearize(_pendulum(), [0.0], [0.0], ignore=0)


@pytest.mark.parametrize("build, values, message", [
    (lambda v: _pendulum(), 3.0, "^values: expected a sequence of parameter values, got 3.0"),
    (lambda v: _pendulum(), "abc", "^values: expected a sequence of parameter values, got 'abc'"),
    (_pendulum(), [1.0], r"^build: expected a callable build\(value\) returning a System, got System"),
    (lambda v: (_pendulum(), [0.0]), [1.0],
     r"^build: .*<lambda>\(1.0\) returned a tuple of 2; expected a System or \(system, q, s_dot\)"),
], ids=["values-scalar", "values-string", "build-not-callable", "build-tuple-of-two"])
def test_eigenvalue_sweep_arguments(build, values, message):
    """Passes if each malformed sweep is refused by name; before: bare TypeErrors ('float' object
    is not iterable, 'System' object is not callable) and "not enough values to unpack"."""
    with pytest.raises(ValueError, match=message):
        pq.eigenvalue_sweep(build, values)


@pytest.mark.parametrize("inputs, message", [
    (["ghost"], r"^inputs: unknown joint 'ghost'; the system has \['bob'\]"),
    ("bob", r"^inputs: expected a sequence of joint names, got the string 'bob'"),
], ids=["unknown", "string"])
def test_state_jacobians_name_their_inputs(inputs, message):
    """Passes if projeq.analysis.jacobians.state_jacobians refuses the inputs linearize refuses,
    by the same words (before: "name: unknown subsystem 'ghost'" and, for "bob", "name: unknown
    subsystem 'b'", the parameter of System.index)."""
    with pytest.raises(ValueError, match=message):
        state_jacobians(_pendulum(), [0.0], [0.0], inputs=inputs)


def test_state_jacobians_of_a_name_is_refused():
    """Passes if a scene's name instead of a model is refused by name (before: AttributeError
    "'str' object has no attribute 'check_state'")."""
    with pytest.raises(ValueError, match="^system: expected a System or a ConstrainedSystem"):
        state_jacobians("chain", [0.0], [0.0])


@pytest.mark.parametrize("jacobians", [
    lambda system, q, s_dot: pq.linearize(system, q, s_dot, require_steady=False, ignore=None),
    lambda system, q, s_dot: state_jacobians(system, q, s_dot),
], ids=["linearize", "state_jacobians"])
def test_jacobians_at_a_coordinate_singularity_are_refused(jacobians):
    """Passes if Barhorst's rolling disk at the tilt q2 = π/2, where his Euler angles degenerate
    (K(q) holds sec q2, Barhorst §3.2, eq. 96), is refused as simulate refuses it, naming K and
    the joint. Before, linearize returned A with entries of −2.4e14 (sec(π/2) in floating point,
    1.6e16, times R = 0.015 m): numbers, not a linearisation."""
    system = pq.scenes.rolling_disk(m_ecc=0.0)
    flat = np.array([0.0, np.pi / 2, 0.0, 0.0, 0.0])
    assert abs(1.0 / np.cos(flat[1])) > 1e15  # the reference: sec q2 at the singularity
    with pytest.raises(ValueError, match=r"^K\(q\) of q̇ = K ṡ loses rank .* for the joint of 'disk'"):
        jacobians(system, flat, [0.0, 20.0, 0.0])
