"""projeq: equations of motion of multibody systems by H. Bremer's Projection Equation.

Σ_n (∂ẏ_n/∂ṡ)ᵀ (M_n ÿ_n + G_n ẏ_n − Q_n) = 0, assembled densely (Gauss form) or solved
recursively in order n. See docs/ and shared/design/THEORY.md.
"""

from projeq import inertia
from projeq.assembly import SingularMassError
from projeq.forces import Force, JointForce, JointSpring, SpringDamper, Torque
from projeq.linearization import linearize
from projeq.joints import Fixed, Free, Joint, Planar, Prescribed, Prismatic, Revolute, UserJoint
from projeq.subsystems import Frame, PlanarBody, PointMass, RigidBody, RitzBeam, Subsystem
from projeq.system import GROUND, System, SystemBuilder

__version__ = "0.1.0"

__all__ = [
    "GROUND", "System", "SystemBuilder", "Subsystem", "RigidBody", "PlanarBody", "PointMass", "Frame", "RitzBeam",
    "Joint", "Revolute", "Prismatic", "Fixed", "Planar", "Free", "Prescribed", "UserJoint",
    "Force", "Torque", "JointForce", "JointSpring", "SpringDamper", "SingularMassError",
    "inertia", "simulate", "Result", "SimulationError", "scenes", "linearize",
]


def __getattr__(name):
    # simulate and scenes import scipy; load them on first use to keep `import projeq` light
    if name in ("simulate", "Result", "SimulationError"):
        from projeq import simulation

        return getattr(simulation, name)
    if name == "scenes":
        import projeq.scenes as scenes

        return scenes
    raise AttributeError(f"module 'projeq' has no attribute {name!r}")
