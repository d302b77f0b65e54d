"""Barhorst's formulation study measured fairly: every right-hand side generated from sympy and compiled.

A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion", §3.1 and §3.3: the particle with ẏ − y²ẋ = 0 (10 s; his projective and
canonical forms "95 %" and "94 %" faster than Hamilton's canonical DAE, i.e. time ratios 0.05 and 0.06)
and the quick-return mechanism (10 s in 0.056 s, his Lagrangian canonical form). Each formulation's
right-hand side is printed from its sympy derivation and compiled by numba
(:func:`projeq.studies.barhorst_compiled.compiled_study`); all are integrated by the same Radau IIA
(the DAE included) and the ODE forms by the same DOP853, at rtol 1e-8, atol 1e-10. Times are process
(CPU) seconds of a warm run, with the generation and compilation seconds beside; ratios are to Hamilton's
DAE (Radau IIA) as in his particle figure.

    python benchmarks/barhorst_compiled.py           # particle and quick return, 10 s, numba
    python benchmarks/barhorst_compiled.py --quick   # particle, 1 s, the generated code run by numpy (≤ 3 s)
"""

from __future__ import annotations

import argparse
import os

import numpy as np

from projeq.studies.barhorst_compiled import compiled_study

#: Barhorst's numbers (§3.1 text and Figs. 1–3; §3.3 text): integration time, or its ratio to Hamilton's DAE.
PAPER = {
    "barhorst_particle": {"hamilton canonical + multipliers (DAE)": "1 (baseline)",
                          "kane (projective), u = ẏ": "0.05 (“95 % faster”)",
                          "barhorst projective canonical, u = ẏ": "0.06 (“94 %”)",
                          "barhorst lagrangian canonical, u = ẏ": "not run (same equations as projective)"},
    "quick_return": {"kane (projective), u = q̇1": "not in the paper",
                     "barhorst projective canonical, u = q̇1": "not in the paper",
                     "barhorst lagrangian canonical, u = q̇1": "0.056 s for 10 s"},
}


def table(study: str, runs) -> list[dict]:
    """Rows of one study: times, ratios to the first row's Radau IIA time, steps, Barhorst's number."""
    baseline = runs[0].radau_s
    rows = []
    for run in runs:
        dop853_ratio = None if run.dop853_s is None else run.dop853_s / baseline
        rows.append({"formulation": run.formulation, "generate_s": run.generate_s, "compile_s": run.compile_s,
                     "radau_s": run.radau_s, "radau_ratio": run.radau_s / baseline,
                     "radau_steps": run.radau_steps, "dop853_s": run.dop853_s, "dop853_ratio": dop853_ratio,
                     "dop853_steps": run.dop853_steps, "paper": PAPER[study][run.formulation],
                     "gap": float(np.abs(run.q[:, -1] - runs[0].q[:, -1]).max())})
    print(f"\n{study}: CPU s of a warm run (ratio to the first row's Radau IIA), "
          "generation and compilation beside")
    print(f"{'formulation':40} {'gen_s':>6} {'comp_s':>6} {'Radau s':>8} {'ratio':>5} {'steps':>5} "
          f"{'DOP853 s':>8} {'ratio':>5} {'steps':>5} {'|Δq(end)|':>9}  Barhorst")
    for r in rows:
        dop = ("—", "—", "—") if r["dop853_s"] is None else (
            f"{r['dop853_s']:.3f}", f"{r['dop853_ratio']:.2f}", str(r["dop853_steps"]))
        print(f"{r['formulation']:40} {r['generate_s']:6.2f} {r['compile_s']:6.2f} {r['radau_s']:8.3f} "
              f"{r['radau_ratio']:5.2f} {r['radau_steps']:5d} {dop[0]:>8} {dop[1]:>5} {dop[2]:>5} "
              f"{r['gap']:9.1e}  {r['paper']}")
    return rows


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", default=os.environ.get("PROJEQ_QUICK") == "1")
    args = parser.parse_args(argv)
    if args.quick:
        return {"barhorst_particle": table("barhorst_particle",
                                           compiled_study("barhorst_particle", 1.0, compile=False, repeat=1))}
    return {study: table(study, compiled_study(study, 10.0))
            for study in ("barhorst_particle", "quick_return")}


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
