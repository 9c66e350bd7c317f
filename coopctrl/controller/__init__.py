"""The control layer as one object: :class:`Controller`, stepped once per control period from a
:class:`Measurement`, returning :class:`Torques`, with its state a :class:`ControllerState` (``docs/controller.md``).

- :mod:`~coopctrl.controller.controller`: :class:`Controller`;
- :mod:`~coopctrl.controller.measurement`: :class:`Measurement`, what one step reads;
- :mod:`~coopctrl.controller.torques`: :class:`Torques`, what one step returns;
- :mod:`~coopctrl.controller.controller_state`: :class:`ControllerState`, what it carries between steps.

The compiled step itself is the tick's controller step (coopctrl/core/tick.h, ``coopctrl._core.Tick.controller_step``).
"""

from coopctrl.controller.controller import Controller
from coopctrl.controller.controller_state import ControllerState
from coopctrl.controller.measurement import Measurement
from coopctrl.controller.torques import Torques

__all__ = ["Controller", "ControllerState", "Measurement", "Torques"]
