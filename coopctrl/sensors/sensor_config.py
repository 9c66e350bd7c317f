"""Configuration of one measurement channel."""

from __future__ import annotations

import math
from dataclasses import dataclass

from coopctrl.errors import ScenarioError


@dataclass(frozen=True)
class SensorConfig:
    """Additive Gaussian noise followed by uniform quantization.

    Attributes:
        noise_std: Standard deviation of the additive Gaussian noise, in the units of the
            measured quantity (e.g. [rad] for joint angles, [N] for forces); ``0`` = no noise.
        quantization: Quantization step, in the same units; ``0`` = no quantization.

    Raises:
        ScenarioError: (a ``ValueError``) naming the field, for a negative or non-finite value.
    """

    noise_std: float = 0.0
    quantization: float = 0.0

    def __post_init__(self):
        for name in ("noise_std", "quantization"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ScenarioError(name, value, "a finite number >= 0")
            if not (math.isfinite(value) and value >= 0.0):
                raise ScenarioError(name, value, "a finite number >= 0 (0 turns it off)")
            object.__setattr__(self, name, float(value))

    @property
    def is_exact(self) -> bool:
        """True when the channel neither adds noise nor quantizes."""
        return self.noise_std == 0.0 and self.quantization == 0.0
