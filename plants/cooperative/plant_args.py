"""The plant's kernel arrays by name: :class:`PlantArgs`, what a compiled caller passes the plant's kernels.

A :class:`~plants.cooperative.cooperative_plant.CooperativePlant` packs its model into a few arrays once
(:attr:`CooperativePlant.plant_args`); the compiled right-hand side, control terms and energy read them
by name (``P.arm_kind``, ``P.bases``).
"""

from __future__ import annotations

from collections import namedtuple

#: Codes of ``PlantArgs.arm_kind`` (plants/core/cooperative_planar.h, ``ArmKind``): a serial arm; an actuated
#: node without arm dynamics (a contact point); a spatial serial arm whose node's angles are taken in the node's
#: own chart at each evaluation (``C = R_tip(q)``, ``A = 0``; docs/model.md s.2): it never meets the Euler
#: singularity.
ARM_SERIAL, ARM_CONTACT_POINT, ARM_SERIAL_OWN_CHART = 0, 1, 2

PlantArgs = namedtuple("PlantArgs", "arm_kind arm_dof q_off tables table_off bases tools gravity node_params "
                                    "edge_index edge_params Y_ref immobile")
PlantArgs.__doc__ = """The plant's kernel arrays, by name (one plant: read-only to its kernels, except the
bases and gravity of a plant with its own world, ``CooperativePlant.with_own_world``).

``arm_kind``: int64 (m,), each arm's kind (:data:`ARM_SERIAL`, :data:`ARM_SERIAL_OWN_CHART`,
:data:`ARM_CONTACT_POINT`); ``arm_dof``: int64 (m,), its joints (p for a contact point);
``q_off``: int64 (m,), where its coordinates start in ``z``; ``tables``: the serial arms' joint tables
stacked (float64 (rows, 32) spatial, (rows, 7) planar; ``plants.arms``' ``kernel_table``); ``table_off``:
int64 (m,), each arm's first row in ``tables``; ``bases``: the arms' base frames in the world,
float64 (m, 4, 4) [m] spatial or (m, 3) [m, m, rad] planar; ``tools``: the node frames in the last link,
the same shapes; ``gravity``: float64 (3,) or (2,) [m/s^2]; ``node_params``: float64 (m + 1, w), each
node's mass [kg] and principal inertia [kg m^2] (and, in rotation charts, its chart: docs/model.md s.2);
``edge_index``: int64 (e, 4), the two nodes each spring and damper joins, its element and its damping
form (codes of ``plants.elastic._layout``); ``edge_params``: float64 (e, w),
their stiffness [N/m, N m/rad], damping [N s/m, N m s/rad] and rest geometry (``plants.elastic._layout``);
``Y_ref``: float64 (m + 1, p), the unloaded node poses an immobile state's springs start from [m, rad];
``immobile``: bool, the object is held (the book's immobile unloaded state).
"""


def is_spatial(P) -> bool:
    """True for a spatial plant's arrays (bases (m, 4, 4)), False for a planar plant's (bases (m, 3))."""
    return P.bases.ndim == 3
