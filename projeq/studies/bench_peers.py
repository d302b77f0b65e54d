"""projeq's defaults against its peers on the same models (``benchmarks/peers.py``,
``projeq bench --peers``); every comparison first checks that both sides compute the same.

- **chain**: s̈ of ``scenes.chain(n)`` by projeq's default evaluator (``system.evaluator()``,
  :mod:`projeq.assembly.auto`) against Pinocchio's ABA (``pin.aba``; Featherstone, *Rigid Body
  Dynamics Algorithms*, 2008, ch. 7), MuJoCo's ``mj_forward`` (the whole pipeline: collision,
  constraints, sensors, energy — with contacts off and no geoms most of it is empty) and
  MuJoCo's smooth dynamics alone (``mj_kinematics``, ``mj_comPos``, ``mj_crb``,
  ``mj_factorM``, ``mj_comVel``, ``mj_rne``, ``mj_solveM``: what the Projection Equation
  computes, s̈ = M⁻¹(τ − b), and nothing else), the same chain built from the same
  parameters (:func:`projeq.studies.bench.pinocchio_chain`, :func:`~projeq.studies.bench.mujoco_chain`).
  The s̈ of each peer is compared with projeq's before the timing; the growth exponent is
  the log-log slope over the sizes.
- **rolling disk**: s̈ of ``scenes.rolling_disk(m_ecc=0)`` (the uniform disk) against sympy's
  own rolling-disc model (the "Rolling Disc, Kane's Method" example of the
  ``sympy.physics.mechanics`` documentation, also its ``test_kane.py``: Euler angles z-x-y,
  speeds the angular velocity in the lean frame) derived by ``KanesMethod`` and turned into
  what a PyDy user runs: ``lambdify`` of the mass matrix and forcing vector (with ``cse``),
  then ``numpy.linalg.solve``. The two models use other speeds; the check compares the
  angular acceleration in the disk's frame, which is projeq's s̈ (its ṡ is the body-fixed
  angular velocity, Barhorst (2004) eqs. 92–93) and follows from sympy's u̇ and the
  kinematics. projeq's s̈ also carries the two contact coordinates q4, q5 that sympy's
  model leaves out.
- **spin-up**: ``simulate(scenes.spin_up_beam(omega_s=4), 20.0)`` with no knobs, and with the
  scene's settings for ``projeq run``, against Exudyn's nonlinear ANCF cable
  (:func:`exudyn_tip_deflection`): CPU time and the in-plane tip deflection at 7, 10 and 20 s.
  Exudyn's clock runs over its time integration (``SolveDynamic``, not the model's assembly),
  projeq's over ``simulate`` once the default evaluator has given its first s̈ (the compiled
  kernel loaded from numba's disk cache, timed apart as ``first_call_s``: the first-call
  latency, also reported by :func:`projeq.studies.bench_scenes.first_call_latency`).

Every timed pair is timed alternately in one run (:func:`projeq.studies.timing.time_per_call`),
so the ratios hold on a loaded machine; absolute times are this machine's only.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from projeq import scenes
from projeq.studies.bench import PINOCCHIO_UP_TO, deviations, mujoco_chain, pinocchio_chain, slopes
from projeq.studies.bench_scenes import first_call_latency
from projeq.studies.timing import time_per_call

CHAIN_SIZES = (10, 100, 200, 1000)
SPIN_UP_TIMES = (7.0, 10.0, 20.0)  # s: where the tip deflections are compared
#: largest accepted deviation of a peer's s̈ from projeq's, relative to max(1, |s̈|∞): the
#: order-n recursions agree to a few ε per link (1.1e-13 from an exact s̈ up to n = 300,
#: tests/studies/test_chain_exact.py); MuJoCo factors M (condition number κ(M) ≈ 1.3e8 at
#: n = 100 at this state), so its s̈ is within κ(M) ε ≈ 3e-8 only
SAME_S_DDOT = {"pinocchio": 1e-10, "mujoco": 1e-6, "mujoco_smooth": 1e-6, "sympy": 1e-12}


def chain_peers(n: int) -> dict:
    """Name → (q, ṡ) ↦ s̈ of ``scenes.chain(n)``: projeq's default evaluator and the
    installed peers (Pinocchio up to n = 300: its Data grows as n²)."""
    evaluator = scenes.chain(n).evaluator()
    funcs = {"projeq": lambda q, s_dot: evaluator.accelerations(q, s_dot, 0.0)}
    peers = {"pinocchio": pinocchio_chain(n) if n <= PINOCCHIO_UP_TO else None,
             "mujoco": mujoco_chain(n), "mujoco_smooth": mujoco_chain(n, smooth_only=True)}
    return funcs | {name: f for name, f in peers.items() if f is not None}


def checked(s_ddot: dict, reference: str) -> dict:
    """Name → deviation of each s̈ from ``s_ddot[reference]`` (relative to max(1, |s̈|∞));
    AssertionError naming the peer whose s̈ is beyond :data:`SAME_S_DDOT`: it is not the
    same model, and its timing would mean nothing."""
    deviation = deviations(s_ddot, s_ddot[reference])
    for name, d in deviation.items():
        if name != reference and not d <= SAME_S_DDOT[name]:
            raise AssertionError(f"{name}: s̈ differs from projeq's by {d:.1e} > {SAME_S_DDOT[name]:.0e}: not the same model")
    return deviation


def chain_rows(sizes=CHAIN_SIZES, budget: float = 1.0, show=None) -> list[dict]:
    """One row per chain length: µs per call, the deviations from projeq's s̈ (checked
    first, :func:`checked`) and projeq's time over each peer's."""
    rng = np.random.default_rng(0)
    rows = []
    for n in sizes:
        q, s_dot = rng.uniform(-1, 1, (2, n))
        funcs = chain_peers(n)
        deviation = checked({name: f(q, s_dot) for name, f in funcs.items()}, "projeq")
        seconds = time_per_call(funcs, q, s_dot, budget)
        rows.append({"n": n, "seconds": seconds, "deviation": deviation,
                     "ratio": {name: seconds["projeq"] / s for name, s in seconds.items() if name != "projeq"}})
        if show is not None:
            show(f"chain({n}): " + ", ".join(f"{k} {s * 1e6:.1f} µs" for k, s in seconds.items())
                 + "; projeq / " + ", ".join(f"{k} {r:.2f}" for k, r in rows[-1]["ratio"].items()))
    return rows


def sympy_rolling_disc(m: float, r: float, g: float) -> dict:
    """The rolling disc of the sympy.physics.mechanics documentation ("Rolling Disc, Kane's
    Method"), numeric: ``"M_F"`` (q, u) ↦ (M, F) lambdified with cse, M u̇ = F;
    ``"speeds"`` (q, ω_R) ↦ u, the lean-frame speeds of a body-fixed angular velocity;
    ``"body_acceleration"`` (q, u, u̇) ↦ the angular acceleration in the disk frame R."""
    import sympy as sp
    from sympy.physics.mechanics import KanesMethod, Point, ReferenceFrame, RigidBody, dot, dynamicsymbols, inertia

    q = dynamicsymbols("q1:4")
    u = dynamicsymbols("u1:4")
    N = ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [q[0], N.z])
    L = Y.orientnew("L", "Axis", [q[1], Y.x])
    R = L.orientnew("R", "Axis", [q[2], L.y])
    w_R_N_qd = R.ang_vel_in(N)
    R.set_ang_vel(N, u[0] * L.x + u[1] * L.y + u[2] * L.z)
    C = Point("C")
    C.set_vel(N, 0)
    Dmc = C.locatenew("Dmc", r * L.z)
    Dmc.v2pt_theory(C, N, R)
    disc = RigidBody("disc", Dmc, R, m, (inertia(L, m / 4 * r**2, m / 2 * r**2, m / 4 * r**2), Dmc))
    kane = KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=[dot(R.ang_vel_in(N) - w_R_N_qd, uv) for uv in L])
    kane.kanes_equations([disc], [(Dmc, -m * g * Y.z)])
    q_s, u_s, ud_s, w_s = (sp.symbols(f"{name}1:4") for name in ("q", "u", "ud", "w"))
    plain = dict(zip(q, q_s)) | dict(zip(u, u_s))

    def numeric(expr):
        return expr.subs(kane.kindiffdict()).subs(dict(zip([x.diff() for x in u], ud_s))).subs(plain)

    alpha = numeric(R.ang_acc_in(N).to_matrix(R))
    omega = (w_s[0] * R.x + w_s[1] * R.y + w_s[2] * R.z).to_matrix(L).subs(plain)
    return {
        "M_F": sp.lambdify([q_s, u_s], [numeric(kane.mass_matrix), numeric(kane.forcing)], cse=True),
        "speeds": sp.lambdify([q_s, w_s], omega),
        "body_acceleration": sp.lambdify([q_s, u_s, ud_s], alpha),
    }


def rolling_disk_row(budget: float = 1.0, q=(0.3, 0.15, 0.2, 0.0, 0.0), s_dot=(0.5, 20.0, -0.4)) -> dict:
    """The rolling disk (module docstring): µs per s̈ of projeq's default evaluator and of
    sympy's lambdified KanesMethod RHS at (q, ṡ), their ratio, and the deviation of the
    body-frame angular accelerations (checked first, :func:`checked`)."""
    m, r, g = 0.030, 0.015, 9.81  # scenes.rolling_disk's defaults (Barhorst's disk in SI)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the interpreted-evaluator warning: the row says which evaluator ran
        system = scenes.rolling_disk(m_disk=m, R=r, m_ecc=0.0, g=g, q0=q, s_dot0=s_dot)
        evaluator = system.evaluator()
    disc = sympy_rolling_disc(m, r, g)
    q, s_dot = np.asarray(q, float), np.asarray(s_dot, float)
    u = np.asarray(disc["speeds"](q[:3], s_dot), float).ravel()

    def sympy_rhs(_q, _s):
        M, F = disc["M_F"](q[:3], u)
        return np.linalg.solve(M, np.ravel(F))

    funcs = {"projeq": lambda _q, _s: evaluator.accelerations(q, s_dot, 0.0), "sympy": sympy_rhs}
    alpha = np.asarray(disc["body_acceleration"](q[:3], u, sympy_rhs(None, None)), float).ravel()
    deviation = checked({"projeq": funcs["projeq"](None, None), "sympy": alpha}, "projeq")
    seconds = time_per_call(funcs, None, None, budget)
    return {"evaluator": getattr(evaluator, "name", type(evaluator).__name__), "seconds": seconds,
            "deviation": deviation, "ratio": seconds["projeq"] / seconds["sympy"]}


def exudyn_generalized_alpha(mbs, t_end: float, h: float, newton_atol: float,
                             spectral_radius: float | None = None) -> float:
    """CPU seconds of Exudyn's generalized-α integration (``SolveDynamic``) of the assembled ``mbs``
    over [0, t_end] at the fixed step h, its sensors stored at every step, no files written; Newton's
    absolute tolerance ``newton_atol``, the spectral radius ρ∞ Exudyn's default unless given."""
    import exudyn as exu
    from exudyn.solver import SolveDynamic

    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = round(t_end / h)
    settings.timeIntegration.endTime = t_end
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.absoluteTolerance = newton_atol
    if spectral_radius is not None:
        settings.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = h
    started = time.process_time()
    SolveDynamic(mbs, settings, exu.DynamicSolverType.GeneralizedAlpha)
    return time.process_time() - started


def exudyn_tip_deflection(omega_s: float = 4.0, times=SPIN_UP_TIMES, n_elements: int = 16, h: float = 1e-3,
                          axial_stiffness: float = 2.8e7, newton_atol: float = 1e-6) -> tuple[np.ndarray, float]:
    """The in-plane tip deflection v(L, t) of ``scenes.spin_up_beam`` at ``times`` by Exudyn's
    nonlinear ANCF cable (``ObjectANCFCable2D``, ``n_elements``, generalized-α with step
    ``h``) and the CPU time of its time integration.

    The beam is clamped at the hub axis by four coordinate constraints on its first node:
    position (0, 0) and slope (cos θ(t), sin θ(t)) with θ(t) of ``spin_up_motion``, the
    offsets set once per step by a PreStepUserFunction (Exudyn's recommendation for
    prescribed motion). Newton's absolute tolerance is raised from 1e-10 to 1e-6 N: the
    residual of the axially stiff beam at rest is EA × round-off ≈ 3e-9 N, above Exudyn's
    default (Newton then "fails" and cuts the step to 1e-6 s, 50× the CPU time); 1e-6 N is
    1e-9 of the centrifugal root force ρAΩs²L²/2 ≈ 960 N. Its beam is extensible (EA) and
    its curvature exact; projeq's default is inextensible with the linear curvature v″ and the
    second-order axial field u₂ (docs/theory.md §10).
    """
    import exudyn as exu
    from exudyn.beams import GenerateStraightLineANCFCable2D
    from exudyn.itemInterface import CoordinateConstraint, MarkerNodeCoordinate, NodePointGround, ObjectANCFCable2D, SensorNode

    from projeq.scenes.elastic import spin_up_motion

    defaults = scenes.scene_parameters(scenes.get_scene("spin_up_beam"))
    p = {parameter.name: parameter.default for parameter in defaults}
    motion, times = spin_up_motion(omega_s, p["t_s"]), np.asarray(times, float)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    template = ObjectANCFCable2D(physicsMassPerLength=p["rho_A"], physicsBendingStiffness=p["EI"],
                                 physicsAxialStiffness=axial_stiffness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # renamed in Exudyn 1.11, same elements
        nodes = GenerateStraightLineANCFCable2D(mbs, [0, 0, 0], [p["length"], 0, 0], n_elements, template)[0]
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    # node 0's coordinates are displacements from the reference (0, 0, 1, 0) of (x, y, x', y'):
    # position held at the axis, slope (cos θ, sin θ) following the hub
    clamp = [mbs.AddObject(CoordinateConstraint(markerNumbers=[
        ground_marker, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=k))])) for k in range(4)]

    def follow_hub(mbs_, t):  # t is the end of the step (Exudyn's PreStepUserFunction)
        theta = motion(t)[0]
        mbs_.SetObjectParameter(clamp[2], "offset", np.cos(theta) - 1.0)
        mbs_.SetObjectParameter(clamp[3], "offset", np.sin(theta))
        return True

    mbs.SetPreStepUserFunction(follow_hub)
    tip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    cpu = exudyn_generalized_alpha(mbs, float(times[-1]), h, newton_atol)
    data = mbs.GetSensorStoredData(tip)  # rows (t, x, y, z)
    rows = [np.argmin(np.abs(data[:, 0] - t)) for t in times]
    theta = np.array([motion(t)[0] for t in times])
    x, y = data[rows, 1], data[rows, 2]
    return -np.sin(theta) * x + np.cos(theta) * y, cpu


