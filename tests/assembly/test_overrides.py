"""A plug-in's own statement is what every evaluator uses: an override is never bypassed.

Subsystems with the rigid-body terms of B(13) may be evaluated in batches, by the compiled
kernel or in sympy from (m, r_c, I_c) (``rigid_inertia``); joints have a compiled kind and a
sympy form next to ``relative``; force laws a sympy form next to their wrench. A subclass
that restates the numeric terms loses these derived forms unless it restates them too
(projeq/subsystems/base.py, projeq/joints/base.py, projeq/forces.py), so the batched,
compiled and symbolic paths fall back to the override or refuse it by name. Each check is
against Newton's law for a single translation, in closed form, in every evaluator that
takes the system; the ones that do not ("fast", the compiled kernel; "hub_beam", a beam on
a hub) refuse it with their reason, and "auto" takes it.
"""

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import EVALUATORS, InterpretedWarning
from projeq.assembly.beam_fast import HubBeamEvaluator
from projeq.assembly.fast import FastEvaluator
from projeq.symbolic import gauss_form

EVERY_EVALUATOR = sorted(EVALUATORS)
REFUSING = {"fast", "hub_beam"}  # evaluators of some systems only: others are refused with the reason
THRUST = 10.0  # N


def _s_ddot(system, method: str, piece: str):
    """s̈ at the initial state by ``method``, or None where that evaluator refuses the system:
    only "fast" and "hub_beam" may, "fast" naming ``piece`` (the override it cannot compile)."""
    try:
        return system.accelerations(system.q0, system.s_dot0, method=method)
    except ValueError as refusal:
        assert method in REFUSING and str(refusal).startswith("system: "), (method, refusal)
        assert method != "fast" or piece in str(refusal), refusal
        return None


class Thruster(pq.RigidBody):
    """A rigid body whose own terms add a thrust T along its x axis at its origin:
    h_n += (T e_x, 0) (a force at O has no moment about O)."""

    def gauss_terms(self, y_dot, R, gravity, q_e=None):
        M, h = super().gauss_terms(y_dot, R, gravity, q_e)
        return M, h + np.array([THRUST, 0.0, 0.0, 0.0, 0.0, 0.0])


def _thruster_on_a_slider() -> pq.System:
    """Mass 1 kg on a prismatic joint along x, no gravity: s̈ = T / m = 10 m/s²."""
    return pq.System({"rocket": Thruster(1.0, I_c=np.eye(3))}, {"rocket": pq.Prismatic(axis="x")}, gravity=(0.0, 0.0, 0.0))


@pytest.mark.parametrize("method", EVERY_EVALUATOR)
def test_a_thrust_in_an_overridden_gauss_terms_accelerates_in_every_evaluator(method):
    system = _thruster_on_a_slider()
    s_ddot = _s_ddot(system, method, "'rocket' is a Thruster")
    assert s_ddot is None or s_ddot == pytest.approx([THRUST / 1.0], rel=1e-14)


@pytest.mark.parametrize("compiled", [True, False])
def test_the_fast_evaluator_does_not_compile_an_overridden_body(compiled):
    """Neither the numba kernel nor its interpreted twin take the body: they would use
    (m, r_c, I_c) and lose the thrust. They refuse it by name; "auto" takes the recursive
    evaluator, which keeps the thrust."""
    if compiled:
        pytest.importorskip("numba")
    system = _thruster_on_a_slider()
    with pytest.raises(ValueError, match="subsystem 'rocket' is a Thruster"):
        FastEvaluator(system, compiled=compiled)
    evaluator = system.evaluator("auto")
    assert evaluator.name == "recursive" and "rocket" in evaluator.reason
    assert evaluator.accelerations(system.q0, system.s_dot0, 0.0) == pytest.approx([THRUST], rel=1e-14)


@pytest.mark.parametrize("method", EVERY_EVALUATOR)
def test_the_override_counts_beside_batched_rigid_bodies(method):
    """A cart (m_1) sliding along x carries the thruster (m_2) on a second slider along x,
    next to two plain bodies that are batched: Newton for the cart and for the thruster,
    (m_1 + m_2) s̈_1 + m_2 s̈_2 = T and m_2 (s̈_1 + s̈_2) = T, give s̈_1 = 0, s̈_2 = T / m_2.
    The two plain pendulums hang at rest from the ground (θ̈ = −(g/l) sin θ = 0 at θ = 0)."""
    m1, m2 = 3.0, 2.0
    system = pq.System(
        {"cart": pq.RigidBody(m1, I_c=np.eye(3)), "rocket": Thruster(m2, I_c=np.eye(3)),
         "left": pq.PointMass(1.0, (0.0, 0.0, -1.0)), "right": pq.PointMass(2.0, (0.0, 0.0, -0.5))},
        {"cart": pq.Prismatic(axis="x"), "rocket": pq.Prismatic(parent="cart", axis="x"),
         "left": pq.Revolute(axis="y", r_pn=(0.0, 1.0, 0.0)), "right": pq.Revolute(axis="y", r_pn=(0.0, -1.0, 0.0))},
        gravity=(0.0, 0.0, -9.81),
    )
    s_ddot = _s_ddot(system, method, "'rocket' is a Thruster")
    if s_ddot is not None:
        s_ddot = dict(zip(system.names, s_ddot))
        assert s_ddot == pytest.approx({"cart": 0.0, "rocket": THRUST / m2, "left": 0.0, "right": 0.0}, abs=1e-13)


