"""Robot arms (MODEL.md s.4): ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q)``, ``J``, ``dJ dq``.

The hot path is the numba kernels :func:`spatial_arm_terms` and :func:`planar_arm_terms`
(``plants.arms._spatial_kernels`` / ``_planar_kernels``); the classes wrap them for Python use.
"""

from plants.arms.arm_terms import ArmTerms
from plants.arms.dh_link import DHLink
from plants.arms.planar3r import planar3r
from plants.arms.planar_arm import PlanarArm
from plants.arms.planar_link import PlanarLink
from plants.arms.puma560 import puma560
from plants.arms.serial_arm import SerialArm

__all__ = ["ArmTerms", "DHLink", "PlanarArm", "PlanarLink", "SerialArm", "planar3r", "puma560"]
