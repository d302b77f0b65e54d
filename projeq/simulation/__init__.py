"""From equations to trajectories (THEORY, "From the equation to a trajectory").

- :mod:`.driver`: :func:`simulate`, :class:`Result`, :class:`SimulationError`;
- :mod:`.integrators`: projected integrators and the stiffness monitor;
- :mod:`.sweep`: parameter sweeps on a process pool or Dask;
- :mod:`.export`: ParaView time series; :mod:`.plots`: matplotlib figures of a Result.
"""
