"""Replay data without a simulation: a result that holds the scene's unloaded state at given
sample times (the page's tests check its drawing and its text, not the motion)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from coopctrl.scenario import build


def still_result(scenario, times, name=None, status="ok", reason=""):
    """A stand-in for :class:`~coopctrl.results.SimulationResult` with the fields
    :func:`coopctrl.replay.replay_data` reads: the unloaded state at every time of ``times`` [s]."""
    plant = scenario.plant()
    x0 = build.unloaded_state(scenario)
    t = np.asarray(times, dtype=float)
    m = len(scenario.arms)
    return SimpleNamespace(scenario=scenario.name if name is None else name, status=status, reason=reason,
                           t=t, x=np.tile(x0, (len(t), 1)), F_measured=np.zeros((len(t), m, plant.p)),
                           integrator=scenario.simulation.integrator, duration_s=float(t[-1]))
