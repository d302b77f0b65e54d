"""projeq.analysis.campbell: modal data and Campbell diagrams against exact solutions.

- modes of the double pendulum: ω² = (g/l)(2 ± √2) with shapes (1, ±√2 − 1) in relative
  angles (the Lagrange seminars Problem 8);
- the blade on a hub (``scenes.rotating_blade``): the first two flapwise and lead-lag
  frequencies against the Frobenius series of Wright et al. (1982) extended to a hub
  radius and to lead-lag (tests/analysis/rotating_cantilever.py), and the first flapwise
  one against their Table 1;
- the beam spinning about its own axis (``scenes.spinning_beam``, ρI = 0): forward and
  backward whirl |ω_k ∓ Ω| in the co-rotating frame, through the zero of the forward whirl
  and the crossings of branches, and both at ω_k seen from the inertial frame (Genta 2005);
- two coupled oscillators: tracking by shape crosses uncoupled branches and follows a
  veering pair.
"""

import csv

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.campbell import campbell, mac, modes
from projeq.subsystems.beam.shapes import clamped_free_roots
from tests.analysis.rotating_cantilever import WRIGHT_1982, frobenius_frequencies

G = 9.81
EPS = np.finfo(float).eps


def test_modes_of_the_double_pendulum():
    """Equal masses and rods l: ω² = (g/l)(2 ± √2); in relative angles (θ₁, θ₂ − θ₁) the
    shapes are (1, ±√2 − 1)... of the absolute angles (1, ±√2): (1, −1 ± √2). Frequencies
    to 100 ε relative (measured 2.2e-16), shape ratios to 100 ε × their size √2 + 1 (measured
    1.5e-15); undamped: ζ = 0 to 100 ε (measured 1.4e-16)."""
    l = 0.8
    found = modes(pq.scenes.double_pendulum(l1=l, l2=l, q0=(0.0, 0.0)))
    expected = np.sqrt(G / l * np.array([2 - np.sqrt(2), 2 + np.sqrt(2)]))
    error = np.abs(found.frequencies / expected - 1).max()
    assert error < 100 * EPS, f"frequencies off by {error:.3g} relative"
    assert np.abs(found.damping).max() < 100 * EPS, f"ζ = {found.damping}"
    ratios = found.shapes[1] / found.shapes[0]
    error = np.abs(ratios - [np.sqrt(2) - 1, -np.sqrt(2) - 1]).max()
    assert error < 100 * EPS * (np.sqrt(2) + 1), f"shape ratios off by {error:.3g}"
    assert found.coordinates == ("bob1.q[0]", "bob2.q[0]") and found.real_eigenvalues.size == 0


@pytest.mark.parametrize("hub_radius", [0.0, 0.5, 1.0])
def test_blade_flapwise_and_lead_lag_against_the_frobenius_series(hub_radius):
    """``projeq campbell rotating_blade`` in numbers: ten clamped–free functions per plane,
    η = Ω √(ρA L⁴/EI) = 1, 3, 5 and hub radius R/L = 0, 0.5, 1: the first two flapwise and
    lead-lag branches (found by their labels) equal the roots of the Frobenius series to
    1e-4 relative (measured ≤ 1.0e-5, at R/L = 1, η = 5: Ritz upper bounds)."""
    diagram = campbell(lambda omega: pq.scenes.rotating_blade(omega=omega, hub_radius=hub_radius, n_shapes=10),
                       [1.0, 3.0, 5.0], n_modes=4, refine=False)
    assert sorted(diagram.labels) == ["flapwise 1", "flapwise 2", "lead-lag 1", "lead-lag 2"]
    for k, eta in enumerate(diagram.speeds):
        flap = frobenius_frequencies(eta, hub_radius, 2)
        lag = frobenius_frequencies(eta, hub_radius, 2, lead_lag=True)
        found = [diagram.branch(f"{kind} {i}")[k] for kind in ("flapwise", "lead-lag") for i in (1, 2)]
        error = np.array(found) / np.r_[flap, lag] - 1.0
        assert np.all(error > -1e-9) and np.all(error < 1e-4), (eta, error)
    assert np.all(diagram.branch("lead-lag 1") < diagram.branch("flapwise 1"))  # softened in its plane


