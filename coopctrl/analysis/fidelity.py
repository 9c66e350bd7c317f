"""The model-fidelity trade: one task, simulated with models of increasing fidelity.

The same task (object, grasps, springs, trajectory, load split, gains, integration step) is
described by scenes of different fidelity, e.g. ``scenarios/fidelity_planar.toml`` (two planar
3R arms), ``fidelity_contact_points.toml`` (spatial, the arms replaced by actuated contact
nodes) and ``fidelity_spatial_arms.toml`` (two Puma 560 arms). :func:`compare_fidelity` runs
each closed loop and reports, per model,

* the **cost**: state size, joints per arm, the median time of one evaluation of the plant's
  right-hand side (all models timed side by side, interleaved, in one process), the
  closed-loop wall time and its real-time factor;
* the **outcome**: the model's own tracking errors, and its difference from the
  highest-fidelity model (:func:`fidelity_rank`) in the common plane: object position [m] and
  angle [rad], contact forces [N] and moments [N m], the QP's external and internal parts,
  and the squeeze [N].

The common plane
----------------
A faithful comparison needs a task that lives in the vertical x-z plane of the world (gravity
along -z; docs/model.md §2, planar reduction). Spatial results are mapped into it explicitly by
:func:`plane_trace`, and nothing out of the plane is dropped silently:

* position ``(x, y, z) -> (x, z)``; the out-of-plane offset ``y - y(0)`` is reported;
* orientation ``R -> theta_p = atan2(R[2, 0], R[0, 0])``: the direction of the body x axis in
  the x-z plane, from +x toward +z (the planar convention). For ``psi = phi = 0``,
  ``R = R_y(theta)`` and ``theta_p = -theta``: a positive pitch about +y turns +x toward -z.
  The out-of-plane rotation ``arccos(R[1, 1])`` (angle between the body and the world y axes)
  is reported;
* a contact wrench ``(f, n)`` (world axes, at the contact point) ``-> (f_x, f_z, -n_y)``: the
  planar moment ``d_x f_z - d_z f_x`` about the plane normal is ``-(d x f)_y``, because a
  planar rotation from +x toward +z is a rotation about -y; ``f_y``, ``n_x`` and ``n_z`` are
  reported as out-of-plane;
* the squeeze is the virtual-linkage squeeze per contact pair, a scalar in both spaces.

:func:`planar_task` maps a scenario's task into the plane the same way, and
:func:`check_same_task` rejects scenes that do not describe the same task.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.errors import ScenarioError

#: Relative tolerance [-] on the task parameters compared by :func:`check_same_task` (they are
#: numbers typed in files, so they must agree to the digits written; 1e-6 allows 7 digits).
TASK_RTOL = 1e-6
#: Absolute tolerance on task quantities near zero ([m], [rad], [kg], ...).
TASK_ATOL = 1e-9
#: Largest out-of-plane offset [m] or rotation [rad] of a spatial task pose (object, grasps,
#: vias) accepted as "in the x-z plane": the numbers in the files are exact, so 1e-9.
PLANE_TOLERANCE = 1e-9
#: Control periods of a warm-up run (loads the compiled core and the QP before timing).
WARM_UP_TICKS = 10


# ---------------------------------------------------------------------- the plane
def _angles(A) -> tuple[np.ndarray, ...]:
    A = np.atleast_2d(np.asarray(A, dtype=float))
    return (np.cos(A[:, 0]), np.sin(A[:, 0]), np.cos(A[:, 1]), np.sin(A[:, 1]), np.cos(A[:, 2]), np.sin(A[:, 2]))


def planar_angle(A) -> np.ndarray:
    """Planar angle ``theta_p = atan2(R[2, 0], R[0, 0])`` [rad] of ZYX angles ``A`` (N, 3) or (3,).

    ``R = Rz(psi) Ry(theta) Rx(phi)`` (docs/model.md §2) has ``R[0, 0] = cos(psi) cos(theta)`` and
    ``R[2, 0] = -sin(theta)``: the direction of the body x axis in the x-z plane, from +x toward
    +z; ``-theta`` for a pure pitch ``A = (0, theta, 0)``.
    """
    cps, sps, cth, sth, cph, sph = _angles(A)
    out = np.arctan2(-sth, cps * cth)
    return out if np.ndim(A) > 1 else out[0]


def out_of_plane_rotation(A) -> np.ndarray:
    """Angle [rad] between the body y axis and the world y axis, ``arccos(R[1, 1])`` with
    ``R[1, 1] = sin(psi) sin(theta) sin(phi) + cos(psi) cos(phi)``; (N,) or a scalar.

    0 for a rotation about +y; pi for a frame flipped about an in-plane axis (a follower's
    node frame turned by yaw pi has ``R[1, 1] = -1``: it still moves in the plane)."""
    cps, sps, cth, sth, cph, sph = _angles(A)
    out = np.arccos(np.clip(sps * sth * sph + cps * cph, -1.0, 1.0))
    return out if np.ndim(A) > 1 else out[0]


def pose_in_plane(pose, space: str) -> np.ndarray:
    """A pose as planar ``(x, z, theta_p)`` [m, m, rad] (planar poses are returned as they are)."""
    pose = np.asarray(pose, dtype=float)
    if space == "planar":
        return pose.copy()
    return np.array([pose[0], pose[2], float(planar_angle(pose[3:6]))])


def wrench_in_plane(F: np.ndarray, space: str) -> np.ndarray:
    """Wrenches ``(..., 6)`` ``(f, n)`` as planar ``(..., 3)`` ``(f_x, f_z, -n_y)`` [N, N, N m]."""
    F = np.asarray(F, dtype=float)
    if space == "planar":
        return F.copy()
    return np.stack([F[..., 0], F[..., 2], -F[..., 4]], axis=-1)


def _wrap(a: np.ndarray) -> np.ndarray:
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


@dataclass(frozen=True, eq=False)
class PlaneTrace:
    """One closed-loop run mapped into the x-z plane (see the module docstring).

    Attributes:
        scenario: Name of the scenario; space: ``"planar"`` or ``"spatial"``.
        t: Sample times (N,) [s].
        pose, pose_nominal: Object MC ``(x, z, theta_p)`` (N, 3) [m, m, rad], actual and nominal.
        wrench: Measured contact wrenches ``(f_x, f_z, n)`` (N, m, 3) [N, N, N m].
        commanded, external, internal: The QP's setpoints and their external (load-carrying) and
            internal (null(G)) parts, (N, m, 3).
        squeeze: Measured virtual-linkage squeeze per contact pair (N, pairs) [N].
        out_of_plane_position: ``max |y - y(0)|`` of the object [m] (0 planar).
        out_of_plane_rotation: ``max arccos(R[1, 1])`` of the object [rad] (0 planar).
        out_of_plane_force: ``max |f_y|`` over contacts [N] (0 planar).
        out_of_plane_moment: ``max(|n_x|, |n_z|)`` over contacts [N m] (0 planar).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: str
    space: str
    t: np.ndarray
    pose: np.ndarray
    pose_nominal: np.ndarray
    wrench: np.ndarray
    commanded: np.ndarray
    external: np.ndarray
    internal: np.ndarray
    squeeze: np.ndarray
    out_of_plane_position: float = 0.0
    out_of_plane_rotation: float = 0.0
    out_of_plane_force: float = 0.0
    out_of_plane_moment: float = 0.0


