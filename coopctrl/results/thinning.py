"""The record a run keeps: every ``record_every``-th control tick (and the last), with the node poses.

The compiled loop records every tick; the summary's metrics are computed on that whole record
first (:attr:`SimulationResult.tick_summary`), then the record is thinned to the samples

    k = 0, r, 2 r, ..., and N - 1 (the last tick, always kept),

with ``r = simulation.record_every``. Events are kept whole. The node (end-effector) poses
``Y_nodes[k, i] = Phi_i(q_i(t_k))`` [m, rad] are computed on the kept samples only.
"""

from __future__ import annotations

from dataclasses import fields, replace
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: Array fields of a result that are not per sample (every other array whose first axis has N entries
#: is: t, x, tau, Y0, the wrenches, squeeze, the QP's figures, the energies, Y_nodes).
NOT_PER_SAMPLE = ("squeeze_desired", "tau_max")
#: Per-sample lists of a result.
SAMPLE_LISTS = ("qp_status", "qp_binding")


def kept_samples(n: int, record_every: int) -> np.ndarray:
    """Indices of the kept samples of ``n``: ``0, r, 2 r, ...`` and ``n - 1``."""
    if isinstance(record_every, bool) or not isinstance(record_every, (int, np.integer)) or record_every < 1:
        raise ValueError(f"record_every = {record_every!r} is invalid: expected an integer >= 1")
    index = np.arange(0, n, int(record_every))
    if n and index[-1] != n - 1:
        index = np.append(index, n - 1)
    return index


def thin(result: "SimulationResult", record_every: int) -> "SimulationResult":
    """``result`` keeping the samples :func:`kept_samples`; its summary stays the one of every tick.

    ``record_every = 1`` returns ``result`` itself."""
    n = result.t.shape[0]
    index = kept_samples(n, record_every)
    if record_every == 1:
        return result
    changes = {"record_every": int(record_every) * result.record_every,
               "tick_summary": result.summary()}
    for item in fields(result):
        value = getattr(result, item.name)
        if item.name not in NOT_PER_SAMPLE and isinstance(value, np.ndarray) and value.shape[:1] == (n,):
            changes[item.name] = value[index].copy()
    for name in SAMPLE_LISTS:
        value = getattr(result, name)
        if len(value) == n:
            changes[name] = [value[k] for k in index]
    return replace(result, **changes)


def node_poses(result: "SimulationResult", plant) -> np.ndarray:
    """``Y_nodes`` (N, m, p) of ``result``'s states: each arm's node pose (docs/model.md §2), in one
    compiled pass (:func:`coopctrl.results.node_poses.node_poses_of`)."""
    from coopctrl.results.node_poses import node_poses_of

    return node_poses_of(result.x, plant)


def finish_record(result: "SimulationResult", plant, record_every: int = 1) -> "SimulationResult":
    """The returned record of a run: thinned to every ``record_every``-th tick (:func:`thin`), with the
    node poses of the kept samples (:func:`node_poses`) of ``plant`` (``None``: without them)."""
    result = thin(result, record_every)
    if plant is not None:
        result.Y_nodes = node_poses(result, plant)
    return result