def test_blade_first_flapwise_frequency_matches_wright_et_al():
    """At zero hub radius the first flapwise branch reproduces Wright et al. (1982), Table 1
    (η = 0 … 5) within the table's rounding 5e-5 plus the Ritz error (< 1.2e-6): 6e-5
    (measured ≤ 5.2e-5, at η = 5)."""
    diagram = campbell(lambda omega: pq.scenes.rotating_blade(omega=omega, n_shapes=10), sorted(WRIGHT_1982), n_modes=2,
                       refine=False)
    table = np.array([WRIGHT_1982[eta] for eta in sorted(WRIGHT_1982)])
    assert np.abs(diagram.branch("flapwise 1") - table).max() < 6e-5


def test_critical_speed_of_the_blade_against_the_frobenius_series():
    """Lead-lag 1 meets the engine order 2Ω where √(λ_flap(η)² − η²) = 2η (the Frobenius
    series, solved by brentq): Brent's method on the branch between two speeds of the sweep
    finds it to 4e-7 relative (measured 4.4e-8: the Ritz error of ten functions), the linear
    interpolation between η = 1.5 and 1.95 only to 3e-3 (measured 3.0e-4)."""
    from scipy.optimize import brentq

    exact = brentq(lambda eta: np.sqrt(frobenius_frequencies(eta, 0.0, 1)[0] ** 2 - eta**2) - 2 * eta, 1.5, 1.95,
                   xtol=1e-13)
    for refine, bound in ((True, 4e-7), (False, 3e-3)):
        diagram = campbell(lambda omega: pq.scenes.rotating_blade(omega=omega, n_shapes=10), [1.5, 1.95], orders=[2],
                           n_modes=2, refine=refine)
        (critical,) = diagram.critical_speeds
        assert critical.mode == "lead-lag 1" and critical.order == 2
        assert abs(critical.speed / exact - 1) < bound, (refine, critical.speed / exact - 1)


def test_spinning_beam_whirls_at_omega_k_plus_minus_spin():
    """Without rotary inertia the spinning beam is the non-rotating cantilever seen from the
    co-rotating frame: forward whirl |ω_k − Ω|, backward whirl ω_k + Ω (ω_k = (β_k L)² for
    EI = ρA = L = 1, Blevins (1979), Table 8-1). The four clamped–free eigenfunctions per plane
    are exact, so the branches are to round-off over the Ritz model's eigensolution (bounds 10× the
    relative errors measured: forward 5.7e-12, backward 3.5e-13, |ζ| 7.7e-14; were all 1e-10),
    over Ω = 0 … 30 where the forward whirls pass through zero (at Ω = ω₁, ω₂) and cross the
    backward ones: a diagram sorted by frequency would mix the branches. Seen from the inertial
    frame (``stationary``, w + Ω with the co-rotating whirl w signed) both whirls are the
    non-rotating cantilever's ω_k at every speed (G. Genta, "Dynamics of Rotating Systems",
    Springer, 2005; measured 3.5e-13 relative, bound 3.5e-12), on both sides of the forward
    whirl's zero."""
    speeds = np.linspace(0.0, 30.0, 16)
    diagram = campbell(lambda omega: pq.scenes.spinning_beam(omega=omega, n_shapes=4), speeds, orders=[0, 1])
    omega_k = clamped_free_roots(4) ** 2
    forward = max(np.abs(diagram.branch(f"forward whirl {k + 1}") / np.abs(omega_k[k] - speeds) - 1).max()
                  for k in range(4))
    backward = max(np.abs(diagram.branch(f"backward whirl {k + 1}") / (omega_k[k] + speeds) - 1).max()
                   for k in range(4))
    assert forward < 5.7e-11 and backward < 3.5e-12, (forward, backward)
    stationary = max(np.abs(diagram.branch(f"{kind} whirl {k + 1}", "stationary") / omega_k[k] - 1).max()
                     for k in range(4) for kind in ("forward", "backward"))
    assert stationary < 3.5e-12, stationary
    assert np.abs(diagram.damping).max() < 7.7e-13, np.abs(diagram.damping).max()
    first = [c for c in diagram.critical_speeds if c.mode == "forward whirl 1" and c.order == 1]
    # an unbalance (fixed in the rotor, order 0) resonates where a forward whirl's co-rotating
    # frequency passes through zero: Ω = ω₁, ω₂ (Brent on the signed branch, down to the
    # frequency below which modes() counts an eigenvalue as real, 1e-9 max |λ|: 3e-7 relative,
    # measured 3.5e-8)
    unbalance = [c for c in diagram.critical_speeds if c.order == 0]
    assert [c.mode for c in unbalance] == ["forward whirl 1", "forward whirl 2"]
    assert np.allclose([c.speed for c in unbalance], omega_k[:2], rtol=3e-7, atol=0)
    # |ω₁ − Ω| = Ω at Ω = ω₁/2 (Brent's method on the branch: 100 ε, measured 1.1e-15; was 1e-10)
    assert len(first) == 1 and first[0].speed == pytest.approx(omega_k[0] / 2, rel=100 * EPS)