def _pose_trace(Y: np.ndarray, space: str) -> np.ndarray:
    if space == "planar":
        return Y.copy()
    return np.column_stack([Y[:, 0], Y[:, 2], planar_angle(Y[:, 3:6]) if len(Y) else np.zeros(0)])


def plane_trace(result) -> PlaneTrace:
    """Map a :class:`~coopctrl.results.SimulationResult` into the x-z plane (module docstring)."""
    r, space = result, result.space
    oop = {}
    if space == "spatial" and len(r.t):
        oop = dict(
            out_of_plane_position=float(np.max(np.abs(r.Y0[:, 1] - r.Y0[0, 1]))),
            out_of_plane_rotation=float(np.max(out_of_plane_rotation(r.Y0[:, 3:6]))),
            out_of_plane_force=float(np.max(np.abs(r.F_measured[:, :, 1]))),
            out_of_plane_moment=float(np.max(np.abs(r.F_measured[:, :, [3, 5]]))),
        )
    return PlaneTrace(
        scenario=r.scenario, space=space, t=r.t.copy(), pose=_pose_trace(r.Y0, space),
        pose_nominal=_pose_trace(r.Y0_nominal, space), wrench=wrench_in_plane(r.F_measured, space),
        commanded=wrench_in_plane(r.F_commanded, space), external=wrench_in_plane(r.F_external, space),
        internal=wrench_in_plane(r.F_internal, space), squeeze=np.asarray(r.squeeze, dtype=float).copy(), **oop)


