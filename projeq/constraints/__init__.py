"""Constraints (docs/theory.md §7): closed loops and Pfaffian constraints given as equations on a tree.

- :mod:`.partitioned`: :class:`ConstrainedSystem`, the partitioned model with minimal velocities;
- :mod:`.tangent`: :class:`TangentSystem`, minimal velocities in the constraints' null space (through
  singular positions, redundant constraints taken as they are);
- :mod:`.augmented`: :class:`AugmentedSystem`, the augmented Lagrangian formulation (the alternative);
- :mod:`.cut_joints`: cut joints of closed loops (:class:`PinClosure`);
- :mod:`.batched`: the loop closures' derivatives from one call at a batch of points;
- :mod:`.compiled`: the constrained s̈ (Φ compiled, its derivatives, F, the projection) in one compiled call;
- :mod:`.reactions`: reaction forces and the contact event;
- :mod:`.nonholonomic`: checks of non-holonomic quasi-velocities (singular K, constraint drift).
"""
