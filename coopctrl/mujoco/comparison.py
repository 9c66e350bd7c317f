"""Two plants side by side: one scene run on the elastic plant and on MuJoCo with the same controller.

:func:`compare_plants` runs both and reports, per signal, the largest difference between the two records and
its time: the object's position [m] and orientation [rad] (the Euler-angle difference of ``Y_0``), the
measured contact wrenches (forces [N] and couples [N m]) and the joint torques [N m]; beside each run's own
tracking figures. docs/mujoco.md says which differences come from the models and which would be a bug.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SignalDifference:
    """The largest difference of one signal between the two runs.

    Attributes:
        signal: Its name.
        unit: Its unit.
        max_abs: The largest norm of the difference over the run (per tick: the Euclidean norm over the signal's
            components of one contact, joint set or pose part; the largest over contacts) [unit].
        time_s: The time of ``max_abs`` [s].
        rms: The RMS over ticks of that per-tick norm [unit].
        scale: The largest norm of the signal itself in the elastic run [unit] (what the difference compares to).
    """

    signal: str
    unit: str
    max_abs: float
    time_s: float
    rms: float
    scale: float


@dataclass(frozen=True)
class PlantComparison:
    """The two runs' summaries and their differences.

    Attributes:
        scenario: The scene's name.
        elastic, mujoco: The two runs' summaries (:meth:`SimulationResult.summary`).
        differences: One :class:`SignalDifference` per signal.
    """

    scenario: str
    elastic: dict
    mujoco: dict
    differences: tuple

    def lines(self) -> list[str]:
        """The comparison as printable lines."""
        out = [f"scene {self.scenario}: elastic plant vs MuJoCo plant, same controller",
               f"{'':34}{'elastic':>14}{'mujoco':>14}"]
        rows = (("status", "status", None, ""), ("object position error RMS", "object_position_error_rms_m", 1e3, "mm"),
                ("object position error max", "object_position_error_max_m", 1e3, "mm"),
                ("follower force error RMS", "follower_force_error_rms_N", 1.0, "N"),
                ("max torque ratio", "max_torque_ratio", 1.0, ""), ("QP failures", "qp_failures", None, ""),
                ("real-time factor", "realtime_factor", 1.0, "x"))
        for label, key, scale, unit in rows:
            vals = []
            for s in (self.elastic, self.mujoco):
                v = s.get(key)
                vals.append("-" if v is None else (f"{v * scale:.4g}" if scale else str(v)))
            out.append(f"{(label + (f' [{unit}]' if unit else '')):34}{vals[0]:>14}{vals[1]:>14}")
        out.append(f"{'difference (mujoco - elastic)':34}{'max':>14}{'at t [s]':>10}{'RMS':>14}{'signal max':>14}")
        for d in self.differences:
            out.append(f"{(d.signal + f' [{d.unit}]'):34}{d.max_abs:>14.4g}{d.time_s:>10.4g}{d.rms:>14.4g}{d.scale:>14.4g}")
        return out

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {"scenario": self.scenario, "elastic": self.elastic, "mujoco": self.mujoco,
                "differences": [d.__dict__ for d in self.differences]}


def _difference(name: str, unit: str, t, a, b) -> SignalDifference:
    """:class:`SignalDifference` of ``b - a`` (ticks, groups, components): per tick the largest group norm."""
    n = min(len(a), len(b))
    diff = np.linalg.norm(b[:n] - a[:n], axis=-1)
    per_tick = diff.reshape(n, -1).max(axis=1) if diff.ndim > 1 else diff
    k = int(np.argmax(per_tick)) if n else 0
    scale = float(np.max(np.linalg.norm(a[:n], axis=-1))) if n else float("nan")
    return SignalDifference(name, unit, float(per_tick[k]) if n else float("nan"), float(t[k]) if n else float("nan"),
                            float(np.sqrt(np.mean(per_tick ** 2))) if n else float("nan"), scale)


def differences(elastic, mujoco) -> tuple:
    """The :class:`SignalDifference` of each compared signal between two :class:`SimulationResult` records."""
    p = elastic.Y0.shape[1]
    npos = 3 if p == 6 else 2
    t = elastic.t
    out = [_difference("object position", "m", t, elastic.Y0[:, :npos], mujoco.Y0[:, :npos]),
           _difference("object orientation", "rad", t, elastic.Y0[:, npos:], mujoco.Y0[:, npos:]),
           _difference("contact force", "N", t, elastic.F_measured[:, :, :npos], mujoco.F_measured[:, :, :npos]),
           _difference("contact couple", "N m", t, elastic.F_measured[:, :, npos:], mujoco.F_measured[:, :, npos:]),
           _difference("joint torques", "N m", t, elastic.tau, mujoco.tau)]
    return tuple(out)


def compare_plants(scenario, progress: bool = False) -> PlantComparison:
    """Run ``scenario`` on both plants (every tick recorded) and compare them (:class:`PlantComparison`)."""
    from dataclasses import replace

    from coopctrl.simulator import simulate

    every = replace(scenario, simulation=replace(scenario.simulation, record_every=1))
    elastic = simulate(every, progress=progress, node_poses=False)
    mujoco = simulate(every, progress=progress, node_poses=False, plant="mujoco")
    return PlantComparison(scenario.name, elastic.summary(), mujoco.summary(), differences(elastic, mujoco))
