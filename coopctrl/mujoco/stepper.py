"""The MuJoCo plant as the compiled loop's external plant (:data:`coopctrl.loop.tick_codes.PLANT_EXTERNAL`).

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
from plants.errors import PlantError


class StateChanged(PlantError, RuntimeError):
    """The loop changed the plant state between two MuJoCo steps (its world chart re-centred on the object):
    the MuJoCo plant cannot follow a turned state. The run stops with this reason.

    Attributes:
        time_s: The time of the step [s].
    """

    def __init__(self, time_s: float):
        self.time_s = float(time_s)
        super().__init__(f"the loop turned the state into a new world chart at t = {time_s:.6g} s (the object's pitch "
                         "left the chart), which the MuJoCo plant cannot follow; run this scene on the elastic plant")


class MujocoStepper:
    """``step(f, t, x, tau, h)`` advances a :class:`MujocoPlant` by ``h`` [s] with ``tau`` [N m] held.

    MuJoCo's state is set from ``x`` at a run's start (after :meth:`reset`, at ``t = 0``); afterwards every ``x``
    must be the state the last step returned, and MuJoCo continues from its own state. A loop that turned the
    state (its world chart re-centred: :meth:`reset` again, or another ``x``) stops the run with
    :class:`StateChanged`.

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
        if self._last is None and t == 0.0:
            mp.set_state(x)
        elif self._last is None or not np.array_equal(self._last, x):
            raise StateChanged(t)
        self._last = mp.advance(tau, h).copy()
        return self._last.copy()