def projeq_tip_deflection(omega_s: float = 4.0, times=SPIN_UP_TIMES, **options) -> tuple[np.ndarray, float, dict]:
    """v(L, t) at ``times`` of ``simulate(scenes.spin_up_beam(omega_s), times[-1], **options)``
    (no options: the defaults), its CPU time and the run's method, evaluations, warnings and
    ``first_call_s``: the CPU time of the default evaluator's first s̈ before (loading its
    compiled kernel; module docstring)."""
    from projeq.simulation.driver import simulate

    system = scenes.spin_up_beam(omega_s=omega_s)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        started = time.process_time()
        system.evaluator(options.get("evaluator")).accelerations(system.q0, system.s_dot0, 0.0)
        first_call = time.process_time() - started
        started = time.process_time()
        result = simulate(system, float(times[-1]), t_eval=np.concatenate(([0.0], times)), **options)
        cpu = time.process_time() - started
    beam = system.subsystem("beam")
    run = {"nfev": result.nfev, "method": result.method, "first_call_s": first_call, "warnings": sorted({f"{type(w.message).__name__}: {w.message}" for w in said})}
    return beam.deflection(result, beam.length)[1:, 1], cpu, run


def spin_up_row(omega_s: float = 4.0, times=SPIN_UP_TIMES) -> dict:
    """Tip deflections and CPU times of Exudyn and of projeq, by ``simulate``'s defaults and by
    the scene's settings for ``projeq run`` (:data:`projeq.scenes.SPIN_UP_SETTINGS`)."""
    exudyn_tip, exudyn_cpu = exudyn_tip_deflection(omega_s, times)
    row = {"omega_s": omega_s, "times_s": list(times), "exudyn_tip_m": exudyn_tip.tolist(), "exudyn_cpu_s": exudyn_cpu}
    for name, options in (("defaults", {}), ("scene_settings", scenes.SPIN_UP_SETTINGS)):
        tip, cpu, run = projeq_tip_deflection(omega_s, times, **options)
        row[name] = {"options": options, "tip_m": tip.tolist(), "max_difference_m": float(np.abs(tip - exudyn_tip).max()),
                     "cpu_s": cpu, "cpu_ratio": cpu / exudyn_cpu, **run}
    return row


