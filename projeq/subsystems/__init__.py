"""What moves: subsystems and their Gauss-form terms M_n ÿ_n + G_n ẏ_n − Q_n (B(13)–(14))."""

from projeq.subsystems.base import Subsystem
from projeq.subsystems.beam import RitzBeam
from projeq.subsystems.rigid import Frame, PlanarBody, PointMass, RigidBody

__all__ = ["Subsystem", "RigidBody", "PlanarBody", "PointMass", "Frame", "RitzBeam"]