# ---------------------------------------------------------------------- the task
@dataclass(frozen=True)
class PlanarTask:
    """What a scene asks, mapped into the x-z plane; two scenes describe the same task when
    their ``PlanarTask`` agree (:func:`task_differences`). The arms (model and base) are left
    out: they are what the fidelity comparison varies.

    Attributes:
        object_mass: [kg]. object_inertia: moment about the plane normal [kg m^2].
        gravity: [m/s^2]. roles: role of each arm.
        grasps: ``(x, z, theta_p)`` of each contact node in the object frame [m, m, rad].
        node_masses [kg], node_inertias (about the plane normal) [kg m^2].
        springs: per spring ``(i, j, element, c_x, c_z, torsion, damping, torsion_damping)``
            [-, -, -, N/m, N/m, N m/rad, N s/m, N m s/rad].
        via: per via ``(time, x, z, theta_p)`` [s, m, m, rad].
        load_distribution, controllers, sensors: the sections as dicts (space-independent).
        simulation: ``(control_period [s], substeps, integrator, duration [s], start)``.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    object_mass: float
    object_inertia: float
    gravity: float
    roles: tuple[str, ...]
    grasps: tuple[tuple[float, ...], ...]
    node_masses: tuple[float, ...]
    node_inertias: tuple[float, ...]
    springs: tuple[tuple, ...]
    via: tuple[tuple[float, ...], ...]
    load_distribution: dict = field(hash=False)
    controllers: dict = field(hash=False)
    sensors: dict = field(hash=False)
    simulation: tuple = ()


def _inertia_about_y(inertia, A) -> float:
    """Moment [kg m^2] about the world y axis of a body with principal ``inertia`` and ZYX angles
    ``A``: ``e_y^T R diag(I) R^T e_y = sum_k R[1, k]^2 I_k``."""
    from plants.frames import rotation_zyx

    R = rotation_zyx(np.asarray(A, dtype=float))
    return float(sum(R[1, k] ** 2 * inertia[k] for k in range(3)))


def _check_in_plane(scenario, path: str, pose, *, flipped_ok: bool) -> None:
    """Reject a spatial pose that does not lie in the x-z plane (y = 0 offset, rotation about y)."""
    pose = np.asarray(pose, dtype=float)
    tilt = float(out_of_plane_rotation(pose[3:6]))
    if flipped_ok:
        tilt = min(tilt, math.pi - tilt)
    if abs(pose[1]) > PLANE_TOLERANCE or tilt > PLANE_TOLERANCE:
        raise ScenarioError(path, [float(v) for v in pose],
                            "a pose in the vertical x-z plane for the fidelity comparison (y = 0 and a rotation "
                            "about y only: psi = phi = 0" + (", or yaw pi for a node frame facing -x)" if flipped_ok else ")"),
                            scenario.source)


def planar_task(scenario) -> PlanarTask:
    """The task of ``scenario`` in the x-z plane (see :class:`PlanarTask`).

    A spatial scenario must keep its task in the plane: the object pose and every via at
    ``y = y_object(0)`` with a rotation about y only, and the grasps at ``y = 0`` with a rotation
    about y (possibly composed with a yaw of pi, the usual frame of a node facing -x).

    Raises:
        ScenarioError: A spatial pose out of the plane (the message names the field).
    """
    space = scenario.space
    obj = scenario.object
    if space == "planar":
        inertia = float(obj.inertia[0])
        grasps = tuple(tuple(float(v) for v in a.grasp) for a in scenario.arms)
        node_inertias = tuple(float(a.node_inertia[0]) for a in scenario.arms)
        via = tuple((float(v.time), *(float(c) for c in v.pose)) for v in scenario.trajectory.via)
    else:
        y0 = float(obj.pose[1])
        shifted = lambda pose: (pose[0], pose[1] - y0, *pose[2:])  # noqa: E731 - the plane y = y0
        _check_in_plane(scenario, "object.pose", shifted(obj.pose), flipped_ok=False)
        for k, v in enumerate(scenario.trajectory.via):
            _check_in_plane(scenario, f"trajectory.via[{k}].pose", shifted(v.pose), flipped_ok=False)
        for k, a in enumerate(scenario.arms):
            _check_in_plane(scenario, f"arms[{k}].grasp", a.grasp, flipped_ok=True)
        inertia = _inertia_about_y(obj.inertia, np.asarray(obj.pose[3:6], dtype=float))
        grasps = tuple(tuple(float(c) for c in pose_in_plane(a.grasp, space)) for a in scenario.arms)
        node_inertias = tuple(_inertia_about_y(a.node_inertia, np.asarray(a.grasp[3:6], dtype=float))
                              for a in scenario.arms)
        via = tuple((float(v.time), *(float(c) for c in pose_in_plane(v.pose, space))) for v in scenario.trajectory.via)
    springs = []
    for s in scenario.springs:
        c = s.stiffness_per_axis(space)
        cA = s.torsion_per_axis(space)
        c_xz = (c[0], c[1]) if space == "planar" else (c[0], c[2])
        torsion = cA[0] if space == "planar" else cA[1]
        springs.append((*s.pair, s.element, float(c_xz[0]), float(c_xz[1]), float(torsion), float(s.damping),
                        float(s.torsion_damping)))
    sim = scenario.simulation
    return PlanarTask(
        object_mass=float(obj.mass), object_inertia=inertia, gravity=float(scenario.scene.gravity),
        roles=tuple(a.role for a in scenario.arms), grasps=grasps,
        node_masses=tuple(float(a.node_mass) for a in scenario.arms), node_inertias=node_inertias,
        springs=tuple(springs), via=via, load_distribution=scenario.to_dict()["load_distribution"],
        controllers=scenario.to_dict()["controllers"], sensors=scenario.to_dict()["sensors"],
        simulation=(float(sim.control_period), int(sim.substeps), sim.integrator, float(sim.duration), sim.start))


def _differ(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() != b.keys() or any(_differ(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) != len(b) or any(_differ(x, y) for x, y in zip(a, b))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or isinstance(b, str):
        return a != b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return not math.isclose(a, b, rel_tol=TASK_RTOL, abs_tol=TASK_ATOL)
    return a != b


def _angles_differ(a: Sequence[float], b: Sequence[float]) -> bool:
    """Poses ``(x, z, theta)`` (optionally after a time) differ, angles compared modulo 2 pi."""
    return any(abs(float(_wrap(x - y))) > TASK_ATOL if k == len(a) - 1 else _differ(x, y)
               for k, (x, y) in enumerate(zip(a, b))) or len(a) != len(b)


def task_differences(a: PlanarTask, b: PlanarTask) -> list[tuple[str, Any, Any]]:
    """The fields in which two planar tasks differ: ``[(field, value in a, value in b), ...]``."""
    out = []
    for f in ("object_mass", "object_inertia", "gravity", "roles", "node_masses", "node_inertias", "springs",
              "load_distribution", "controllers", "sensors", "simulation"):
        va, vb = getattr(a, f), getattr(b, f)
        if _differ(va, vb):
            out.append((f, va, vb))
    for f in ("grasps", "via"):
        va, vb = getattr(a, f), getattr(b, f)
        if len(va) != len(vb) or any(_angles_differ(x, y) for x, y in zip(va, vb)):
            out.append((f, va, vb))
    return out


def check_same_task(scenarios: Sequence) -> list[PlanarTask]:
    """The planar tasks of ``scenarios``; raise if any differs from the first one's.

    Raises:
        ScenarioError: Naming the scenario, the field (in the plane) and both values.
    """
    tasks = [planar_task(s) for s in scenarios]
    for s, task in zip(scenarios[1:], tasks[1:]):
        diff = task_differences(tasks[0], task)
        if diff:
            name, mine, theirs = diff[0]
            raise ScenarioError(
                f"{name} (in the x-z plane)", _plain(theirs),
                f"the value of {scenarios[0].name}, {_plain(mine)}: the scenes of a fidelity comparison must describe "
                "the same task (object, grasps, springs, trajectory, load split, gains, step)", s.source)
    return tasks


def _plain(value):
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float):
        return float(f"{value:.6g}")
    return value


# ---------------------------------------------------------------------- fidelity rank
def fidelity_rank(scenario) -> tuple[bool, int, bool, int]:
    """Sort key of a model's fidelity: spatial over planar, then the number of arms with
    dynamics (not contact points), then the mobile unloaded state (the general model, (113))
    over the immobile linear one (4.5), then the state size. The highest is the comparison's
    reference (the first of equals)."""
    arms = sum(1 for a in scenario.arms if a.model != "contact_point")
    return (scenario.space == "spatial", arms, scenario.scene.unloaded_state == "mobile", scenario.state_size)


# ---------------------------------------------------------------------- cost
def rhs_times_us(plants_and_states, calls: int, rounds: int = 10) -> list[float]:
    """Median time [us] of one ``plant.rhs(0, x, tau)`` call per plant, timed side by side.

    The plants are timed in ``rounds`` interleaved rounds of ``calls // rounds`` individually
    timed calls each (so that a slow moment of the machine hits every model alike); the
    first call of each plant (which may load compiled code) is not timed.
    """
    per_round = max(1, calls // rounds)
    samples = [[] for _ in plants_and_states]
    for plant, x, tau in plants_and_states:
        plant.rhs(0.0, x, tau)
    clock = time.perf_counter
    for _ in range(rounds):
        for k, (plant, x, tau) in enumerate(plants_and_states):
            rhs = plant.rhs
            times = samples[k]
            for _ in range(per_round):
                t0 = clock()
                rhs(0.0, x, tau)
                times.append(clock() - t0)
    return [float(np.median(s)) * 1e6 for s in samples]


# ---------------------------------------------------------------------- the report
@dataclass
class FidelityModel:
    """One model of the comparison: its cost, its own tracking, and its difference from the
    reference in the x-z plane (``None`` where a figure is undefined, e.g. an empty run).

    Attributes:
        scenario, space, arm_models, dof_per_arm, state_size: the model.
        rhs_median_us: Median time of one right-hand-side evaluation [us] (side by side).
        wall_time_s: Median closed-loop wall time over the repeats [s]; realtime_factor the
            simulated time over it [-]; tick_us the wall time per control tick [us].
        status, reason: The run's status (``"ok"``, ``"diverged"``, ``"qp_failed"``).
        tracking: The model's own errors (object position max/RMS [m], orientation max [rad],
            follower force error RMS [N], internal force error RMS [N], max |tau|/tau_max).
        difference: Max over time of the difference from the reference (module docstring):
            object position [m] and angle [rad], contact force [N] (also relative to the
            reference's largest contact force [-]) and moment [N m], the QP's commanded,
            external and internal forces [N], squeeze [N]; ``compared_until_s`` [s].
        out_of_plane: Spatial models: the object's ``max |y - y(0)|`` [m] and out-of-plane
            rotation [rad], the contacts' ``max |f_y|`` [N] and ``max |n_x|, |n_z|`` [N m].
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: str
    space: str
    arm_models: list[str]
    dof_per_arm: list[int]
    state_size: int
    rhs_median_us: float
    wall_time_s: float
    realtime_factor: float | None
    tick_us: float | None
    status: str
    reason: str
    tracking: dict[str, float | None]
    difference: dict[str, float | None] = field(default_factory=dict)
    out_of_plane: dict[str, float] = field(default_factory=dict)


@dataclass
class FidelityReport:
    """The model-fidelity comparison: one :class:`FidelityModel` per scenario, in the order given,
    the ``reference`` (highest fidelity) by name, and the plane traces (for plots and saving)."""

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    models: list[FidelityModel]
    reference: str
    traces: list[PlaneTrace] = field(default_factory=list, repr=False)
    repeats: int = 1
    rhs_calls: int = 0

    @property
    def ok(self) -> bool:
        """True when every run ended with status ``"ok"``."""
        return all(m.status == "ok" for m in self.models)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dict (NaN and inf as ``None``)."""
        from dataclasses import asdict

        from coopctrl.results.summary import json_safe

        return json_safe({
            "reference": self.reference,
            "plane": "x-z (spatial: x, z, theta_p = atan2(R[2,0], R[0,0]) = -pitch; wrench (f_x, f_z, -n_y))",
            "repeats": self.repeats,
            "rhs_calls": self.rhs_calls,
            "models": [asdict(m) for m in self.models],
        })

    def table(self) -> str:
        """An aligned text table: one column per model, one row per figure."""
        return format_table(self)

    def save(self, directory: str | Path) -> list[Path]:
        """Write ``fidelity.json`` and ``fidelity_traces.npz`` (the plane traces, keys
        ``<k>_<field>`` for model k) atomically into ``directory`` (created if needed)."""
        import json

        from coopctrl.io.atomic import atomic_write

        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        path_json = directory / "fidelity.json"
        with atomic_write(path_json) as f:
            json.dump(self.to_dict(), f, indent=2, allow_nan=False)
            f.write("\n")
        arrays = {"scenarios": np.array([tr.scenario for tr in self.traces])}
        for k, tr in enumerate(self.traces):
            for name in ("t", "pose", "pose_nominal", "wrench", "commanded", "external", "internal", "squeeze"):
                arrays[f"{k}_{name}"] = getattr(tr, name)
        path_npz = directory / "fidelity_traces.npz"
        with atomic_write(path_npz, "wb") as f:
            np.savez(f, **arrays)
        return [path_json, path_npz]


#: Rows of :func:`format_table`: (section, key, label, scale, unit).
_TABLE_ROWS = (
    ("", "space", "space", None, ""),
    ("", "arm_models", "arms", None, ""),
    ("", "status", "status", None, ""),
    ("cost", "state_size", "state size", None, ""),
    ("cost", "dof_per_arm", "joints per arm", None, ""),
    ("cost", "rhs_median_us", "rhs evaluation (median)", 1.0, "us"),
    ("cost", "rhs_ratio", "rhs / reference", 1.0, "x"),
    ("cost", "tick_us", "closed-loop tick", 1.0, "us"),
    ("cost", "wall_time_s", "closed-loop wall time", 1.0, "s"),
    ("cost", "realtime_factor", "real-time factor", 1.0, "x"),
    ("tracking", "object_position_error_max_m", "object position error max", 1e3, "mm"),
    ("tracking", "object_orientation_error_max_rad", "object angle error max", 1e3, "mrad"),
    ("tracking", "follower_force_error_rms_N", "follower force error RMS", 1.0, "N"),
    ("tracking", "internal_force_error_rms_N", "squeeze error RMS", 1.0, "N"),
    ("tracking", "max_torque_ratio", "max |tau| / tau_max", 1.0, ""),
    ("difference", "object_position_max_m", "object position", 1e3, "mm"),
    ("difference", "object_angle_max_rad", "object angle", 1e3, "mrad"),
    ("difference", "contact_force_max_N", "contact force", 1.0, "N"),
    ("difference", "contact_force_relative", "contact force / max force", 1e2, "%"),
    ("difference", "contact_moment_max_Nm", "contact moment", 1.0, "N m"),
    ("difference", "external_force_max_N", "QP external part", 1.0, "N"),
    ("difference", "internal_force_max_N", "QP internal part", 1.0, "N"),
    ("difference", "squeeze_max_N", "squeeze", 1.0, "N"),
    ("out of plane", "position_m", "object |y - y(0)|", 1e3, "mm"),
    ("out of plane", "rotation_rad", "object rotation off the plane", 1e3, "mrad"),
    ("out of plane", "force_N", "contact |f_y|", 1.0, "N"),
    ("out of plane", "moment_Nm", "contact |n_x|, |n_z|", 1.0, "N m"),
)


def _cell(value, scale, unit) -> str:
    if value is None:
        return "-"
    if isinstance(value, list):
        return ",".join(str(v) for v in value)
    if scale is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
        if not math.isfinite(value):
            return "-"
        return f"{value * scale:.4g}" + (f" {unit}" if unit else "")
    return str(value)


def format_table(report: FidelityReport) -> str:
    """The report as an aligned text table (one column per model)."""
    ref = next(m for m in report.models if m.scenario == report.reference)
    header = ["", *[m.scenario + (" (ref)" if m.scenario == report.reference else "") for m in report.models]]
    lines = [header]
    section = None
    for sec, key, label, scale, unit in _TABLE_ROWS:
        cells = []
        for m in report.models:
            if sec == "":
                value = getattr(m, key)
            elif sec == "cost":
                value = (m.rhs_median_us / ref.rhs_median_us if ref.rhs_median_us else None) if key == "rhs_ratio" \
                    else getattr(m, key)
            elif sec == "tracking":
                value = m.tracking.get(key)
            elif sec == "difference":
                value = m.difference.get(key) if m.scenario != report.reference else None
            else:
                value = m.out_of_plane.get(key) if m.space == "spatial" else None
            cells.append(_cell(value, scale, unit))
        if sec != section:
            title = {"cost": "cost", "tracking": "own tracking (vs. its nominal)",
                     "difference": f"difference from {report.reference} (max over time, in the plane)",
                     "out of plane": "out of the plane (spatial models)"}.get(sec)
            if title:
                lines.append([f"-- {title}"] + [""] * len(report.models))
            section = sec
        lines.append([f"  {label}" if sec else label, *cells])
    widths = [max(len(row[k]) for row in lines if not row[0].startswith("--") or k > 0) for k in range(len(header))]
    out = []
    for row in lines:
        if row[0].startswith("--"):
            out.append(row[0])
            continue
        out.append("  ".join([row[0].ljust(widths[0]), *(c.rjust(w) for c, w in zip(row[1:], widths[1:]))]).rstrip())
    return "\n".join(out)


# ---------------------------------------------------------------------- the comparison
def _on_grid(t_ref: np.ndarray, t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (N, ...) sampled at ``t`` linearly interpolated onto ``t_ref``."""
    if t.shape == t_ref.shape and np.allclose(t, t_ref, rtol=0.0, atol=1e-12):
        return values
    flat = values.reshape(len(t), -1)
    out = np.column_stack([np.interp(t_ref, t, flat[:, k]) for k in range(flat.shape[1])]) if flat.shape[1] else \
        np.zeros((len(t_ref), 0))
    return out.reshape((len(t_ref),) + values.shape[1:])


def trace_difference(trace: PlaneTrace, ref: PlaneTrace) -> dict[str, float | None]:
    """Max over the common time span of the differences of ``trace`` from ``ref`` (in the plane).

    Returns the keys of :attr:`FidelityModel.difference`; ``None`` for all of them if the two
    runs share fewer than two samples.
    """
    keys = ("object_position_max_m", "object_angle_max_rad", "contact_force_max_N", "contact_force_relative",
            "contact_moment_max_Nm", "commanded_force_max_N", "external_force_max_N", "internal_force_max_N",
            "squeeze_max_N")
    if len(trace.t) < 2 or len(ref.t) < 2 or trace.wrench.shape[1] != ref.wrench.shape[1]:
        return {**{k: None for k in keys}, "compared_until_s": None}
    end = min(trace.t[-1], ref.t[-1])
    sel = ref.t <= end + 1e-12
    t = ref.t[sel]

    def on(values):
        return _on_grid(t, trace.t, values)

    pose, ref_pose = on(trace.pose), ref.pose[sel]
    out: dict[str, float | None] = {}
    out["object_position_max_m"] = float(np.max(np.linalg.norm(pose[:, :2] - ref_pose[:, :2], axis=1)))
    out["object_angle_max_rad"] = float(np.max(np.abs(_wrap(pose[:, 2] - ref_pose[:, 2]))))
    F, F_ref = on(trace.wrench), ref.wrench[sel]
    out["contact_force_max_N"] = float(np.max(np.linalg.norm(F[..., :2] - F_ref[..., :2], axis=-1)))
    scale = float(np.max(np.linalg.norm(F_ref[..., :2], axis=-1)))
    out["contact_force_relative"] = out["contact_force_max_N"] / scale if scale > 0 else None
    out["contact_moment_max_Nm"] = float(np.max(np.abs(F[..., 2] - F_ref[..., 2])))
    for name, key in (("commanded", "commanded_force_max_N"), ("external", "external_force_max_N"),
                      ("internal", "internal_force_max_N")):
        a, b = on(getattr(trace, name)), getattr(ref, name)[sel]
        out[key] = float(np.max(np.linalg.norm(a[..., :2] - b[..., :2], axis=-1)))
    if trace.squeeze.shape[1] == ref.squeeze.shape[1] and trace.squeeze.shape[1]:
        out["squeeze_max_N"] = float(np.max(np.abs(on(trace.squeeze) - ref.squeeze[sel])))
    else:
        out["squeeze_max_N"] = None
    out["compared_until_s"] = float(t[-1])
    return out


def _with_duration(scenario, duration: float):
    return replace(scenario, simulation=replace(scenario.simulation, duration=duration))


def compare_fidelity(scenarios: Sequence, *, repeats: int = 1, rhs_calls: int = 5000,
                     check_task: bool = True, progress=None) -> FidelityReport:
    """Run the fidelity comparison of ``scenarios`` (see the module docstring).

    Args:
        scenarios: At least two :class:`~coopctrl.scenario.Scenario` of the same task.
        repeats: Closed-loop runs per model (round-robin, after a short warm-up run); the wall
            time reported is their median. The outcome is the first run's (runs are deterministic).
        rhs_calls: Individually timed right-hand-side calls per model.
        check_task: Reject scenes that do not describe the same task (:func:`check_same_task`).
        progress: Called with one line per stage (``"run 2/3: fidelity_planar ..."``), or ``None``.

    Raises:
        ScenarioError: Fewer than two scenarios, scenes of different tasks, or a bad scene.
    """
    from coopctrl.simulator import simulate

    scenarios = list(scenarios)
    if len(scenarios) < 2:
        raise ScenarioError("scenarios", [s.name for s in scenarios], "at least two scenes of one task to compare")
    if int(repeats) != repeats or repeats < 1:
        raise ScenarioError("repeats", repeats, "an integer >= 1")
    if int(rhs_calls) != rhs_calls or rhs_calls < 1:
        raise ScenarioError("rhs_calls", rhs_calls, "an integer >= 1")
    if check_task:
        check_same_task(scenarios)
    ref_index = max(range(len(scenarios)), key=lambda k: fidelity_rank(scenarios[k]))
    say = progress or (lambda _message: None)
    say(f"timing the right-hand side of {len(scenarios)} models ({rhs_calls} calls each)")

    # cost of one right-hand side, side by side (plants at their loaded initial state, no torque)
    timed = []
    for s in scenarios:
        plant, x0 = s.plant(), s.initial_state()
        timed.append((plant, np.ascontiguousarray(x0), np.zeros(plant.input_size)))
    rhs_us = rhs_times_us(timed, rhs_calls)
    del timed

    # closed loops: warm-up, then round-robin repeats
    say(f"warm-up runs ({WARM_UP_TICKS} control periods each)")
    for s in scenarios:
        simulate(_with_duration(s, WARM_UP_TICKS * s.simulation.control_period))
    results = [None] * len(scenarios)
    walls: list[list[float]] = [[] for _ in scenarios]
    total = repeats * len(scenarios)
    for rep in range(repeats):
        for k, s in enumerate(scenarios):
            say(f"run {rep * len(scenarios) + k + 1}/{total}: {s.name} ({s.simulation.duration:g} s simulated)")
            r = simulate(s)
            walls[k].append(r.wall_time_s)
            if results[k] is None:
                results[k] = r
    traces = [plane_trace(r) for r in results]
    models = []
    for k, (s, r) in enumerate(zip(scenarios, results)):
        summary = r.summary()
        wall = float(np.median(walls[k]))
        simulated = float(r.t[-1] - r.t[0]) if len(r.t) > 1 else 0.0
        tr = traces[k]
        models.append(FidelityModel(
            scenario=s.name, space=s.space, arm_models=[a.model for a in s.arms], dof_per_arm=list(s.dof_per_arm),
            state_size=int(s.state_size), rhs_median_us=rhs_us[k], wall_time_s=wall,
            realtime_factor=simulated / wall if wall > 0 and simulated > 0 else None,
            tick_us=wall / len(r.t) * 1e6 if len(r.t) else None, status=r.status, reason=r.reason,
            tracking={key: summary.get(key) for key in (
                "object_position_error_max_m", "object_position_error_rms_m", "object_orientation_error_max_rad",
                "follower_force_error_rms_N", "internal_force_error_rms_N", "max_torque_ratio")}
            | ({"max_torque_ratio": None} if all(a.model == "contact_point" for a in s.arms) else {}),
            difference=trace_difference(tr, traces[ref_index]),
            out_of_plane={"position_m": tr.out_of_plane_position, "rotation_rad": tr.out_of_plane_rotation,
                          "force_N": tr.out_of_plane_force, "moment_Nm": tr.out_of_plane_moment}
            if s.space == "spatial" else {},
        ))
    return FidelityReport(models=models, reference=scenarios[ref_index].name, traces=traces, repeats=int(repeats),
                          rhs_calls=int(rhs_calls))
