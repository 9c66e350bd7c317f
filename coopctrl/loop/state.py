"""``LoopState``: everything a run of the closed loop carries from one tick to the next."""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

import coopctrl._core as _core
from coopctrl.load_distribution.goldfarb_idnani import gi_workspace


@dataclass
class ChartState:
    """Where a run in rotation charts (:mod:`coopctrl.loop.charts`) ended, in its own world chart: what a
    continuation resumes from exactly (the :class:`LoopState` fields are turned back into the book's world
    coordinates, which would round).

    Attributes:
        C: (3, 3) the world chart in use at the end [-].
        x, tau, integrals, last_split: the loop state's fields of the same names in that chart.
        next_check: the tick (counted from the motion's start) at which the run would next have checked
            whether to re-centre the chart.
    """

    C: np.ndarray
    x: np.ndarray
    tau: np.ndarray
    integrals: np.ndarray
    last_split: np.ndarray
    next_check: int


@dataclass
class LoopState:
    """The state of a closed-loop run between two ticks (the compiled tick reads and updates it in place).

    One tick is a function of this state alone (and of the loop's constant parts), so a run from a
    fresh state is repeatable: :meth:`start` makes one for every run. A run's record ends with the state at
    its end (``record.final_state``); ``loop.run(final_state, duration)`` continues from it, and the two
    runs' records, one after the other, are those of one long run, bit for bit. (The reference path's QP
    backend, ``load_distribution.solver`` other than ``"compiled"``, is not part of it: a continuation starts
    that solver cold, and agrees with the long run to the solver's tolerance.)

    Attributes:
        x: (nx,) plant state ``(z, z')`` at the current tick [m, rad, m/s, rad/s].
        tau: (nu,) torques held over the current period [N m].
        integrals: (m, p) followers' force-error integrals [N s, N m s] (the leader's row stays 0).
        last_split: (3, m, p) the last feasible split ``(F, external, internal)`` [N, N m], held when a
            QP solve fails.
        flags: the run's tallies by name (:class:`coopctrl._core.LoopFlags`: ``have_last_split``,
            ``consecutive_failures``, ``saturated_ticks``, ``qp_solves``, ``first_saturated``, ``last_saturated``,
            ``advance_first``); ``advance_first`` = 1 at the end of a run: ``x`` is the state of tick
            ``tick - 1``, the last recorded, and the plant is yet to advance over that tick's period with
            ``tau`` (a continuation does it first).
        saturated_joints: (nu,) int64 ticks on which each joint's torque was clipped.
        hold: the next tick's hold (:class:`coopctrl._core.HoldState`: ``mode``, ``qp_status``, ``iterations``,
            ``binding``): mode 1 holds the last split (a failed compiled solve, after the failure policy).
        ws: The compiled QP's workspace (its factor and the active set: the warm start of the next solve).
        tick: Index of the next tick to record, counted from the motion's start (the trajectory's time
            ``tick T`` [s] and the position in the sensor-noise streams).
        plan: The integrator's work arrays and step-to-step state (an implicit scheme's Newton matrix, an
            error-controlled scheme's step size), or None for a cold start.
        chart: A run in rotation charts: where it ended, in its world chart (:class:`ChartState`); else None.
        resumable: False for the final state of a run that stopped early: a failed run cannot be continued.
    """

    x: np.ndarray
    tau: np.ndarray
    integrals: np.ndarray
    last_split: np.ndarray
    flags: _core.LoopFlags
    saturated_joints: np.ndarray
    hold: _core.HoldState
    ws: tuple
    tick: int = 0
    plan: object = None
    chart: ChartState | None = None
    resumable: bool = True

    @classmethod
    def start(cls, x0, nu: int, m: int, p: int, n_qp: int, n_rows: int) -> "LoopState":
        """The state at tick 0: plant state ``x0``, zero torques and integrals, no split yet, a cold QP."""
        return cls(np.array(x0, dtype=float), np.zeros(nu), np.zeros((m, p)), np.zeros((3, m, p)),
                   _core.LoopFlags(), np.zeros(nu, dtype=np.int64), _core.HoldState(), gi_workspace(n_qp, n_rows), 0)

    def copy(self) -> "LoopState":
        """A copy that shares no array with this state (a run works on a copy: what it was given is unchanged)."""
        return copy.deepcopy(self)

    def for_continuation(self) -> "LoopState":
        """A copy to continue from: the per-run tallies (saturated ticks, per joint, first and last) start
        afresh; the dynamics' state (``x``, ``tau``, integrals, last split, the QP's warm start and failure
        count, the integrator's plan) is carried over."""
        state = self.copy()
        fresh = _core.LoopFlags()
        state.flags.saturated_ticks = fresh.saturated_ticks
        state.flags.first_saturated, state.flags.last_saturated = fresh.first_saturated, fresh.last_saturated
        state.saturated_joints[:] = 0
        return state


__all__ = ["ChartState", "LoopState"]
