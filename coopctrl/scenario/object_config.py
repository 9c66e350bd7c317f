"""``[object]``: the carried rigid object (node 0 of the elastic system)."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.scenario.checks import number, optional_vector
from coopctrl.scenario.schema import key, limits


@dataclass(frozen=True)
class ObjectConfig:
    """The object.

    Attributes:
        mass: Mass in [kg], > 0.
        inertia: Principal moments of inertia in [kg m^2]: 1 value planar, 3 spatial.
            ``None`` = 0.01 per axis (resolved by :class:`~coopctrl.scenario.Scenario`).
        pose: Initial pose of the object MC: planar ``[x, z, theta]``, spatial
            ``[x, y, z, psi, theta, phi]`` in [m] and [rad]. Redundant with the trajectory's first
            via and best left out: ``None`` = ``trajectory.via[0].pose``; if given, it must equal it.
            (The built-in default scene, which has no trajectory, starts 0.5 m above the origin.)
    """

    mass: float = key(1.0, unit="kg", ge=1e-4, le=1e4,
                      why="from 0.1 g to 10 t; beyond, the mass matrix is singular to rounding against the "
                      "node masses (1e-300 kg gave a LinAlgError)")
    inertia: tuple[float, ...] | None = key(None, unit="kg m^2", ge=1e-10, le=1e4,
                                            why="as the mass, for a body of 1 mm to 10 m")
    pose: tuple[float, ...] | None = key(None, unit="m, rad")

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", number("mass", self.mass, **limits(self, "mass")))
        object.__setattr__(
            self, "inertia", optional_vector("inertia", self.inertia, lengths=(1, 3), **limits(self, "inertia"))
        )
        object.__setattr__(self, "pose", optional_vector("pose", self.pose, lengths=(3, 6), what="m and rad"))
