"""RitzBeams anywhere in a tree on the compiled path (projeq/assembly/kernels.py, the elastic block
and the stations' frames): s̈ equals the dense Gauss form (docs/theory.md §5, an independent
O(N³) formulation) within the bound of tests/assembly/test_recursive_vs_dense.py, on random
trees with beams on revolute, prismatic, fixed and prescribed joints (beams with rotary inertia,
sometimes torsion, on free, spherical and planar joints too; any joint in the rigid part), both
integration strategies, children on the beams' stations (beams on beams too), and the kernel's
twins equal the beam's own statements."""

import types
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import Tree, random_inertia, random_mass, random_rotation, random_state, spatial_joint, trees, with_couplings
from test_recursive_vs_dense import _agree

import projeq as pq
from projeq.assembly import InterpretedWarning, kernels
from projeq.assembly.fast import FastEvaluator

# a beam without rotary inertia has none about its axis x: a joint that may turn it about x
# alone (free, spherical, planar yz) gives a singular D_n, so such beams sit on these; a beam
# with rotary inertia (ρI_p about x) sits on any of ROTARY_BEAM_JOINTS
EPS = np.finfo(float).eps
BEAM_JOINTS = ("revolute", "prismatic", "fixed", "prescribed")
ROTARY_BEAM_JOINTS = BEAM_JOINTS + ("free", "spherical", "planar")


def _beam(rng, rotary: bool | None = None) -> pq.RitzBeam:
    """A beam with random bending (and sometimes axial) functions, family, stiffening,
    damping and integration strategy; with rotary inertia (``rotary``; default: at random),
    then sometimes with torsion (the kernel's rotary block, kernels.rotary_body)."""
    n_v, n_w, n_u = (int(n) for n in rng.integers(0, 4, 3))
    n_v = max(n_v, 1)
    rotary = bool(rng.random() < 0.5) if rotary is None else rotary
    options = {}
    if rotary:
        options = dict(rho_I=tuple(rng.uniform(1e-4, 1e-2, 2)), rho_I_p=float(rng.uniform(1e-4, 1e-2)))
        if rng.random() < 0.5:
            options.update(n_beta=int(rng.integers(1, 3)), GI_t=float(rng.uniform(1.0, 20.0)))
    return pq.RitzBeam(
        float(rng.uniform(0.3, 2.0)), float(rng.uniform(0.5, 5.0)), float(rng.uniform(5.0, 100.0)),
        EI_y=float(rng.uniform(5.0, 100.0)), EA=float(rng.uniform(1e3, 1e4)), n_v=n_v, n_w=n_w, n_u=n_u % 2,
        family=("polynomial", "clamped_free")[rng.integers(2)], stiffening=bool(rng.random() < 0.8),
        damping=float(rng.choice([0.0, 0.01])), precomputed_integrals=bool(rng.random() < 0.5), **options,
    )


def _on_station(beam_name: str, beam: pq.RitzBeam, rng, turns: bool) -> pq.Joint:
    """A joint at a random station x ∈ [0, L] with a cross-section offset (a Revolute only
    if ``turns``: a point mass on its own axis moves no inertia)."""
    r_pn = (float(rng.uniform(0.0, beam.length)), *rng.uniform(-0.1, 0.1, 2))
    kind = rng.integers(3) if turns else 2 * rng.integers(2)
    if kind == 0:
        return pq.Fixed(beam_name, r_pn, random_rotation(rng) if rng.random() < 0.5 else None)
    axis = rng.standard_normal(3)
    joint = pq.Revolute if kind == 1 else pq.Prismatic
    return joint(beam_name, axis / np.linalg.norm(axis), r_pn, random_rotation(rng) if rng.random() < 0.5 else None)


@st.composite
def trees_with_beams(draw):
    """A random rigid tree (every spatial joint, no force laws) with 1–2 RitzBeams on random
    bodies by random joints, and 0–2 bodies (rigid, point masses, or a beam) on each beam's
    stations."""
    base = draw(trees(max_n=4, forces=False))
    seed = draw(st.integers(0, 2**32 - 1), label="beam seed")
    rng = np.random.default_rng(seed)
    system = base.system
    subsystems, joints = dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints))
    beams = []
    for i in range(int(rng.integers(1, 3))):
        name, beam = f"beam{i}", _beam(rng)
        parent = None if rng.random() < 0.2 else system.names[rng.integers(len(system.names))]
        subsystems[name] = beam
        kinds = BEAM_JOINTS if beam.rotary is None else ROTARY_BEAM_JOINTS
        joints[name] = spatial_joint(kinds[rng.integers(len(kinds))], parent, rng)
        beams.append((name, beam))
    for name, beam in list(beams):
        for j in range(int(rng.integers(0, 3))):
            child = f"{name}_on{j}"
            kind = rng.integers(3)
            m = random_mass(rng)
            subsystems[child] = (pq.RigidBody(m, rng.uniform(-0.3, 0.3, 3), random_inertia(rng, m)) if kind == 0
                                 else pq.PointMass(m) if kind == 1 else _beam(rng))
            joints[child] = _on_station(name, beam, rng, turns=kind != 1)
    beam_system = pq.System(subsystems, joints, gravity=system.gravity)
    q, s_dot, t = random_state(beam_system, rng)
    e = [i for n in range(len(beam_system.names)) for i in range(beam_system.e_q_slice[n].start, beam_system.e_q_slice[n].stop)]
    q[e] *= 0.05  # moderate deflections: Ritz amplitudes of a few cm
    return Tree(beam_system, beam_system.normalized(q), s_dot, t, base.kinds, base.parents, [], seed, False, rng)


