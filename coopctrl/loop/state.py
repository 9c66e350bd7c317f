"""``LoopState``: everything a run of the closed loop carries from one tick to the next."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.load_distribution.goldfarb_idnani import gi_workspace


@dataclass
class LoopState:
    """The state of a closed-loop run between two ticks (the compiled tick reads and updates it in place).

    One tick is a function of this state alone (and of the loop's constant parts), so a run from a
    fresh state is repeatable: :meth:`start` makes one for every run.

    Attributes:
        x: (nx,) plant state ``(z, z')`` at the current tick [m, rad, m/s, rad/s].
        tau: (nu,) torques held over the current period [N m].
        integrals: (m, p) followers' force-error integrals [N s, N m s] (the leader's row stays 0).
        last_split: (3, m, p) the last feasible split ``(F, external, internal)`` [N, N m], held when a
            QP solve fails.
        flags: int64 ``(have_last_split, consecutive_qp_failures, saturated_ticks, qp_solves,
            first_saturated_tick, last_saturated_tick)``.
        saturated_joints: (nu,) int64 ticks on which each joint's torque was clipped.
        hold: int64 ``(mode, qp_status_code, qp_iterations, binding_mask)`` for the next tick: mode 1 holds
            the last split (a failed solve), 2 takes the QP answer the caller supplied (the reference path).
        ws: The compiled QP's workspace (its factor and the active set: the warm start of the next solve).
        tick: Index of the next tick to run (the position in the pre-drawn sensor-noise streams too).
    """

    x: np.ndarray
    tau: np.ndarray
    integrals: np.ndarray
    last_split: np.ndarray
    flags: np.ndarray
    saturated_joints: np.ndarray
    hold: np.ndarray
    ws: tuple
    tick: int = 0

    @classmethod
    def start(cls, x0, nu: int, m: int, p: int, n_qp: int, n_rows: int) -> "LoopState":
        """The state at tick 0: plant state ``x0``, zero torques and integrals, no split yet, a cold QP."""
        return cls(np.array(x0, dtype=float), np.zeros(nu), np.zeros((m, p)), np.zeros((3, m, p)),
                   np.array([0, 0, 0, 0, -1, -1], dtype=np.int64), np.zeros(nu, dtype=np.int64),
                   np.zeros(4, dtype=np.int64), gi_workspace(n_qp, n_rows), 0)
