"""``[load_distribution]``: the options of the load-distribution QP (docs/model.md s.6).

The section *is* the QP's own configuration (:class:`coopctrl.load_distribution.LoadDistributionConfig`,
validated there); a scene only changes the default squeeze to a light 5 N grip.
"""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.load_distribution.config import LoadDistributionConfig as _QPConfig
from coopctrl.scenario.checks import integer
from coopctrl.scenario.schema import key, spec


@dataclass(frozen=True)
class LoadDistributionConfig(_QPConfig):
    """:class:`coopctrl.load_distribution.LoadDistributionConfig` with ``squeeze = 5.0`` N by default."""

    squeeze: float | tuple[float, ...] = key(5.0, unit="N", ge=0, le=1e6, why="a grasp pushes; 1 MN crushes any object")
    friction_facets: int = key(4, ge=3, le=64, why="64 facets match the Coulomb cone to 0.12 %; each adds a QP row "
                               "per contact")
    max_iter: int = key(1000, ge=1, le=100000, why="the proxsuite solver converges in tens of iterations")
    max_consecutive_failures: int = key(5, ge=1, le=100000, why="each failure holds the previous split for one period")

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("friction_facets", "max_iter", "max_consecutive_failures"):
            meta = spec(self, name)
            integer(name, getattr(self, name), minimum=meta["ge"], maximum=meta["le"])
        values = self.squeeze if isinstance(self.squeeze, tuple) else (self.squeeze,)
        if any(v < 0 or v > 1e6 for v in values):
            raise ScenarioError("squeeze", self.squeeze, "squeezes >= 0 and <= 1e6 [N] (a grasp pushes; it cannot pull)")

    def squeeze_per_pair(self, arms: int) -> tuple[float, ...]:
        """Desired squeeze of each of the m(m-1)/2 contact pairs [N]."""
        n = arms * (arms - 1) // 2
        return self.squeeze if isinstance(self.squeeze, tuple) else (float(self.squeeze),) * n
