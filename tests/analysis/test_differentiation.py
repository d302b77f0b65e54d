"""The stencils of projeq.analysis.differentiation have the truncation errors their docstrings
state (Taylor expansion: the leading term C hᵖ f⁽ᵖ⁺ᵏ⁾ of a k-th derivative stencil of order p).

Known function: f(ε) = exp(1 + ε), whose derivatives at 0 are all e. With steps 0.2 … 0.025
the truncation error (≥ 1e-8) dominates the round-off (≤ 1e-12) by four orders, so the
log–log slope of the error is the order p (measured within 0.03 of it) and the error at
the smallest step is the stated leading term (measured within 0.9 % of it: the next term
is smaller by a factor of order h).
"""

import numpy as np
import pytest

from projeq.analysis import differentiation as d

E = np.e
STEPS = np.array([0.2, 0.1, 0.05, 0.025])


def f(eps):
    return np.exp(1.0 + eps)


# (rule, order p, leading error coefficient C with |error| ≈ C hᵖ e, exact value)
RULES = {
    "central": (lambda h: d.central(f, h), 2, 1 / 6, E),
    "richardson": (lambda h: d.richardson(f, h), 4, 1 / 30, E),
    "second": (lambda h: d.second(f, h), 4, 1 / 90, E),
    "forward": (lambda h: d.forward(f, h), 1, 1 / 2, E),
    "forward, f(0) given": (lambda h: d.forward(f, h, f(0.0)), 1, 1 / 2, E),
    "complex step": (lambda h: d.complex_step(f, h), 2, 1 / 6, E),
}


@pytest.mark.parametrize("name", RULES)
def test_each_stencil_has_its_stated_order_and_leading_error(name):
    rule, order, C, exact = RULES[name]
    errors = np.array([abs(rule(h) - exact) for h in STEPS])
    slope = np.polyfit(np.log(STEPS), np.log(errors), 1)[0]
    assert abs(slope - order) < 0.05, slope  # measured ≤ 0.03 (forward), ≤ 0.002 (the others)
    assert errors[-1] / (C * STEPS[-1] ** order * E) == pytest.approx(1.0, abs=0.02)  # measured ≤ 0.009


def test_complex_step_is_exact_to_round_off():
    """Im f(ih)/h with the default h = 1e-30: truncation h²/6 e ≈ 5e-61, nothing subtracted,
    so the derivative is e to within one rounding (measured: exactly e)."""
    assert abs(d.complex_step(f) - E) <= 2 * np.finfo(float).eps * E


def test_jacobian_is_fourth_order():
    """Richardson extrapolation of central differences: the error falls by ≈ 2⁴ = 16 when the
    step halves (d/dz of exp at 1, steps large enough that round-off is negligible)."""
    g = lambda z: np.exp(z)  # noqa: E731
    errors = [abs(d.jacobian(g, np.array([1.0]), step)[0, 0] - np.e) for step in (0.2, 0.1)]
    assert 12 < errors[0] / errors[1] < 20


def test_gradient_step_rule_and_orders():
    """∇ of exp(x₀) + exp(2 x₁) at x = (1, −1) with h_i = step (1 + |x_i|) = 2 step: central
    error h²/6 |f‴| = (2 step)²/6 (e, 8e⁻²) per component, forward h/2 |f″| = step (e, 4e⁻²)."""
    x = np.array([1.0, -1.0])
    g = lambda x: np.exp(x[0]) + np.exp(2 * x[1])  # noqa: E731
    exact = np.array([E, 2 * np.exp(-2.0)])
    step = 0.01
    central = (d.gradient(g, x, step=step) - exact) / ((2 * step) ** 2 / 6 * np.array([E, 8 * np.exp(-2.0)]))
    forward = (d.gradient(g, x, g(x), step=step) - exact) / (step * np.array([E, 4 * np.exp(-2.0)]))
    np.testing.assert_allclose(central, 1.0, atol=5e-4)  # measured ≤ 1e-4 off
    np.testing.assert_allclose(forward, 1.0, atol=0.05)  # measured ≤ 0.014 off
