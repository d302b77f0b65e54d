"""Studies built on the library: comparison of formulations, work-precision trade-offs, benchmarks.

- :mod:`.compare`: Projection Equation vs Hamel vs Lagrange/Hamilton, term by term and by effort;
- :mod:`.tradeoff`: error against CPU time per integrator, tolerance and model knob;
- :mod:`.bench`: ``projeq bench``; :mod:`.bench_exact`: an extended-precision reference s̈.
"""
