"""Which inertia did Barhorst's rolling disk have? (A. A. Barhorst, "Generalized momenta in
constrained non-holonomic systems", §3.2, Figs. 5–8.)

For the uniform thin disk (I = m R²/4, J = m R²/2) and the hoop (I = m R²/2, J = m R²), with
his parameters and start (``scenes.rolling_disk``): the energy E0 and the momentum
p₂ = ∂T/∂u₂ at the start, and over his 10 s the ranges of the heading q1, the roll q3, the
contact point (q4, q5) and p₂, in his units (g, cm, s). His figures: E ≈ 75197 g cm²/s²
(Fig. 8), p₂ axes from about 2850 g cm²/s (Figs. 6, 8); heading axes to about −60 rad, roll to
about 250 rad, q4 within about ±6 cm, q5 down to about −12 cm.

    python benchmarks/rolling_disk_inertia.py           # ~1 min
    python benchmarks/rolling_disk_inertia.py --quick   # his first 0.1 s (a test runs it)
"""

import os
import argparse

import numpy as np

import projeq as pq

G_CM2_S2 = 1e7  # 1 kg m²/s² in g cm²/s²


def study(inertia: str, t_end: float = 10.0) -> dict:
    system = pq.scenes.rolling_disk(inertia=inertia)
    result = pq.simulate(system, t_end, method="DOP853", rtol=1e-10, atol=1e-12,
                         n_points=int(200 * t_end) + 1)
    dense = system.evaluator("dense")
    p2 = np.array([(dense.gauss_form(q, u, 0.0)[0] @ u)[1] for q, u in zip(result.q, result.s_dot)]) * G_CM2_S2
    q1, q3, q4, q5 = result.q[:, 0], result.q[:, 2], 100 * result.q[:, 3], 100 * result.q[:, 4]
    return {"inertia": inertia, "E0 (g cm²/s²)": sum(system.energy(system.q0, system.s_dot0)) * G_CM2_S2,
            "p2(0) (g cm²/s)": p2[0], "p2 range": (p2.min(), p2.max()), "q1 min (rad)": q1.min(),
            "q3 max (rad)": q3.max(), "q4 range (cm)": (q4.min(), q4.max()), "q5 range (cm)": (q5.min(), q5.max()),
            "energy drift": result.energy_drift}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first 0.1 s only")
    args = parser.parse_args(argv)
    for inertia in ("disk", "hoop"):
        for key, value in study(inertia, 0.1 if args.quick else 10.0).items():
            text = f"[{value[0]:.4g}, {value[1]:.4g}]" if isinstance(value, tuple) else (
                f"{value:.6g}" if isinstance(value, float) else value)
            print(f"{key:>18}: {text}")
        print()


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
