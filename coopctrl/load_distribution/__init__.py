"""Load distribution: contact wrenches that carry the object's nominal load (docs/model.md section 6).

One concept per module: :mod:`.grasp_matrix` (``G``, the virtual-linkage basis ``E``, the null-space basis and the pair tensions),
:mod:`.config` (:class:`LoadDistributionConfig`), :mod:`.assembly` (the QP's rows, in numba: written
once, called by :mod:`.problem` and by the compiled tick), :mod:`.contact_model` (the rows' inputs from
the plant's terms, the contact normals and the torque-limit model, in numba: written once, called by the
compiled tick and :mod:`coopctrl.loop.qp_inputs`), :mod:`.problem` (the QP arrays),
:mod:`.solvers` (backends and :class:`QPStats`), :mod:`.load_split` (:class:`LoadSplit`) and
:mod:`.load_distribution` (:class:`LoadDistribution`, with the failure policy).
"""

from .config import LoadDistributionConfig
from .grasp_matrix import (contact_pairs, grasp_matrix, internal_force_basis, internal_null_basis, pair_tensions,
                           virtual_linkage_squeeze)
from .load_distribution import LoadDistribution
from .load_split import LoadSplit
from .problem import LoadDistributionProblem
from .solvers import ProxsuiteSolver, QPStats, QpsolversSolver, make_solver

__all__ = [
    "LoadDistribution",
    "LoadDistributionConfig",
    "LoadDistributionProblem",
    "LoadSplit",
    "ProxsuiteSolver",
    "QPStats",
    "QpsolversSolver",
    "contact_pairs",
    "grasp_matrix",
    "internal_force_basis",
    "internal_null_basis",
    "make_solver",
    "pair_tensions",
    "virtual_linkage_squeeze",
]
