"""Scratch of the compiled core's torque model (coopctrl/core/qp_contact_model.h, ``coopctrl._core.torque_model_into``).

The core's control arithmetic (the LU solve, the computed torque of a square or redundant arm, the dynamically
consistent acceleration) works in arrays the caller makes once per run: :func:`control_work` makes them.
"""

from __future__ import annotations

import numpy as np

#: Rows of the vector scratch ``wv`` and matrices of ``wm`` that :func:`control_work` makes.
WORK_VECTORS = 8
WORK_MATRICES = 4


def control_work(nmax: int):
    """Scratch ``(wv, wm)``: ``wv`` (:data:`WORK_VECTORS`, nmax) vectors and ``wm`` (:data:`WORK_MATRICES`,
    nmax, nmax) matrices for arms of up to ``nmax`` joints (``nmax >= p``, the task dimension)."""
    return np.empty((WORK_VECTORS, nmax)), np.empty((WORK_MATRICES, nmax, nmax))
