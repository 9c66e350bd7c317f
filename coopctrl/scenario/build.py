"""From a validated :class:`Scenario` to the objects of the closed loop: plant, state, QP, controllers.

Every physical error found while building (an unreachable grasp, an Euler singularity, a torque
limit below the static load) is re-raised as a :class:`ScenarioError` naming the scenario field,
so that it is reported before any simulation starts.
"""

from __future__ import annotations

import functools

import numpy as np

from coopctrl.errors import ScenarioError
from plants.arms import DHLink, SerialArm, from_urdf, planar3r, puma560
from plants.arms.named_robots import APPROACH_TOOLS, named_robot
from plants.arms.puma560 import GRIPPER_TOOL
from plants.cooperative import ContactPoint, assemble_plant, nominal_node_poses
from plants.elastic import Interconnection, Node
from plants.errors import EulerSingularityError, ParameterError, UnreachablePoseError
from plants.frames import rotation_zyx

#: Scenes whose plant and unloaded state :func:`_build` keeps [-]: a notebook or a benchmark alternating
#: between a few scenes (or a run's scene and a sweep's variant of it) does not build them again.
BUILD_CACHE_SIZE = 4
_CACHE: dict[int, tuple] = {}  # id(scenario) -> (scenario, (plant, x0)), the least recently used first


def pose_matrix(pose) -> np.ndarray:
    """The 4x4 homogeneous transform ``[[R(A), p], [0, 1]]`` of a spatial ``pose = (p, A)`` (an arm's
    ``base`` or ``tool``): position ``p`` [m] and ZYX Euler angles ``A`` [rad], ``R(A)`` as
    :func:`plants.frames.rotation_zyx`."""
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(np.asarray(pose[3:], dtype=float))
    T[:3, 3] = pose[:3]
    return T


def make_arm(scenario, k: int):
    """The arm model of ``arms[k]``."""
    cfg = scenario.arms[k]
    space = scenario.space
    if cfg.model == "contact_point":
        return ContactPoint(space, name=f"arms[{k}]")
    if cfg.model == "puma560":
        arm = puma560(base=pose_matrix(cfg.base), tool=GRIPPER_TOOL, name=f"arms[{k}]")
    elif cfg.model == "planar3r":
        arm = planar3r(base=np.asarray(cfg.base, dtype=float), gravity=(0.0, -scenario.scene.gravity), name=f"arms[{k}]")
    else:
        arm = _spatial_arm(scenario, k)
    if cfg.tau_max is not None:
        if len(cfg.tau_max) != arm.dof:
            raise ScenarioError(f"arms[{k}].tau_max", list(cfg.tau_max), f"{arm.dof} torque limits [N m]")
        from dataclasses import replace

        arm = replace(arm, tau_max=np.asarray(cfg.tau_max, dtype=float))
    if cfg.q0 is not None and len(cfg.q0) != arm.dof:
        raise ScenarioError(f"arms[{k}].q0", list(cfg.q0), f"{arm.dof} joint values [rad]")
    return arm


def _spatial_arm(scenario, k: int):
    """A named robot, a URDF arm or a DH table of ``arms[k]``; plant-side parameter errors are
    reported as the scenario field they come from (``arms[k].urdf``, ``.tip_link``, ``.dh``)."""
    cfg = scenario.arms[k]
    where = f"arms[{k}]"
    base = pose_matrix(cfg.base)
    gravity = (0.0, 0.0, -scenario.scene.gravity)
    tool = None if cfg.tool is None else pose_matrix(cfg.tool)
    q_rest = None if cfg.q_rest is None else np.asarray(cfg.q_rest, dtype=float)
    try:
        if cfg.model == "dh":
            links = tuple(DHLink.named(f"{where}.dh[{i}]", a=r[0], alpha=r[1], d=r[2], offset=r[3], mass=r[4], rc=r[5:8],
                                       inertia=r[8:14], check_triangle_inequality=False) for i, r in enumerate(cfg.dh))
            arm = SerialArm(name=where, links=links, base=base, tool=np.eye(4) if tool is None else tool,
                            gravity=np.array(gravity))
            if q_rest is not None:
                raise ScenarioError(f"{where}.q_rest", list(cfg.q_rest), "no value: q_rest is read for URDF and named arms", scenario.source)
            return arm
        if cfg.model == "urdf":
            path = cfg.urdf_path(scenario.source)
            return from_urdf(path, cfg.base_link, cfg.tip_link, tool, base=base, name=where, gravity=gravity, q_rest=q_rest)
        return named_robot(cfg.model, APPROACH_TOOLS[cfg.model] if tool is None else tool, base=base, name=where,
                           gravity=gravity, q_rest=q_rest)
    except ParameterError as exc:
        field = exc.parameter
        if field in ("urdf", "base_link", "tip_link", "q_rest", "motor_inertia"):
            raise ScenarioError(f"{where}.{field}", exc.value, exc.allowed, scenario.source) from None
        if field.startswith(where):  # a DH row: arms[k].dh[i].mass
            raise ScenarioError(field, exc.value, exc.allowed, scenario.source) from None
        # an element of the URDF file (joint 'x'.type, link 'y'.inertial): name the file field
        got = "" if exc.value is None else f" (got {exc.value!r})"
        raise ScenarioError(f"{where}.urdf", cfg.urdf, f"a URDF whose {field} is {exc.allowed}{got}", scenario.source) from None


