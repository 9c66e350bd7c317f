"""``[load_distribution]``: the options of the load-distribution QP (docs/model.md s.6).

The section *is* the QP's own configuration (:class:`coopctrl.load_distribution.LoadDistributionConfig`,
validated there); a scene only changes the default squeeze to a light 5 N grip.
"""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.load_distribution.config import LoadDistributionConfig as _QPConfig
from coopctrl.scenario.schema import key


@dataclass(frozen=True)
class LoadDistributionConfig(_QPConfig):
    """:class:`coopctrl.load_distribution.LoadDistributionConfig` with ``squeeze = 5.0`` N by default."""

    squeeze: float | tuple[float, ...] = key(5.0, unit="N", ge=0, le=1e6, why="a grasp pushes; 1 MN crushes any object")

    def __post_init__(self) -> None:
        super().__post_init__()
        values = self.squeeze if isinstance(self.squeeze, tuple) else (self.squeeze,)
        if any(v < 0 or v > 1e6 for v in values):
            raise ScenarioError("squeeze", self.squeeze, "squeezes >= 0 and <= 1e6 [N] (a grasp pushes; it cannot pull)")

    def squeeze_per_pair(self, arms: int) -> tuple[float, ...]:
        """Desired squeeze of each of the m(m-1)/2 contact pairs [N]."""
        n = arms * (arms - 1) // 2
        return self.squeeze if isinstance(self.squeeze, tuple) else (float(self.squeeze),) * n
