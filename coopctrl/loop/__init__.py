"""The closed loop's parts: its state (:mod:`.state`), the compiled tick (:mod:`.kernel`), the driver
that runs a :class:`~coopctrl.closed_loop.ClosedLoop` with it (:mod:`.compiled`), the record
(:mod:`.record`), why a run stopped (:mod:`.diagnosis`), the loaded start (:mod:`.loaded_start`), the
Euler-angle band (:mod:`.euler_band`) and the QP's contact inputs for the loaded start (:mod:`.qp_inputs`,
wrapping their one definition in :mod:`coopctrl.load_distribution.contact_model`). Nothing here
imports ``coopctrl.analysis``."""

from coopctrl.loop.state import LoopState

__all__ = ["LoopState"]
