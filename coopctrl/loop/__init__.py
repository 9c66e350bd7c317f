"""The closed loop's run machinery: its state (:mod:`.state`), the compiled tick (:mod:`.kernel`) and
the driver that runs a :class:`~coopctrl.closed_loop.ClosedLoop` with it (:mod:`.compiled`)."""

from coopctrl.loop.state import LoopState

__all__ = ["LoopState"]
