"""Bad input to the joints (UserJoint from callables, Prescribed, coupled joints) refused by
name at construction, with the message starting with the parameter's name; and the time symbol
of a prescribed motion read whatever its sympy assumptions."""

import numpy as np
import pytest
import sympy as sp

import projeq as pq

ROD = {"m": 1.0, "r_c": (0, 0, -0.5), "I_c": np.diag([0.1, 0.1, 0.01])}


def _pose(q, t):
    return np.eye(3), np.array([q[0], 0 * q[0], 0 * q[0]])


def _F(q, t):
    return np.array([[1.0], [0], [0], [0], [0], [0]]) + 0 * q[0]


def _K(q, t):
    return np.eye(1)


def _slider(n_q=1, n_s=1, pose=_pose, F=_F, K=_K, **kwargs):
    """A slider along x as a user joint from callables."""
    return pq.UserJoint.from_functions(n_q, n_s, pose, F, K, **kwargs)


def _unavailable(q, t):
    raise ConnectionError("the lookup table server is down")


@pytest.mark.parametrize("kwargs, message", [
    ({"n_c": 1}, r"^n_c: 1 constraint residual\(s\) announced, but no constraints function gives them"),
    ({"n_c": -1, "constraints": lambda q, q_dot, t: []}, r"^n_c: expected an integer >= 0, got -1"),
    ({"n_q": -1}, r"^n_q: expected an integer >= 0, got -1"),
    ({"n_s": 1.5}, r"^n_s: expected an integer >= 0, got 1.5"),
    ({"pose": _unavailable}, r"^pose: _unavailable raised ConnectionError: the lookup table server is down "
                             r"at q0 = \[0.0\], t = 0"),
    ({"F": _unavailable}, r"^F: _unavailable raised ConnectionError"),
    ({"K": np.eye(1)}, r"^K: expected a callable K\(q, t\), got ndarray"),
    ({"constraints": [0.0], "n_c": 1}, r"^constraints: expected a callable constraints\(q, q_dot, t\), got list"),
], ids=["n_c-without-constraints", "n_c-negative", "n_q-negative", "n_s-fraction", "pose-raises", "F-raises",
        "K-not-callable", "constraints-not-callable"])
def test_user_joint_from_functions_refuses_by_name(kwargs, message):
    """Passes if each is a ValueError naming the parameter. Before: n_c = 1 without a function
    was accepted and simulate failed with numpy's "cannot reshape array of size 0 into shape
    (3,1)"; n_q = −1 "negative dimensions are not allowed", n_s = 1.5 a TypeError of numpy; a
    callable that raised came out bare (ConnectionError), without the parameter's name."""
    with pytest.raises(ValueError, match=message):
        _slider(**kwargs)


def test_coupling_to_an_unknown_joint_names_coupling():
    """Passes if a gear coupled to a joint not in the system names ``coupling`` (before: "name:
    unknown subsystem 'ghost'", the parameter of System.index, which the user never called)."""
    with pytest.raises(ValueError, match=r"^coupling: 'b' follows 'ghost', which is not in the system; "
                                         r"known subsystems are \['a', 'b'\]"):
        pq.System({"a": pq.RigidBody(**ROD), "b": pq.RigidBody(**ROD)},
                  {"a": pq.Revolute(axis="y"), "b": pq.Revolute(axis="y", coupling={"ghost": 2.0})})


@pytest.mark.parametrize("motion", [None, [1.0, 2.0], "t > 1"], ids=["None", "list", "relation"])
def test_prescribed_motion_that_is_no_expression(motion):
    """Passes if a motion that is neither callable nor an expression in t is refused by name
    (before: None was "AttributeError: 'NoneType' object has no attribute 'free_symbols'")."""
    with pytest.raises(ValueError, match="^motion: cannot read .* as an expression in t"):
        pq.Prescribed(pq.Revolute(axis="z"), motion)


def test_prescribed_motion_in_a_real_time_symbol():
    """Passes if θ = sin 2t written with t = sp.Symbol("t", real=True) gives (θ, θ̇, θ̈) =
    (sin 2t, 2 cos 2t, −4 sin 2t) at t = 0.3 (closed form). Before: "motion: depends on ['t'];
    only t is allowed" — the symbol t with an assumption is another sympy symbol than t."""
    t = sp.Symbol("t", real=True)
    angles = pq.Prescribed(pq.Revolute(axis="z"), sp.sin(2 * t)).angles(0.3)
    assert angles == pytest.approx((np.sin(0.6), 2 * np.cos(0.6), -4 * np.sin(0.6)), rel=1e-15)


def test_a_coupling_ratio_of_zero_is_refused():
    """Passes if a gear coupled with ratio 0 (its coordinate 0 · q_a ≡ 0: welded, following
    nothing) is refused by name; before, it was accepted as a joint that never moves."""
    with pytest.raises(ValueError, match=r"^coupling\['a'\]: a ratio of 0 couples nothing, got 0.0"):
        pq.Revolute(axis="y", coupling={"a": 0.0})
