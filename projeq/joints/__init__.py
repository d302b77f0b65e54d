"""How subsystems connect: the kinematic chain ẏ_n = T_np ẏ_p + F_n ṡ_n (docs/theory.md §4).

- :mod:`.base`: the joint contract (:class:`Joint`, :class:`Relative`, :class:`SymbolicRelative`)
  and the pose/twist check;
- :mod:`.statement`: a joint's one statement (:class:`Stated`: pose, F⁶, f⁶, K, k as scalar code
  over a namespace), run on numpy, traced with sympy and printed for numba;
- :mod:`.standard`: Revolute, Prismatic, Fixed, Planar, Free, Prescribed, each with its sympy
  form (written with :mod:`projeq.symbolic.algebra`) and compiled kind next to ``relative``, and
  Cylindrical, Universal, Spherical, each stated once;
- :mod:`.rolling`: RollingDisk and RollingSphere, rolling without slipping on a plane
  (non-holonomic, stated once);
- :mod:`.user`: :class:`UserJoint` from sympy or callables, compiled by :mod:`.user_compiler`.
"""

from projeq.joints.base import Joint, Relative, SymbolicRelative, pose_twist_mismatch
from projeq.joints.statement import Stated
from projeq.joints.standard import (Cylindrical, Fixed, Free, Planar, Prescribed, Prismatic, Revolute, Spherical,
                                   Universal)
from projeq.joints.rolling import RollingDisk, RollingSphere
from projeq.joints.user import UserJoint

__all__ = ["Joint", "Relative", "Stated", "SymbolicRelative", "pose_twist_mismatch", "Revolute", "Prismatic", "Fixed",
           "Planar", "Free", "Prescribed", "Cylindrical", "Universal", "Spherical", "RollingDisk", "RollingSphere",
           "UserJoint"]
