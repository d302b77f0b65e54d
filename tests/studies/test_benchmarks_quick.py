"""Every script in benchmarks/ runs in its quick mode, in this process, so that none can rot (issue 34,
item 4): ``main(["--quick"])`` of each, and what it prints holds the heads of its tables.

A script found in benchmarks/ that is neither in :data:`PRINTS` nor in :data:`OWN_TESTS` fails
here: a new benchmark gets a quick mode (the same code paths as its full run on the smallest
models and horizons, ≤ 3 s warm) and its line below. The quick runs measure nothing worth
comparing (their timings are of a few calls); their numbers are checked by the full runs and by
the tests of the library. Peers that are not installed (Exudyn, MuJoCo) are left out by the
scripts with one line saying so. The quick modes that cost more than the suite's CI budget allows
(:data:`OPT_IN`: fresh processes, sympy derivations, numba compilations at every run) run here only
with ``PROJEQ_ALL_BENCHMARKS=1``.
"""

import importlib.util
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCHMARKS = ROOT / "benchmarks"

#: scripts whose quick mode a test of its own runs, with more checks: script → that test's file
OWN_TESTS = {
    "barhorst_compiled.py": "tests/studies/test_barhorst_compiled.py",
    "campbell.py": "tests/analysis/test_campbell.py",
    "closure_linalg.py": "tests/constraints/test_compiled_closures.py",
    "effort_growth.py": "tests/studies/test_effort_growth.py",
    "iftomm.py": "tests/studies/test_iftomm_benchmark.py",
    "mutation.py": "tests/studies/test_mutation_benchmark.py",
    "spinning_beam_frequencies.py": "tests/symbolic/test_spinning_beam.py",
    "statements.py": "tests/studies/test_statements_benchmark.py",
    "time_loads.py": "tests/assembly/test_time_loads.py",
    "urdf_pinocchio.py": "tests/scenes/test_urdf.py",
}

#: scripts whose quick mode costs more than the suite's budget allows (warm, this module ≤ 45 s), run with
#: PROJEQ_ALL_BENCHMARKS=1 only: script → why (wall seconds warm, measured on 2 loaded cores)
OPT_IN = {
    "flexible_arm_integrators.py": "its compiled loops take the kernels as first-class arguments, whose "
                                   "types numba's cache does not keep across processes (~1 CPU minute a run)",
    "spinning_beam_chain.py": "the three Ritz models derived by sympy and the slice chains (17 s)",
    "pin_closures.py": "the numpy path's runs and the driven crank's sympy motion (14 s)",
    "output_rows.py": "two fresh processes (13 s)",
    "run_default.py": "four fresh processes (10 s)",
    "extremes.py": "six studies, a 1000-body chain among them (10 s)",
    "closure_runs.py": "Andrews' squeezer on the numpy path, 501 output rows (9 s)",
    "run_profile.py": "two fresh processes (8 s)",
    "beam_convergence.py": "projeq bench's quick study: seven 20 s spin-ups (8 s)",
    "scene_builds.py": "a fresh process (4 s)",
    "tangent_profile.py": "its six profiling loops compiled by numba at every run with an empty cache, each "
                          "linking the closure kernels' helpers (40 s of the 42 s it took in CI)",
}

