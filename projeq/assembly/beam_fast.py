"""The evaluator of a beam on a moving hub, ``method="hub_beam"``: one RitzBeam whose root
follows a prescribed motion (a rheonomic hub, docs/theory.md §4) or is fixed to the ground — the
spin-up beam.

Then the beam's reference frame moves as given, ẏ = (w(t), q̇_e) with the hub's twist w
and ÿ = (ζ(t), q̈_e) with ζ = Ḟ⁶ θ̇ + F⁶ θ̈ (the parent is the ground at rest), and the
Projection Equation B(14) projected on the only minimal velocities ṡ = q̇_e,

    M_ee q̈_e = h_e − M_eR ζ,

needs neither the kinematic chain nor the passes of docs/theory.md §6: the beam's terms and one
n_e × n_e solve. With precomputed shape integrals (:mod:`projeq.subsystems.beam.integrals`)
and no rotary inertia only the elastic rows (M_ee, M_eR, h_e) are formed
(:meth:`~projeq.subsystems.beam.beam.RitzBeam.elastic_terms`). M_ee = ∫ Φ_rᵀ Φ_r dm is
positive definite for the independent Ritz functions a RitzBeam accepts, so a plain LU
solve suffices. Equal to the general evaluators to round-off
(tests/assembly/test_fast.py). Any other subsystem with internal coordinates and the beam's
layout ẏ = (twist, q̇_e) takes the same path through its ``elastic_terms``
(:class:`projeq.Subsystem`: by default the last n_e rows of its own ``gauss_terms``).

>>> import numpy as np, projeq as pq
>>> system = pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=2, family="clamped_free")
>>> ev = HubBeamEvaluator(system)
>>> q, s_dot = np.array([0.01, 0.0, 0.002, 0.0]), np.array([0.1, 0.0, 0.0, 0.0])
>>> bool(np.allclose(ev.accelerations(q, s_dot, 3.0), system.accelerations(q, s_dot, 3.0), rtol=1e-12, atol=1e-12))
True
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def hub_beam_unsupported(system) -> str | None:
    """Why ``system`` is not one subsystem with internal coordinates laid out as a beam's,
    ẏ = (twist, q̇_e) (``S`` = [E; 0], a RitzBeam), on a root joint without coordinates,
    whose motion is a given function of time (Prescribed, Fixed) (None if it is)."""
    if len(system.subsystems) != 1:
        return f"the system has {len(system.subsystems)} subsystems (the beam path takes one RitzBeam)"
    name, beam, joint = system.names[0], system.subsystems[0], system.joints[0]
    if not beam.n_e or beam.S is None or not np.array_equal(beam.S, np.eye(6 + beam.n_e, 6)):
        return (f"subsystem {name!r} is a {type(beam).__name__}, not one with internal coordinates and "
                "ẏ = (twist, q̇_e) (a RitzBeam)")
    if joint.n_q or joint.n_s or joint.coupling:
        return (f"joint {name!r} is a {type(joint).__name__} with coordinates (the beam path takes hubs "
                "whose motion is given: Prescribed or Fixed)")
    if system.forces:
        return "the system has force laws (the beam path knows gravity only)"
    return None


class HubBeamEvaluator:
    """q̈_e of one RitzBeam on a prescribed or fixed hub (module docstring).

    Parameters
    ----------
    system : System
        One RitzBeam (or another subsystem with internal coordinates and ẏ = (twist, q̇_e),
        through its ``elastic_terms``) on a :class:`~projeq.Prescribed` or
        :class:`~projeq.Fixed` joint to the ground, without force laws; otherwise
        ValueError naming the reason.

    Attributes: ``name`` ("hub_beam"), ``n_calls``.
    """

    name = "hub_beam"

    def __init__(self, system):
        reason = hub_beam_unsupported(system)
        if reason is not None:
            raise ValueError(f"system: {reason}")
        self.system = system
        self.beam, self.joint = system.subsystems[0], system.joints[0]
        self._empty = np.zeros(0)
        self.n_calls = 0

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """q̈_e = M_ee⁻¹ (h_e − M_eR ζ) at (q, ṡ, t) = (q_e, q̇_e, t)."""
        self.n_calls += 1
        joint = self.joint
        hub = joint.relative(self._empty, self._empty, t)
        R = joint.orientation @ hub.A  # the ground is at rest: R_n = A_pn
        y_dot = np.concatenate((hub.w, s_dot))
        M_e, h_e = self.beam.elastic_terms(y_dot, R, self.system.gravity, q)
        return np.linalg.solve(M_e[:, 6:], h_e - M_e[:, :6] @ hub.zeta)
