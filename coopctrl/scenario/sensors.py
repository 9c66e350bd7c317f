"""``[sensors]``: noise and quantization of the measurements read at the control rate.

Each channel has its own unit and so its own physical range: a value beyond it is refused when the
scene loads, naming the key (``sensors.object.noise_std``), instead of surfacing as a failed load
distribution or a diverged run once the noise buries the signal.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from coopctrl.scenario.checks import field_scope, instance, number
from coopctrl.scenario.schema import key, limits


@dataclass(frozen=True)
class SensorConfig:
    """One sensor.

    Attributes:
        noise_std: Standard deviation of additive Gaussian noise, in the sensor's unit
            ([rad] joints, [N] / [N m] forces, [m] / [rad] object pose), >= 0.
        quantization: Quantization step in the same unit, >= 0 (0 = off).
    """

    noise_std: float = key(0.0, unit="unit of the sensor", ge=0, le=1e6,
                           why="a noise a million times the unit buries any signal")
    quantization: float = key(0.0, unit="unit of the sensor", ge=0, le=1e6, why="as noise_std")

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise_std", number("noise_std", self.noise_std, **limits(self, "noise_std")))
        object.__setattr__(self, "quantization", number("quantization", self.quantization, **limits(self, "quantization")))


@dataclass(frozen=True)
class JointSensorConfig(SensorConfig):
    """``[sensors.joints]``: the joint encoders (angles of revolute joints [rad], positions of
    prismatic ones and of contact-point arms [m])."""

    noise_std: float = key(0.0, unit="rad or m", ge=0, le=0.1,
                           why="0.1 rad (5.7 deg) is far beyond any joint encoder's error")
    quantization: float = key(0.0, unit="rad or m", ge=0, le=0.1, why="as noise_std (a 64-count encoder quantizes to 0.098 rad)")


@dataclass(frozen=True)
class ForceSensorConfig(SensorConfig):
    """``[sensors.forces]``: the contact force/torque sensors ([N] forces, [N m] moments)."""

    noise_std: float = key(0.0, unit="N or N m", ge=0, le=1e3,
                           why="a force sensor with 1 kN of noise measures no grasp force (squeezes are tens of N)")
    quantization: float = key(0.0, unit="N or N m", ge=0, le=1e3, why="as noise_std")


@dataclass(frozen=True)
class ObjectSensorConfig(SensorConfig):
    """``[sensors.object]``: the object's pose measurement ([m] positions, [rad] angles)."""

    noise_std: float = key(0.0, unit="m or rad", ge=0, le=0.1,
                           why="a pose measured to worse than 0.1 m or 0.1 rad (5.7 deg) carries no object")
    quantization: float = key(0.0, unit="m or rad", ge=0, le=0.1, why="as noise_std")


#: The class of each channel of ``[sensors]``: its unit and range.
CHANNELS: dict[str, type[SensorConfig]] = {
    "joints": JointSensorConfig,
    "forces": ForceSensorConfig,
    "object": ObjectSensorConfig,
}


@dataclass(frozen=True)
class SensorsConfig:
    """``[sensors]``: joint encoders, contact force sensors, object pose measurement.

    A plain :class:`SensorConfig` given for a channel is checked against that channel's range.
    """

    joints: SensorConfig = field(default_factory=JointSensorConfig)
    forces: SensorConfig = field(default_factory=ForceSensorConfig)
    object: SensorConfig = field(default_factory=ObjectSensorConfig)

    def __post_init__(self) -> None:
        for name, cls in CHANNELS.items():
            value = instance(name, getattr(self, name), SensorConfig)
            if not isinstance(value, cls):
                with field_scope(name):
                    value = cls(noise_std=value.noise_std, quantization=value.quantization)
                object.__setattr__(self, name, value)