def test_stationary_whirls_split_by_rotary_inertia_and_in_the_csv(tmp_path):
    """With rotary inertia (ρI = 0.01) the shaft is gyroscopic: seen from the inertial frame the
    forward whirls rise and the backward ones fall from their common value at rest (Genta,
    2005; second whirls at Ω = 10: 21.75 and 16.86 rad/s from 19.14); the CSV carries a whirl's
    stationary frequency beside its co-rotating one, which is ω_rot + Ω (forward, its co-rotating
    whirl not through zero here) and ω_rot − Ω (backward) to round-off (100 ε relative: measured 7.3e-16
    for the two whirls at rest; was 1e-12); a
    blade has no stationary frequency and asking for one is named."""
    speeds = np.array([0.0, 5.0, 10.0])
    diagram = campbell(lambda omega: pq.scenes.spinning_beam(omega=omega, n_shapes=2, rho_I=0.01), speeds,
                       n_modes=4, refine=False)
    forward, backward = (diagram.branch(f"{kind} whirl 2", "stationary") for kind in ("forward", "backward"))
    assert forward[0] == pytest.approx(backward[0], rel=100 * np.finfo(float).eps, abs=0)
    assert np.all(np.diff(forward) > 0.5) and np.all(np.diff(backward) < -0.5), (forward, backward)
    assert np.abs(forward - (diagram.branch("forward whirl 2") + speeds)).max() < 1e-12 * forward.max()
    assert np.abs(backward - (diagram.branch("backward whirl 2") - speeds)).max() < 1e-12 * backward.max()
    diagram.write_csv(tmp_path / "spinning.csv")
    rows = list(csv.reader(open(tmp_path / "spinning.csv", encoding="utf-8")))
    column = rows[0].index("forward whirl 2 stationary frequency (rad/s)")
    assert np.array(rows[1:], dtype=float)[:, column].tolist() == forward.tolist()
    blade = campbell(lambda w: pq.scenes.rotating_blade(omega=w, n_shapes=1), [0.0, 1.0], refine=False)
    with pytest.raises(ValueError, match="label: 'flapwise 1' is no whirl"):
        blade.branch("flapwise 1", frame="stationary")
    with pytest.raises(ValueError, match="frame: expected 'rotating'"):
        blade.branch("flapwise 1", frame="inertial")


def _oscillators(stiffness: float, coupling: float) -> pq.System:
    """Two unit masses on x, grounded by springs of ``stiffness`` and 2, joined by ``coupling``:
    K = [[k₁ + ε, −ε], [−ε, 2 + ε]]."""
    def mass(x):
        return pq.PointMass(1.0, (0.0, 0.0, 0.0))
    return pq.System({"a": mass(0.0), "b": mass(1.0)},
                     {"a": pq.Prismatic(axis="x"), "b": pq.Prismatic(axis="x", r_pn=(1.0, 0.0, 0.0))},
                     forces=[pq.JointSpring("a", stiffness), pq.JointSpring("b", 2.0),
                             pq.SpringDamper("a", (0, 0, 0), "b", (0, 0, 0), coupling, length=1.0)])


@pytest.mark.parametrize("coupling", [0.0, 0.02], ids=["crossing", "veering"])
def test_tracking_by_shape_crosses_and_veers(coupling):
    """k₁ = 1 + Ω sweeps past k₂ = 2. Uncoupled, the branch that starts as mass a's mode
    follows √(k₁) across the other (a crossing; sorted frequencies would swap them);
    coupled by ε = 0.02, the two branches veer: each follows the eigenvalues of K
    continuously, never crossing, while the shapes exchange (MAC with the start ≈ 0 at
    the end). Frequencies to 100 ε relative (measured 2.2e-16 crossing, 6.7e-16 veering)."""
    speeds = np.linspace(0.0, 2.0, 41)
    diagram = campbell(lambda omega: _oscillators(1.0 + omega, coupling), speeds, orders=[1], refine=False)
    a = diagram.frequencies[:, 0] if diagram.frequencies[0, 0] < diagram.frequencies[0, 1] else diagram.frequencies[:, 1]
    if coupling == 0.0:
        error = np.abs(a / np.sqrt(1.0 + speeds) - 1).max()
        assert error < 100 * EPS, f"crossing branch off by {error:.3g} relative"
        return
    exact = np.array([np.sqrt(np.linalg.eigvalsh([[1 + w + coupling, -coupling], [-coupling, 2 + coupling]]))[0]
                      for w in speeds])
    error = np.abs(a / exact - 1).max()
    assert error < 100 * EPS, f"veering branch off by {error:.3g} relative"
    start, end = (modes(_oscillators(1.0 + w, coupling)) for w in (0.0, 2.0))
    assert mac(start.shapes[:, :1], end.shapes[:, :1])[0, 0] < 0.01


