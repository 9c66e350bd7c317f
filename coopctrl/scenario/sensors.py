"""``[sensors]``: noise and quantization of the measurements read at the control rate."""

from __future__ import annotations

from dataclasses import dataclass, field

from coopctrl.scenario.checks import instance, number
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
class SensorsConfig:
    """``[sensors]``: joint encoders, contact force sensors, object pose measurement."""

    joints: SensorConfig = field(default_factory=SensorConfig)
    forces: SensorConfig = field(default_factory=SensorConfig)
    object: SensorConfig = field(default_factory=SensorConfig)

    def __post_init__(self) -> None:
        for name in ("joints", "forces", "object"):
            instance(name, getattr(self, name), SensorConfig)