def _build(scenario):
    key = id(scenario)
    if key in _CACHE and _CACHE[key][0] is scenario:  # held here, so its id is not reused while cached
        _CACHE[key] = _CACHE.pop(key)  # now the most recently used
        return _CACHE[key][1]
    space = scenario.space
    obj = scenario.object
    arms = [make_arm(scenario, k) for k in range(len(scenario.arms))]
    nodes = [Node(a.node_mass, a.node_inertia, name=f"arms[{k}].node") for k, a in enumerate(scenario.arms)]
    springs = [_interconnection(scenario, e) for e in range(len(scenario.springs))]
    grasps = true_grasps(scenario)
    q0 = [None if a.q0 is None else np.asarray(a.q0, dtype=float) for a in scenario.arms]
    try:
        plant, x0 = assemble_plant(space, Node(obj.mass, obj.inertia, name="object"), np.asarray(obj.pose, float),
                                   arms, grasps, nodes, springs, gravity=scenario.scene.gravity,
                                   unloaded_state=scenario.scene.unloaded_state, leader=scenario.leader, q0=q0)
    except UnreachablePoseError as exc:
        k = int(exc.arm.split("[")[1].split("]")[0]) if exc.arm.startswith("arms[") else 0
        arm = scenario.arms[k]
        if arm.grasp_error is not None and any(arm.grasp_error):  # the plant holds grasp + grasp_error: name what was set
            true = [float(v) for v in np.add(arm.grasp, arm.grasp_error)]
            raise ScenarioError(f"arms[{k}].grasp_error", list(arm.grasp_error),
                                f"an error that keeps the true grasp arms[{k}].grasp + grasp_error = {true} within reach "
                                f"of the arm at base {list(arm.base)} (inverse kinematics residual {exc.residual:.3g})",
                                scenario.source) from None
        raise ScenarioError(f"arms[{k}].grasp", list(arm.grasp),
                            f"a grasp within reach of the arm at base {list(arm.base)} "
                            f"(inverse kinematics residual {exc.residual:.3g})", scenario.source) from None
    except EulerSingularityError as exc:
        raise ScenarioError("arms[*].grasp", exc.where, "grasp orientations away from pitch = +-90 deg "
                            "(ZYX Euler singularity)", scenario.source) from None
    except ParameterError as exc:
        raise ScenarioError(exc.parameter, exc.value, exc.allowed, scenario.source) from None
    from coopctrl.scenario.structure import check_structure

    check_structure(scenario, plant.elastic)  # every grasp supported: before any use of the plant
    _check_static_torques(scenario, plant, x0)
    while len(_CACHE) >= BUILD_CACHE_SIZE:
        del _CACHE[next(iter(_CACHE))]
    _CACHE[key] = (scenario, (plant, x0))
    return plant, x0


