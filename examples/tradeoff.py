"""Work-precision: the cheapest integrator setting for an accuracy (``projeq.studies.tradeoff``).

The knife-edge disc (Orsino (2020), slides 28-37) integrated by DOP853 at two relative
tolerances, each run's error measured against a converged reference (DOP853 at rtol 1e-13,
``projeq.studies.tradeoff``'s reference run). The checked fact: an error-controlled integrator
meets the request — the error at the end is within a small multiple of rtol times the
solution's size (here O(1) m and rad) — and tightening rtol by 1e4 buys at least 1e3.

Run: python examples/tradeoff.py  (PROJEQ_QUICK=1: DOP853 over 1 s only, as the tests do)
"""

import os

from projeq.studies.tradeoff import cheapest, format_table, plot, tradeoff

QUICK = bool(os.environ.get("PROJEQ_QUICK"))
methods = ["DOP853"] if QUICK else ["RK45", "DOP853", "Radau", "LSODA"]
table = tradeoff("knife_edge_disc", methods=methods, tolerances=[1e-4, 1e-8], knobs=["recursive"], quick=True,
                 t_end=1.0 if QUICK else None)
print(format_table(table))
dop853 = table["method"] == "DOP853"
loose, tight = table["error"][dop853]
# a global error of a few local tolerances over the run (achieved 0.15 and 0.12 rtol in 1 s, 0.7 and 0.9
# over the quick study's time): 100 rtol
assert loose < 100 * 1e-4 and tight < 100 * 1e-8 and tight < 1e-3 * loose
print("cheapest setting per error level:")
for level, row in cheapest(table).items():  # row index into the table, None where no setting reaches it
    setting = "none reaches it" if row is None else (
        f"{table['method'][row]} at rtol {table['rtol'][row]:.0e} ({table['knob'][row]} evaluator), "
        f"error {table['error'][row]:.1e}, {table['cpu'][row]:.3g} s CPU")
    print(f"  error ≤ {level:.0e}: {setting}")
plot(table).savefig("work_precision.png")
