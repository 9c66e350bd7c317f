"""``[object]``: the carried rigid object (node 0 of the elastic system)."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.scenario.checks import number, optional_vector


@dataclass(frozen=True)
class ObjectConfig:
    """The object.

    Attributes:
        mass: Mass in [kg], > 0.
        inertia: Principal moments of inertia in [kg m^2]: 1 value planar, 3 spatial.
            ``None`` = 0.01 per axis (resolved by :class:`~coopctrl.scenario.Scenario`).
        pose: Initial pose of the object MC: planar ``[x, z, theta]``, spatial
            ``[x, y, z, psi, theta, phi]`` in [m] and [rad]. ``None`` = 0.5 m above the origin.
    """

    mass: float = 1.0
    inertia: tuple[float, ...] | None = None
    pose: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", number("mass", self.mass, positive=True, unit="kg"))
        object.__setattr__(
            self, "inertia", optional_vector("inertia", self.inertia, lengths=(1, 3), positive=True, what="kg m^2")
        )
        object.__setattr__(self, "pose", optional_vector("pose", self.pose, lengths=(3, 6), what="m and rad"))
