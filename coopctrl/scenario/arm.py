"""``[[arms]]``: one manipulator and the elastic node at its contact."""

from __future__ import annotations

import os
from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, number, optional_vector, string, vector
from coopctrl.scenario.schema import key, limits
from plants.urdf_reader import MAX_CHAIN_JOINTS

#: Robots shipped with the package as URDF files (plants.arms.panda / ur5e / iiwa14).
NAMED_ROBOTS = ("panda", "ur5e", "iiwa14")
ARM_MODELS = ("puma560", "planar3r", "contact_point", *NAMED_ROBOTS, "urdf", "dh")
ROLES = ("leader", "follower")

#: Joints per arm model; ``None`` = one joint per pose coordinate (3 planar, 6 spatial);
#: ``"urdf"`` and ``"dh"`` arms count their joints in their file or table.
MODEL_DOF: dict[str, int | None] = {"puma560": 6, "planar3r": 3, "contact_point": None,
                                    "panda": 7, "ur5e": 6, "iiwa14": 7}
#: Spaces each arm model can live in.
MODEL_SPACES: dict[str, tuple[str, ...]] = {
    "puma560": ("spatial",),
    "planar3r": ("planar",),
    "contact_point": ("planar", "spatial"),
    "panda": ("spatial",),
    "ur5e": ("spatial",),
    "iiwa14": ("spatial",),
    "urdf": ("spatial",),
    "dh": ("spatial",),
}
#: Columns of a row of a DH table in a scene: standard DH (as Corke's toolbox, frame k follows
#: frame k-1 by ``Rz(q + offset) Tz(d) Tx(a) Rx(alpha)``) and the link's mass properties in
#: frame k.
DH_COLUMNS = ("a", "alpha", "d", "offset", "mass", "rcx", "rcy", "rcz", "Ixx", "Iyy", "Izz", "Ixy", "Iyz", "Ixz")
DH_UNITS = "a [m], alpha [rad], d [m], offset [rad], mass [kg], rc [m] (3), I about the COM [kg m^2] (Ixx Iyy Izz Ixy Iyz Ixz)"

#: Most joints of a DH arm (and of a URDF arm's chain counted here): far more than any manipulator.
MAX_DH_JOINTS = MAX_CHAIN_JOINTS  # rows of a DH table: the joint bound of any serial arm

_UNRESOLVED = object()


