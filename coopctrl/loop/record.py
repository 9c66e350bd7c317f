"""``LoopRecord``: what one run of the closed loop records, tick by tick, with units."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np


@dataclass
class LoopRecord:
    """The record of a closed-loop run (N ticks recorded; m arms, p pose size, npos position size).

    Arrays (one row per recorded tick ``k``, at ``t_k = k T``):

    Attributes:
        t: (N,) tick times [s].
        x: (N, nx) plant state ``(z, z')`` at the tick [m, rad, m/s, rad/s].
        tau: (N, nu) joint torques applied over the period that starts at the tick (after
            saturation) [N m].
        Y0_nominal: (N, p) nominal object pose [m, rad].
        F_measured: (N, m, p) contact wrenches the force sensors read [N, N m].
        F_commanded: (N, m, p) the QP's split (held on a failed solve) [N, N m].
        F_external: (N, m, p) its external part ``A w_N`` [N, N m].
        F_internal: (N, m, p) its internal part ``F - A w_N`` [N, N m].
        r_contacts: (N, m, npos) true contact-node positions [m].
        squeeze: (N, m(m-1)/2) virtual-linkage squeeze per contact pair ``i < j`` of ``F_measured`` at
            ``r_contacts`` [N] (positive: compression), relative to the loop's desired squeeze where the
            pairs are dependent; NaN where it is ill-conditioned (:mod:`coopctrl.loop.squeeze`, recorded per tick).
        qp_iterations: (N,) active-set changes (compiled) or iterations of the QP solve (the reference
            path's backend; -1 when it does not report them, and on a passive run) [-].
        qp_active_rows: (N,) inequality rows active (held at a bound) at the compiled solver's answer
            [-]; -1 where the kernel did not solve (a held split, the reference path's backend, a passive run).
        qp_solve_time_s: (N,) QP solve time [s] of the reference path's backend (NaN with the compiled
            solver, which the kernel does not time per solve, and on a passive run).
        energy, kinetic_energy: (N,) total and kinetic energy [J] (passive runs only, else NaN).
        qp_status: per tick the QP status (``"solved"``, ``"infeasible"``, ...).
        qp_binding: per tick the binding inequality families joined by ``+`` (``""``: none).

    Run summary:
        status: ``"ok"``, ``"diverged"`` or ``"qp_failed"``; reason: why it stopped (``""`` if ok).
        events: ``(t [s], kind, message)`` of what happened (held QP splits, saturation, the stop).
        wall_time_s: wall time of the run [s], from its first tick; startup_s: its start-up before the
            first tick, compiling (a first run of its kind) or loading the compiled kernels [s]; qp_time_s: total QP time [s] (NaN with the compiled
            solver, not timed; 0 on a passive run).
        qp_binding_counts: ticks on which each family was binding; saturated_ticks: ticks with a
            torque clipped at its limit; saturated_joint_ticks: (nu,) such ticks per joint;
            saturation_first_time_s: time of the first [s] (NaN: none); saturated_last_tick: index of
            the last (-1: none); rhs_evaluations: plant right-hand-side calls of the kernel's integration
            (``None`` when an integrator outside the kernel steps the plant); integration_steps: (N, 4)
            per tick of an error-controlled integrator (``rk23``, ``rk45``, ``trbdf2``): accepted steps,
            rejected steps, right-hand-side evaluations, smallest accepted step [s] (``None`` for a
            fixed-step integrator); stop: the raw facts of a failed run's stop
            (:class:`~coopctrl.loop.diagnosis.Stop`; ``None`` when the run did not stop early), which
            :func:`coopctrl.simulator.simulate` diagnoses after the run; final_state: the
            :class:`~coopctrl.loop.state.LoopState` at the end of the run (the plant state, held torques, the
            followers' force-error integrals ``integrals`` (m, p) [N s, N m s], the last feasible split),
            in arrays of the run's own: the controllers and the state the run was given are unchanged;
            object_rotation: (N, 4) the object's rotation as a unit quaternion ``(w, x, y, z)`` [-] of a run
            in rotation charts (exact at every pitch, where the book's angles of ``x`` are not), else ``None``.

    Item access (``record["x"]``, ``record.get``, ``record.update``, ``record.items()``) reads and writes
    the same fields, for code written against the former dict.
    """

    t: np.ndarray
    x: np.ndarray
    tau: np.ndarray
    Y0_nominal: np.ndarray
    F_measured: np.ndarray
    F_commanded: np.ndarray
    F_external: np.ndarray
    F_internal: np.ndarray
    r_contacts: np.ndarray
    squeeze: np.ndarray
    qp_iterations: np.ndarray
    qp_active_rows: np.ndarray
    qp_solve_time_s: np.ndarray
    energy: np.ndarray
    kinetic_energy: np.ndarray
    qp_status: list = field(default_factory=list)
    qp_binding: list = field(default_factory=list)
    status: str = "ok"
    reason: str = ""
    events: list = field(default_factory=list)
    wall_time_s: float = 0.0
    startup_s: float = 0.0
    qp_time_s: float = 0.0
    qp_binding_counts: dict = field(default_factory=dict)
    saturated_ticks: int = 0
    saturated_joint_ticks: np.ndarray | None = None
    saturation_first_time_s: float = float("nan")
    saturated_last_tick: int = -1
    rhs_evaluations: int | None = None
    integration_steps: np.ndarray | None = None
    stop: object | None = None
    final_state: object = None
    object_rotation: np.ndarray | None = None

    def __repr__(self) -> str:
        """A few lines: status, ticks and timing (never the arrays: ``record.x`` has them)."""
        from coopctrl.compact_repr import compact_repr

        n = int(np.shape(self.t)[0])
        return compact_repr(self, ["status", "reason", "wall_time_s", "saturated_ticks"],
                            extra=[("ticks", n), ("t_end_s", float(self.t[-1]) if n else None),
                                   ("state_size", int(np.shape(self.x)[1]) if np.ndim(self.x) == 2 else None),
                                   ("events", len(self.events))])

    @classmethod
    def empty(cls, N: int, nx: int, nu: int, m: int, p: int, npos: int) -> "LoopRecord":
        """NaN-filled arrays for ``N`` ticks (a run truncates them to the ticks it recorded)."""
        def nan(*shape):
            return np.full(shape, np.nan)

        return cls(t=nan(N), x=nan(N, nx), tau=nan(N, nu), Y0_nominal=nan(N, p), F_measured=nan(N, m, p),
                   F_commanded=nan(N, m, p), F_external=nan(N, m, p), F_internal=nan(N, m, p),
                   r_contacts=nan(N, m, npos), squeeze=nan(N, m * (m - 1) // 2), qp_iterations=np.full(N, -1, dtype=np.int64),
                   qp_active_rows=np.full(N, -1, dtype=np.int64), qp_solve_time_s=nan(N),
                   energy=nan(N), kinetic_energy=nan(N), saturated_joint_ticks=np.zeros(nu, dtype=np.int64))

    # ---- the former dict's access
    def keys(self):
        return list(_NAMES)

    def values(self):
        return [getattr(self, k) for k in _NAMES]

    def items(self):
        return [(k, getattr(self, k)) for k in _NAMES]

    def __getitem__(self, key: str):
        if key not in _NAME_SET:
            raise KeyError(key)
        return getattr(self, key)

    def __setitem__(self, key: str, value) -> None:
        if key not in _NAME_SET:
            raise KeyError(f"{key!r} is not a field of LoopRecord")
        setattr(self, key, value)

    def __contains__(self, key) -> bool:
        return key in _NAME_SET

    def get(self, key: str, default=None):
        return getattr(self, key) if key in _NAME_SET else default

    def update(self, other=(), **values) -> None:
        for key, value in dict(other, **values).items():
            self[key] = value


#: The record's field names, in order (its keys), and as a set.
_NAMES = tuple(f.name for f in fields(LoopRecord))
_NAME_SET = frozenset(_NAMES)
