"""``[sensors]``: noise and quantization of the measurements read at the control rate."""

from __future__ import annotations

from dataclasses import dataclass, field

from coopctrl.scenario.checks import instance, number


@dataclass(frozen=True)
class SensorConfig:
    """One sensor.

    Attributes:
        noise_std: Standard deviation of additive Gaussian noise, in the sensor's unit
            ([rad] joints, [N] / [N m] forces, [m] / [rad] object pose), >= 0.
        quantization: Quantization step in the same unit, >= 0 (0 = off).
    """

    noise_std: float = 0.0
    quantization: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise_std", number("noise_std", self.noise_std, nonnegative=True))
        object.__setattr__(self, "quantization", number("quantization", self.quantization, nonnegative=True))


@dataclass(frozen=True)
class SensorsConfig:
    """``[sensors]``: joint encoders, contact force sensors, object pose measurement."""

    joints: SensorConfig = field(default_factory=SensorConfig)
    forces: SensorConfig = field(default_factory=SensorConfig)
    object: SensorConfig = field(default_factory=SensorConfig)

    def __post_init__(self) -> None:
        for name in ("joints", "forces", "object"):
            instance(name, getattr(self, name), SensorConfig)