def peers_report(sizes=CHAIN_SIZES, budget: float = 1.0, spin_up: bool = True, latency: bool = True, show=None) -> dict:
    """Every comparison of the module docstring in one run (``show``, e.g. ``print``, receives
    each line as it is measured); a peer that is not installed is left out and named."""
    show = show or (lambda text: None)
    missing = [name for name in ("pinocchio", "mujoco", "exudyn") if not _installed(name)]
    report = {"missing_peers": missing}
    if latency:
        report["first_call"] = first_call_latency()
        show("first compiled s̈ in a fresh process (import projeq excluded): "
             f"{report['first_call']['first_call_cold_cache_s']:.2f} s with an empty numba cache, "
             f"{report['first_call']['first_call_warm_cache_s']:.3f} s with it filled; import "
             f"{report['first_call']['import_s']:.2f} s")
    report["chain"] = chain_rows(sizes, budget, show)
    report["chain_slopes"] = slopes(report["chain"])
    show("growth exponent (log-log slope over n = " + ", ".join(map(str, sizes)) + "): "
         + ", ".join(f"{k} {v:.2f}" for k, v in report["chain_slopes"].items()))
    disk = report["rolling_disk"] = rolling_disk_row(budget)
    show(f"rolling disk: projeq ({disk['evaluator']}) {disk['seconds']['projeq'] * 1e6:.1f} µs, sympy KanesMethod "
         f"lambdified {disk['seconds']['sympy'] * 1e6:.1f} µs: ratio {disk['ratio']:.2f}; "
         f"angular accelerations differ by {disk['deviation']['sympy']:.1e}")
    if spin_up and "exudyn" not in missing:
        row = report["spin_up"] = spin_up_row()
        show(f"spin-up Ωs = {row['omega_s']:g} rad/s to {row['times_s'][-1]:g} s: Exudyn CPU {row['exudyn_cpu_s']:.2f} s, "
             f"in-plane tip at {row['times_s']} s: {np.round(row['exudyn_tip_m'], 6).tolist()} m")
        for name in ("defaults", "scene_settings"):
            run = row[name]
            show(f"  projeq simulate({run['options'] or 'no options'}): {run['method']}, CPU {run['cpu_s']:.2f} s = "
                 f"{run['cpu_ratio']:.2f} of Exudyn's (first s̈ before it {run['first_call_s']:.2f} s), tip {np.round(run['tip_m'], 6).tolist()} m, max difference {run['max_difference_m']:.1e} m, "
                 f"{run['nfev']} evaluations; warnings: {run['warnings'] or 'none'}")
    if missing:
        show(f"not installed (pip install 'projeq[bench]'): {', '.join(missing)}")
    return report


def _installed(module: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(module) is not None