def test_diagram_files(tmp_path):
    """The CSV holds one row per speed with each branch's frequency and damping (read back
    equal to the diagram's numbers); the plot has a line per branch and per engine order."""
    diagram = campbell(lambda omega: pq.scenes.rotating_blade(omega=omega, n_shapes=2), [0.0, 2.0, 4.0], n_modes=2,
                       refine=False)
    diagram.write_csv(tmp_path / "campbell.csv")
    rows = list(csv.reader(open(tmp_path / "campbell.csv", encoding="utf-8")))
    assert rows[0][0] == "speed (rad/s)" and len(rows) == 4 and len(rows[0]) == 1 + 2 * 2
    assert np.array_equal(np.array(rows[1:], dtype=float)[:, 1::2], diagram.frequencies)
    pytest.importorskip("matplotlib")
    figure = diagram.plot()
    assert len(figure.axes[0].lines) == 2 + 3 + (1 if diagram.critical_speeds else 0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: campbell(lambda w: pq.scenes.rotating_blade(omega=w, n_shapes=1), [1.0]), "speeds: expected at least two"),
        (lambda: campbell(lambda w: pq.scenes.rotating_blade(omega=w, n_shapes=1), [2.0, 1.0]), "speeds: must increase"),
        (lambda: campbell(lambda w: pq.scenes.rotating_blade(omega=w, n_shapes=1), [0.0, 1.0], orders=[-1]), "orders"),
        (lambda: campbell(lambda w: pq.scenes.rotating_blade(omega=w, n_shapes=1), [0.0, 1.0], n_modes=0), "n_modes"),
        (lambda: campbell(pq.scenes.chain(2), [0.0, 1.0]), "joint: campbell of a System needs"),
        (lambda: campbell(lambda w: 3, [0.0, 1.0]), "system: expected a System"),
        (lambda: campbell("blade", [0.0, 1.0]), "system: expected a System or a build function"),
    ],
    ids=["one-speed", "decreasing", "order", "n_modes", "no-joint", "not-a-system", "not-callable"],
)
def test_bad_campbell_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_free_hub_at_a_steady_speed():
    """A System with ``joint``: the beam's hub turning freely at ṡ = Ω (a steady motion; the
    hub angle is dropped as ignorable). The hub's inertia couples with lead-lag (the hub
    recoils), raising it above the prescribed hub's, while flapwise is unchanged (its plane
    does not move the hub): to round-off, 100 ε relative (measured 6.7e-16; was 1e-10)."""
    beam = pq.RitzBeam(1.0, 1.0, 1.0, n_v=4, n_w=4, family="clamped_free")
    free = pq.System({"hub": pq.RigidBody(1.0, I_c=np.diag([1.0, 1.0, 0.5])), "beam": beam},
                     {"hub": pq.Revolute(axis="z"), "beam": pq.Fixed(parent="hub", r_pn=(0.5, 0.0, 0.0))})
    diagram = campbell(free, [1.0, 2.0], joint="hub", n_modes=3, refine=False)
    prescribed = campbell(lambda w: pq.scenes.rotating_blade(omega=w, hub_radius=0.5, n_shapes=4), [1.0, 2.0], n_modes=3,
                          refine=False)
    assert np.abs(diagram.branch("flapwise 1") / prescribed.branch("flapwise 1") - 1).max() < 100 * np.finfo(float).eps
    assert np.all(diagram.branch("lead-lag 1") > prescribed.branch("lead-lag 1") * (1 + 1e-3))


def test_the_benchmark_quick_mode():
    """benchmarks/campbell.py --quick (≤ 3 s): the spinning beam's whirls against |ω_k ∓ Ω|
    to 1.5e-13 and the blade's ω_lag² = ω_flap² − Ω² to 2.3e-14 (relative; measured ≤ 1.5e-14 and 2.3e-15,
    were 1e-10: the script's QUICK_BOUNDS); exit code 0."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[2] / "benchmarks" / "campbell.py"
    spec = importlib.util.spec_from_file_location("campbell_benchmark", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick"]) == 0