def _check_static_torques(scenario, plant, x0) -> None:
    """Reject torque limits below the arm's own static gravity load (links and node) at the
    initial configuration: no load split can help such an arm. (Whether the object's weight
    can be shared within the limits is the QP's question, asked at every step.)"""
    terms = plant.control_terms(x0)
    for i, arm in enumerate(plant.arms):
        if isinstance(arm, ContactPoint):
            continue
        n = arm.dof
        J = terms.J[i, :, :n]
        tau = terms.h[i, :n] + J.T @ terms.w_free[i + 1]
        ratio = np.abs(tau) / arm.tau_max
        if np.any(ratio > 1.0):
            j = int(np.argmax(ratio))
            raise ScenarioError(
                f"arms[{i}].tau_max", [float(v) for v in arm.tau_max],
                f"limits above the arm's own gravity load at the initial pose (joint {j + 1} needs "
                f"{abs(tau[j]):.3g} N m to hold the arm and its node)", scenario.source)


def build_plant(scenario):
    """The :class:`~plants.cooperative.CooperativePlant` of a scenario."""
    return _build(scenario)[0]


def unloaded_state(scenario) -> np.ndarray:
    """The unloaded configuration at rest: every interconnection at its rest length."""
    return _build(scenario)[1].copy()


def trajectory(scenario):
    """The object's nominal trajectory through ``trajectory.via``: a
    :class:`~coopctrl.trajectory.MinimumJerkTrajectory`, or with ``trajectory.orientation = "geodesic"`` in a
    spatial scene a :class:`~coopctrl.trajectory.GeodesicTrajectory`, whose Euler view (what the loop
    runs on in the book's angles) must stay out of the band around pitch +-90 deg (else bad input naming the
    via that ends the segment entering it). Both are immutable: the same scene's is built once and shared
    (a run builds it for its start, its loop and its path check)."""
    return _trajectory(scenario.trajectory, scenario.space, scenario.scene.rotations, scenario.source)


@functools.lru_cache(maxsize=8)
def _trajectory(config, space: str, rotations: str, source):
    """:func:`trajectory` of the ``[trajectory]`` section ``config`` (hashable: frozen) in a scene."""
    import coopctrl.trajectory as trajectories

    via = config.via
    times, poses = [v.time for v in via], [v.pose for v in via]
    if config.orientation == "euler" or space != "spatial":
        return trajectories.MinimumJerkTrajectory(times, poses, space)
    path = trajectories.GeodesicTrajectory(times, poses)
    if rotations == "charts":  # the loop runs on the rotations, in charts: any pitch
        return path
    entry = path.euler_band_entry()
    if entry is not None:
        segment, t, pitch = entry
        k = segment + 1 if len(via) > 1 else 0
        margin = trajectories.EULER_VIEW_MARGIN_DEG
        raise ScenarioError(
            f"trajectory.via[{k}].pose", list(via[k].pose),
            f"a geodesic path whose ZYX pitch stays at least {margin:g} deg away from +-90 deg: the object reaches "
            f"pitch {pitch:.2f} deg at t = {t:.4g} s, where the loop's Euler coordinates do not exist; keep |pitch| "
            f"below {90.0 - margin:g} deg or re-orient the object frame so that the large rotation is a yaw or a roll",
            source)
    return path


def check_path(scenario) -> None:
    """Refuse a spatial nominal path that enters the Euler-angle band in the book's angles
    (``scene.rotations = "book"``; a :class:`ScenarioError` naming the via pose, exit 2 on the command
    line), or in charts a contact node's angles in the object's chart (naming the grasp), as the loop
    refuses it, but before anything is compiled or
    built: a few milliseconds (the nominal node pitches along the path,
    :func:`coopctrl.loop.euler_band.check_nominal_path`)."""
    if scenario.space == "spatial" and scenario.scene.rotations == "book":
        from coopctrl.loop.euler_band import check_nominal_path

        check_nominal_path(trajectory(scenario), nominal_grasps(scenario))
    elif scenario.space == "spatial":  # charts: the object has no band, a contact node in its chart has
        from coopctrl.loop.charts import check_nominal_path_in_charts

        check_nominal_path_in_charts(trajectory(scenario), nominal_grasps(scenario))