@dataclass(frozen=True)
class ArmConfig:
    """One arm.

    Attributes:
        model: ``"puma560"`` (6 joints, spatial), ``"planar3r"`` (3 joints, planar),
            ``"contact_point"`` (a point actuated directly in task space, 3 or 6 "joints"),
            ``"panda"`` (Franka Panda, 7 joints), ``"ur5e"`` (6), ``"iiwa14"`` (KUKA iiwa 14, 7)
            (URDF files shipped with the package), ``"urdf"`` (your own URDF file: keys
            ``urdf``, ``base_link``, ``tip_link``) or ``"dh"`` (a standard-DH table, key ``dh``).
        role: ``"leader"`` or ``"follower"``; a scenario has exactly one leader (docs/model.md §1).
        base: Pose of the arm base in the world, same shape as a pose [m, rad].
        grasp: Pose of the contact node relative to the object frame [m, rad].
        node_mass: Mass of the contact node (gripper tip and pad) in [kg].
        node_inertia: Principal moments of the node in [kg m^2] (1 planar, 3 spatial);
            ``None`` = 1e-3 per axis.
        tau_max: Per-joint torque limits in [N m] overriding the model's, or ``None``.
        grasp_error: Offset of the true grasp from ``grasp`` that the controllers do not know
            (same shape as a pose) [m, rad], or ``None`` (exact grasp). It models the
            calibration error that force regulation exists to absorb.
        q0: Seed of the inverse kinematics for the initial configuration in [rad], or ``None``.
        urdf: ``model = "urdf"``: path of the URDF file, relative to the scene file.
        base_link: ``model = "urdf"``: the link fixed at ``base``.
        tip_link: ``model = "urdf"``: the link whose frame (times ``tool``) is the node frame.
        tool: Node frame in the tip link frame (the last DH frame for ``"dh"``), a pose
            [m, rad] (6 numbers, ZYX Euler), or ``None``: identity for ``"urdf"`` and ``"dh"``;
            for the named robots the node's x axis along the approach axis of the flange
            (``plants.arms.named_robots.APPROACH_TOOLS``).
        dh: ``model = "dh"``: the DH table, one row of 14 numbers per joint (:data:`DH_COLUMNS`).
        q_rest: Rest posture of a redundant arm's null-space posture task [rad], or ``None``
            (the middle of the joint limits).
    """

    model: str = key(allowed=ARM_MODELS)
    role: str = key(allowed=ROLES)
    base: tuple[float, ...]
    grasp: tuple[float, ...]
    node_mass: float = key(0.1, unit="kg", ge=1e-4, le=1e3, why="from 0.1 g to 1 t, as the object's mass")
    node_inertia: tuple[float, ...] | None = None
    tau_max: tuple[float, ...] | None = None
    q0: tuple[float, ...] | None = None
    grasp_error: tuple[float, ...] | None = None
    urdf: str | None = None
    base_link: str | None = None
    tip_link: str | None = None
    tool: tuple[float, ...] | None = None
    dh: tuple[tuple[float, ...], ...] | None = None
    q_rest: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "model", choice("model", self.model, ARM_MODELS))
        s(self, "role", choice("role", self.role, ROLES))
        s(self, "base", vector("base", self.base, lengths=(3, 6), what="a pose, m and rad"))
        s(self, "grasp", vector("grasp", self.grasp, lengths=(3, 6), what="a pose, m and rad"))
        s(self, "node_mass", number("node_mass", self.node_mass, **limits(self, "node_mass")))
        s(self, "node_inertia", optional_vector("node_inertia", self.node_inertia, lengths=(1, 3), positive=True, what="kg m^2"))
        s(self, "tau_max", optional_vector("tau_max", self.tau_max, positive=True, what="N m per joint"))
        s(self, "q0", optional_vector("q0", self.q0, what="rad per joint"))
        s(self, "grasp_error", optional_vector("grasp_error", self.grasp_error, lengths=(3, 6), what="a pose offset, m and rad"))
        s(self, "tool", optional_vector("tool", self.tool, lengths=(6,), what="the node frame in the tip link frame, m and rad"))
        s(self, "q_rest", optional_vector("q_rest", self.q_rest, what="rad per joint"))
        urdf_keys = ("urdf", "base_link", "tip_link")
        if self.model == "urdf":
            for key in urdf_keys:
                if getattr(self, key) is None:
                    raise ScenarioError(key, None, f"a value: model = 'urdf' needs the keys {', '.join(urdf_keys)}")
                s(self, key, string(key, getattr(self, key), nonempty=True, one_line=True))
        else:
            for key in urdf_keys:
                if getattr(self, key) is not None:
                    raise ScenarioError(key, getattr(self, key), "no value: this key is read only with model = 'urdf'")
        if self.model == "dh":
            s(self, "dh", _dh_table(self.dh))
        elif self.dh is not None:
            raise ScenarioError("dh", self.dh, "no value: this key is read only with model = 'dh'")
        if self.tool is not None and self.model in ("puma560", "planar3r", "contact_point"):
            raise ScenarioError("tool", list(self.tool), "no value: the tool pose is read for model = 'urdf', 'dh', "
                                + ", ".join(repr(r) for r in NAMED_ROBOTS))

    def dof(self, space: str, source=_UNRESOLVED) -> int | None:
        """Number of joints of this arm in a scene of the given ``space``.

        A ``"urdf"`` arm counts the moving joints between ``base_link`` and ``tip_link`` in its
        file, found relative to the scene file ``source`` (``None``: the working directory);
        without ``source`` its count is ``None`` (not known yet).
        """
        if self.model == "dh":
            return len(self.dh)
        if self.model == "urdf":
            if source is _UNRESOLVED:
                return None
            return urdf_chain_dof(self.urdf_path(source), self.base_link, self.tip_link)
        n = MODEL_DOF[self.model]
        return n if n is not None else (3 if space == "planar" else 6)

    def urdf_path(self, source) -> str:
        """The URDF file, resolved relative to the directory of the scene file ``source``."""
        if os.path.isabs(self.urdf):
            return self.urdf
        folder = os.path.dirname(os.fspath(source)) if source else os.getcwd()
        return os.path.normpath(os.path.join(folder, self.urdf))


def _dh_table(value) -> tuple[tuple[float, ...], ...]:
    """A DH table: a non-empty list of rows of :data:`DH_COLUMNS` numbers."""
    what = f"a list of 1 to {MAX_DH_JOINTS} rows of {len(DH_COLUMNS)} numbers, one row per joint: {DH_UNITS}"
    if not isinstance(value, (list, tuple)) or not value:
        raise ScenarioError("dh", value, what)
    if len(value) > MAX_DH_JOINTS:
        raise ScenarioError("dh", f"{len(value)} rows", what)
    rows = []
    for i, row in enumerate(value):
        if not isinstance(row, (list, tuple)) or len(row) != len(DH_COLUMNS):
            got = f"{len(row)} numbers" if isinstance(row, (list, tuple)) else type(row).__name__
            raise ScenarioError(f"dh[{i}]", row, f"{len(DH_COLUMNS)} numbers ({DH_UNITS}); got {got}")
        rows.append(vector(f"dh[{i}]", row, lengths=(len(DH_COLUMNS),), what=DH_UNITS))
    return tuple(rows)


def urdf_chain_dof(path: str, base_link: str, tip_link: str) -> int:
    """Moving joints between ``base_link`` and ``tip_link`` of a URDF file, read by
    :func:`plants.urdf_reader.chain_dof` (the safe parser and the tree, size and chain-length checks
    of ``plants.arms.from_urdf``, without the numbers or the compiled core: the full checks are made when the
    arm is built)."""
    from plants.errors import ParameterError
    from plants.urdf_reader import chain_dof

    try:
        return chain_dof(path, base_link, tip_link)
    except ParameterError as exc:
        field = exc.parameter if exc.parameter in ("urdf", "base_link", "tip_link") else "urdf"
        if field != exc.parameter:  # an element of the file (joint 'x'.limit.effort): name the file
            got = "" if exc.value is None else f" (got {exc.value!r})"
            raise ScenarioError("urdf", path, f"a URDF whose {exc.parameter} is {exc.allowed}{got}") from None
        raise ScenarioError(field, exc.value, exc.allowed) from None
