"""``ControllerState``: everything a :class:`~coopctrl.Controller` carries from one step to the next."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

import coopctrl._core as _core


@dataclass(frozen=True)
class ControllerState:
    """A snapshot of a controller's state between two steps (a frozen value: its arrays are read-only copies).

    ``controller.state`` takes one; ``controller.state = snapshot`` (or ``controller.restore(snapshot)``) puts it
    back, after which the controller steps exactly as it did from there (bit for bit). A snapshot fits the
    controller of the same scene only.

    Attributes:
        tau: (nu,) the torques of the last step, saturated [N m].
        integrals: (m, p) the followers' force-error integrals [N s, N m s] (the leader's row stays 0).
        last_split: (3, m, p) the last feasible split ``(F, external, internal)`` [N, N m], held when a QP
            solve fails.
        flags: the tallies by name (a copy of the controller's :class:`coopctrl._core.LoopFlags`:
            ``have_last_split``, ``consecutive_failures``, ``saturated_ticks`` (steps), ``qp_solves``,
            ``first_saturated``, ``last_saturated`` (steps)).
        saturated_joints: (nu,) int64 steps on which each joint's torque was clipped.
        qp_workspace: the compiled QP's workspace (its factor and active set: the next solve's warm start).
        qp_hessian: (n, n) the QP's cost matrix (the elastic split keeps it between steps).
        qp_answer: (n,) the last answer [N, N m]; qp_multipliers: its row multipliers.
        elastic_stiffness: (n, n) the elastic split's grasp stiffness of the last step.
        steps: the steps taken.
    """

    tau: np.ndarray
    integrals: np.ndarray
    last_split: np.ndarray
    flags: _core.LoopFlags
    saturated_joints: np.ndarray
    qp_workspace: tuple
    qp_hessian: np.ndarray
    qp_answer: np.ndarray
    qp_multipliers: np.ndarray
    elastic_stiffness: np.ndarray
    steps: int

    @classmethod
    def of(cls, live: dict, steps: int) -> "ControllerState":
        """A snapshot of the ``live`` arrays (field name -> the controller's own array, or tuple of arrays)."""
        def frozen(a):
            if isinstance(a, _core.LoopFlags):
                return a.copy()
            a = np.array(a, copy=True)
            a.flags.writeable = False
            return a

        return cls(**{k: tuple(frozen(a) for a in v) if isinstance(v, tuple) else frozen(v) for k, v in live.items()},
                   steps=int(steps))

    def copy_into(self, live: dict) -> None:
        """Write this snapshot into the ``live`` arrays (shapes checked first; nothing written on a mismatch)."""
        pairs = []
        for f in fields(self):
            if f.name == "steps":
                continue
            mine, theirs = getattr(self, f.name), live[f.name]
            if isinstance(mine, _core.LoopFlags):
                pairs.append((mine, theirs))
                continue
            for a, b in (zip(mine, theirs) if isinstance(mine, tuple) else ((mine, theirs),)):
                if a.shape != b.shape:
                    raise ValueError(f"state.{f.name} has shape {a.shape}, this controller's {b.shape}: restore a "
                                     "snapshot taken from a controller of the same scene")
                pairs.append((a, b))
        for a, b in pairs:
            if isinstance(b, _core.LoopFlags):
                b.assign(a)
            else:
                b[...] = a

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self


__all__ = ["ControllerState"]