#: script → texts its quick run prints (table heads and row labels, no numbers)
PRINTS = {
    "angular_velocity_forms.py": ("trig_normal s", "R_z "),
    "beam_convergence.py": ("n_shapes",),
    "bicycle_compiled.py": ("us_per_call", "ratio_to_chain3", "final_state_max_difference (roll_rate=0.0)"),
    "bicycle_effort.py": ('"projeq"', '"s_ddot_s"', '"eigenvalues_s"'),
    "chain_scaling.py": ("recursive µs", "fast µs", "log-log slope"),
    "closure_runs.py": ("numpy/compiled", "andrews_squeezer"),
    "closures.py": ("default/chain", "four_bar", "andrews_squeezer"),
    "cold_start.py": ("projeq run --t-end 1", "default", "exit codes"),
    "code_size.py": ("compiled path:", "interpreted path:", "ratio compiled / interpreted"),
    "compile_lock.py": ("CPU s (both)", "without", "CPU with / without the lock"),
    "compiled_jacobians.py": ("forward diff.", "chain(10)", "spin-up beam", "per column / one call"),
    "default_integrator.py": ("StiffnessWarning", "spin_up_beam", "Radau", "BDF"),
    "derivation.py": ("projeq_s", "lagrange_s"),
    "elastic_compiled.py": ("run ratio", "spinning beam, ρI", "link + rotary beam", "coupled joint + beam"),
    "exact_rest.py": ("event dρ/dt vs Richardson", "exact/fd", "four_bar: n_x", "A02 N=2: n_x"),
    "extremes.py": tuple(f"== {study} ==" for study in ("spin_up", "stiff_beam", "long_runs", "near_singular",
                                                          "mass_ratios", "big_chain")),
    "exudyn_spin_up.py": ("max |v − ref| m", "projeq "),
    "fastest_mode.py": ("ρ exact", "double_pendulum", "four_bar"),
    "flexible_arm.py": ("rigid last link", "RitzBeam, 4 functions", "Radau"),
    "flexible_arm_alpha.py": ("generalized-α, fixed steps", "h = 0.01 s, ρ∞ 0.9", "per-component error estimate"),
    "flexible_arm_integrators.py": ("DOP853 compiled", "exprb43", "ETDRK4", "costs inside a compiled loop"),
    "flexible_arm_exudyn.py": ("cheapest run of each code per error level", "the issue's targets",
                               "simulate(rtol=1e-04)", "GeneralizedAlpha h=0.01"),
    "flexible_four_bar_exudyn.py": ("projeq n_v=2 defaults", "projeq n_v=4 tight"),
    "formulations.py": ("knife-edge disc", "formulation"),
    "four_bar_mujoco.py": ("projeq/MuJoCo", "MuJoCo RK4 dt", "rtol=1e-6"),
    "given_joints.py": ("ẋ one-call µs", "free_chain", "simulate rolling_disk"),
    "jacobians.py": ("elastic_arm (3 shapes)", "Radau", "BDF", "differences", "exact"),
    "loop_drift.py": ("quick-return", "baumgarte beta=10.0", "projection n_segments=100",
                      "four-bar (crank-rocker)", "rocker, repivot"),
    "loop_overhead.py": ("per evaluation", "scipy's loop", "rolling_disk"),
    "nonholonomic_effort.py": ("| car |", "| knife_edge_disc |", "| rolling_disk |"),
    "loop_vs_cyrk.py": ("CyRK/projeq", "projeq run", "chain(3)"),
    "motion_callables.py": ("rotating_blade: µs per evaluation", "hub chain", "spin_up_beam",
                            "median ratio before / after"),
    "output_rows.py": ("before/after", "simple_pendulum"),
    "peers.py": ("chain",),
    "pin_closures.py": ("PinClosure, compiled kernel", "PinClosure, numpy path", "hand-written Φ",
                        "driven, sympy motion"),
    "rolling_disk_inertia.py": ("E0 (g cm²/s²)", "hoop"),
    "row_costs.py": ("chain ", "four_bar ", "µs/row"),
    "run_default.py": ("projeq run (spin_up_beam", "default, 1 s", "first compiled s̈ in a fresh process",
                       "kernel chain_terms"),
    "run_profile.py": ("simulate", "import self-time by package", "slowest cumulative imports"),
    "scene_builds.py": ("barhorst_particle", "first/repeat"),
    "scene_costs.py": ("chain", "four_bar", "ratio"),
    "simulate_share.py": ("ẋ share", "rows share", "DOP853"),
    "spinning_beam_chain.py": ("1. Ritz-constrained chain", "2. spin-up", "RitzBeam"),
    "short_runs.py": ("CPU per run", "evaluations", "double_pendulum"),
    "sweep_points.py": ("CPU per point", "sweep (one thread)", "simulate, a new System"),
    "tangent_profile.py": ("andrews_squeezer: µs per call", "SVD of A_s", "evaluator.accelerations"),
}


def scripts() -> list[str]:
    return sorted(path.name for path in BENCHMARKS.glob("*.py"))


def test_every_script_has_a_quick_test():
    """Each script is run below or by its own test, which exists and runs its quick mode."""
    missing = set(scripts()) - set(PRINTS) - set(OWN_TESTS)
    assert not missing, f"benchmarks without a quick test (give them a --quick mode, PRINTS): {missing}"
    assert set(OPT_IN) <= set(PRINTS) <= set(scripts()) and set(OWN_TESTS) <= set(scripts())
    for script, test in OWN_TESTS.items():
        text = (ROOT / test).read_text()
        assert script in text and '"--quick"' in text, (script, test)


def load(script: str):
    """The script as a module (not run as __main__), in sys.modules as an imported one is (numba's
    object mode finds a compiled function's globals there)."""
    spec = importlib.util.spec_from_file_location(f"benchmark_{Path(script).stem}", BENCHMARKS / script)
    module = sys.modules[spec.name] = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("script", sorted(set(scripts()) - set(OWN_TESTS)))
def test_quick_mode_prints_its_tables(script, capsys):
    if script not in PRINTS:
        pytest.fail(f"benchmarks/{script} has no quick test: give it a --quick mode and a line in PRINTS")
    if script in OPT_IN and os.environ.get("PROJEQ_ALL_BENCHMARKS") != "1":
        pytest.skip(f"{script}: {OPT_IN[script]}; PROJEQ_ALL_BENCHMARKS=1 runs it")
    load(script).main(["--quick"])
    out = capsys.readouterr().out
    for text in PRINTS[script]:
        assert text in out, (text, out[-3000:])
