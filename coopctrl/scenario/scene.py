"""``[scene]``: the kind of scene (planar or spatial) and its environment."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, number
from coopctrl.scenario.schema import key, limits

SPACES = ("planar", "spatial")
UNLOADED_STATES = ("mobile", "immobile")
ROTATIONS = ("book", "charts")


@dataclass(frozen=True)
class SceneConfig:
    """The scene.

    Attributes:
        space: ``"planar"`` (bodies move in the vertical x-z plane, poses ``[x, z, theta]``) or
            ``"spatial"`` (poses ``[x, y, z, psi, theta, phi]``). docs/model.md §2.
        unloaded_state: ``"mobile"`` (general model, docs/model.md §3, (113)) or ``"immobile"``
            (linear plant about a fixed unloaded state, (95-102)).
        gravity: Magnitude of gravity along -z in [m/s^2].
        rotations: How a spatial node's rotation is taken (docs/model.md s.2): ``"charts"`` the loop runs
            in a world frame re-centred on the object whenever its angles near their singularity, so the
            object may turn through any pitch; ``"book"`` the book's world ZYX Euler angles, singular at
            pitch +-90 deg (a run stops 5 deg before it, a path through it is refused). Charts need springs
            invariant under a rotation of the world: offset, matrix and beam elements, central ones with
            one stiffness and torsion in the geodesic form (or none), no torsion dampers on Euler rates,
            and the mobile model. Absent: ``"charts"`` in a spatial scene of the mobile model whose springs
            allow them, else ``"book"`` (``coopctrl check`` says which and why).
    """

    space: str = key("planar", allowed=SPACES)
    unloaded_state: str = key("mobile", allowed=UNLOADED_STATES)
    gravity: float = key(9.81, unit="m/s^2", ge=0, le=100.0, why="up to ten times the Earth's (Jupiter: 24.8)")
    rotations: str | None = key(None, allowed=ROTATIONS)

    def __post_init__(self) -> None:
        object.__setattr__(self, "space", choice("space", self.space, SPACES))
        object.__setattr__(self, "unloaded_state", choice("unloaded_state", self.unloaded_state, UNLOADED_STATES))
        object.__setattr__(self, "gravity", number("gravity", self.gravity, **limits(self, "gravity")))
        if self.rotations is None and (self.space != "spatial" or self.unloaded_state != "mobile"):
            object.__setattr__(self, "rotations", "book")  # the only one (spatial mobile: chosen by the Scenario)
        if self.rotations is not None:
            object.__setattr__(self, "rotations", choice("rotations", self.rotations, ROTATIONS))
        if self.rotations == "charts" and self.space != "spatial":
            raise ScenarioError("rotations", self.rotations, "'book' in a planar scene (charts are for spatial rotations)")
        if self.rotations == "charts" and self.unloaded_state != "mobile":
            raise ScenarioError("rotations", self.rotations, "'book' with unloaded_state = 'immobile' (the immobile "
                                "model is linear in the book's world angles)")

    @property
    def pose_size(self) -> int:
        """Length of a pose: 3 planar, 6 spatial."""
        return 3 if self.space == "planar" else 6
