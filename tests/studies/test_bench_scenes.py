"""The scenes that run compiled by default stay compiled (issue 15, item 4): a CI
regression check against the baseline of benchmarks/results/2026-11-27/scene_costs.json
(written by ``python benchmarks/scene_costs.py --json``), by the evaluator each scene's
default picks and by the ratio of its s̈ cost to the compiled ``chain(k)``, both timed
alternately in one run (ratios, not absolute times: projeq.studies.timing).

A scene that falls back to an interpreted evaluator costs 50–300× chain(k) (the
2026-11-27 baseline before issue 15's compiled planar bodies, coupled joints and
constrained trees), a compiled one 1–7× (the hub-beam path 10–13×; the constrained scenes,
whose constraint equations are the user's Python callables differentiated by the complex
step, 17–85× with a compiled tree); the ratio check allows 3× its baseline ratio (the
interleaved minima of a loaded 2-core machine vary by less than 2×), so it catches a
fall-back or a comparable regression, not noise; the evaluator check catches any fall-back.
"""

import json
from pathlib import Path

import pytest

from projeq import scenes
from projeq.studies.bench_scenes import COMPILED, default_evaluator, scene_row

BASELINE = json.loads((Path(__file__).parents[2] / "benchmarks/results/2026-11-27/scene_costs.json").read_text())
BASELINE_ROWS = {row["scene"]: row for row in BASELINE["scenes"]}
COMPILED_SCENES = sorted(name for name, row in BASELINE_ROWS.items() if row["evaluator"] in COMPILED)
REGRESSION = 3.0


def test_the_baseline_covers_every_scene_and_most_are_compiled():
    assert set(BASELINE_ROWS) == set(scenes.SCENES)
    assert {"chain", "double_pendulum", "rolling_disk", "knife_edge_disc", "spin_up_beam", "car", "atwood",
            "four_bar", "bricard", "whipple_bicycle"} <= set(COMPILED_SCENES)


@pytest.mark.parametrize("name", COMPILED_SCENES)
def test_a_compiled_scene_stays_compiled_and_as_cheap_relative_to_the_chain(name):
    """The default evaluator is the baseline's compiled one, and s̈ costs at most
    REGRESSION × the baseline's ratio to chain(k) (k = n_s) in one interleaved run."""
    assert default_evaluator(scenes.SCENES[name].build())[0] == BASELINE_ROWS[name]["evaluator"]
    row = scene_row(name, budget=0.1)
    assert row["ratio"] <= REGRESSION * BASELINE_ROWS[name]["ratio"], row
