"""A parameter sweep: the Atwood machine for five masses, in parallel processes.

Mass 1 (m1) and mass 2 (1 kg) hang on a rope over a pulley (0.5 kg disk, radius 0.1 m).
From rest the pulley turns with constant angular acceleration, so after t the angle is
θ = −½ ẍ t²/a with ẍ = (m1 − m2) g / (m1 + m2 + I/a²) (Problem 1, eq. (4) of the Lagrange seminars).
On a cluster pass ``executor=dask.distributed.Client("tcp://scheduler:8786")``.

Run: python examples/sweep.py
"""

import numpy as np

from projeq.simulation.sweep import sweep

if __name__ == "__main__":  # worker processes import this file: only the main process sweeps
    table = sweep("atwood", grid={"m1": np.linspace(0.5, 2.5, 5)}, outputs=["q0"], t_end=1.0,
                           rtol=1e-10, atol=1e-12)
    table.save("atwood_sweep")
    m1 = table["m1"]
    reference = -0.5 * (m1 - 1.0) * 9.81 / (m1 + 1.0 + 0.25) / 0.1
    for row in zip(m1, table["q0"], reference):
        print("m1 = %.2f kg: θ(1 s) = %.6f rad (closed form %.6f)" % row)
    # constant acceleration, rtol 1e-10: agreement to ~1e-10; 1e-8 leaves a margin of 100
    assert np.allclose(table["q0"], reference, rtol=1e-8) and (table["status"] == 0).all()