def test_the_symbolic_derivation_refuses_an_overridden_body_by_name():
    """gauss_form builds rigid bodies from (m, r_c, I_c); an override has no sympy form."""
    with pytest.raises(ValueError, match=r"subsystem 'rocket' \(Thruster\) is not supported symbolically"):
        gauss_form(_thruster_on_a_slider())


def test_a_subclass_that_restates_its_terms_and_their_rigid_form_is_batched_again():
    """Restating rigid_inertia next to gauss_terms declares them the rigid-body terms."""

    class Renamed(pq.RigidBody):
        rigid_inertia = pq.RigidBody.rigid_inertia

        def gauss_terms(self, y_dot, R, gravity, q_e=None):
            return super().gauss_terms(y_dot, R, gravity, q_e)

    assert Thruster(1.0, I_c=np.eye(3)).rigid_inertia is None
    assert Renamed(2.0, I_c=np.eye(3)).rigid_inertia[0] == 2.0 and pq.PointMass(2.0).rigid_inertia[0] == 2.0


class Geared(pq.Prismatic):
    """A slider driven through a gear: the body moves λ x along e for the coordinate x,
    F⁶ = (λ e, 0)."""

    lead = 0.5

    def relative(self, q_n, s_dot_n, t):
        rel = super().relative(self.lead * q_n, self.lead * s_dot_n, t)
        return rel._replace(F=self.lead * rel.F)


@pytest.mark.parametrize("method", EVERY_EVALUATOR)
def test_an_overridden_joint_is_not_compiled_as_its_base_class(method):
    """m λ² ẍ = −m g λ under gravity along −e: ẍ = −g / λ (the kernel's prismatic kind would
    give −g)."""
    g = 9.81
    system = pq.System({"box": pq.PointMass(2.0)}, {"box": Geared(axis="z")}, gravity=(0.0, 0.0, -g))
    assert Geared.compiled_kind is None and pq.Prismatic.compiled_kind == "prismatic"
    s_ddot = _s_ddot(system, method, "'box' is a Geared, which has no compiled kind")
    assert s_ddot is None or s_ddot == pytest.approx([-g / Geared.lead], rel=1e-14)
    with pytest.raises(ValueError, match=r"joint 'box' \(Geared\) is not supported symbolically"):
        gauss_form(system)


class Doubled(pq.Force):
    """A force law whose wrench is twice the force it was given."""

    def wrench(self, R, t, q, s_dot):
        return 2.0 * super().wrench(R, t, q, s_dot)


@pytest.mark.parametrize("method", EVERY_EVALUATOR)
def test_an_overridden_force_law_acts_as_overridden(method):
    """m ẍ = 2 f: ẍ = 2 f / m; the symbolic derivation refuses the law (its sympy form would
    be the base class's f)."""
    f, m = 3.0, 1.5
    system = pq.System({"box": pq.PointMass(m)}, {"box": pq.Prismatic(axis="x")}, gravity=(0.0, 0.0, 0.0),
                       forces=[Doubled("box", (f, 0.0, 0.0))])
    s_ddot = _s_ddot(system, method, "force laws")
    assert s_ddot is None or s_ddot == pytest.approx([2 * f / m], rel=1e-14)
    with pytest.raises(ValueError, match=r"forces\[0\] \(Doubled\) is not supported symbolically"):
        gauss_form(system)


def test_a_beam_subclass_that_adds_a_generalized_force_keeps_it_on_the_fast_hub_path():
    """The hub path solves M_ee q̈_e = h_e − M_eR ζ from the beam's elastic rows; a subclass
    that adds f to h_e (restating gauss_terms only) changes q̈_e by M_ee⁻¹ f, there as in the
    general evaluator."""
    extra = np.array([0.3, -0.1, 0.2, 0.05])

    class Pushed(pq.RitzBeam):
        def gauss_terms(self, y_dot, R, gravity, q_e):
            M, h = super().gauss_terms(y_dot, R, gravity, q_e)
            h[6:] += extra
            return M, h

    plain = pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=2, precomputed_integrals=True)
    beam = plain.subsystems[0]
    pushed = Pushed(beam.length, 1.2, 1.4e4, n_v=2, n_w=2, precomputed_integrals=True)
    system = pq.System({"beam": pushed}, {"beam": plain.joints[0]}, gravity=(0.0, 0.0, 0.0))
    q, s_dot, t = np.array([0.01, 0.0, 0.002, 0.0]), np.array([0.1, 0.0, 0.0, 0.0]), 3.0
    fast = HubBeamEvaluator(system)  # the hub path, not the general one
    with pytest.warns(InterpretedWarning, match=r"interpreted 'hub_beam' path.*'beam' is a Pushed .*restates gauss_terms"):
        assert system.evaluator("auto").name == "hub_beam"  # said: the compiled kernel knows the slice field's terms only
    M = system.evaluator("dense").gauss_form(q, s_dot, t)[0]
    expected = plain.accelerations(q, s_dot, t) + np.linalg.solve(M, extra)
    assert fast.accelerations(q, s_dot, t) == pytest.approx(expected, rel=1e-10, abs=1e-12)
    assert system.accelerations(q, s_dot, t) == pytest.approx(expected, rel=1e-10, abs=1e-12)
