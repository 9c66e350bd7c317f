"""``[[arms]]``: one manipulator and the elastic node at its contact."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.scenario.checks import choice, number, optional_vector, vector
from coopctrl.scenario.schema import key, limits

ARM_MODELS = ("puma560", "planar3r", "contact_point")
ROLES = ("leader", "follower")

#: Joints per arm model; ``None`` = one joint per pose coordinate (3 planar, 6 spatial).
MODEL_DOF: dict[str, int | None] = {"puma560": 6, "planar3r": 3, "contact_point": None}
#: Spaces each arm model can live in.
MODEL_SPACES: dict[str, tuple[str, ...]] = {
    "puma560": ("spatial",),
    "planar3r": ("planar",),
    "contact_point": ("planar", "spatial"),
}


@dataclass(frozen=True)
class ArmConfig:
    """One arm.

    Attributes:
        model: ``"puma560"`` (6 joints, spatial), ``"planar3r"`` (3 joints, planar) or
            ``"contact_point"`` (a point actuated directly in task space, 3 or 6 "joints").
        role: ``"leader"`` or ``"follower"``; a scenario has exactly one leader (MODEL.md §1).
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

    def dof(self, space: str) -> int:
        """Number of joints of this arm in a scene of the given ``space``."""
        n = MODEL_DOF[self.model]
        return n if n is not None else (3 if space == "planar" else 6)
