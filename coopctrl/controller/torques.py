"""``Torques``: the joint torques of one control period, per arm by name."""

from __future__ import annotations

import numpy as np


class Torques:
    """The saturated joint torques a :meth:`coopctrl.Controller.step` returns, to hold over the next period.

    Attributes:
        tau: (nu,) every joint's torque, arm after arm [N m] (a prismatic joint's force [N]); read-only.
        names: The arms' names, in the scene's order.

    ``torques["left"]`` or ``torques[0]``: arm ``left`` (index 0), (n_i,) [N m] (a read-only view of ``tau``);
    ``torques.arms``: every arm's, in order.
    """

    __slots__ = ("tau", "names", "_slices")

    def __init__(self, tau: np.ndarray, names: tuple, slices: tuple):
        tau.flags.writeable = False
        self.tau = tau
        self.names = names
        self._slices = slices

    def __getitem__(self, arm) -> np.ndarray:
        if isinstance(arm, str):
            try:
                arm = self.names.index(arm)
            except ValueError:
                raise KeyError(f"arm {arm!r} is not in this scene: its arms are {', '.join(self.names)}") from None
        return self.tau[self._slices[arm]]

    @property
    def arms(self) -> tuple:
        """Every arm's torques (n_i,) [N m], in the scene's order."""
        return tuple(self.tau[s] for s in self._slices)

    def __len__(self) -> int:
        return len(self.names)

    def __repr__(self) -> str:
        arms = ", ".join(f"{n}={np.array2string(self.tau[s], precision=4)}" for n, s in zip(self.names, self._slices))
        return f"Torques({arms}) [N m]"


__all__ = ["Torques"]