@settings(max_examples=max(10, settings().max_examples // 3), deadline=None)
@given(trees_with_beams())
def test_beams_in_trees_are_compiled_and_equal_dense(tree):
    """The default evaluator of a tree with beams is the compiled kernel (no
    InterpretedWarning), and its s̈ equals the dense Gauss form (bound of _agree)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("ignore", RuntimeWarning)  # an unstiffened beam spun fast: said once
        assert tree.system.evaluator().name == "fast"
        _agree(tree, "auto", "dense")


@settings(max_examples=max(5, settings().max_examples // 6), deadline=None)
@given(trees_with_beams())
def test_beams_beside_coupled_joints_are_compiled_and_equal_dense(tree):
    """Trees with beams and up to three bodies on coupled joints (strategies.with_couplings):
    compiled by default; the kernel's Gauss form (kernels.gauss_form with each body's n_y,
    in every joint's own velocities and the beams' q̇_e after them, projected by P) equals
    the dense J_nᵀ M_n J_n sums to round-off relative to their largest entries, and its s̈
    the dense one (bound of _agree). The coupled bodies on the rigid tree's bodies come before
    the beams, so that the kernel's ṡ_all (a coupled joint's own velocity in it) and the
    System's ṡ place the beams' q̇_e differently."""
    coupled = with_couplings(tree)
    rigid_tree = {f"b{i}" for i in range(tree.n)}
    early = [n for n, j in zip(coupled.names, coupled.joints) if n not in rigid_tree and j.coupling and j.parent in rigid_tree]
    order = sorted(coupled.names, key=lambda n: 0 if n in rigid_tree else 1 if n in early else 2)
    bodies, joints = dict(zip(coupled.names, coupled.subsystems)), dict(zip(coupled.names, coupled.joints))
    system = pq.System({n: bodies[n] for n in order}, {n: joints[n] for n in order}, gravity=coupled.gravity)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("ignore", RuntimeWarning)  # an unstiffened beam spun fast: said once
        assert system.evaluator().name == "fast"
        q, s_dot = system.normalized(tree.rng.uniform(-1, 1, system.n_q)), tree.rng.uniform(-1, 1, system.n_s)
        for n in range(len(system.names)):
            q[system.e_q_slice[n]] *= 0.05  # moderate deflections
        M, b = system.gauss_form(q, s_dot, tree.t)
        M_fast, b_fast = system.evaluator("fast").gauss_form(q, s_dot, tree.t)
        # measured ≤ 2.1e-16 and 4.6e-16 of the scale (was 1e-12)
        assert np.abs(M_fast - M).max() <= 100 * EPS * max(1.0, np.abs(M).max())
        assert np.abs(b_fast - b).max() <= 100 * EPS * max(1.0, np.abs(b).max())
        _agree(types.SimpleNamespace(system=system, q=q, s_dot=s_dot, t=tree.t), "auto", "dense")


@settings(max_examples=max(5, settings().max_examples // 10), deadline=None)
@given(trees_with_beams())
def test_interpreted_kernel_with_beams_equals_recursive(tree):
    """The kernel's source run interpreted (compiled=False) = the recursive evaluator."""
    tree.system._evaluators["fast"] = FastEvaluator(tree.system, compiled=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        _agree(tree, "fast", "recursive")


@pytest.mark.parametrize("seed", range(10))
def test_the_elastic_twins_equal_the_beams_own_terms(seed):
    """kernels.elastic_body and kernels.rotary_body = the beam's gauss_terms (Quadrature and
    PrecomputedIntegrals, restoring and damping forces, rotary inertia and torsion included:
    odd seeds) and kernels.port_motion = BeamPort.relative (whose Ḟ q̇_e is a complex step),
    at random deformed, moving states."""
    rng = np.random.default_rng(seed)
    beam = _beam(rng, rotary=seed % 2 == 1)
    q_e, q_e_dot = 0.05 * rng.standard_normal(beam.n_e), rng.standard_normal(beam.n_e)
    twist, R, g = rng.standard_normal(6), random_rotation(rng), rng.uniform(-10, 10, 3)
    y_dot = np.concatenate((twist, q_e_dot))
    M_ref, h_ref = beam.gauss_terms(y_dot, R, g, q_e)
    M, h = np.empty((beam.n_y, beam.n_y)), np.empty(beam.n_y)
    kernels.elastic_body(beam.mass_weights, *beam.slice_field(), beam.K_e, beam.damping, q_e, q_e_dot, twist, R.T @ g, M, h)
    kernels.rotary_body(*beam.rotation_field(), q_e, q_e_dot, twist, M, h)
    # measured ≤ 6.0e-16, 3.5e-16 and (the port's rows) 5.3e-16 of the scale over the ten seeds (was 1e-12)
    assert np.abs(M - M_ref).max() <= 100 * EPS * np.abs(M_ref).max()
    assert np.abs(h - h_ref).max() <= 100 * EPS * np.abs(h_ref).max()
    port = beam.port_at(np.array([rng.uniform(0, beam.length), *rng.uniform(-0.1, 0.1, 2)]))
    rel = port.relative(q_e, q_e_dot)
    A, r, F, zeta = np.empty((3, 3)), np.empty(3), np.empty((6, beam.n_e)), np.empty(6)
    kernels.port_motion(*port.field, port.offset, q_e, q_e_dot, A, r, F, zeta)
    for mine, reference in ((A, rel.A), (r, rel.r), (F, rel.F), (zeta, rel.zeta)):
        assert np.abs(mine - reference).max() <= 100 * EPS * max(1.0, np.abs(reference).max())
