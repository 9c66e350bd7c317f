"""Robot arms (docs/model.md s.4): ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q)``, ``J``, ``dJ dq``.

The classes call the compiled core (``plants._core``, ``plants/core``: ``chain_arm_*`` for general joints, URDF
and DH arms alike, ``dh_arm_*``, ``planar_arm_*``); :mod:`plants.arms.chain_table` lays out a chain's joint table.
"""

from plants.arms.arm_terms import ArmTerms
from plants.arms.chain_arm import ChainArm
from plants.arms.chain_joint import ChainJoint
from plants.arms.dh_link import DHLink
from plants.arms.planar3r import planar3r
from plants.arms.planar_arm import PlanarArm
from plants.arms.planar_link import PlanarLink
from plants.arms.puma560 import puma560
from plants.arms.named_robots import iiwa14, panda, ur5e
from plants.arms.serial_arm import SerialArm
from plants.arms.urdf import from_urdf

__all__ = [
    "ArmTerms", "ChainArm", "ChainJoint", "DHLink", "PlanarArm", "PlanarLink", "SerialArm",
    "from_urdf", "iiwa14", "panda", "planar3r", "puma560", "ur5e",
]
