"""Result of one load-distribution step."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .grasp_matrix import virtual_linkage_squeeze


@dataclass(frozen=True)
class LoadSplit:
    """Contact wrenches chosen by the load-distribution QP for one step.

    ``F = external + internal`` with ``G F = w_N``; ``external = A w_N`` (the non-squeezing split,
    or ``A_K w_N`` for the elastic split) and ``internal`` in ``null(G)``.

    Attributes:
        F: Contact wrench of each arm on the object, shape (m, 6) [N, N m] or (m, 3) planar
            ``(f_x, f_z, n)``.
        external: The part ``A w_N``, same shape [N, N m].
        internal: ``F - external``, in ``null(G)``, same shape [N, N m].
        r_contacts: The contact points of the step [m] (of the held step for a held split).
        space: ``"spatial"`` or ``"planar"``.
        status: Status of this step's solve (``"solved"``, ``"infeasible"``, ``"max_iter"``,
            ``"failed"``); for a held split, the status of the failed solve.
        iterations: Solver iterations of this step (-1 if unknown).
        solve_time_s: Wall-clock solve time of this step [s].
        binding: Constraint families that are active (on success) or violated (on failure):
            ``"min_grip"``, ``"friction"``, ``"torque_limits"``, ``"balance"``.
        held: ``True`` if this is the last feasible split, held because this step's solve failed.
    """

    F: np.ndarray
    external: np.ndarray
    internal: np.ndarray
    r_contacts: np.ndarray
    space: str
    status: str
    iterations: int
    solve_time_s: float
    binding: tuple[str, ...] = ()
    held: bool = False

    def __post_init__(self):
        shape = self.F.shape
        if len(shape) != 2 or shape[1] not in (3, 6):
            raise ValueError(f"LoadSplit.F: expected shape (m, 6) or (m, 3), got {shape}")
        if self.external.shape != shape or self.internal.shape != shape:
            raise ValueError(f"LoadSplit.external/internal: expected shape {shape}, got "
                             f"{self.external.shape} and {self.internal.shape}")
        for name in ("F", "external", "internal", "r_contacts"):
            a = getattr(self, name)
            if isinstance(a, np.ndarray):
                a.flags.writeable = False

    @cached_property
    def squeeze(self) -> np.ndarray:
        """Virtual-linkage squeeze of ``internal`` per contact pair ``i < j`` (lexicographic),
        positive = compression [N]; computed on first access (``E^+ F_int``)."""
        s = virtual_linkage_squeeze(self.internal, self.r_contacts, self.space)
        s.flags.writeable = False
        return s
