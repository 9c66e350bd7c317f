"""The :class:`SimulationResult` of one closed-loop run: signals, QP statistics and status."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

STATUSES = ("ok", "diverged", "qp_failed")


@dataclass
class SimulationResult:
    """Time histories of one closed-loop run (N samples at the control rate).

    Shapes: N samples, nx states, nu joints in total, m contacts (arms), p = 6 spatial or 3
    planar (pose / wrench size), n_pairs contact pairs.

    Attributes:
        scenario: Name of the scenario.
        space: ``"planar"`` or ``"spatial"``.
        t: Sample times (N,) [s].
        x: States (N, nx) (``col(q, Y_0, q', Y_0')``, [rad], [m], [rad/s], [m/s]).
        tau: Joint torques (N, nu) [N m].
        Y0: Object MC pose (N, p) [m, rad]; ``Y0_nominal`` its nominal trajectory (N, p).
        F_measured: Contact wrenches measured at the nodes (N, m, p) [N, N m].
        F_commanded: Contact wrenches commanded by the load distribution (N, m, p).
        F_external: External (load-carrying) part of the QP split (N, m, p).
        F_internal: Internal (squeeze, in null(G)) part of the QP split (N, m, p).
        squeeze: Measured internal squeeze per contact pair (N, n_pairs) [N].
        squeeze_desired: Desired squeeze per pair (n_pairs,) [N].
        tau_max: Joint torque limits (nu,) [N m], or ``None``.
        qp_status: Solver status per solve (``"solved"`` counts as success, see :data:`QP_SUCCESS`).
        qp_binding: Per solve, the constraint families binding (``"torque_limits+friction"``;
            ``""`` none), as the QP reported them.
        qp_iterations: Solver iterations per solve (N,).
        qp_solve_time_s: Solve time per solve (N,) [s] (NaN where not timed: the compiled solver).
        qp_active_rows: Inequality rows active at each solve's answer (N,) [-] (the compiled
            solver; -1 where not known: a held split, another backend).
        events: ``(t [s], kind, message)`` tuples (saturations, QP failures, ...).
        status: ``"ok"``, ``"diverged"`` or ``"qp_failed"``; ``reason`` says why (one line).
        model: ``{"arms", "dof_per_arm", "space", "unloaded_state", "state_size"}``.
        integrator, step_s, control_period_s, duration_s: Integration settings ([s]).
        wall_time_s: Wall-clock time of the run [s], from its first tick.
        startup_s: Start-up of the run before its first tick [s]: compiling (the first run of its kind
            on a machine) or loading the compiled kernels; not in ``wall_time_s`` (NaN: not known).
        energy: Total energy T + Pi + gravity (N,) [J], or ``None``.
        kinetic_energy: Kinetic energy T (N,) [J], or ``None`` (scales the energy drift).
        energy_conserving: True when the run had no control and no damping.
        leader: Index of the leader arm (0-based); ``followers`` the followers' indices.
        Y_nodes: Node (end-effector) poses (N, m, p) [m, rad], or ``None``.
        object_rotation: The object's rotation as unit quaternions ``(w, x, y, z)`` (N, 4) [-] of a run in
            rotation charts (``scene.rotations = "charts"``: exact at every pitch, where the ZYX angles of
            ``Y0`` lose digits near +-90 deg), or ``None`` (``Y0`` has it).
        record_every: Every how many control ticks a sample was kept (``simulation.record_every``);
            ``t`` and every per-sample array hold the kept samples only.
        tick_summary: The :meth:`summary` computed on every tick before the record was thinned, or
            ``None`` (``record_every = 1``: the summary is computed from the record itself).
        scenario_sha256: SHA-256 (hex) of the ``scenario.toml`` saved with the result, or ``""``.
        integration_statistics: The steps of an error-controlled integrator (``rk23``, ``rk45``,
            ``trbdf2``) over the run, or ``None`` (a fixed step): ``steps_accepted``,
            ``steps_rejected``, ``rejected_share`` [-], ``rhs_evaluations``, ``smallest_step_s`` and
            ``mean_step_s`` [s] (``step_s`` is then the mean step).
        final_state: The :class:`~coopctrl.loop.state.LoopState` at the run's end, from which
            ``simulate(scenario, state=result.final_state)`` continues it, or ``None`` (a result read from
            files, which do not keep it).
    """

    scenario: str
    space: str
    t: np.ndarray
    x: np.ndarray
    tau: np.ndarray
    Y0: np.ndarray
    Y0_nominal: np.ndarray
    F_measured: np.ndarray
    F_commanded: np.ndarray
    F_external: np.ndarray
    F_internal: np.ndarray
    squeeze: np.ndarray
    squeeze_desired: np.ndarray
    tau_max: np.ndarray | None = None
    qp_status: list[str] = field(default_factory=list)
    qp_binding: list[str] = field(default_factory=list)
    qp_iterations: np.ndarray | None = None
    qp_solve_time_s: np.ndarray | None = None
    events: list[tuple[float, str, str]] = field(default_factory=list)
    status: str = "ok"
    reason: str = ""
    model: dict[str, Any] = field(default_factory=dict)
    integrator: str = ""
    step_s: float = float("nan")
    control_period_s: float = float("nan")
    duration_s: float = float("nan")
    wall_time_s: float = float("nan")
    startup_s: float = float("nan")
    energy: np.ndarray | None = None
    kinetic_energy: np.ndarray | None = None
    energy_conserving: bool = False
    leader: int = 0
    followers: list[int] = field(default_factory=list)
    Y_nodes: np.ndarray | None = None
    record_every: int = 1
    tick_summary: dict[str, Any] | None = None
    scenario_sha256: str = ""
    qp_active_constraints: dict[str, int] = field(default_factory=dict)
    qp_time_s: float = float("nan")
    torque_saturated_ticks: int = 0
    qp_active_rows: np.ndarray | None = None
    integration_statistics: dict[str, Any] | None = None
    object_rotation: np.ndarray | None = None
    final_state: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.space not in ("planar", "spatial"):
            raise ValueError(f"SimulationResult: space = {self.space!r} is invalid: expected 'planar' or 'spatial'")
        if self.status not in STATUSES:
            raise ValueError(f"SimulationResult: status = {self.status!r} is invalid: expected one of {STATUSES}")
        p = 3 if self.space == "planar" else 6
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        n = self.t.shape[0]

        def arr(name: str, ndim: int, tail: tuple | None = None) -> None:
            value = np.asarray(getattr(self, name), dtype=float)
            if value.ndim == ndim - 1 and n == 0:
                value = value.reshape((0,) + value.shape)
            if value.ndim != ndim or value.shape[0] != n or (tail is not None and value.shape[1:] != tail):
                want = "(N" + "".join(f", {d}" for d in (tail or ("...",) * (ndim - 1))) + ")"
                raise ValueError(f"SimulationResult: {name} has shape {value.shape}, expected {want} with N = {n} = len(t)")
            setattr(self, name, value)

        arr("x", 2)
        arr("tau", 2)
        arr("Y0", 2, (p,))
        arr("Y0_nominal", 2, (p,))
        arr("F_measured", 3)
        m = self.F_measured.shape[1]
        if self.F_measured.shape[2] != p:
            raise ValueError(f"SimulationResult: F_measured has shape {self.F_measured.shape}, expected (N, m, {p})")
        for name in ("F_commanded", "F_external", "F_internal"):
            arr(name, 3, (m, p))
        arr("squeeze", 2)
        self.squeeze_desired = np.asarray(self.squeeze_desired, dtype=float).reshape(-1)
        if self.squeeze_desired.shape[0] != self.squeeze.shape[1]:
            raise ValueError(
                f"SimulationResult: squeeze_desired has shape {self.squeeze_desired.shape}, expected ({self.squeeze.shape[1]},) like squeeze's columns"
            )
        if self.tau_max is not None:
            self.tau_max = np.asarray(self.tau_max, dtype=float).reshape(-1)
            if self.tau_max.shape[0] != self.tau.shape[1]:
                raise ValueError(f"SimulationResult: tau_max has shape {self.tau_max.shape}, expected ({self.tau.shape[1]},) like tau's columns")
        self.qp_status = [str(s) for s in self.qp_status]
        self.qp_binding = [str(s) for s in self.qp_binding]
        for name in ("qp_iterations", "qp_solve_time_s", "qp_active_rows"):
            value = getattr(self, name)
            setattr(self, name, np.zeros(0) if value is None else np.asarray(value, dtype=float).reshape(-1))
        for name in ("energy", "kinetic_energy"):
            value = getattr(self, name)
            if value is not None:
                arr(name, 1)
        if self.Y_nodes is not None:
            arr("Y_nodes", 3, (m, p))
        if self.object_rotation is not None:
            arr("object_rotation", 2, (4,))
        if isinstance(self.record_every, bool) or int(self.record_every) != self.record_every or self.record_every < 1:
            raise ValueError(f"SimulationResult: record_every = {self.record_every!r} is invalid: expected an integer >= 1")
        self.record_every = int(self.record_every)
        if self.tick_summary is not None and not isinstance(self.tick_summary, dict):
            raise ValueError(f"SimulationResult: tick_summary is a {type(self.tick_summary).__name__}, expected a dict or None")
        self.events = [(float(e[0]), str(e[1]), str(e[2])) for e in self.events]
        self.followers = [int(k) for k in self.followers]
        self.leader = int(self.leader)

    def __repr__(self) -> str:
        """A few lines: scene, status, sizes and key figures (never the arrays: ``result.x`` has them)."""
        from coopctrl.compact_repr import compact_repr

        n = int(self.t.shape[0])
        try:
            s = self.summary()
        except Exception:  # noqa: BLE001 - a repr must never raise
            s = {}
        return compact_repr(self, ["scenario", "status", "reason", "space", "integrator", "step_s", "control_period_s"],
                            extra=[("samples", n), ("t_end_s", float(self.t[-1]) if n else None),
                                   ("arms", self.arms), ("state_size", int(self.x.shape[1])),
                                   ("joints", int(self.tau.shape[1])),
                                   ("position_error_rms_m", s.get("object_position_error_rms_m")),
                                   ("max_torque_ratio", s.get("max_torque_ratio")),
                                   ("qp_failures", s.get("qp_failures")), ("wall_time_s", self.wall_time_s)])

    # ------------------------------------------------------------------ views
    @property
    def pose_size(self) -> int:
        """p: 3 planar, 6 spatial."""
        return 3 if self.space == "planar" else 6

    @property
    def object_quaternion(self) -> np.ndarray | None:
        """The object's rotation as unit quaternions ``(w, x, y, z)`` [-], shape (N, 4), of the ZYX angles of
        ``Y0`` (``R = Rz(psi) Ry(theta) Rx(phi)``), or :attr:`object_rotation` when the run has it (rotation
        charts), each sample's sign chosen nearest the previous one so that the signal is continuous
        (``q`` and ``-q`` are one rotation); ``None`` for a planar result."""
        if self.pose_size != 6:
            return None
        from coopctrl.trajectory.quaternion import from_zyx

        q = from_zyx(self.Y0[:, 3:6]) if self.object_rotation is None else np.array(self.object_rotation, dtype=float)
        if q.shape[0] > 1:  # flip where the next sample points away: the running product of the signs
            flips = np.sign(np.einsum("ij,ij->i", q[1:], q[:-1]))
            flips[flips == 0.0] = 1.0
            q[1:] *= np.cumprod(flips)[:, None]
        return q

    @property
    def arms(self) -> int:
        """m: number of contacts."""
        return int(self.F_measured.shape[1])

    # ------------------------------------------------------------------ outputs
    def summary(self) -> dict[str, Any]:
        """Key figures as a JSON-serialisable dict (no NaN or inf: those are ``None``), computed on
        every control tick even when the record was thinned (``record_every > 1``)."""
        from coopctrl.results.summary import summarize

        if self.tick_summary is not None:
            return dict(self.tick_summary)
        return summarize(self)

    def save(self, directory: str | Path) -> list[Path]:
        """Write ``result.npz``, ``result.csv`` and ``summary.json`` atomically into ``directory``
        (created if needed). Returns the paths written."""
        from coopctrl.results.storage import save_result

        return save_result(self, directory)

    @classmethod
    def load(cls, directory: str | Path) -> "SimulationResult":
        """Read a result written by :meth:`save` (from its ``result.npz``)."""
        from coopctrl.results.storage import load_result

        return load_result(directory)

    def to_pandas(self, units_in_names: bool = False):
        """A pandas DataFrame (index ``t``, one named column per signal; units in
        ``df.attrs["units"]``); see :func:`coopctrl.results.export.to_pandas`. Needs pandas
        (``pip install 'coopctrl[pandas]'``)."""
        from coopctrl.results.export import to_pandas

        return to_pandas(self, units_in_names=units_in_names)

    def to_time_response(self):
        """A python-control ``TimeResponseData`` (inputs: joint torques; states: x; outputs: the
        other signals, named; ``.units``); see :func:`coopctrl.results.export.to_time_response`."""
        from coopctrl.results.export import to_time_response

        return to_time_response(self)

    def figures(self) -> dict:
        """Every plot as ``{file name: matplotlib Figure}``, nothing written
        (:mod:`coopctrl.results.plots`: tracking, force regulation, limits, QP time)."""
        from coopctrl.results.plots import figures

        return figures(self)

    def plot(self, directory: str | Path) -> list[Path]:
        """Write the PNG plots (``object_pose``, ``contact_forces``, ``joint_torques``,
        ``qp_solve_times``) into ``directory``. Returns the paths written."""
        from coopctrl.results.plots import plot_result

        return plot_result(self, directory)
