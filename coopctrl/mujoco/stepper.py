"""The MuJoCo plant as the compiled loop's external plant (:data:`coopctrl.loop.kernel.PLANT_EXTERNAL`).

The compiled loop runs an integrator it does not implement between its kernel calls: after each tick's
record it returns with the held torques, and the caller advances the state over the period with
``integrator.step(f, t, x, tau, h)``. :class:`MujocoStepper` is such an integrator whose ``step`` ignores the
right-hand side ``f`` and advances :class:`~coopctrl.mujoco.plant.MujocoPlant` instead; the loop's state ``x``
is MuJoCo's, mapped exactly (:class:`~coopctrl.mujoco.state_map.StateMap`). The loop then senses, splits the
load and controls at that state as with its own plant.
"""

from __future__ import annotations

import numpy as np

from coopctrl.mujoco.plant import MujocoPlant


class MujocoStepper:
    """``step(f, t, x, tau, h)`` advances a :class:`MujocoPlant` by ``h`` [s] with ``tau`` [N m] held.

    MuJoCo's state is set from ``x`` when ``x`` is not the state the last step returned (a run's start, or a
    state the caller changed); otherwise MuJoCo continues from its own state (warm starts included).

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario`.
        plant: The loop's plant (``build_plant(scenario)``), or ``None`` to build it.
    """

    #: The plant's name, as results and summaries show it.
    plant_name = "mujoco"

    def __init__(self, scenario, plant=None):
        self.mujoco_plant = MujocoPlant(scenario, plant)
        import mujoco

        self.name = "mujoco"
        self.timestep = self.mujoco_plant.timestep
        #: The integrator row of a result's summary: the plant, MuJoCo's version and its integrator.
        self.label = f"mujoco plant (MuJoCo {mujoco.__version__}, semi-implicit Euler)"
        self._last = None

    def reset(self) -> None:
        """Forget the last state: the next :meth:`step` sets MuJoCo's state from its ``x``."""
        self._last = None

    def step(self, f, t: float, x, tau, h: float) -> np.ndarray:
        """The plant state ``h`` [s] after ``x`` with the joint torques ``tau`` held (``f``, ``t`` unused)."""
        mp = self.mujoco_plant
        if self._last is None or not np.array_equal(self._last, x):
            mp.set_state(x)
        self._last = mp.advance(tau, h).copy()
        return self._last.copy()
