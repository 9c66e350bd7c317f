"""A result in the formats people use: a pandas DataFrame and a python-control ``TimeResponseData``.

Both carry the signals of :mod:`coopctrl.results.signals` under the same names and units as
``result.csv``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from coopctrl.results.signals import joint_labels, pose_names, signals

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: Where the wrenches are expressed (stated in every export).
WRENCH_FRAME = "world frame; wrench on the object at the contact node"


def to_pandas(result: "SimulationResult", units_in_names: bool = False):
    """A wide DataFrame: index ``t`` [s] (the control instants), one column per signal.

    Units are in ``df.attrs["units"]`` (column -> unit, ``"t"`` included) and, with
    ``units_in_names=True``, in the column names too (``"tau_arm1_j2 [N m]"``, as in result.csv).
    ``df.attrs`` also holds the scenario, status, reason, space and the wrench frame.

    Raises:
        ImportError: pandas is not installed (``pip install 'coopctrl[pandas]'``).
    """
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - exercised only without pandas
        raise ImportError("SimulationResult.to_pandas() needs pandas: pip install 'coopctrl[pandas]'") from None
    table = signals(result)
    names = [f"{n} [{u}]" if units_in_names else n for n, u, _ in table]
    data = np.column_stack([v for _, _, v in table]) if table else np.zeros((result.t.shape[0], 0))
    index = pd.Index(result.t, name="t [s]" if units_in_names else "t")
    frame = pd.DataFrame(data, index=index, columns=names)
    frame.attrs.update({
        "units": {"t": "s", **{n: u for n, u, _ in table}},
        "scenario": result.scenario,
        "status": result.status,
        "reason": result.reason,
        "space": result.space,
        "wrench_frame": WRENCH_FRAME,
    })
    return frame


def state_labels(result: "SimulationResult") -> list[str]:
    """Names of the state ``x = col(q, Y0, q', Y0')``: ``q_arm1_j1 ... Y0_x ... qd_... Y0d_...``."""
    joints = joint_labels(result)
    pose = pose_names(result.pose_size)
    return ([f"q_{j}" for j in joints] + [f"Y0_{c}" for c in pose]
            + [f"qd_{j}" for j in joints] + [f"Y0d_{c}" for c in pose])


def state_units(result: "SimulationResult") -> list[str]:
    """Units of :func:`state_labels`."""
    joints = len(joint_labels(result))
    pose = ["m" if c in ("x", "y", "z") else "rad" for c in pose_names(result.pose_size)]
    return ["rad"] * joints + pose + ["rad/s"] * joints + [u + "/s" for u in pose]


def to_time_response(result: "SimulationResult"):
    """A python-control :class:`control.TimeResponseData` with named signals.

    inputs: the joint torques ``tau_arm<i>_j<k>`` [N m]; states: ``x`` (:func:`state_labels`);
    outputs: every other signal of :mod:`coopctrl.results.signals` (object pose and its nominal,
    contact wrenches, squeezes, QP figures). ``response.units`` maps every label to its unit.
    """
    import control

    table = signals(result)
    inputs = [(n, u, v) for n, u, v in table if n.startswith("tau_")]
    outputs = [(n, u, v) for n, u, v in table if not n.startswith(("tau_", "q_", "qd_"))]
    labels = state_labels(result)
    x = result.x if result.x.shape[1] == len(labels) else None
    response = control.TimeResponseData(
        result.t,
        np.array([v for _, _, v in outputs]),
        states=None if x is None else x.T,
        inputs=np.array([v for _, _, v in inputs]),
        output_labels=[n for n, _, _ in outputs],
        input_labels=[n for n, _, _ in inputs],
        state_labels=labels if x is not None else None,
        title=f"{result.scenario} ({result.status})",
        sysname=result.scenario,
        success=result.status == "ok",
        message=result.reason or None,
    )
    units = {n: u for n, u, _ in outputs + inputs}
    if x is not None:
        units.update(zip(labels, state_units(result)))
    response.units = units
    response.wrench_frame = WRENCH_FRAME
    return response