def initial_state(scenario, loop=None) -> np.ndarray:
    """The state the run starts from (``simulation.start``): the unloaded state, or the loaded
    state of :func:`coopctrl.loop.loaded_start.loaded_state` (object on its nominal pose, grasps
    carrying the QP split of t = 0), planned from the loop's parts: those of ``loop``, the scene's
    built closed loop (:meth:`ClosedLoop.loaded_state <coopctrl.closed_loop.ClosedLoop.loaded_state>`), or
    built here (the simulator is not needed). A spatial nominal path through the Euler-angle band is
    refused first, as the loop refuses it."""
    x = unloaded_state(scenario)
    if scenario.simulation.start == "unloaded":
        return x
    if loop is not None:  # its parts are the scene's: built from it, its path checked
        try:
            return loop.loaded_state(x)
        except UnreachablePoseError as exc:
            raise ScenarioError("simulation.start", "loaded", f"a loaded pose within reach ({exc})",
                                scenario.source) from None
    from coopctrl.controllers import GraspCompliance
    from coopctrl.loop.loaded_start import loaded_state

    check_path(scenario)
    plant = build_plant(scenario)
    path = trajectory(scenario)
    grasps = nominal_grasps(scenario)
    ld = scenario.load_distribution
    try:
        return loaded_state(plant, path, grasps, ld, GraspCompliance(plant), ld.torque_limits, x)
    except UnreachablePoseError as exc:
        raise ScenarioError("simulation.start", "loaded", f"a loaded pose within reach ({exc})", scenario.source) from None


def _interconnection(scenario, e: int) -> Interconnection:
    """``springs[e]`` as the plant's interconnection (a beam: a :class:`plants.elastic.fem.BeamElement`,
    whose length and axis the plant takes from the nodes at rest)."""
    from plants.elastic.fem import BeamElement

    s, space = scenario.springs[e], scenario.space
    name = f"springs[{e}]"
    try:
        if s.element in ("central", "offset"):
            return Interconnection(tuple(s.pair), stiffness=s.stiffness_per_axis(space), torsion=s.torsion_per_axis(space),
                                   damping=s.damping, torsion_damping=s.torsion_damping, element=s.element,
                                   damping_form=s.damping_form, rotation_form=s.rotation_form, name=name)
        if s.element == "beam":
            if space == "spatial" and (s.Iz is None or s.J is None):
                raise ParameterError(f"{name}.{'Iz' if s.Iz is None else 'J'}", None, "a number [m^4] for a beam in a spatial scene")
            beam = BeamElement(tuple(s.pair), E=s.E, G=s.G, A=s.A, Iy=s.Iy, Iz=s.Iz if s.Iz is not None else s.Iy,
                               J=s.J if s.J is not None else s.Iy, shear=s.shear, internal_nodes=s.internal_nodes)
            return Interconnection(tuple(s.pair), 0.0, element="beam", beam=beam,
                                   rayleigh_damping=s.rayleigh_damping, name=name)
        frame = None if s.frame is None else _frame_rotation(s.frame, space)
        C = None if s.matrix_damping is None else np.asarray(s.matrix_damping, dtype=float)
        return Interconnection(tuple(s.pair), 0.0, element="matrix", matrix=np.asarray(s.matrix, dtype=float),
                               matrix_damping=C, frame=frame, rayleigh_damping=s.rayleigh_damping, name=name)
    except ParameterError as exc:
        field = exc.parameter if exc.parameter.startswith(name) else f"{name}.{exc.parameter}"
        raise ScenarioError(field, exc.value, exc.allowed, scenario.source) from None


def _frame_rotation(angles, space: str) -> np.ndarray:
    """The element frame's rotation from its ZYX Euler angles (3 spatial) or its angle (1 planar) [rad]."""
    if space == "spatial":
        from plants.frames import rotation_zyx

        return rotation_zyx(np.asarray(angles, dtype=float))
    c, s = np.cos(angles[0]), np.sin(angles[0])
    return np.array([[c, -s], [s, c]])


def true_grasps(scenario) -> np.ndarray:
    """(m, p) grasp poses the plant is built with: ``grasp + grasp_error``."""
    return np.array([np.add(a.grasp, a.grasp_error) if a.grasp_error is not None else a.grasp
                     for a in scenario.arms], dtype=float)


def nominal_grasps(scenario) -> np.ndarray:
    """(m, p) grasp poses in the object frame, as the controllers know them."""
    return np.array([a.grasp for a in scenario.arms], dtype=float)


def reference_poses(scenario) -> np.ndarray:
    """(m + 1, p) unloaded node poses."""
    return nominal_node_poses(np.asarray(scenario.object.pose, float), nominal_grasps(scenario), scenario.space)
