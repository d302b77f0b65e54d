"""The compiled integration loop (projeq/simulation/loop.py) against scipy's solve_ivp: the same
algorithm, so the same steps, the same number of evaluations and the same rows to round-off. The
compiled loop pauses at simulate's segment ends without cutting a step short there, so its run of
20 segments takes the steps of solve_ivp's run in one segment (``n_segments=1``); a closed loop's
state is projected onto Φ = 0 at each segment's end, so both of its runs take one segment.

The second formulation is scipy's own RK23, RK45 and DOP853 (``method=`` the scipy class keeps
solve_ivp stepping): the same evaluations in every case, and rows that differ by round-off (the
sums of the stages in another order than BLAS's); each bound is 10× the largest difference measured
over the cases of its test, stated beside it.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.integrate

import projeq as pq
from projeq.assembly import compilation
from projeq.simulation import loop


@pytest.fixture
def calls(monkeypatch):
    """The number of compiled segments run, counted."""
    counted = {"segments": 0}
    run = loop.CompiledLoop.run

    def counting(self, *args):
        counted["segments"] += 1
        return run(self, *args)

    monkeypatch.setattr(loop.CompiledLoop, "run", counting)
    return counted


def _differences(a, b) -> tuple[float, float]:
    """The largest differences in q and ṡ between two Results, relative to the largest entry of each."""
    return (np.max(np.abs(a.q - b.q)) / np.max(np.abs(b.q)), np.max(np.abs(a.s_dot - b.s_dot)) / np.max(np.abs(b.s_dot)))


#: 10x the largest relative difference measured over the cases of test_the_compiled_loop_takes_scipys_steps
#: (q: 1.1e-13, s_dot: 1.5e-12, the rolling disk's DOP853 over its one segment of 1 s; the chain's at most
#: 3.6e-15 and 1.3e-14)
STEPS_RTOL = (1.1e-12, 1.5e-11)


@pytest.mark.parametrize("method", loop.EXPLICIT)
@pytest.mark.parametrize("scene", ["chain", "rolling_disk"])
def test_the_compiled_loop_takes_scipys_steps(scene, method, calls):
    """A tree without (chain) and with (rolling disk: the rolling joint's C callbacks) joints of kind
    GIVEN: the compiled loop runs the 20 segments in calls that join them (driver.CHUNK_EVALUATIONS: 2 to
    10 here), with the steps of its own run in one segment (bit for bit), and equals scipy's run of the
    same method in one segment (same evaluations, q and ṡ to round-off)."""
    system = getattr(pq.scenes, scene)()
    compiled = pq.simulate(system, 1.0, method=method, n_points=101)
    joined = calls["segments"]
    assert 2 <= joined < 20  # the first segment alone, then as many as CHUNK_EVALUATIONS reach
    one = pq.simulate(system, 1.0, method=method, n_points=101, n_segments=1)  # the same steps, bit for bit
    assert compiled.nfev == one.nfev and np.array_equal(compiled.q, one.q) and np.array_equal(compiled.s_dot, one.s_dot)
    reference = pq.simulate(system, 1.0, method=getattr(scipy.integrate, method), n_points=101, n_segments=1)
    assert calls["segments"] == joined + 1  # scipy's class: solve_ivp steps
    assert compiled.nfev == reference.nfev
    dq, ds = _differences(compiled, reference)
    assert dq <= STEPS_RTOL[0] and ds <= STEPS_RTOL[1], (dq, ds)
    np.testing.assert_array_equal(compiled.t, reference.t)


#: 10x the largest relative difference measured over the cases of test_closed_loops_step_in_the_compiled_loop
#: (q: 5.1e-14, s_dot: 8.5e-14, the four-bar's DOP853; the bicycle's at most 1.4e-15 and 0)
CLOSED_RTOL = (5.1e-13, 8.5e-13)


@pytest.mark.parametrize("method", loop.EXPLICIT)
@pytest.mark.parametrize("scene", ["four_bar", "whipple_bicycle"])
def test_closed_loops_step_in_the_compiled_loop(scene, method, calls):
    """ConstrainedSystems (coordinate partitioning): a four-bar closed by Φ and the Whipple bicycle
    (holonomic and Pfaffian rows, UserJoints from sympy) step every segment in the compiled loop, their
    ẋ the closure's one compiled call, and equal scipy's run of the same method: the same evaluations
    (DOP853 fewer: with the partition's event solve_ivp forms the interpolant at the segment's end),
    q and ṡ to round-off."""
    system = pq.scenes.SCENES[scene].build()
    compiled = pq.simulate(system, 0.5, method=method, n_points=21, n_segments=1)
    assert calls["segments"] == 1
    reference = pq.simulate(system, 0.5, method=getattr(scipy.integrate, method), n_points=21, n_segments=1)
    assert calls["segments"] == 1
    assert compiled.nfev == reference.nfev if method != "DOP853" else compiled.nfev <= reference.nfev
    dq, ds = _differences(compiled, reference)
    assert dq <= CLOSED_RTOL[0] and ds <= CLOSED_RTOL[1], (dq, ds)


#: 10x the largest relative difference measured over the cases of test_the_null_space_form_steps_in_the_compiled_loop
#: (q: 6.9e-13, s_dot: 9.3e-13, A01's DOP853; A02 through its singular positions at most 2.9e-13 and 1.8e-13,
#: A04 7.7e-14 and 1.5e-13)
TANGENT_RTOL = (6.9e-12, 9.3e-12)


@pytest.mark.parametrize("method", ["RK45", "DOP853"])
@pytest.mark.parametrize("scene", ["simple_pendulum", "n_four_bar", "bricard"])
def test_the_null_space_form_steps_in_the_compiled_loop(scene, method, calls):
    """TangentSystems (IFToMM A01, A02 through singular positions, A04 with a redundant row): the
    compiled ẋ of the null-space form (its kept tangent the system's, between segments too) and its
    event κ = 1/σ_min(N_ind) − limit: the runs re-partition where scipy's do (A01 once, at t = 0.5897 s:
    measured 9.4e-15 s apart, bound 3e-14 s), q and ṡ to round-off."""
    system = pq.scenes.SCENES[scene].build()
    compiled = pq.simulate(system, 1.0, method=method, n_points=21, n_segments=1)
    assert calls["segments"] >= 1
    reference = pq.simulate(system, 1.0, method=getattr(scipy.integrate, method), n_points=21, n_segments=1)
    assert [p[1:] for p in compiled.partitions] == [p[1:] for p in reference.partitions]
    assert np.abs(np.subtract([p[0] for p in compiled.partitions], [p[0] for p in reference.partitions])).max() < 3e-14
    dq, ds = _differences(compiled, reference)
    assert dq <= TANGENT_RTOL[0] and ds <= TANGENT_RTOL[1], (dq, ds)


def test_a_partition_degenerating_inside_a_compiled_segment(calls):
    """The crank–rocker four-bar of tests/constraints/test_repivot.py (independent velocity the rocker's,
    which degenerates at t ≈ 0.091 s): the compiled ẋ fails where κ reaches 0.999 of the partition's
    limit, solve_ivp goes on from the compiled loop's last step, locates the event κ − limit and
    re-partitions; the switch lands where scipy's run puts it (measured 1.1e-14 s apart; bound 1.2e-13 s),
    the rows within 10× the measured 5.7e-15 (RK45) and 9.3e-14 (DOP853) of scipy's (both in one segment)."""
    from projeq.scenes.mechanisms import four_bar

    system = four_bar(a=0.3, b=1.0, c=0.8, d=1.0, m=(1.0, 2.0, 1.5), g=9.81, theta1=0.0, omega1=6.0) \
        .with_independent([1], repivot=True)
    for method, bound in (("RK45", 5.7e-14), ("DOP853", 9.3e-13)):
        runs = [pq.simulate(system, 0.3, t_eval=np.linspace(0, 0.3, 31), rtol=1e-9, atol=1e-11, method=m, n_segments=1)
                for m in (method, getattr(scipy.integrate, method))]
        assert [p[1] for p in runs[0].partitions] == [p[1] for p in runs[1].partitions] == [(1,), (2,)]
        assert abs(runs[0].partitions[1][0] - runs[1].partitions[1][0]) < 1.2e-13
        assert np.abs(runs[0].q - runs[1].q).max() < bound
    assert calls["segments"] == 2 * 2  # the compiled loop up to κ, and after the switch


def test_segments_join_only_where_their_ends_change_nothing(calls):
    """The compiled loop joins a tree's segments (driver.CHUNK_EVALUATIONS: the double pendulum's 20 in
    two calls) but not those of a top on a Spherical joint, whose quaternion is normalised at each
    segment's end, nor a closed loop's (q projected onto Φ = 0 there): both keep a call per segment."""
    pq.simulate(pq.scenes.double_pendulum(), 0.5, method="RK45")
    assert calls["segments"] == 2
    top = pq.System({"top": pq.RigidBody(1.0, (0.0, 0.0, 0.1), np.diag([0.01, 0.01, 0.02]))}, {"top": pq.Spherical()},
                    gravity=(0.0, 0.0, -9.81), s_dot0=(0.1, 0.0, 5.0))
    for system in (top, pq.scenes.four_bar()):
        calls["segments"] = 0
        pq.simulate(system, 0.5, method="RK45")
        assert calls["segments"] == 20


def test_output_times_and_the_largest_step(calls):
    """Unequal output times (the first at t_start, some at segments' ends, some between) and
    max_step: the compiled loop's four segments (in two calls: the first, then the three that
    driver.CHUNK_EVALUATIONS joins) give the rows scipy's run in one segment gives, at the same times
    (measured: 8.8e-16 relative in q, 1.6e-15 in ṡ), with as many evaluations."""
    system = pq.scenes.double_pendulum()
    t_eval = np.unique(np.concatenate(([0.0, 0.001, 0.5, 1.0], np.sort(np.random.default_rng(3).uniform(0, 1, 37)))))
    runs = [pq.simulate(system, 1.0, method=m, t_eval=t_eval, max_step=0.01, n_segments=n)
            for m, n in (("DOP853", 4), (scipy.integrate.DOP853, 1))]
    assert calls["segments"] == 2
    np.testing.assert_array_equal(runs[0].t, t_eval)
    assert runs[0].nfev == runs[1].nfev
    dq, ds = _differences(*runs)
    assert dq <= 8.8e-15 and ds <= 1.6e-14, (dq, ds)


def test_one_compiled_loop_for_every_tree():
    """The model enters the loop as data (its ẋ kernel as a first-class function): chains of other
    lengths, another scene and a force law's other ẋ kernel use the loop compiled once per signature
    of the ẋ kernel (the trees without joints of kind GIVEN share one)."""
    pq.simulate(pq.scenes.chain(2), 0.01, method="RK45")
    before, specialised = loop._compiled.cache_info().currsize, len(loop._SPECIALISED)
    pq.simulate(pq.scenes.chain(7), 0.01, method="RK45")
    assert len(loop._SPECIALISED) == specialised  # found by the arrays' layout, without numba's typeof
    for system in (pq.scenes.double_pendulum(), pq.scenes.flyball_governor()):
        pq.simulate(system, 0.01, method="RK45")
    assert loop._compiled.cache_info().currsize == before


@pytest.mark.parametrize("method", ["RK45", "Radau"])
def test_a_failing_evaluation_is_named(method, calls):
    """A load that turns NaN after t = 0.35 s inside a compiled segment (a callable numba compiles), an
    explicit method's or Radau's, ends the run as solve_ivp's loop of the same method ends it: the same
    error naming the law and the time, the same status, the same rows kept (those up to the last
    accepted step). An explicit step whose stage fails is rejected and retried shorter, so RK45 fails
    where the law turns NaN (0.35 s); Radau at its first NaN (t = 0.684 s: the steps of chain(2) are
    long)."""
    system = pq.scenes.chain(2)
    system = pq.System(dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
                       gravity=system.gravity,
                       forces=[pq.JointForce(system.names[0], lambda t, q, s_dot: np.nan if t > 0.35 else 0.0)])
    failures = []
    for way in (method, getattr(scipy.integrate, method)):  # the compiled loop's, scipy's
        with pytest.raises(pq.SimulationError, match=r"failed at t = 0\.\d+ s .*tau of joint 'link1': non-finite") as failed:
            pq.simulate(system, 1.0, method=way, n_segments=10)
        failures.append(failed.value)
    assert calls["segments"] == 2  # the first segment, then the rest joined up to the failure
    assert str(failures[0]) == str(failures[1]) and failures[0].result.status == failures[1].result.status
    assert re.search(r"failed at t = (\S+) s", str(failures[0])).group(1) == ("0.35" if method == "RK45" else "0.684399")
    np.testing.assert_array_equal(failures[0].result.t, failures[1].result.t)
    assert 0.1 <= failures[0].result.t[-1] < 0.35


def test_a_loop_numba_would_compile_waits_for_the_budget(monkeypatch, calls):
    """Under the cold-start policy (projeq.assembly.compilation) the loop compiles only when the
    interpreted budget is spent: while numba would compile it, solve_ivp steps (the same steps)."""
    def not_cached(model, method):
        if compilation._ANNOUNCER.deferring.on:
            raise compilation.NotCompiled("segment")
        raise AssertionError("compiled while the budget lasts")

    monkeypatch.setattr(loop, "CompiledLoop", not_cached)
    monkeypatch.setattr(compilation, "compile_now", lambda: False)
    result = pq.simulate(pq.scenes.chain(2), 0.1, method="RK45")
    assert calls["segments"] == 0 and result.status == 0
