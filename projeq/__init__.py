"""projeq: equations of motion of multibody systems by H. Bremer's Projection Equation.

Σ_n (∂ẏ_n/∂ṡ)ᵀ (M_n ÿ_n + G_n ẏ_n − Q_n) = 0, assembled densely (Gauss form) or solved
recursively in order n. See docs/theory.md and docs/architecture.md.

Docstrings cite equations as B(n), eq. (n) of H. Bremer (2009), "Problems in Fast Moving
Non-Holonomic Elastic Systems", and K(n), eq. (n) of R. M. M. Orsino (2020), "Non-Holonomic
Systems; Lagrange Multipliers"; other publications by the short keys of the References in
docs/theory.md, and that page by its numbered sections ("docs/theory.md §6").
"""

from projeq.subsystems import inertia
from projeq.assembly import SingularMassError
from projeq.forces import BodyLoad, Force, ForceLaw, JointForce, JointSpring, SpringDamper, Torque
from projeq.analysis.linearize import Linearization, NotSteadyError, eigenvalue_sweep, linearize
from projeq.joints import (Cylindrical, Fixed, Free, Joint, Planar, Prescribed, Prismatic, Revolute, RollingDisk,
                           RollingSphere, Spherical, Universal, UserJoint)
from projeq.subsystems import Frame, PlanarBody, PointMass, RigidBody, RitzBeam, Subsystem
from projeq.system import GROUND, System, SystemBuilder

__version__ = "0.1.0"

__all__ = [
    "GROUND", "System", "SystemBuilder", "Subsystem", "RigidBody", "PlanarBody", "PointMass", "Frame", "RitzBeam",
    "Joint", "Revolute", "Prismatic", "Fixed", "Planar", "Free", "Prescribed", "Cylindrical", "Universal",
    "Spherical", "RollingDisk", "RollingSphere", "UserJoint",
    "ForceLaw", "BodyLoad", "Force", "Torque", "JointForce", "JointSpring", "SpringDamper", "SingularMassError",
    "inertia", "simulate", "Result", "SimulationError", "scenes", "linearize", "Linearization", "NotSteadyError",
    "eigenvalue_sweep", "modes", "Modes", "campbell", "CampbellDiagram", "compare", "ComparisonTable", "ConstrainedSystem", "reactions", "joint_reactions", "PinClosure",
    "contact_event", "StiffnessWarning", "plots", "sweep", "SweepTable", "symbolic", "from_urdf",
]


# names loaded on first use (they import scipy, matplotlib or tqdm): keeps `import projeq` light
_LAZY = {
    "modes": "projeq.analysis.campbell", "Modes": "projeq.analysis.campbell", "campbell": "projeq.analysis.campbell",
    "CampbellDiagram": "projeq.analysis.campbell",
    "simulate": "projeq.simulation.driver", "Result": "projeq.simulation.driver", "SimulationError": "projeq.simulation.driver",
    "compare": "projeq.studies.compare", "ComparisonTable": "projeq.studies.compare",
    "ConstrainedSystem": "projeq.constraints.partitioned",
    "PinClosure": "projeq.constraints.cut_joints",
    "reactions": "projeq.constraints.reactions", "joint_reactions": "projeq.constraints.reactions",
    "contact_event": "projeq.constraints.reactions",
    "sweep": "projeq.simulation.sweep", "SweepTable": "projeq.simulation.sweep",
    "StiffnessWarning": "projeq.simulation.integrators",
    "from_urdf": "projeq.scenes.urdf",
}
_LAZY_MODULES = {"scenes": "projeq.scenes", "plots": "projeq.simulation.plots", "symbolic": "projeq.symbolic"}


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    if name in _LAZY_MODULES:
        return importlib.import_module(_LAZY_MODULES[name])
    raise AttributeError(f"module 'projeq' has no attribute {name!r}")
