"""The closed loop's parts: its state (:mod:`.state`), the model and data the compiled tick reads by name
(:mod:`.model`, :mod:`.data`; the tick itself is coopctrl/core/tick.h, :class:`coopctrl._core.Tick`), its stop
codes (:mod:`.tick_codes`), the driver that runs a :class:`~coopctrl.closed_loop.ClosedLoop` with it
(:mod:`.compiled`), the record
(:mod:`.record`), why a run stopped (:mod:`.diagnosis`), the loaded start (:mod:`.loaded_start`), the
Euler-angle band (:mod:`.euler_band`) and the QP's contact inputs for the loaded start (:mod:`.qp_inputs`,
wrapping their one definition in the compiled core, coopctrl/core/qp_contact_model.h). Nothing here
imports ``coopctrl.analysis``.

:class:`LoopState` is imported on first use (PEP 562)."""

__all__ = ["LoopState"]


def __getattr__(name: str):
    """``LoopState``, imported from :mod:`.state` on first use."""
    if name == "LoopState":
        from coopctrl.loop.state import LoopState

        globals()[name] = LoopState
        return LoopState
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
