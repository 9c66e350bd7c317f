"""Load distribution: contact wrenches that carry the object's nominal load (docs/model.md section 6).

One concept per module: :mod:`.grasp_matrix` (``G``, the virtual-linkage basis ``E``, the null-space basis and the pair tensions),
:mod:`.config` (:class:`LoadDistributionConfig`), :mod:`.answer_check` (the answer's check and binding families),
:mod:`.goldfarb_idnani` (the compiled solver's method and workspace), :mod:`.problem` (the QP arrays),
:mod:`.solvers` (backends and :class:`QPStats`), :mod:`.load_split` (:class:`LoadSplit`) and
:mod:`.load_distribution` (:class:`LoadDistribution`, with the failure policy).

The configuration and the grasp matrix load with numpy alone; the QP's classes are imported on first use
(:func:`__getattr__`, PEP 562), so that validating a scenario (which reads :class:`LoadDistributionConfig`)
does not import scipy or the compiled core: a bad input is refused, and a sweep's runs are validated, before
those load.

The QP's rows (coopctrl/core/qp_assembly.h), their inputs from the plant's terms (the contact normals and the
torque-limit model, coopctrl/core/qp_contact_model.h), the elastic split's inputs (qp_elastic_assembly.h), the
answer's check (qp_answer_check.h) and the pair tensions (qp_tensions.h) are written once, in the C++ core
(``coopctrl._core``), which :mod:`.problem`, :mod:`coopctrl.loop.qp_inputs` and the compiled tick call.
"""

import importlib

from .config import LoadDistributionConfig
from .grasp_matrix import (contact_pairs, grasp_matrix, internal_force_basis, internal_null_basis, pair_tensions,
                           virtual_linkage_squeeze)

#: The names imported on first use, and their modules.
_LAZY = {
    "LoadDistribution": ".load_distribution",
    "LoadSplit": ".load_split",
    "LoadDistributionProblem": ".problem",
    "ProxsuiteSolver": ".solvers",
    "QPStats": ".solvers",
    "QpsolversSolver": ".solvers",
    "make_solver": ".solvers",
}


def __getattr__(name: str):
    """Import one of :data:`_LAZY`'s names from its module on first use (then it is a plain attribute)."""
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))

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
