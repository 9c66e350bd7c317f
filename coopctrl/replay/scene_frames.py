"""The geometry of a run, frame by frame, for the 3-D replay.

:func:`replay_data` turns a :class:`~coopctrl.results.SimulationResult` and the scenario it ran
into a JSON-ready dict: per frame the arms' link polylines (from their joint frames,
:func:`plants.arms.joint_frames.arm_polyline`), the contact nodes, the object's position and
rotation, each interconnection's two attachment points (it is drawn as a spring between them, so
it stretches) and the contact forces (world frame, on the object, at the contact nodes). Planar
scenes are mapped to the world x-z plane (y = 0). Positions in [m], forces in [N].
"""

from __future__ import annotations

import math

import numpy as np

from plants.arms.joint_frames import arm_polyline
from plants.frames import rotation_zyx

#: At most this many frames are stored in the page (the run is subsampled evenly).
MAX_FRAMES = 400


def _rotation(pose: np.ndarray, space: str) -> np.ndarray:
    if space == "spatial":
        return rotation_zyx(pose[3:6])
    c, s = math.cos(pose[2]), math.sin(pose[2])  # theta from +x towards +z: about -y
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def _position(pose: np.ndarray, space: str) -> np.ndarray:
    return np.asarray(pose[:3], float) if space == "spatial" else np.array([pose[0], 0.0, pose[1]])


def _force3(wrench: np.ndarray, space: str) -> np.ndarray:
    return np.asarray(wrench[:3], float) if space == "spatial" else np.array([wrench[0], 0.0, wrench[1]])


#: Drawn length of an unstretched interconnection, as a fraction of its grasp offset: the spring
#: is drawn from a point this far inside the grasp point to the node, so that it is visible
#: (the true deformations are millimetres) and stretches by the true amount.
SPRING_DRAWN_FRACTION = 0.4


def _grasp3(g: np.ndarray, space: str) -> np.ndarray:
    return np.array(g[:3], float) if space == "spatial" else np.array([g[0], 0.0, g[1]])


def _box_size(grasps: np.ndarray, space: str) -> list[float]:
    """Object box [m]: the springs' inner ends lie on its faces; every side at least 35 % of
    the longest (and 4 cm)."""
    inner = 1.0 - SPRING_DRAWN_FRACTION
    if space == "spatial":
        extent = np.abs(grasps[:, :3]).max(axis=0) * 2.0 * inner
    else:
        g = np.abs(grasps[:, :2]).max(axis=0) * 2.0 * inner
        extent = np.array([g[0], 0.0, g[1]])
    extent = np.maximum(extent, max(0.04, 0.35 * float(extent.max())))
    if space == "planar":
        extent[1] = 0.06  # a slab across the plane, so that it reads as a body
    return [float(v) for v in extent]


def _r(values, digits: int = 5) -> list:
    return np.round(np.asarray(values, float), digits).reshape(-1).tolist()


def replay_data(result, scenario, max_frames: int = MAX_FRAMES) -> dict:
    """The dict embedded in ``replay.html`` (see the module docstring)."""
    from coopctrl.scenario import build

    plant = scenario.plant()
    space = scenario.space
    grasps = build.true_grasps(scenario)
    m = len(scenario.arms)
    n_samples = int(result.t.shape[0])
    finite = np.isfinite(result.x).all(axis=1) if n_samples else np.zeros(0, bool)
    last = int(np.nonzero(finite)[0][-1]) if finite.any() else -1
    count = last + 1
    step = max(1, math.ceil(count / max_frames)) if count else 1
    picks = list(range(0, count, step))
    if count and picks[-1] != last:
        picks.append(last)  # always show the last finite state (where a failed run stopped)

    p = plant.p
    frames = []
    for k in picks:
        x = result.x[k]
        Y = plant.node_poses(x).reshape(m + 1, p)
        obj_pos, obj_R = _position(Y[0], space), _rotation(Y[0], space)
        nodes = [_position(Y[i], space) for i in range(1, m + 1)]
        arms = []
        for i, arm in enumerate(plant.arms):
            pts = arm_polyline(arm, x[plant.q_slice(i)])
            if pts is None and scenario.arms[i].model != "contact_point":
                # an arm without joint frames here: one segment from its base to its node
                pts = np.array([_position(np.asarray(scenario.arms[i].base, float), space), nodes[i]])
            arms.append(_r(pts) if pts is not None else [])  # a contact point is its node alone
        springs, stretch = [], []
        for sp in scenario.springs:
            ends, true_ends = [], []
            for node, other in (sp.pair, sp.pair[::-1]):
                if node == 0:
                    offset = _grasp3(grasps[other - 1], space)
                    true_ends.append(obj_pos + obj_R @ offset)
                    ends.append(obj_pos + obj_R @ (offset * (1.0 - SPRING_DRAWN_FRACTION)))
                else:
                    true_ends.append(nodes[node - 1])
                    ends.append(nodes[node - 1])
            springs.append(_r(np.concatenate(ends)))
            stretch.append(float(np.linalg.norm(true_ends[1] - true_ends[0])) if 0 in sp.pair else 0.0)
        F = result.F_measured[k] if np.isfinite(result.F_measured[k]).all() else np.zeros((m, p))
        frames.append({
            "t": round(float(result.t[k]), 6),
            "arms": arms,
            "nodes": _r(np.array(nodes)),
            "object": _r(np.concatenate([obj_pos, obj_R.reshape(-1)]), 6),
            "springs": springs,
            "deformation_mm": round(max(stretch) * 1e3, 4) if stretch else 0.0,
            "forces": _r(np.array([_force3(F[i], space) for i in range(m)]), 3),
        })
    fmax = max((float(np.abs(np.array(f["forces"])).max()) for f in frames if f["forces"]), default=0.0)
    pts = np.array([v for f in frames for a in f["arms"] for v in np.reshape(a, (-1, 3))] +
                   [v for f in frames for v in np.reshape(f["nodes"], (-1, 3))]) if frames else np.zeros((0, 3))
    bounds = (pts.min(axis=0).tolist(), pts.max(axis=0).tolist()) if len(pts) else ([-1, -1, 0], [1, 1, 1])
    span = float(np.max(np.subtract(bounds[1], bounds[0]))) if len(pts) else 1.0
    fail_t = None
    if result.status != "ok":
        fail_t = float(result.t[last]) if last >= 0 else 0.0
    return {
        "scenario": result.scenario,
        "status": result.status,
        "reason": result.reason,
        "space": space,
        "integrator": result.integrator,
        "duration_s": float(result.duration_s),
        "fail_t": fail_t,
        "box": _box_size(grasps, space),
        "bounds": bounds,
        "force_scale_m_per_N": (0.2 * span / fmax) if fmax > 0 else 0.0,
        "force_max_N": fmax,
        "arm_models": [a.model for a in scenario.arms],
        "leader": int(scenario.leader),
        "springs_pairs": [list(s.pair) for s in scenario.springs],
        "frames": frames,
    }
