"""What a work-precision study of each scene varies and how it measures the error.

A :class:`Study` names a registered scene, its fixed parameters, the model knobs (scene
parameters and an evaluator), the converged reference and the measured quantity; the
error of a run is max |m(run) − m(reference)| over the entries of that quantity at t_end.
``STUDIES`` holds the built-in studies (``projeq tradeoff SCENE``):

========================  ==========================================  =====================
scene                     knobs                                       measured at t_end
========================  ==========================================  =====================
chain (n = 30)            evaluator: recursive, dense, fast, symbolic  q (rad)
knife_edge_disc           evaluator: recursive, dense                 q = (x, y, ψ, ϕ, θ)
spin_up_beam              Ritz functions, quadrature vs precomputed   in-plane tip
                          integrals, stiffening on/off                deflection v(L) (m)
whipple_bicycle           drift correction: projection, baumgarte,    q (m, rad)
                          none
========================  ==========================================  =====================
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

#: The symbolic evaluator is derived by sympy; its cost grows steeply with the number of
#: bodies (derivation and compilation of chain(5): 0.5 s CPU, chain(6): 1.1 s, chain(10):
#: unfinished after 400 s on the loaded 2-core development machine), so larger trees get a
#: "skipped" row instead of an open-ended sympy run.
SYMBOLIC_MAX_BODIES = 6


@dataclass(frozen=True)
class Knob:
    """One model setting: scene parameters on top of the study's and an evaluator name
    (``None``: the system's default; ``"symbolic"``: the compiled sympy Gauss form)."""

    label: str
    overrides: dict = field(default_factory=dict)
    evaluator: str | None = None


@dataclass(frozen=True)
class Study:
    """A work-precision study of one scene.

    Attributes
    ----------
    scene : registered scene name; overrides : its fixed parameters for the study
    knobs : the model settings compared; quick_knobs : labels of the quick subset
    reference : the finest model; reference_method, reference_rtol : how it is integrated
    measure : ``measure(system, result) -> array``, the compared quantity at t_end
    measure_doc : what ``measure`` is, with units (printed with the table)
    t_end, quick_t_end : simulated time (s) of the full and the quick study
    atol_scale : atol = atol_scale · rtol (the size of the states' entries)
    """

    scene: str
    overrides: dict
    knobs: tuple
    quick_knobs: tuple
    reference: Knob
    measure: Callable
    measure_doc: str
    t_end: float
    quick_t_end: float
    reference_method: str = "DOP853"
    reference_rtol: float = 1e-13
    atol_scale: float = 1.0


def final_q(system, result) -> np.ndarray:
    """q at the end time."""
    return result.q[-1]


def tip_v(system, result) -> np.ndarray:
    """In-plane tip deflection v(L) of the subsystem ``"beam"`` at the end time (m)."""
    beam = system.subsystems[system.index("beam")]
    return beam.deflection(result, beam.length)[-1, 1:2]


def _evaluator_knobs(*names) -> tuple:
    return tuple(Knob(name, evaluator=name) for name in names)


def _beam_knobs() -> tuple:
    knobs = [Knob(f"{n} Ritz fn", {"n_shapes": n}) for n in (2, 3, 4, 5)]
    knobs.append(Knob("4 Ritz fn, precomputed", {"n_shapes": 4, "precomputed_integrals": True}))
    knobs.append(Knob("4 Ritz fn, unstiffened", {"n_shapes": 4, "stiffening": False}))
    return tuple(knobs)


STUDIES = {
    "chain": Study(
        "chain", {"n": 30}, _evaluator_knobs("recursive", "dense", "fast", "symbolic"),
        ("recursive", "fast"), Knob("recursive", evaluator="recursive"), final_q,  # symbolic: n > 6, skipped
        "max |q - q_ref| over the joint angles at t_end (rad)", t_end=5.0, quick_t_end=1.0,
    ),
    "knife_edge_disc": Study(
        "knife_edge_disc", {}, _evaluator_knobs("recursive", "dense"), ("recursive",),
        Knob("recursive", evaluator="recursive"), final_q,
        "max |q - q_ref| over (x, y, psi, phi, theta) at t_end (m, rad)", t_end=20.0, quick_t_end=5.0,
    ),
    "spin_up_beam": Study(
        "spin_up_beam", {}, _beam_knobs(),
        ("2 Ritz fn", "4 Ritz fn", "4 Ritz fn, precomputed", "4 Ritz fn, unstiffened"),
        # 4 functions: v(L) at 4 s differs from 6 functions by 1.7e-7 m (DOP853, rtol 1e-7),
        # so smaller errors are against the 4-function model. Finer models are stiff: with 5
        # functions LSODA at rtol 1e-11 needs 20000 evaluations per second of motion, Radau
        # more; with 4, LSODA at 1e-10 needs 7000 (DOP853 is held at its stability limit)
        Knob("4 Ritz fn", {"n_shapes": 4}), tip_v,
        "|v(L) - v_ref(L)|, the in-plane tip deflection at t_end (m)", t_end=20.0, quick_t_end=2.0,
        reference_method="LSODA", reference_rtol=1e-10, atol_scale=1e-3,
    ),
    "whipple_bicycle": Study(
        "whipple_bicycle", {"speed": 5.0, "roll_rate": 0.5},
        tuple(Knob(c, {"correction": c}) for c in ("projection", "baumgarte", "none")), ("projection", "none"),
        # the projection onto Φ = 0 stops at a residual of 1e-12 max(1, |q|) (θ_R grows to
        # ~30 rad), a non-smooth 1e-11 floor: DOP853 at rtol 1e-9, 1e-11, 1e-13 over 0.2 s
        # differ by 3e-11 in the roll angle, and below 1e-11 it only rejects steps
        Knob("projection", {"correction": "projection"}), final_q,
        "max |q - q_ref| over (x, y, psi, phi, theta, theta_R, delta, theta_F) at t_end (m, rad)",
        t_end=5.0, quick_t_end=2.0, reference_rtol=1e-11,
    ),
}


def evaluator_for(system, knob: Knob):
    """The knob's evaluator of ``system``; ValueError naming why a symbolic one is not built."""
    if knob.evaluator != "symbolic":
        return system.evaluator(knob.evaluator)
    if len(system.subsystems) > SYMBOLIC_MAX_BODIES:
        raise ValueError(
            f"evaluator: symbolic derivation skipped for {len(system.subsystems)} bodies "
            f"(more than SYMBOLIC_MAX_BODIES = {SYMBOLIC_MAX_BODIES})"
        )
    from projeq.symbolic import SymbolicEvaluator, gauss_form

    return SymbolicEvaluator(gauss_form(system), {})
