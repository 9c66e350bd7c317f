"""The :class:`Scenario`: the root of the configuration tree, with the cross-field checks."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, is_dataclass, replace

from coopctrl.errors import ScenarioError
from coopctrl.scenario.arm import MODEL_SPACES, ArmConfig
from coopctrl.scenario.checks import field_scope, instance, string
from coopctrl.scenario.controllers import ControllersConfig
from coopctrl.scenario.load_distribution import LoadDistributionConfig
from coopctrl.scenario.object_config import ObjectConfig
from coopctrl.scenario.scene import SceneConfig
from coopctrl.scenario.sensors import SensorsConfig
from coopctrl.scenario.simulation import SimulationConfig
from coopctrl.scenario.spring import SpringConfig
from coopctrl.scenario.trajectory import TrajectoryConfig, ViaPoint, check_segments

#: Most arms in a scene (each adds its joints, a contact and m - 1 squeeze pairs to every tick).
MAX_ARMS = 16
#: Most via points of a trajectory.
MAX_VIA_POINTS = 10000
#: Closest two contact points may be [m]: the squeeze of a pair acts along the line joining them.
MIN_CONTACT_DISTANCE_M = 1e-6

#: Default lift of the default trajectory [m] and its duration [s].
DEFAULT_LIFT_M = 0.1
DEFAULT_LIFT_TIME_S = 1.0


def default_arms() -> tuple[ArmConfig, ...]:
    """Two planar 3R arms facing each other, holding the object from both sides."""
    return (
        ArmConfig(model="planar3r", role="leader", base=(-0.6, 0.0, 0.0), grasp=(-0.1, 0.0, 0.0)),
        ArmConfig(model="planar3r", role="follower", base=(0.6, 0.0, 0.0), grasp=(0.1, 0.0, math.pi)),
    )


def default_object_pose(space: str) -> tuple[float, ...]:
    """0.5 m above the origin, not rotated."""
    return (0.0, 0.5, 0.0) if space == "planar" else (0.0, 0.0, 0.5, 0.0, 0.0, 0.0)


def default_trajectory(pose: tuple[float, ...], space: str) -> TrajectoryConfig:
    """Lift the object by :data:`DEFAULT_LIFT_M` along +z over :data:`DEFAULT_LIFT_TIME_S`."""
    z = 1 if space == "planar" else 2
    end = list(pose)
    end[z] += DEFAULT_LIFT_M
    return TrajectoryConfig(via=(ViaPoint(0.0, tuple(pose)), ViaPoint(DEFAULT_LIFT_TIME_S, tuple(end))))


def _check_euler(path: str, pose: tuple[float, ...], charts: bool = False) -> None:
    """Reject a spatial pose at the Euler-angle singularity cos(theta) = 0 (docs/model.md §2), unless the
    scene takes its rotations in charts (``scene.rotations = "charts"``: any rotation is a pose)."""
    if not charts and len(pose) == 6 and abs(math.cos(pose[4])) < 1e-6:
        raise ScenarioError(path, list(pose), "an orientation with cos(theta) != 0 (Euler singularity, docs/model.md §2)")


def _check_distinct_contacts(arms, translations: int) -> None:
    """Refuse two arms whose grasps put their contacts at one point of the object (both at its centre,
    say): the squeeze of a pair acts along the line joining its contacts, which is then undefined.
    The grasps are in the object frame, so their distance is that of the contacts in the world."""
    for j in range(1, len(arms)):
        for i in range(j):
            a, b = arms[i].grasp[:translations], arms[j].grasp[:translations]
            if math.dist(a, b) < MIN_CONTACT_DISTANCE_M:
                raise ScenarioError(f"arms[{j}].grasp", list(arms[j].grasp),
                                    f"a contact point at least {MIN_CONTACT_DISTANCE_M:g} m from arms[{i}].grasp = "
                                    f"{list(arms[i].grasp)} (its first {translations} values are the contact's position "
                                    "in the object frame; two arms cannot hold the object at one point: the squeeze "
                                    "between them would have no direction)")


def chart_obstacle(springs) -> tuple[str, object, str] | None:
    """Why ``springs`` need the book's world angles, as ``(field, value, what charts allow)``; ``None`` when
    every spring is invariant under a rotation of the world, so the loop may run in charts
    (``scene.rotations = "charts"``, docs/model.md s.2). Offset, matrix and beam elements are (their
    rotational terms act on the exact relative rotation); a central element is with one stiffness (per-axis
    values act on the world axes) and its torsion in the geodesic form or none (the book's
    Euler-difference torsion depends on the angles' chart); torsion dampers on Euler rates
    (``damping_form = "book"``) are not. A spring whose ``rotation_form`` is absent takes the geodesic form
    in charts."""
    for k, spring in enumerate(springs):
        if spring.element == "central":
            if isinstance(spring.stiffness, tuple) and len(set(spring.stiffness)) > 1:
                return (f"springs[{k}].stiffness", list(spring.stiffness), "one value for a central element with "
                        "scene.rotations = 'charts' (per-axis values act on the world axes)")
            if spring.rotation_form == "book" and spring.torsion != 0.0 and spring.torsion != (0.0,) * 3:
                return (f"springs[{k}].rotation_form", spring.rotation_form, "'geodesic' for a central element with "
                        "torsion and scene.rotations = 'charts' (the book's Euler-difference torsion depends on the "
                        "angles' chart)")
        if spring.damping_form == "book" and spring.torsion_damping != 0.0:
            return (f"springs[{k}].damping_form", spring.damping_form, "'frame_invariant' with scene.rotations = "
                    "'charts' (the book's torsion dampers act on Euler rates, which depend on the chart), or "
                    "torsion_damping = 0")
    return None


def rotations_text(scenario) -> str:
    """How a spatial scene takes its rotations, and why when not in charts (``coopctrl check`` prints it);
    ``""`` for a planar scene (one angle, no singularity)."""
    if scenario.space != "spatial":
        return ""
    if scenario.scene.rotations == "charts":
        return "rotations in charts (any pitch)"
    if scenario.scene.unloaded_state != "mobile":
        why = "unloaded_state = 'immobile': the immobile model is linear in them"
    else:
        obstacle = chart_obstacle(scenario.springs)
        why = "scene.rotations = 'book'" if obstacle is None else (
            f"{obstacle[0]} = {obstacle[1]!r}; charts need {obstacle[2]}")
    return f"rotations in the book's world angles ({why}; a path within 5 deg of pitch +-90 deg is refused)"


def _rotations(scene: SceneConfig, springs) -> str:
    """The scene's rotations: as given, or when absent (a spatial scene of the mobile model) ``"charts"`` if
    the springs allow them (:func:`chart_obstacle`), else the book's world angles."""
    if scene.rotations is not None:
        return scene.rotations
    if springs is None:
        return "charts"  # one default spring per arm: an offset element
    if not isinstance(springs, (list, tuple)) or not all(isinstance(sp, SpringConfig) for sp in springs):
        return "book"  # refused below with the field
    return "charts" if chart_obstacle(springs) is None else "book"


@dataclass(frozen=True)
class Scenario:
    """A complete scene: plant, controllers, trajectory and simulation settings.

    Built from a TOML file by :func:`coopctrl.scenario.load_scenario`; ``Scenario()`` is the
    built-in default scene (two planar 3R arms lifting a 1 kg object by 0.1 m in 1 s).
    Every field is checked when built; errors are :class:`~coopctrl.errors.ScenarioError`
    naming the dotted path of the field.

    Attributes:
        name: Name of the scenario.
        description: One line, shown by ``coopctrl list``.
        scene: ``[scene]``: planar or spatial, gravity.
        object: ``[object]``: the carried body. ``object.pose`` absent = the trajectory's first
            via pose.
        arms: ``[[arms]]``: at least two, exactly one leader. Required in a file; the built-in
            default scene has two planar 3R arms.
        springs: ``[[springs]]``: the interconnections. Absent = one spring per arm between the
            object (node 0) and the arm's node, with the defaults below.
        trajectory: ``[trajectory]``: the object's nominal motion. Required in a file; absent
            (only outside a file, the built-in default scene) = a 0.1 m lift in 1 s.
        load_distribution: ``[load_distribution]``: the load-distribution QP.
        controllers: ``[controllers]``: the leader's and the followers' gains.
        sensors: ``[sensors]``: measurement noise and quantization.
        simulation: ``[simulation]``: duration, control period, integrator.
        source: Path of the file it was loaded from, or ``None`` (not part of the scene).
    """

    name: str = "default"
    description: str = "Two planar 3R arms lift a 1 kg object by 0.1 m in 1 s."
    scene: SceneConfig = field(default_factory=SceneConfig)
    object: ObjectConfig = field(default_factory=ObjectConfig)
    arms: tuple[ArmConfig, ...] = field(default_factory=default_arms)
    springs: tuple[SpringConfig, ...] | None = None
    trajectory: TrajectoryConfig | None = None
    load_distribution: LoadDistributionConfig = field(default_factory=LoadDistributionConfig)
    controllers: ControllersConfig = field(default_factory=ControllersConfig)
    sensors: SensorsConfig = field(default_factory=SensorsConfig)
    simulation: SimulationConfig = field(default_factory=SimulationConfig)
    source: str | None = field(default=None, compare=False)

    # ------------------------------------------------------------------ checks
    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "name", string("name", self.name, nonempty=True, one_line=True))
        s(self, "description", string("description", self.description, one_line=True))
        for name, cls in (
            ("scene", SceneConfig),
            ("object", ObjectConfig),
            ("load_distribution", LoadDistributionConfig),
            ("controllers", ControllersConfig),
            ("sensors", SensorsConfig),
            ("simulation", SimulationConfig),
        ):
            instance(name, getattr(self, name), cls)
        if self.source is not None:
            s(self, "source", str(self.source))
        if self.scene.rotations is None:  # absent: charts where the springs allow them (docs/model.md s.2)
            s(self, "scene", replace(self.scene, rotations=_rotations(self.scene, self.springs)))
        space = self.scene.space
        p = self.scene.pose_size
        r = 1 if space == "planar" else 3  # rotational axes
        pose_what = "a planar pose [x, z, theta]" if p == 3 else "a spatial pose [x, y, z, psi, theta, phi]"

        # object
        obj = self.object
        if obj.inertia is None:
            obj = replace(obj, inertia=(0.01,) * r)
        given_pose = obj.pose
        if obj.pose is None:
            start = self.trajectory.via[0].pose if isinstance(self.trajectory, TrajectoryConfig) else None
            obj = replace(obj, pose=start if start is not None else default_object_pose(space))
        s(self, "object", obj)
        if len(obj.inertia) != r:
            raise ScenarioError("object.inertia", list(obj.inertia), f"{r} principal moment(s) in a {space} scene [kg m^2]")
        pose_path = "object.pose" if given_pose is not None or self.trajectory is None else "trajectory.via[0].pose"
        if len(obj.pose) != p:
            raise ScenarioError(pose_path, list(obj.pose), f"{pose_what} in a {space} scene")
        charts = self.scene.rotations == "charts"
        _check_euler(pose_path, obj.pose, charts)

        # arms
        if not isinstance(self.arms, (list, tuple)) or not 2 <= len(self.arms) <= MAX_ARMS:
            shown = f"{len(self.arms)} tables" if isinstance(self.arms, (list, tuple)) else self.arms
            raise ScenarioError("arms", shown, f"a list of 2 to {MAX_ARMS} [[arms]] tables")
        arms = []
        for k, arm in enumerate(self.arms):
            path = f"arms[{k}]"
            instance(path, arm, ArmConfig)
            if arm.node_inertia is None:
                arm = replace(arm, node_inertia=(1e-3,) * r)
            with field_scope(path):
                if space not in MODEL_SPACES[arm.model]:
                    fit = [m for m, sp in MODEL_SPACES.items() if space in sp]
                    raise ScenarioError("model", arm.model, f"one of {', '.join(map(repr, fit))} in a {space} scene")
                for name in ("base", "grasp", "grasp_error"):
                    if getattr(arm, name) is not None and len(getattr(arm, name)) != p:
                        raise ScenarioError(name, list(getattr(arm, name)), f"{pose_what} in a {space} scene")
                if len(arm.node_inertia) != r:
                    raise ScenarioError("node_inertia", list(arm.node_inertia), f"{r} principal moment(s) in a {space} scene [kg m^2]")
                n = arm.dof(space)
                for name in ("tau_max", "q0"):
                    value = getattr(arm, name)
                    if value is not None and n is not None and len(value) != n:  # n None: a URDF arm, checked at build
                        raise ScenarioError(name, list(value), f"{n} values, one per joint of a {arm.model} arm")
            arms.append(arm)
        s(self, "arms", tuple(arms))
        leaders = [k for k, arm in enumerate(arms) if arm.role == "leader"]
        if len(leaders) != 1:
            path = f"arms[{leaders[1]}].role" if len(leaders) > 1 else "arms"
            value = "leader" if len(leaders) > 1 else [a.role for a in arms]
            raise ScenarioError(path, value, f"exactly one arm with role = 'leader' (found {len(leaders)})")
        m = len(arms)
        _check_distinct_contacts(arms, p - r)

        # springs
        springs = self.springs
        if springs is None:
            springs = tuple(SpringConfig(pair=(0, k)) for k in range(1, m + 1))
        if not isinstance(springs, (list, tuple)) or not springs:
            raise ScenarioError("springs", springs, "a non-empty list of [[springs]] tables")
        seen: dict[frozenset, int] = {}
        for k, spring in enumerate(springs):
            path = f"springs[{k}]"
            instance(path, spring, SpringConfig)
            with field_scope(path):
                if max(spring.pair) > m:
                    raise ScenarioError("pair", list(spring.pair), f"node indices in 0..{m} (0 = object, 1..{m} = arms)")
                key = frozenset(spring.pair)
                if key in seen:
                    raise ScenarioError("pair", list(spring.pair), f"a pair not already connected by springs[{seen[key]}]")
                seen[key] = k
                if isinstance(spring.stiffness, tuple) and len(spring.stiffness) != p - r:
                    raise ScenarioError("stiffness", list(spring.stiffness), f"a scalar or {p - r} values (translational axes) in a {space} scene [N/m]")
                if isinstance(spring.torsion, tuple) and len(spring.torsion) != r:
                    raise ScenarioError("torsion", list(spring.torsion), f"a scalar or {r} value(s) (rotational axes) in a {space} scene [N m/rad]")
        if charts:
            obstacle = chart_obstacle(springs)
            if obstacle is not None:
                raise ScenarioError(*obstacle)
        form = "geodesic" if charts else "book"  # an absent rotation_form: the scene's
        springs = tuple(sp if sp.rotation_form is not None else replace(sp, rotation_form=form) for sp in springs)
        s(self, "springs", springs)
        reached, frontier = {0}, [0]
        while frontier:
            node = frontier.pop()
            for spring in springs:
                if node in spring.pair:
                    other = spring.pair[1] if spring.pair[0] == node else spring.pair[0]
                    if other not in reached:
                        reached.add(other)
                        frontier.append(other)
        if len(reached) != m + 1:
            lost = sorted(set(range(m + 1)) - reached)
            raise ScenarioError("springs", [list(sp.pair) for sp in springs], f"pairs connecting the object (node 0) to every arm node (not connected: {lost})")

        # trajectory
        trajectory = self.trajectory
        if trajectory is None:
            trajectory = default_trajectory(obj.pose, space)
        instance("trajectory", trajectory, TrajectoryConfig)
        if trajectory.orientation is None:  # absent: on the rotation in charts, the book's angles otherwise
            trajectory = replace(trajectory, orientation="geodesic" if charts else "euler")
        if len(trajectory.via) > MAX_VIA_POINTS:
            raise ScenarioError("trajectory.via", f"{len(trajectory.via)} points", f"at most {MAX_VIA_POINTS} via points")
        s(self, "trajectory", trajectory)
        for k, via in enumerate(trajectory.via):
            path = f"trajectory.via[{k}].pose"
            if len(via.pose) != p:
                raise ScenarioError(path, list(via.pose), f"{pose_what} in a {space} scene")
            _check_euler(path, via.pose, charts)
        check_segments(trajectory, self.simulation.control_period)
        if given_pose is not None and any(abs(a - b) > 1e-9 for a, b in zip(trajectory.via[0].pose, obj.pose)):
            raise ScenarioError("object.pose", list(obj.pose), f"the trajectory's start trajectory.via[0].pose = "
                                f"{list(trajectory.via[0].pose)} (the object starts where its trajectory starts: "
                                "leave object.pose out)")

        # load distribution
        ld = self.load_distribution
        if ld.shares is not None and len(ld.shares) != m:
            raise ScenarioError("load_distribution.shares", list(ld.shares), f"{m} shares, one per arm")
        pairs = m * (m - 1) // 2
        if isinstance(ld.squeeze, tuple) and len(ld.squeeze) != pairs:
            raise ScenarioError("load_distribution.squeeze", list(ld.squeeze), f"a scalar or {pairs} values, one per contact pair [N]")

    # ------------------------------------------------------------------ views
    def __repr__(self) -> str:
        """A few lines: name, space, arms, integrator, duration and source (``to_dict()`` has every field)."""
        from coopctrl.compact_repr import compact_repr

        sim = self.simulation
        return compact_repr(self, ["name", "source"],
                            extra=[("space", self.scene.space), ("arms", [f"{a.model} {a.role}" for a in self.arms]),
                                   ("integrator", sim.integrator), ("control_period_s", sim.control_period),
                                   ("substeps", sim.substeps), ("duration_s", sim.duration)])

    @property
    def space(self) -> str:
        """``"planar"`` or ``"spatial"``."""
        return self.scene.space

    @property
    def pose_size(self) -> int:
        """Length p of a pose or a wrench: 3 planar, 6 spatial."""
        return self.scene.pose_size

    @property
    def leader(self) -> int:
        """Index (0-based, into ``arms``) of the leader."""
        return next(k for k, arm in enumerate(self.arms) if arm.role == "leader")

    @property
    def followers(self) -> list[int]:
        """Indices (0-based, into ``arms``) of the followers."""
        return [k for k, arm in enumerate(self.arms) if arm.role == "follower"]

    @property
    def dof_per_arm(self) -> list[int]:
        """Number of joints of each arm."""
        out = []
        for k, arm in enumerate(self.arms):
            with field_scope(f"arms[{k}]"):  # a URDF arm counts its joints in its file
                out.append(arm.dof(self.space, getattr(self, "source", None)))
        return out

    @property
    def state_size(self) -> int:
        """Size of the state ``(z, z')`` with ``z = col(q, Y_0)`` (docs/model.md §5): 2 (sum n_i + p)."""
        return 2 * (sum(self.dof_per_arm) + self.pose_size)

    # ------------------------------------------------------------------ build
    def plant(self):
        """The plant of this scene (``coopctrl.scenario.build.build_plant``)."""
        from coopctrl.scenario import build

        return build.build_plant(self)

    def initial_state(self):
        """The initial state of the plant (``coopctrl.scenario.build.initial_state``)."""
        from coopctrl.scenario import build

        return build.initial_state(self)

    # ------------------------------------------------------------------ dicts
    def to_dict(self) -> dict:
        """A TOML-shaped dict (tables, lists, numbers, strings; absent options left out) that
        :meth:`from_dict` turns back into an equal scenario. ``source`` is not included."""
        out = _to_plain(self)
        out.pop("source", None)
        return out

    @classmethod
    def from_dict(cls, data: dict, *, source: str | None = None) -> "Scenario":
        """Build a scenario from a TOML-shaped dict, rejecting unknown keys."""
        from coopctrl.scenario.loader import scenario_from_dict

        return scenario_from_dict(data, source=source)


def _to_plain(value):
    if is_dataclass(value):
        out = {}
        for f in fields(value):
            v = getattr(value, f.name)
            if v is not None:
                out[f.name] = _to_plain(v)
        return out
    if isinstance(value, (list, tuple)):
        return [_to_plain(v) for v in value]
    return value
