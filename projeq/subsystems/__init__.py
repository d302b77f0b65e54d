"""What moves: subsystems and their Gauss-form terms M_n ÿ_n + G_n ẏ_n − Q_n (B(13)–(14)).

- :mod:`.base`: the subsystem protocol (and :class:`.Visual`, a solid that draws one);
- :mod:`.rigid`: RigidBody, PlanarBody, PointMass, Frame;
- :mod:`.beam`: RitzBeam (direct Ritz approach, B(19)–(25)): shapes, integrals, probes, checks;
- :mod:`.inertia`: inertia tensors of common shapes.
"""

from projeq.subsystems import inertia
from projeq.subsystems.base import Subsystem, Visual
from projeq.subsystems.beam.beam import RitzBeam
from projeq.subsystems.rigid import Frame, PlanarBody, PointMass, RigidBody

__all__ = ["Subsystem", "Visual", "RigidBody", "PlanarBody", "PointMass", "Frame", "RitzBeam", "inertia"]
